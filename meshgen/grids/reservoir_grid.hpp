// Structured, non-uniform Cartesian reservoir grid (paper section 5: the reservoir mesh).
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "meshgen/case/case.hpp"
#include "meshgen/core/mesh_builder.hpp"

namespace hm {

/// Index arithmetic over the lattice; coordinates come from the case file.
struct ReservoirGrid {
  std::vector<double> x, y, z;  ///< node coordinates per axis (strictly increasing)
  int nx() const { return static_cast<int>(x.size()) - 1; }
  int ny() const { return static_cast<int>(y.size()) - 1; }
  int nz() const { return static_cast<int>(z.size()) - 1; }
  int n_cells() const { return nx() * ny() * nz(); }
  int n_nodes() const { return (nx() + 1) * (ny() + 1) * (nz() + 1); }
  /// Natural (Eclipse) order: i fastest, then j, then k.
  int cell_index(int i, int j, int k) const { return i + nx() * (j + ny() * k); }
  std::array<int, 3> cell_ijk(int c) const { return {c % nx(), (c / nx()) % ny(), c / (nx() * ny())}; }
  int node_index(int i, int j, int k) const { return i + (nx() + 1) * (j + (ny() + 1) * k); }
  Vec3 node(int i, int j, int k) const { return {x[i], y[j], z[k]}; }
  Vec3 cell_center(int c) const;
  Vec3 cell_lo(int c) const;  ///< min corner
  Vec3 cell_hi(int c) const;  ///< max corner
  /// The 8 lattice node indices of cell c; bit 0 of the position = +x, bit 1 = +y, bit 2 = +z.
  std::array<int, 8> cell_nodes(int c) const;
  /// The 4 lattice node indices of face `side` of cell c (side: 0 -x, 1 +x, 2 -y, 3 +y, 4 -z, 5 +z),
  /// ordered so that the right-hand normal points out of cell c.
  std::array<int, 4> cell_face_nodes(int c, int side) const;
  /// Neighbour across `side`, or -1 on the outer boundary.
  int neighbour(int c, int side) const;
  double box_volume() const { return (x.back() - x.front()) * (y.back() - y.front()) * (z.back() - z.front()); }
};

ReservoirGrid make_reservoir_grid(const ReservoirSpec& spec);

/// Adds every lattice node to the builder; returns the builder id of lattice node n at [n].
std::vector<int32_t> add_reservoir_nodes(const ReservoirGrid& grid, MeshBuilder& builder);

/// Adds the active cells (active[c] != 0) as hexahedra with (i,j,k), perm and porosity.
/// Outer-box faces get patch kOuterBoundary; faces toward an inactive cell are
/// interior (the transition mesh must claim them). Returns the mesh cell id per
/// reservoir cell (-1 when inactive). `added_after`: what the caller adds next, reserved now so
/// that the builder's million-entry arrays are not grown (copied) again for a few more cells.
std::vector<int32_t> add_reservoir_cells(const ReservoirGrid& grid, const ReservoirSpec& spec,
                                         const std::vector<int32_t>& node_ids,
                                         const std::vector<char>& active, MeshBuilder& builder,
                                         const BuilderCapacity& added_after = {});

}  // namespace hm
