#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "meshgen/core/geometry.hpp"
#include "meshgen/core/mesh_builder.hpp"

using namespace hm;

namespace {
// Faces of the axis-aligned box [lo, hi] with node ids n[0..7] (bit 0 = x, bit 1 = y, bit 2 = z),
// oriented outward.
std::vector<CellFace> box_faces(const int32_t n[8]) {
  return {{{n[0], n[2], n[3], n[1]}, kOuterBoundary}, {{n[4], n[5], n[7], n[6]}, kOuterBoundary},
          {{n[0], n[1], n[5], n[4]}, kOuterBoundary}, {{n[2], n[6], n[7], n[3]}, kOuterBoundary},
          {{n[0], n[4], n[6], n[2]}, kOuterBoundary}, {{n[1], n[3], n[7], n[5]}, kOuterBoundary}};
}
}  // namespace

TEST(CanonicalCycle, RotationAndReversalGiveTheSameKey) {
  bool r1 = false, r2 = false, r3 = false;
  auto a = canonical_cycle({5, 2, 9, 7}, &r1);
  auto b = canonical_cycle({9, 7, 5, 2}, &r2);
  auto c = canonical_cycle({7, 9, 2, 5}, &r3);
  EXPECT_EQ(a, b);
  EXPECT_EQ(a, c);
  EXPECT_EQ(r1, r2);
  EXPECT_NE(r1, r3);
}

TEST(MeshBuilder, TwoBoxesShareOneFaceAndAreClosedWithExactVolumes) {
  MeshBuilder b;
  int32_t id[3][2][2];
  const double xs[3] = {0.0, 1.5, 4.0};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k) id[i][j][k] = b.add_node({xs[i], 2.0 * j, 0.7 * k});
  for (int i = 0; i < 2; ++i) {
    int32_t n[8];
    for (int c = 0; c < 8; ++c) n[c] = id[i + (c & 1)][(c >> 1) & 1][(c >> 2) & 1];
    auto faces = box_faces(n);
    CellAttributes at;
    at.fv_center = {0.5 * (xs[i] + xs[i + 1]), 1.0, 0.35};
    b.add_cell(faces, at);
  }
  BuildReport rep;
  PolyMesh m = b.finish(&rep);
  ASSERT_TRUE(rep.ok) << (rep.problems.empty() ? "" : rep.problems[0]);
  EXPECT_EQ(m.n_cells(), 2);
  EXPECT_EQ(m.n_faces(), 11);
  EXPECT_EQ(m.n_nodes(), 12);
  EXPECT_TRUE(check_csr_invariants(m).ok);
  int interior = 0;
  for (int f = 0; f < m.n_faces(); ++f) interior += m.face_neighbour[f] >= 0;
  EXPECT_EQ(interior, 1);
  MeshGeometry g = compute_geometry(m);
  EXPECT_NEAR(g.cell_volume[0], 1.5 * 2.0 * 0.7, 1e-14);
  EXPECT_NEAR(g.cell_volume[1], 2.5 * 2.0 * 0.7, 1e-14);
  for (int c = 0; c < 2; ++c) EXPECT_LT(norm(cell_area_sum(m, g, c)), 1e-14);
  EXPECT_NEAR(g.cell_centroid[1].x, 2.75, 1e-14);
}

TEST(MeshBuilder, SameOrientationTwiceIsReportedNotAccepted) {
  MeshBuilder b;
  int32_t n[8];
  for (int c = 0; c < 8; ++c) n[c] = b.add_node({double(c & 1), double((c >> 1) & 1), double((c >> 2) & 1)});
  auto faces = box_faces(n);
  b.add_cell(faces, {});
  b.add_cell(faces, {});  // the same cell twice: every face reused with the same orientation
  BuildReport rep;
  b.finish(&rep);
  EXPECT_FALSE(rep.ok);
  EXPECT_EQ(rep.misoriented_faces, 6);
}

TEST(MeshBuilder, InteriorFaceWithoutPartnerIsUnmatched) {
  MeshBuilder b;
  int32_t n[8];
  for (int c = 0; c < 8; ++c) n[c] = b.add_node({double(c & 1), double((c >> 1) & 1), double((c >> 2) & 1)});
  auto faces = box_faces(n);
  faces[0].patch = kInteriorFace;
  b.add_cell(faces, {});
  BuildReport rep;
  PolyMesh m = b.finish(&rep);
  EXPECT_FALSE(rep.ok);
  EXPECT_EQ(rep.unmatched_faces, 1);
  EXPECT_EQ(m.face_patch[0], kUnmatchedFace);
}

TEST(Geometry, NonPlanarFaceKeepsCellClosed) {
  // Lift one top corner: the top face becomes non-planar; the cell must stay closed.
  PolyMesh m;
  {
    MeshBuilder bb;
    int32_t q[8];
    for (int c = 0; c < 8; ++c) q[c] = bb.add_node({double(c & 1), double((c >> 1) & 1), double((c >> 2) & 1) + (c == 7 ? 0.3 : 0.0)});
    bb.add_cell(box_faces(q), {});
    BuildReport rep;
    m = bb.finish(&rep);
    ASSERT_TRUE(rep.ok);
  }
  MeshGeometry g = compute_geometry(m);
  EXPECT_LT(norm(cell_area_sum(m, g, 0)), 1e-15);
  EXPECT_GT(g.cell_volume[0], 1.0);
  EXPECT_LT(g.cell_volume[0], 1.1);
}

TEST(CsrInvariants, DetectsBrokenPointers) {
  MeshBuilder b;
  int32_t n[8];
  for (int c = 0; c < 8; ++c) n[c] = b.add_node({double(c & 1), double((c >> 1) & 1), double((c >> 2) & 1)});
  b.add_cell(box_faces(n), {});
  BuildReport rep;
  PolyMesh m = b.finish(&rep);
  ASSERT_TRUE(check_csr_invariants(m).ok);
  PolyMesh broken = m;
  broken.face_nodes[3] = 99;
  EXPECT_FALSE(check_csr_invariants(broken).ok);
  broken = m;
  broken.face_neighbour[0] = 0;
  EXPECT_FALSE(check_csr_invariants(broken).ok);
  broken = m;
  broken.cell_faces.pop_back();
  EXPECT_FALSE(check_csr_invariants(broken).ok);
}

// Connections without a face (PolyMesh::nnc_cells, nnc_trans): two distinct valid cells each, as many
// values as pairs, finite and >= 0.
TEST(CsrInvariants, DetectsBadConnectionsWithoutAFace) {
  MeshBuilder b;
  for (int x = 0; x < 2; ++x) {  // two unit boxes two metres apart: no face in common
    int32_t n[8];
    for (int c = 0; c < 8; ++c) n[c] = b.add_node({2.0 * x + (c & 1), double((c >> 1) & 1), double((c >> 2) & 1)});
    b.add_cell(box_faces(n), {});
  }
  BuildReport rep;
  PolyMesh m = b.finish(&rep);
  ASSERT_TRUE(rep.ok);
  m.nnc_cells = {{0, 1}};
  m.nnc_trans = {2.5};
  EXPECT_TRUE(check_csr_invariants(m).ok);
  PolyMesh broken = m;
  broken.nnc_cells[0] = {1, 1};
  EXPECT_FALSE(check_csr_invariants(broken).ok);
  broken = m;
  broken.nnc_cells[0] = {0, 2};
  EXPECT_FALSE(check_csr_invariants(broken).ok);
  broken = m;
  broken.nnc_trans[0] = std::nan("");
  EXPECT_FALSE(check_csr_invariants(broken).ok);
  broken = m;
  broken.nnc_trans[0] = -1;
  EXPECT_FALSE(check_csr_invariants(broken).ok);
  broken = m;
  broken.nnc_trans.clear();
  EXPECT_FALSE(check_csr_invariants(broken).ok);
}

namespace {
// An n x n x n lattice of unit boxes; cell (i,j,k)'s faces are handed over rotated by
// (i + j + k) % 4 positions (the builder must find a face from any rotation of its cycle).
MeshBuilder lattice_builder(int n, bool misorient_one) {
  MeshBuilder b;
  auto id = [&](int i, int j, int k) { return static_cast<int32_t>((k * (n + 1) + j) * (n + 1) + i); };
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) b.add_node({double(i), double(j), double(k)});
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        int32_t q[8];
        for (int c = 0; c < 8; ++c) q[c] = id(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
        std::vector<CellFace> faces = box_faces(q);
        for (CellFace& f : faces) {
          std::rotate(f.nodes.begin(), f.nodes.begin() + (i + j + k) % 4, f.nodes.end());
          if (!(i == 0 && j == 0 && k == 0)) f.patch = kInteriorFace;
        }
        for (int s = 0; s < 6; ++s) {
          const bool outer = (s == 0 && k == 0) || (s == 1 && k == n - 1) || (s == 2 && j == 0) ||
                             (s == 3 && j == n - 1) || (s == 4 && i == 0) || (s == 5 && i == n - 1);
          faces[s].patch = outer ? kOuterBoundary : kInteriorFace;
        }
        if (misorient_one && i == n / 2 && j == n / 2 && k == n / 2)  // its +x face named as its neighbour names it
          std::reverse(faces[5].nodes.begin(), faces[5].nodes.end());
        b.add_cell(faces, {});
      }
  return b;
}
}  // namespace

// The face lookup (a hash table that grows many times here) finds every shared face from
// any rotation of its cycle: 3 n^2 (n + 1) faces, n^3 cells, each interior face used twice.
TEST(MeshBuilder, LargeLatticeSharesEveryInteriorFaceOnce) {
  const int n = 24;
  MeshBuilder b = lattice_builder(n, false);
  BuildReport rep;
  const PolyMesh m = b.finish(&rep);
  ASSERT_TRUE(rep.ok) << (rep.problems.empty() ? "" : rep.problems[0]);
  EXPECT_EQ(m.n_cells(), n * n * n);
  EXPECT_EQ(m.n_faces(), 3 * n * n * (n + 1));
  int interior = 0;
  for (int f = 0; f < m.n_faces(); ++f) interior += m.face_neighbour[f] >= 0;
  EXPECT_EQ(interior, 3 * n * n * (n - 1));
  EXPECT_TRUE(check_csr_invariants(m).ok);
  // finish() leaves the builder empty (the arrays moved into the mesh).
  EXPECT_EQ(b.n_nodes(), 0);
}

// The same lattice with one face named twice in the same orientation: found, and reported.
TEST(MeshBuilder, LargeLatticeReportsTheOneMisorientedFace) {
  MeshBuilder b = lattice_builder(24, true);
  BuildReport rep;
  b.finish(&rep);
  EXPECT_FALSE(rep.ok);
  EXPECT_EQ(rep.misoriented_faces, 1);
  EXPECT_EQ(rep.unmatched_faces, 0);
}
