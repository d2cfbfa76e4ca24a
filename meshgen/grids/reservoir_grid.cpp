#include "reservoir_grid.hpp"

#include <algorithm>
#include <array>

namespace hm {

ReservoirGrid make_reservoir_grid(const ReservoirSpec& spec) {
  ReservoirGrid g;
  g.x = spec.x;
  g.y = spec.y;
  g.z = spec.z;
  return g;
}

Vec3 ReservoirGrid::cell_lo(int c) const {
  const auto ijk = cell_ijk(c);
  return {x[ijk[0]], y[ijk[1]], z[ijk[2]]};
}

Vec3 ReservoirGrid::cell_hi(int c) const {
  const auto ijk = cell_ijk(c);
  return {x[ijk[0] + 1], y[ijk[1] + 1], z[ijk[2] + 1]};
}

Vec3 ReservoirGrid::cell_center(int c) const { return 0.5 * (cell_lo(c) + cell_hi(c)); }

std::array<int, 8> ReservoirGrid::cell_nodes(int c) const {
  const auto ijk = cell_ijk(c);
  std::array<int, 8> n{};
  for (int b = 0; b < 8; ++b) n[b] = node_index(ijk[0] + (b & 1), ijk[1] + ((b >> 1) & 1), ijk[2] + ((b >> 2) & 1));
  return n;
}

std::array<int, 4> ReservoirGrid::cell_face_nodes(int c, int side) const {
  const auto n = cell_nodes(c);
  // Corner bit layout: bit 0 = +x, bit 1 = +y, bit 2 = +z; cycles give outward normals.
  static const int kFace[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                  {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  return {n[kFace[side][0]], n[kFace[side][1]], n[kFace[side][2]], n[kFace[side][3]]};
}

int ReservoirGrid::neighbour(int c, int side) const {
  auto ijk = cell_ijk(c);
  const int axis = side / 2;
  const int step = (side % 2) ? 1 : -1;
  const int lim[3] = {nx(), ny(), nz()};
  ijk[axis] += step;
  if (ijk[axis] < 0 || ijk[axis] >= lim[axis]) return -1;
  return cell_index(ijk[0], ijk[1], ijk[2]);
}

std::vector<int32_t> add_reservoir_nodes(const ReservoirGrid& grid, MeshBuilder& builder) {
  std::vector<int32_t> ids(grid.n_nodes());
  for (int k = 0; k <= grid.nz(); ++k)
    for (int j = 0; j <= grid.ny(); ++j)
      for (int i = 0; i <= grid.nx(); ++i) ids[grid.node_index(i, j, k)] = builder.add_node(grid.node(i, j, k));
  return ids;
}

std::vector<int32_t> add_reservoir_cells(const ReservoirGrid& grid, const ReservoirSpec& spec,
                                         const std::vector<int32_t>& node_ids, const std::vector<char>& active,
                                         MeshBuilder& builder, const BuilderCapacity& added_after) {
  std::vector<int32_t> cell_id(grid.n_cells(), -1);
  std::vector<CellFace> faces(6);  // reused: no allocation per cell
  std::vector<int32_t> face_ids;
  const size_t n_active = static_cast<size_t>(std::count(active.begin(), active.end(), 1));
  const size_t n_outer = 2 * (static_cast<size_t>(grid.nx()) * grid.ny() + static_cast<size_t>(grid.ny()) * grid.nz() +
                              static_cast<size_t>(grid.nx()) * grid.nz());
  const size_t n_faces = 3 * n_active + n_outer;  // each cell's three low faces, and the far sides
  builder.reserve(n_active + added_after.cells, n_faces + added_after.faces, 4 * n_faces + added_after.face_nodes);
  // A face between two active cells is named by id by the second (the structure pairs them);
  // only faces toward inactive (cavity) cells are looked up by their nodes, by the transition.
  std::array<std::vector<int32_t>, 3> high_face;  // per axis: the face id of each cell's + side
  for (auto& h : high_face) h.assign(grid.n_cells(), -1);
  for (int c = 0; c < grid.n_cells(); ++c) {
    if (!active[c]) continue;
    for (int side = 0; side < 6; ++side) {
      const auto fn = grid.cell_face_nodes(c, side);
      CellFace& face = faces[side];
      face.nodes.assign({node_ids[fn[0]], node_ids[fn[1]], node_ids[fn[2]], node_ids[fn[3]]});
      const int nb = grid.neighbour(c, side);
      face.patch = nb < 0 ? kOuterBoundary : kInteriorFace;
      const bool paired = nb >= 0 && active[nb];
      face.known_face = paired && side % 2 == 0 ? high_face[side / 2][nb] : -1;
      face.by_id_only = nb < 0 || (paired && side % 2 == 1);
    }
    CellAttributes at;
    at.region = kReservoir;
    at.fv_center = grid.cell_center(c);
    const auto ijk = grid.cell_ijk(c);
    at.ijk = {ijk[0], ijk[1], ijk[2]};
    assign_reservoir_rock(spec, c, at);
    cell_id[c] = builder.add_cell(faces, at, &face_ids);
    for (int axis = 0; axis < 3; ++axis) high_face[axis][c] = face_ids[2 * axis + 1];
  }
  return cell_id;
}

}  // namespace hm
