// Optimisation of the transition mesh (paper 6.2): small edges are removed, then
// expanded, under finite-volume controls (in all three phases: see optimize.cpp). Constrained vertices (those of the reservoir
// and well grids) never move, so conformity with the structured grids and the total
// volume are preserved; every accepted change keeps the touched cells closed, convex
// (if they were) and with positive volume, and keeps every face within OpenFOAM's skewness
// limit if it was; a last phase collapses skewed faces where the controls allow it.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "meshgen/core/polymesh.hpp"

namespace hm {

struct OptimizeParams {
  std::array<double, 3> gamma{0.05, 0.30, 0.40};  ///< G1, G2, G3: edge thresholds as fractions of h
  double omega_o = 85;     ///< orthogonality threshold (deg): a cell is orthogonal if Q_O(V) >= it
  double omega_p = 10;     ///< planarity threshold (deg): a cell is planar if Q_P(V) <= it
  double expansion = 1.1;  ///< edge expansion coefficient alpha, 1 < alpha <= 1.1
  int max_passes = 30;     ///< passes per phase before giving up on a fixed point
};

struct OptimizeReport {
  int removed_below_g1 = 0;      ///< phase 1: edges < G1 h removed
  int removed_below_g2 = 0;      ///< phase 2: edges < G2 h removed
  int expanded = 0;              ///< phase 3: edges < G3 h, expanded
  int collapsed_faces = 0;       ///< of the removals: small faces collapsed to a point at once
  int rejected = 0;              ///< candidate operations refused (the sum of the reasons below)
  int rejected_invalid = 0;      ///< would open, flatten or invert a cell
  int rejected_convexity = 0;    ///< would make a convex cell non-convex
  int rejected_orthogonality = 0;  ///< Q_O(V) below the cell's threshold
  int rejected_planarity = 0;    ///< Q_P(V) above the cell's threshold
  int rejected_centering = 0;    ///< a site would leave its cell
  int rejected_shape = 0;        ///< expansion without mean Q_S improvement
  int rejected_skewness = 0;     ///< a face within the skewness limit pushed above it (or the target face not unskewed)
  int skewness_removed = 0;      ///< skewness phase: operations that removed or unskewed a face
  int skewed_faces = 0;          ///< after: faces of transition cells with OpenFOAM skewness > kOpenFoamSkewnessLimit
  double max_skewness = 0;       ///< after: their largest OpenFOAM skewness
  int passes = 0;
};

/// OpenFOAM's face skewness (checkMesh flags faces above 4), per face: cell centres are
/// geometric centroids and face centres area-weighted, computed as OpenFOAM does.
std::vector<double> openfoam_face_skewness(const PolyMesh& mesh);

/// Skewness above which the optimiser treats a face as skewed: OpenFOAM's 4, less a margin
/// for the precision of the written points.
inline constexpr double kOpenFoamSkewnessLimit = 3.95;

/// Optimises the transition cells (region kTransition) of `mesh`. h_ref[c] is the Q_S
/// reference length of cell c (used for transition cells). Returns the new mesh: same
/// cells in the same order with the same attributes; nodes renumbered.
PolyMesh optimize_transition(const PolyMesh& mesh, const std::vector<double>& h_ref, const OptimizeParams& params,
                             OptimizeReport* report);

}  // namespace hm
