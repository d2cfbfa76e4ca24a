// Reservoir models from Eclipse/OPM decks (GRDECL: SPECGRID/COORD/ZCORN/ACTNUM, PERMX/PERMY/PERMZ,
// PORO, NTG, MAPAXES), read with OPM's own parser and grid (libopm-common), so that every keyword
// (INCLUDE, MULTIPLY, BOX, EQUALS, MINPV, PINCH, ...) means what it means in OPM Flow.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "meshgen/core/vec3.hpp"

namespace hm {

struct ReservoirSpec;

/// A corner-point model as OPM reads it. Arrays are per cell in natural order
/// (i fastest, then j, then k; size nx*ny*nz), rock in mD and fractions.
struct CornerPointModel {
  int nx = 0, ny = 0, nz = 0;
  /// 8 corners per cell in the grid's input frame (COORD/ZCORN; z depth, positive down);
  /// corner bit 0 = +i, bit 1 = +j, bit 2 = +k (OPM's and Eclipse's order).
  std::vector<std::array<Vec3, 8>> corners;
  std::vector<int> actnum;                     ///< 1 active, 0 inactive (ACTNUM after MINPV/PINCH)
  std::vector<double> permx, permy, permz;     ///< mD
  std::vector<double> poro, ntg;               ///< NTG is 1 where the deck has none
  bool has_mapaxes = false;
  /// MAPAXES as OPM applies it: the map (world) position of grid point (0, 0) and of the
  /// unit grid x and y directions (origin, unit_x, unit_y), for has_mapaxes.
  std::array<double, 2> map_origin{0, 0}, map_unit_x{1, 0}, map_unit_y{0, 1};
  int n_active() const;
};

/// Reads a deck or a GRDECL file (INCLUDEs followed, relative to its folder). Throws InputError
/// naming `key` when the file is missing, OPM refuses it, or it has no grid or no PERMX/PORO.
CornerPointModel read_corner_point_model(const std::string& path, const std::string& key);

/// The reservoir of a corner-point model whose geometry is a rectilinear grid (vertical pillars
/// on lines x = x_i, y = y_j, horizontal layers z = z_k, every cell active): axes and per-cell
/// rock (porosity x NTG). Decided by exact equality of the corner coordinates, no tolerance. Throws
/// InputError naming `key` and the first cell that is not (corner-point geometry is not meshed yet).
ReservoirSpec rectilinear_reservoir(const CornerPointModel& model, const std::string& key);

}  // namespace hm
