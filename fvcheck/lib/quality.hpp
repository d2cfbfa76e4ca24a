// Quality statistics per region and histograms for fvcheck's reports; the criteria
// themselves (Q_S, Q_O, Q_P) are the kernel in meshgen/core/fv_quality.hpp.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "meshgen/core/fv_quality.hpp"
#include "meshgen/core/geometry.hpp"
#include "meshgen/core/polymesh.hpp"

namespace hm {

/// Counts of values in nbins equal bins over [lo, hi]; values outside are clamped to the
/// first/last bin, NaNs are ignored.
std::vector<int64_t> histogram(const std::vector<double>& values, const std::vector<bool>& mask, double lo,
                               double hi, int nbins);

struct RegionQuality {
  int32_t region = 0;
  std::string name;  ///< "reservoir", "transition", "well", or "region_<code>"
  int64_t cells = 0;
  Stats q_s, q_o, q_p;  ///< over the region's cells (cell values Q_S, Q_O(V), Q_P(V))
  /// K-non-orthogonality (deg) over the region's cells, cell value = max over its faces of
  /// face_k_nonorthogonality; count 0 when the mesh has no permeability.
  Stats k_angle;
  Stats k_angle_interior;  ///< the same over interior faces only (boundary faces measure to the face centroid)
};
std::string region_name(int32_t region);
/// One entry per region present in the mesh, ascending region code.
std::vector<RegionQuality> quality_by_region(const PolyMesh& mesh, const std::vector<double>& q_s,
                                             const std::vector<double>& q_o_cell,
                                             const std::vector<double>& q_p_cell,
                                             const std::vector<double>& k_angle_cell = {},
                                             const std::vector<double>& k_angle_interior_cell = {});

}  // namespace hm
