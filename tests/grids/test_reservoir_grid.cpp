#include <gtest/gtest.h>

#include "meshgen/core/geometry.hpp"
#include "meshgen/grids/reservoir_grid.hpp"

using namespace hm;

namespace {
ReservoirSpec spec() {
  ReservoirSpec s;
  s.x = {0, 30, 55, 61.7, 70, 100};
  s.y = {-10, 0, 2.5, 40};
  s.z = {1000, 1003, 1010.1, 1030};
  s.permeability = {120, 80, 12};
  s.porosity = 0.25;
  return s;
}
}  // namespace

TEST(ReservoirGrid, AllActiveGridIsConformingClosedWithExactVolumes) {
  const ReservoirSpec s = spec();
  const ReservoirGrid g = make_reservoir_grid(s);
  MeshBuilder b;
  const auto nodes = add_reservoir_nodes(g, b);
  const std::vector<char> active(g.n_cells(), 1);
  const auto ids = add_reservoir_cells(g, s, nodes, active, b);
  BuildReport rep;
  const PolyMesh m = b.finish(&rep);
  ASSERT_TRUE(rep.ok) << (rep.problems.empty() ? "" : rep.problems[0]);
  EXPECT_TRUE(check_csr_invariants(m).ok);
  ASSERT_EQ(m.n_cells(), 5 * 3 * 3);
  // Faces: interior ones shared, boundary ones on the outer patch; counts by axis.
  const int nx = 5, ny = 3, nz = 3;
  const int interior = (nx - 1) * ny * nz + nx * (ny - 1) * nz + nx * ny * (nz - 1);
  const int boundary = 2 * (ny * nz + nx * nz + nx * ny);
  int n_interior = 0, n_outer = 0;
  for (int f = 0; f < m.n_faces(); ++f) (m.face_neighbour[f] >= 0 ? n_interior : n_outer) += 1;
  EXPECT_EQ(n_interior, interior);
  EXPECT_EQ(n_outer, boundary);
  const MeshGeometry geo = compute_geometry(m);
  for (int c = 0; c < g.n_cells(); ++c) {
    const int mc = ids[c];
    const Vec3 lo = g.cell_lo(c), hi = g.cell_hi(c);
    const double exact = (hi.x - lo.x) * (hi.y - lo.y) * (hi.z - lo.z);
    EXPECT_NEAR(geo.cell_volume[mc], exact, 1e-12 * exact);
    EXPECT_LT(norm(cell_area_sum(m, geo, mc)), 1e-12 * std::pow(exact, 2.0 / 3.0));
    EXPECT_EQ(m.cell_ijk[mc][0], g.cell_ijk(c)[0]);
    EXPECT_EQ(m.cell_fv_center[mc], g.cell_center(c));
    EXPECT_EQ(m.cell_perm[mc], s.permeability);
  }
  EXPECT_NEAR(total_volume(geo), g.box_volume(), 1e-12 * g.box_volume());
}

TEST(ReservoirGrid, InactiveCellsLeaveFacesThatMustBeClaimed) {
  const ReservoirSpec s = spec();
  const ReservoirGrid g = make_reservoir_grid(s);
  MeshBuilder b;
  const auto nodes = add_reservoir_nodes(g, b);
  std::vector<char> active(g.n_cells(), 1);
  active[g.cell_index(2, 1, 1)] = 0;  // an interior cell: its 6 neighbours' faces are unmatched
  add_reservoir_cells(g, s, nodes, active, b);
  BuildReport rep;
  b.finish(&rep);
  EXPECT_FALSE(rep.ok);
  EXPECT_EQ(rep.unmatched_faces, 6);
}

TEST(ReservoirGrid, NeighboursAndFaceOrientation) {
  const ReservoirGrid g = make_reservoir_grid(spec());
  const int c = g.cell_index(1, 1, 1);
  EXPECT_EQ(g.neighbour(c, 0), g.cell_index(0, 1, 1));
  EXPECT_EQ(g.neighbour(c, 5), g.cell_index(1, 1, 2));
  EXPECT_EQ(g.neighbour(g.cell_index(4, 0, 0), 1), -1);
  // Each face's right-hand normal points away from the cell centre.
  for (int side = 0; side < 6; ++side) {
    const auto f = g.cell_face_nodes(c, side);
    auto node = [&](int n) {
      const int i = n % (g.nx() + 1), j = (n / (g.nx() + 1)) % (g.ny() + 1), k = n / ((g.nx() + 1) * (g.ny() + 1));
      return g.node(i, j, k);
    };
    const Vec3 n = cross(node(f[1]) - node(f[0]), node(f[2]) - node(f[0]));
    EXPECT_GT(dot(n, node(f[0]) - g.cell_center(c)), 0) << "side " << side;
  }
}

namespace {
// The grid's active cells added with every face looked up by its nodes (the builder's general
// path), for comparison with add_reservoir_cells, which pairs faces by the structure.
PolyMesh by_lookup(const ReservoirGrid& g, const ReservoirSpec& s, const std::vector<char>& active) {
  MeshBuilder b;
  const auto nodes = add_reservoir_nodes(g, b);
  for (int c = 0; c < g.n_cells(); ++c) {
    if (!active[c]) continue;
    std::vector<CellFace> faces(6);
    for (int side = 0; side < 6; ++side) {
      const auto fn = g.cell_face_nodes(c, side);
      faces[side].nodes = {nodes[fn[0]], nodes[fn[1]], nodes[fn[2]], nodes[fn[3]]};
      faces[side].patch = g.neighbour(c, side) < 0 ? kOuterBoundary : kInteriorFace;
    }
    CellAttributes at;
    at.fv_center = g.cell_center(c);
    at.perm = reservoir_permeability(s, c);
    b.add_cell(faces, at);
  }
  BuildReport rep;
  return b.finish(&rep);
}
}  // namespace

TEST(ReservoirGrid, FacesPairedByTheStructureAreTheFacesFoundByTheirNodes) {
  const ReservoirSpec s = spec();
  const ReservoirGrid g = make_reservoir_grid(s);
  std::vector<char> active(g.n_cells(), 1);
  active[g.cell_index(2, 1, 1)] = 0;
  active[g.cell_index(0, 0, 0)] = 0;
  active[g.cell_index(4, 2, 2)] = 0;
  MeshBuilder b;
  const auto nodes = add_reservoir_nodes(g, b);
  add_reservoir_cells(g, s, nodes, active, b);
  // The inactive interior cell's six faces are still found by their nodes (as the transition
  // finds them): a cell naming them reversed closes them.
  const int hole = g.cell_index(2, 1, 1);
  std::vector<CellFace> filler(6);
  for (int side = 0; side < 6; ++side) {
    const auto fn = g.cell_face_nodes(hole, side);
    filler[side].nodes = {nodes[fn[0]], nodes[fn[1]], nodes[fn[2]], nodes[fn[3]]};
  }
  b.add_cell(filler, CellAttributes{});
  BuildReport rep;
  const PolyMesh m = b.finish(&rep);
  EXPECT_EQ(rep.unmatched_faces, 6);  // the two corner cells' neighbours' faces, unclaimed
  EXPECT_EQ(rep.misoriented_faces + rep.overused_faces + rep.degenerate_faces, 0);
  int filler_neighbours = 0;
  for (int f = 0; f < m.n_faces(); ++f) filler_neighbours += m.face_neighbour[f] == m.n_cells() - 1;
  EXPECT_EQ(filler_neighbours, 6);

  // Without the filler: the same faces, owners, neighbours and patches as the lookup path.
  MeshBuilder b2;
  const auto nodes2 = add_reservoir_nodes(g, b2);
  add_reservoir_cells(g, s, nodes2, active, b2);
  BuildReport rep2;
  const PolyMesh paired = b2.finish(&rep2);
  const PolyMesh looked_up = by_lookup(g, s, active);
  EXPECT_EQ(rep2.unmatched_faces, 6 + 3 + 3);  // the hole's six, and three of each corner cell's neighbours
  EXPECT_EQ(paired.face_node_ptr, looked_up.face_node_ptr);
  EXPECT_EQ(paired.face_nodes, looked_up.face_nodes);
  EXPECT_EQ(paired.face_owner, looked_up.face_owner);
  EXPECT_EQ(paired.face_neighbour, looked_up.face_neighbour);
  EXPECT_EQ(paired.face_patch, looked_up.face_patch);
  EXPECT_EQ(paired.cell_faces, looked_up.cell_faces);
}

TEST(MeshBuilderById, AFaceNamedByIdWithOtherNodesOrTheSameOrientationIsReported) {
  MeshBuilder b;
  for (int i = 0; i < 5; ++i) b.add_node({double(i), 0, 0});
  std::vector<int32_t> ids;
  std::vector<CellFace> first(1);
  first[0].nodes = {0, 1, 2};
  first[0].by_id_only = true;
  b.add_cell(first, CellAttributes{}, &ids);
  ASSERT_EQ(ids.size(), 1u);
  std::vector<CellFace> wrong(1);
  wrong[0].nodes = {3, 2, 1};  // not face ids[0]'s nodes
  wrong[0].known_face = ids[0];
  b.add_cell(wrong, CellAttributes{});
  std::vector<CellFace> same(1);
  same[0].nodes = {1, 2, 0};  // face ids[0] in its owner's orientation
  same[0].known_face = ids[0];
  b.add_cell(same, CellAttributes{});
  BuildReport rep;
  b.finish(&rep);
  EXPECT_FALSE(rep.ok);
  EXPECT_EQ(rep.misoriented_faces, 1);
  EXPECT_GE(rep.unmatched_faces, 1);
  ASSERT_FALSE(rep.problems.empty());
  EXPECT_NE(rep.problems[0].find("by its id with other nodes"), std::string::npos);
}
