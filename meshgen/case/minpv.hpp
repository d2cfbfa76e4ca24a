// OPM Flow's MINPV processing of a corner-point model (docs/corner-point.md, "MINPV"): which active
// cells it removes and which cells of a column it connects across them. A port of opm-grid's
// MinpvProcessor::process (release 2022.10, the Debian package flow runs; mergeMinPVCells false, as
// processEclipseFormat calls it), quirks included, so that the mesh removes and connects the cells
// flow does. No OPM here: the caller hands over OPM's arrays.
#pragma once
#include <cstdint>
#include <utility>
#include <vector>

namespace hm {

struct MinpvInput {
  int nx = 0, ny = 0, nz = 0;
  std::vector<double> thickness;  ///< per cell (EclipseGrid::getCellThickness)
  std::vector<double> pore_volume;  ///< per cell (FieldPropsManager::porv(true))
  std::vector<double> minpv;        ///< per cell (EclipseGrid::getMinpvVector)
  std::vector<int> actnum;          ///< per cell (EclipseGrid's)
  double z_tolerance = 0;           ///< PINCH's threshold thickness when PINCH is active, else 0
  bool pinch_nogap = false;         ///< PINCH option NOGAP
};

struct MinpvResult {
  std::vector<int64_t> removed;  ///< active cells below MINPV, natural order
  /// (upper, lower) natural indices: cells of one column flow connects across removed cells.
  std::vector<std::pair<int64_t, int64_t>> connections;
};

MinpvResult opm_minpv(const MinpvInput& in);

}  // namespace hm
