// The reference well model of the accuracy study: the case's reservoir grid with every cell
// active (no well block) and Peaceman well connections in the cells the trajectory crosses.
// Deviated wells use the usual projections (Eclipse/ResInsight practice): per cell the
// trajectory's length components Lx, Ly, Lz, a Peaceman index per direction, combined as
// sqrt(WIx^2 + WIy^2 + WIz^2). Formulas: docs/accuracy.md.
#pragma once
#include <cstdint>
#include <vector>

#include "meshgen/case/case.hpp"
#include "meshgen/core/geometry.hpp"
#include "meshgen/grids/reservoir_grid.hpp"
#include "tpfa.hpp"

namespace hm {

struct CartesianMesh {
  ReservoirGrid grid;
  PolyMesh mesh;
  MeshGeometry geo;
  std::vector<int32_t> mesh_cell;  ///< per reservoir cell (natural order): its mesh cell id
};

/// Every lattice cell as a hexahedron, outer faces on kOuterBoundary.
CartesianMesh make_cartesian_mesh(const ReservoirSpec& spec);

/// The part of a trajectory inside one grid cell (all pieces in that cell merged).
struct TrajectoryInCell {
  int32_t grid_cell = -1;  ///< natural reservoir index
  Vec3 extent;             ///< sum over pieces of (|dx|, |dy|, |dz|) (m)
  double length = 0;       ///< sum of piece lengths (m)
  Vec3 midpoint;           ///< length-weighted mean of the piece midpoints
};

/// Cells crossed by the polyline, in order of first visit. A piece lying exactly on a grid
/// plane is given to the cell on the + side. Pieces outside the box are dropped.
std::vector<TrajectoryInCell> trajectory_cells(const ReservoirGrid& grid, const std::vector<Vec3>& polyline);

/// Peaceman's equivalent radius for a well along one axis, with (d1, k1) and (d2, k2) the
/// cell sizes and permeabilities across it: 0.28 sqrt(sqrt(k2/k1) d1^2 + sqrt(k1/k2) d2^2) /
/// ((k2/k1)^(1/4) + (k1/k2)^(1/4)); 0.1985 d for a square cell in isotropic k.
double peaceman_radius(double d1, double d2, double k1, double k2);

/// Peaceman connection factor (cP.rm3/day/bar) of a trajectory piece in a cell of size
/// `size` and permeability `perm` (mD): the x, y, z components combined in quadrature.
/// Throws std::invalid_argument when r_o <= r_w in a direction that carries length.
double peaceman_connection_factor(Vec3 size, Vec3 perm, Vec3 extent, double r_w);

/// The Peaceman connections of well `well` on a Cartesian mesh (point = midpoint of the
/// trajectory in the cell, where the accuracy study evaluates the exact wellbore pressure).
std::vector<WellConnection> peaceman_connections(const CartesianMesh& cm, const WellSpec& ws, int well);
/// The same along any polyline (the accuracy study uses the meshed axis of the well block).
std::vector<WellConnection> peaceman_connections(const CartesianMesh& cm, const std::vector<Vec3>& polyline,
                                                 double r_w, int well);

}  // namespace hm
