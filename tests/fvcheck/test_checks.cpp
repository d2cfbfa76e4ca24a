// Pass/fail pairs for every finite-volume check, and the quality criteria on cells whose
// values are known in closed form.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "fv_test_meshes.hpp"
#include "fvcheck/lib/checks.hpp"
#include "fvcheck/lib/quality.hpp"
#include "fvcheck/lib/report.hpp"
#include "fvcheck/lib/report_json.hpp"
#include "meshgen/core/parallel.hpp"

using namespace hm;
using namespace fvtest;

namespace {

int64_t count_of(const CheckResult& r, const std::string& name) {
  for (const auto& [k, v] : r.counts)
    if (k == name) return v;
  ADD_FAILURE() << "no count " << name << " in " << r.name;
  return -1;
}

double measure_of(const CheckResult& r, const std::string& name) {
  for (const auto& [k, v] : r.measures)
    if (k == name) return v;
  ADD_FAILURE() << "no measure " << name << " in " << r.name;
  return NAN;
}

int face_between(const PolyMesh& m, int a, int b) {
  for (int f = 0; f < m.n_faces(); ++f)
    if ((m.face_owner[f] == a && m.face_neighbour[f] == b) || (m.face_owner[f] == b && m.face_neighbour[f] == a))
      return f;
  return -1;
}

// Appends a cell whose faces are new boundary face records over the given node cycles.
void append_boundary_cell(PolyMesh& d, const std::vector<std::vector<int32_t>>& cycles) {
  const int cell = d.n_cells();
  for (const std::vector<int32_t>& cyc : cycles) {
    d.cell_faces.push_back(d.n_faces());
    d.face_nodes.insert(d.face_nodes.end(), cyc.begin(), cyc.end());
    d.face_node_ptr.push_back(static_cast<int32_t>(d.face_nodes.size()));
    d.face_owner.push_back(cell);
    d.face_neighbour.push_back(-1);
    d.face_patch.push_back(kOuterBoundary);
  }
  d.cell_face_ptr.push_back(static_cast<int32_t>(d.cell_faces.size()));
  d.cell_region.push_back(0);
  d.cell_fv_center.push_back({0.5, 0.5, 0.5});
  d.cell_ijk.push_back({-1, -1, -1});
  d.cell_perm.push_back({});
  d.cell_porosity.push_back(0);
  d.cell_radial.push_back({});
}

const std::vector<std::pair<double, double>> kSquare{{0, 0}, {2, 0}, {2, 2}, {0, 2}};
const std::vector<std::pair<double, double>> kLShape{{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};

}  // namespace

// ---------------------------------------------------------------- convexity
TEST(Convexity, BoxPassesLShapedPrismFailsWithExactOutsideDistance) {
  const PolyMesh good = prism(kSquare, 0, 1, {1, 1, 0.5});
  const CheckResult ok = check_convexity(good, compute_geometry(good));
  EXPECT_EQ(ok.violations, 0);
  EXPECT_TRUE(ok.ok());
  // Nearest node not on a face is one full edge inside it: -1 / L, L = sqrt(4 + 4 + 1) = 3.
  EXPECT_NEAR(ok.worst, -1.0 / 3.0, 1e-15);

  const PolyMesh bad = prism(kLShape, 0, 1, {0.5, 0.5, 0.5});
  const CheckResult r = check_convexity(bad, compute_geometry(bad));
  EXPECT_EQ(r.violations, 1);
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(count_of(r, "cells_with_node_outside_face_plane"), 1);
  // Both caps are L-shaped: a reflex vertex each.
  EXPECT_EQ(count_of(r, "faces_with_reflex_vertex"), 2);
  EXPECT_EQ(count_of(r, "self_intersecting_faces"), 0);
  ASSERT_EQ(r.worst_ids.size(), 1u);
  EXPECT_EQ(r.worst_ids[0], 0);
  // values: raised to 1 because a face polygon is non-convex; the plane test alone gives 1/3.
  EXPECT_EQ(r.values[0], 1.0);
}

TEST(Convexity, DentInsideANonPlanarFaceIsPlanaritysBusiness) {
  // Documented limit: each face is judged by its mean plane against the nodes NOT on it, so
  // pushing one top node of a cube down (z 1 -> 0.1) dents the non-planar top face without
  // moving any node outside another face's plane. Planarity (Q_P) reports it.
  PolyMesh m = prism({{0, 0}, {1, 0}, {1, 1}, {0, 1}}, 0, 1, {0.5, 0.5, 0.5});
  m.nodes[6].z = 0.1;  // top node (1, 1, 1): Q_P of the top face about 22 degrees
  const MeshGeometry g = compute_geometry(m);
  EXPECT_TRUE(check_convexity(m, g).ok());
  EXPECT_FALSE(check_planarity(m, g).ok());
}

TEST(Convexity, FacePolygonDefects) {
  std::vector<Vec3> p{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0, 0}, {0.3, 0.2, 0}, {0, 0.5, 0}};
  const int32_t square[] = {0, 1, 2, 3};
  const int32_t bowtie[] = {0, 2, 1, 6};        // crossing edges, non-zero area
  const int32_t zero_bowtie[] = {0, 2, 1, 3};   // symmetric: zero area vector, no normal
  const int32_t dart[] = {0, 1, 2, 5};          // (0.3, 0.2) is a reflex vertex
  const int32_t straight[] = {0, 4, 1, 2, 3};   // a node on an edge line is allowed
  const int32_t flat[] = {0, 4, 1};             // collinear: no normal
  EXPECT_EQ(face_polygon_defect(p, square, square + 4, 1e-9), 0);
  EXPECT_EQ(face_polygon_defect(p, bowtie, bowtie + 4, 1e-9), 2);
  EXPECT_EQ(face_polygon_defect(p, zero_bowtie, zero_bowtie + 4, 1e-9), 3);
  EXPECT_EQ(face_polygon_defect(p, dart, dart + 4, 1e-9), 1);
  EXPECT_EQ(face_polygon_defect(p, straight, straight + 5, 1e-9), 0);
  EXPECT_EQ(face_polygon_defect(p, flat, flat + 3, 1e-9), 3);
}

// ---------------------------------------------------------------- conformity
TEST(Conformity, GridPassesFlippedInteriorFaceFails) {
  const PolyMesh good = box_grid(2, 1, 1);
  const MeshGeometry gg = compute_geometry(good);
  const CheckResult ok = check_conformity(good, gg);
  EXPECT_EQ(ok.violations, 0);
  EXPECT_TRUE(ok.worst_ids.empty());

  PolyMesh bad = good;
  const int f = face_between(bad, 0, 1);
  ASSERT_GE(f, 0);
  std::reverse(bad.face_nodes.begin() + bad.face_node_ptr[f], bad.face_nodes.begin() + bad.face_node_ptr[f + 1]);
  const MeshGeometry gb = compute_geometry(bad);
  const CheckResult r = check_conformity(bad, gb);
  EXPECT_EQ(count_of(r, "misoriented_cells"), 2);
  EXPECT_EQ(count_of(r, "open_cells"), 0);
  EXPECT_EQ(r.violations, 2);
  std::vector<int32_t> ids = r.worst_ids;
  std::sort(ids.begin(), ids.end());
  EXPECT_EQ(ids, (std::vector<int32_t>{0, 1}));
  // The flipped face also breaks closure of both cells.
  EXPECT_EQ(check_closure(bad, gb).violations, 2);
}

TEST(Conformity, HangingNodesAreFoundAndTheConformingSplitPasses) {
  const PolyMesh good = split_face_mesh(true);
  const CheckResult ok = check_conformity(good, compute_geometry(good));
  EXPECT_EQ(ok.violations, 0) << count_of(ok, "hanging_nodes");

  const PolyMesh bad = split_face_mesh(false);
  const CheckResult r = check_conformity(bad, compute_geometry(bad));
  // (1,0,.5) and (1,1,.5) hang on A's face x = 1 and on A's faces y = 0 and y = 1.
  EXPECT_EQ(count_of(r, "hanging_nodes"), 2);
  EXPECT_EQ(count_of(r, "hanging_node_face_pairs"), 4);
  EXPECT_EQ(r.violations, 2);
  EXPECT_EQ(r.worst_ids.front(), 0);  // cell A carries every hanging node
  // Every cell is still closed and convex: only conformity sees the defect.
  const MeshGeometry g = compute_geometry(bad);
  EXPECT_TRUE(check_closure(bad, g).ok());
  EXPECT_TRUE(check_convexity(bad, g).ok());
}

TEST(Conformity, AHangingNodeOnATwistedFaceIsFoundOffItsMeanPlane) {
  // Cell A: a unit box whose top corner (1, 1, 1) is lifted to z = 1.4 (a twisted top face);
  // B's corner lies on that face's fan, 0.9 of the way from its node mean to the lifted corner:
  // off the face's mean plane by most of the face's own spread (a search that took the face
  // as planar would miss it).
  MeshBuilder b;
  int32_t n[8];
  for (int c = 0; c < 8; ++c) n[c] = b.add_node({double(c & 1), double((c >> 1) & 1), (c & 4) ? (c == 7 ? 1.4 : 1.0) : 0.0});
  CellAttributes at;
  at.fv_center = {0.5, 0.5, 0.55};
  b.add_cell(fvtest::box_faces(n), at);
  const Vec3 g{0.5, 0.5, 1.1}, lifted{1, 1, 1.4};
  const Vec3 p = 0.9 * lifted + 0.1 * g;
  add_box(b, p, p + Vec3{0.2, 0.2, 0.5});
  const PolyMesh m = finish_ok(b);
  const CheckResult r = check_conformity(m, compute_geometry(m));
  EXPECT_EQ(count_of(r, "hanging_nodes"), 1);
  EXPECT_EQ(count_of(r, "hanging_node_face_pairs"), 1);
}

TEST(Conformity, DuplicatedNodesAtAnInterfaceAreHanging) {
  MeshBuilder b;
  add_box(b, {0, 0, 0}, {1, 1, 1});
  add_box(b, {1, 0, 0}, {2, 1, 1});  // fresh nodes: the interface is two unrelated faces
  const PolyMesh bad = finish_ok(b);
  const CheckResult r = check_conformity(bad, compute_geometry(bad));
  EXPECT_EQ(count_of(r, "hanging_nodes"), 8);
  EXPECT_GT(r.violations, 0);
  const PolyMesh good = box_grid(2, 1, 1);
  EXPECT_EQ(count_of(check_conformity(good, compute_geometry(good)), "hanging_nodes"), 0);
}

TEST(Conformity, UnmatchedAndDuplicateFacesAndBuilderProblems) {
  // An interior face without a partner.
  MeshBuilder b;
  int32_t n[8];
  for (int c = 0; c < 8; ++c) n[c] = b.add_node({double(c & 1), double((c >> 1) & 1), double((c >> 2) & 1)});
  std::vector<CellFace> f = box_faces(n);
  f[0].patch = kInteriorFace;
  CellAttributes at;
  at.fv_center = {0.5, 0.5, 0.5};
  b.add_cell(f, at);
  BuildReport rep;
  const PolyMesh m = b.finish(&rep);
  const CheckResult r = check_conformity(m, compute_geometry(m));
  EXPECT_EQ(count_of(r, "unmatched_faces"), 1);
  EXPECT_EQ(r.violations, 1);

  // A second cell over the same six node cycles, as separate face records.
  PolyMesh d = box_grid(1, 1, 1);
  std::vector<std::vector<int32_t>> cycles;
  for (int q = 0; q < d.n_faces(); ++q) cycles.emplace_back(d.face_begin(q), d.face_end(q));
  append_boundary_cell(d, cycles);
  ASSERT_TRUE(check_csr_invariants(d).ok);
  const CheckResult rd = check_conformity(d, compute_geometry(d));
  EXPECT_EQ(count_of(rd, "duplicate_faces"), 6);
  EXPECT_EQ(count_of(rd, "hanging_nodes"), 0);
  EXPECT_EQ(rd.violations, 6);

  // Problems the builder saw are folded in.
  const PolyMesh g = box_grid(1, 1, 1);
  BuildReport br;
  br.overused_faces = 3;
  br.misoriented_faces = 1;  // two cells naming a face the same way: the built mesh hides it, so it counts
  const CheckResult rb = check_conformity(g, compute_geometry(g), {}, &br);
  EXPECT_EQ(rb.violations, 4);
  EXPECT_EQ(count_of(rb, "builder_misoriented_faces"), 1);
}

// Three records over each face of a cube (the second rotated, the third reversed): a set of n
// equal records counts n - 1 duplicates whatever their cycles; the cube's faces that share a
// smallest node are not duplicates of each other. Examples: the later records of each set.
TEST(Conformity, RecordsOverTheSameNodeSetAreDuplicatesInAnyCycle) {
  PolyMesh d = box_grid(1, 1, 1);
  const int nf = d.n_faces();
  for (int copy = 1; copy <= 2; ++copy) {
    std::vector<std::vector<int32_t>> cycles;
    for (int q = 0; q < nf; ++q) {
      std::vector<int32_t> cyc(d.face_begin(q), d.face_end(q));
      std::rotate(cyc.begin(), cyc.begin() + copy, cyc.end());
      if (copy == 2) std::reverse(cyc.begin(), cyc.end());
      cycles.push_back(cyc);
    }
    append_boundary_cell(d, cycles);
  }
  ASSERT_TRUE(check_csr_invariants(d).ok);
  const CheckResult r = check_conformity(d, compute_geometry(d));
  EXPECT_EQ(count_of(r, "duplicate_faces"), 2 * nf);
  // Each set {f, f + nf, f + 2 nf} marks f once, its middle record twice and the last once.
  EXPECT_EQ(r.values, (std::vector<double>{double(nf), 2.0 * nf, double(nf)}));
  std::vector<int32_t> examples;
  for (const auto& [name, ids] : r.id_lists)
    if (name == "duplicate_faces") examples = ids;
  ASSERT_EQ(examples.size(), 10u);
  for (int32_t f : examples) EXPECT_GE(f, nf) << "the first record of a set is not an example";
}

// ---------------------------------------------------------------- closure
TEST(Closure, ClosedCellPassesOpenCellFailsWithExactRatio) {
  const PolyMesh good = box_grid(1, 1, 1);
  const CheckResult ok = check_closure(good, compute_geometry(good));
  EXPECT_EQ(ok.violations, 0);
  EXPECT_LT(ok.worst, 1e-15);

  std::vector<Vec3> pts;
  for (int c = 0; c < 8; ++c) pts.push_back({double(c & 1), double((c >> 1) & 1), double((c >> 2) & 1)});
  const int32_t n[8] = {0, 1, 2, 3, 4, 5, 6, 7};
  std::vector<std::vector<int32_t>> faces;
  for (const CellFace& f : box_faces(n)) faces.push_back(f.nodes);
  faces.pop_back();  // no x = 1 face
  const PolyMesh open = single_cell(pts, faces, {0.5, 0.5, 0.5});
  const CheckResult r = check_closure(open, compute_geometry(open));
  EXPECT_EQ(r.violations, 1);
  EXPECT_NEAR(r.worst, 1.0 / 5.0, 1e-15);  // |missing unit face| / five unit faces
  EXPECT_EQ(count_of(check_conformity(open, compute_geometry(open)), "open_cells"), 1);
}

// ---------------------------------------------------------------- volume
TEST(Volume, PositivePassesInsideOutFailsWithExactValues) {
  const PolyMesh good = box_grid(1, 1, 1);
  const CheckResult ok = check_volume(good, compute_geometry(good));
  EXPECT_EQ(ok.violations, 0);
  EXPECT_NEAR(ok.worst, 1.0 / std::pow(3.0, 1.5), 1e-15);  // V / L^3, L = sqrt(3)
  EXPECT_NEAR(measure_of(ok, "min_volume"), 1.0, 1e-15);

  PolyMesh bad = good;  // every face reversed: an inside-out cell
  for (int f = 0; f < bad.n_faces(); ++f)
    std::reverse(bad.face_nodes.begin() + bad.face_node_ptr[f], bad.face_nodes.begin() + bad.face_node_ptr[f + 1]);
  const CheckResult r = check_volume(bad, compute_geometry(bad));
  EXPECT_EQ(r.violations, 1);
  EXPECT_NEAR(measure_of(r, "min_volume"), -1.0, 1e-15);
  EXPECT_NEAR(r.worst, -1.0 / std::pow(3.0, 1.5), 1e-15);

  // A flat (zero-volume) cell fails too.
  PolyMesh flat = good;
  for (Vec3& p : flat.nodes) p.z = 0;
  EXPECT_EQ(check_volume(flat, compute_geometry(flat)).violations, 1);
}

// ---------------------------------------------------------------- orthogonality
TEST(Orthogonality, ExactAnglesAndThreshold) {
  // Centres (0.5,0.5,0.5) and (1.5,1.5,0.5) across the face x = 1: 45 degrees.
  MeshBuilder b;
  const Vec3 c1{1.5, 1.5, 0.5};
  int32_t id[12];
  for (int i = 0; i < 12; ++i) id[i] = b.add_node({double(i % 3), double((i / 3) % 2), double(i / 6)});
  auto node = [&](int i, int j, int k) { return id[k * 6 + j * 3 + i]; };
  for (int cell = 0; cell < 2; ++cell) {
    int32_t n[8];
    for (int c = 0; c < 8; ++c) n[c] = node(cell + (c & 1), (c >> 1) & 1, (c >> 2) & 1);
    std::vector<CellFace> f = box_faces(n);
    CellAttributes at;
    at.fv_center = cell == 0 ? Vec3{0.5, 0.5, 0.5} : c1;
    b.add_cell(f, at);
  }
  const PolyMesh m = finish_ok(b);
  const MeshGeometry g = compute_geometry(m);
  const std::vector<double> q = face_orthogonality(m, g);
  const int fi = face_between(m, 0, 1);
  ASSERT_GE(fi, 0);
  EXPECT_NEAR(q[fi], 45.0, 1e-12);
  // Boundary faces of cell 0 (centre at its centroid) are exactly orthogonal.
  for (const int32_t* f = m.cell_begin(0); f != m.cell_end(0); ++f)
    if (*f != fi) {
      EXPECT_NEAR(q[*f], 90.0, 1e-12);
    }
  // Cell 1's centre (1.5,1.5,.5) lies beyond its face y = 1. Its boundary faces y = 0 and y = 1
  // have the centre's foot inside: 90. Faces z = 0, z = 1, x = 2: the foot lies 0.5 beyond the
  // edge y = 1 and the nearest point of the face is on that edge, (0, -.5, -/+.5) or (.5, -.5, 0)
  // from the centre: 45 deg. To the face centroid (the paper's literal eq. 8, BoundaryPoint::
  // Centroid) the segment is (0, -1, -/+.5) or (.5, -1, 0): asin(.5 / sqrt(1.25)) = 26.57 deg.
  const double expect_z0 = std::asin(0.5 / std::sqrt(1.25)) * 180.0 / M_PI;
  const std::vector<double> q_centroid = face_orthogonality(m, g, BoundaryPoint::Centroid);
  int seen = 0;
  for (const int32_t* f = m.cell_begin(1); f != m.cell_end(1); ++f) {
    if (*f == fi) continue;
    const Vec3 c = g.face_centroid[*f];
    const bool foot_inside = std::fabs(c.y) < 1e-15 || std::fabs(c.y - 1) < 1e-15;
    EXPECT_NEAR(q[*f], foot_inside ? 90.0 : 45.0, 1e-12) << "face " << *f;
    EXPECT_NEAR(q_centroid[*f], foot_inside ? 90.0 : expect_z0, 1e-12) << "face " << *f;
    ++seen;
  }
  EXPECT_EQ(seen, 5);
  const std::vector<double> qc = cell_min_of_faces(m, q);
  EXPECT_NEAR(qc[0], 45.0, 1e-12);
  EXPECT_NEAR(qc[1], 45.0, 1e-12);

  CheckOptions strict;
  strict.min_orthogonality_deg = 50;
  const CheckResult fail = check_orthogonality(m, g, strict);
  // Faces below 50 deg: the interior face and cell 1's faces z = 0, z = 1 and x = 2 (45 each).
  EXPECT_EQ(fail.violations, 4);
  EXPECT_NEAR(fail.worst, 45.0, 1e-12);
  EXPECT_NEAR(measure_of(fail, "boundary_centroid_min_deg"), expect_z0, 1e-12);
  EXPECT_EQ(count_of(fail, "boundary_faces_below_threshold_at_centroid"), 3);
  CheckOptions loose;
  loose.min_orthogonality_deg = 20;
  EXPECT_TRUE(check_orthogonality(m, g, loose).ok());
  EXPECT_TRUE(check_orthogonality(box_grid(2, 2, 2), compute_geometry(box_grid(2, 2, 2))).ok());
}

// A boundary face's two-point pair is the FV centre and its boundary flux point: the foot of the
// perpendicular when it lies in the face (docs/fvcheck.md, "Boundary faces"). One flat triangular
// prism, (0,0), (10,0), (9,.5) x [0, 1], with two FV centres inside it (convexity and auto-centering
// hold for both): the first projects into every face, the second projects 5.2 beyond the short
// sloped face (10,0)-(9,.5), 3.04 away from its plane.
TEST(Orthogonality, BoundaryFaceIsOrthogonalExactlyWhenTheCentreProjectsIntoIt) {
  const std::vector<std::pair<double, double>> sliver{{0, 0}, {10, 0}, {9, 0.5}};
  const Vec3 sloped_n = normalized(Vec3{0.5, 1, 0});  // outward normal of the face (10,0)-(9,.5)

  const PolyMesh good = prism(sliver, 0, 1, {9.0, 0.3, 0.5});
  const MeshGeometry gg = compute_geometry(good);
  EXPECT_TRUE(check_convexity(good, gg).ok());
  EXPECT_TRUE(check_auto_centering(good, gg).ok());
  const CheckResult ok = check_orthogonality(good, gg);
  EXPECT_TRUE(ok.ok());
  EXPECT_NEAR(ok.worst, 90.0, 1e-9);
  // The flux point of every face is the foot: the centre minus its distance along the normal.
  const std::vector<Vec3> foot = boundary_flux_points(good, gg);
  for (int f = 0; f < good.n_faces(); ++f) {
    const Vec3 n = normalized(gg.face_area[f]), x = good.cell_fv_center[0];
    const Vec3 expect = x - dot(x - gg.face_centroid[f], n) * n;
    EXPECT_LT(norm(foot[f] - expect), 1e-12) << "face " << f;
  }
  // The centroid rule would have failed every face of this cell; worst the long face (0,0)-(9,.5),
  // seen from the centre (9, .3) towards its centroid (4.5, .25) at 2.5 degrees.
  const Vec3 to_centroid{-4.5, -0.05, 0}, long_n = normalized(Vec3{-0.5, 9, 0});
  EXPECT_NEAR(measure_of(ok, "boundary_centroid_min_deg"),
              std::asin(std::fabs(dot(to_centroid, long_n)) / norm(to_centroid)) * 180 / M_PI, 1e-9);
  EXPECT_EQ(count_of(ok, "boundary_faces_below_threshold_at_centroid"), 5);

  const PolyMesh bad = prism(sliver, 0, 1, {3.0, 0.1, 0.5});
  const MeshGeometry gb = compute_geometry(bad);
  EXPECT_TRUE(check_convexity(bad, gb).ok());
  EXPECT_TRUE(check_auto_centering(bad, gb).ok());
  const CheckResult r = check_orthogonality(bad, gb);
  EXPECT_FALSE(r.ok());
  ASSERT_EQ(r.violations, 1);
  // The nearest point of the sloped face is its edge at (9, .5, .5): d = (6, .4, 0).
  const Vec3 d{6, 0.4, 0};
  EXPECT_NEAR(r.worst, std::asin(std::fabs(dot(d, sloped_n)) / norm(d)) * 180 / M_PI, 1e-9);
  EXPECT_LT(r.worst, 45.0);
  EXPECT_LT(norm(boundary_flux_points(bad, gb)[r.worst_ids[0]] - Vec3{9, 0.5, 0.5}), 1e-12);
}

// ---------------------------------------------------------------- auto-centering
TEST(AutoCentering, InsidePassesOutsideAndOnFaceFail) {
  PolyMesh m = box_grid(1, 1, 1);
  const MeshGeometry g = compute_geometry(m);
  const CheckResult ok = check_auto_centering(m, g);
  EXPECT_EQ(ok.violations, 0);
  EXPECT_NEAR(ok.worst, -0.5 / std::sqrt(3.0), 1e-15);

  m.cell_fv_center[0] = {1.5, 0.5, 0.5};
  const CheckResult out = check_auto_centering(m, g);
  EXPECT_EQ(out.violations, 1);
  EXPECT_NEAR(out.worst, 0.5 / std::sqrt(3.0), 1e-15);

  m.cell_fv_center[0] = {1.0, 0.5, 0.5};  // on the face: not strictly inside
  EXPECT_EQ(check_auto_centering(m, g).violations, 1);
  m.cell_fv_center[0] = {1.0 - 1e-6, 0.5, 0.5};
  EXPECT_EQ(check_auto_centering(m, g).violations, 0);
}

// Every violating item is flagged, not only the ten worst the reports name: the optimiser judges a
// move by the failing cells around it (before, a diagram with more than ten failing cells left it
// blind: corner-point sweep, two wells, seed 4).
TEST(AutoCentering, EveryViolatingCellIsFlaggedBeyondTheTenWorst) {
  PolyMesh m = box_grid(5, 5, 1);
  std::vector<char> expected(m.n_cells(), 0);
  for (int c = 0; c < m.n_cells(); c += 2) {
    m.cell_fv_center[c].z += 2.0;  // above the grid: outside its cell
    expected[c] = 1;
  }
  const MeshGeometry g = compute_geometry(m);
  const CheckResult r = check_auto_centering(m, g);
  EXPECT_EQ(r.violations, 13);
  EXPECT_EQ(r.worst_ids.size(), 10u);
  EXPECT_EQ(r.failing, expected);
  // Each per-item check: a flag per value, as many flags as violations.
  for (const CheckResult& c : {check_convexity(m, g), check_closure(m, g), check_volume(m, g),
                               check_orthogonality(m, g), check_auto_centering(m, g), check_planarity(m, g)}) {
    EXPECT_EQ(c.failing.size(), c.values.size()) << c.name;
    EXPECT_EQ(std::count(c.failing.begin(), c.failing.end(), 1), c.violations) << c.name;
  }
}

// ---------------------------------------------------------------- planarity
TEST(Planarity, ExactValueOfALiftedCorner) {
  // Closed form: top face normal ~ (-t,-t,2); fan triangle normals ~ (0,-t,2), (-t,-2t,2),
  // (-2t,-t,2), (-t,0,2).
  auto expected = [](double t) {
    const double a = std::acos((t * t + 4) / (std::sqrt(2 * t * t + 4) * std::sqrt(t * t + 4)));
    const double b = std::acos((3 * t * t + 4) / (std::sqrt(2 * t * t + 4) * std::sqrt(5 * t * t + 4)));
    return std::max(a, b) * 180.0 / M_PI;
  };
  for (double t : {0.5, 1.0}) {
    const PolyMesh m = lifted_cube(t);
    const MeshGeometry g = compute_geometry(m);
    const std::vector<double> q = face_planarity(m, g);
    EXPECT_NEAR(*std::max_element(q.begin(), q.end()), expected(t), 1e-10) << t;
    EXPECT_EQ(std::count_if(q.begin(), q.end(), [](double x) { return x > 1e-12; }), 1);
    EXPECT_NEAR(cell_max_of_faces(m, q)[0], expected(t), 1e-10);
  }
  // Default threshold 15 deg: t = 0.5 (13.6 deg) passes, t = 1 (24.1 deg) fails.
  const PolyMesh a = lifted_cube(0.5), b = lifted_cube(1.0);
  EXPECT_TRUE(check_planarity(a, compute_geometry(a)).ok());
  const CheckResult r = check_planarity(b, compute_geometry(b));
  EXPECT_EQ(r.violations, 1);
  EXPECT_NEAR(r.worst, expected(1.0), 1e-10);
  CheckOptions strict;
  strict.max_planarity_deg = 10;
  EXPECT_FALSE(check_planarity(a, compute_geometry(a), strict).ok());
  const PolyMesh flat = box_grid(1, 1, 1);
  EXPECT_EQ(check_planarity(flat, compute_geometry(flat)).worst, 0.0);
}

// A unit cube whose corner (1, 0, 1) has a second node 7e-7 from it along the top edge, `lift` above the
// top face's plane, in the top face and the side face y = 0 (near-coincident power vertices of nearly
// co-spherical sites, each computed to ~1e-7 m: realistic sweep seed 2781). The fan triangle between
// the two carries 2.5e-7 of the face's area and its normal is rounding (kPlanarityNegligibleArea): not
// judged, so a lift of 3e-7 leaves the faces planar (31 degrees when it was judged); a lift of 0.1 tilts
// the node's larger fan triangles, and planarity fails.
PolyMesh cube_with_micro_edge(double lift) {
  std::vector<Vec3> pts;
  for (int c = 0; c < 8; ++c) pts.push_back({double(c & 1), double((c >> 1) & 1), double((c >> 2) & 1)});
  pts.push_back({1 - 7e-7, 0, 1 + lift});
  const int32_t n[8] = {0, 1, 2, 3, 4, 5, 6, 7};
  std::vector<std::vector<int32_t>> faces;
  for (const CellFace& f : box_faces(n)) {
    std::vector<int32_t> v = f.nodes;
    for (size_t i = 0; i < v.size(); ++i) {
      const int32_t a = v[i], b = v[(i + 1) % v.size()];
      if ((a == 5 && b == 4) || (a == 4 && b == 5)) {
        v.insert(v.begin() + static_cast<long>(i + 1), 8);
        break;
      }
    }
    faces.push_back(v);
  }
  return single_cell(pts, faces, {0.5, 0.5, 0.5});
}

TEST(Planarity, FanTrianglesOfNegligibleAreaAreNotJudged) {
  const PolyMesh rounding = cube_with_micro_edge(3e-7), lifted = cube_with_micro_edge(0.1);
  const std::vector<double> q = face_planarity(rounding, compute_geometry(rounding));
  EXPECT_LT(*std::max_element(q.begin(), q.end()), 1e-4);
  EXPECT_TRUE(check_planarity(rounding, compute_geometry(rounding)).ok());
  const CheckResult r = check_planarity(lifted, compute_geometry(lifted));
  EXPECT_FALSE(r.ok());
  EXPECT_GT(r.worst, 15.0);
}

// ---------------------------------------------------------------- shape quality
TEST(ShapeQuality, ExactValuesOnABox) {
  MeshBuilder b;
  add_box(b, {0, 0, 0}, {1, 2, 3});
  const PolyMesh m = finish_ok(b);
  EXPECT_NEAR(cell_mean_edge_length(m)[0], 2.0, 1e-15);
  EXPECT_NEAR(cell_shape_quality(m, {2.0})[0], 0.5, 1e-15);   // edge 1 vs h = 2
  EXPECT_NEAR(cell_shape_quality(m, {3.0})[0], 1.0 / 3.0, 1e-15);
  EXPECT_NEAR(cell_shape_quality(m, {})[0], 0.5, 1e-15);      // h = mean edge = 2
  EXPECT_NEAR(cell_shape_quality(m, {0.0})[0], 0.5, 1e-15);   // unusable h: fallback
  EXPECT_NEAR(cell_shape_quality(box_grid(1, 1, 1), {})[0], 1.0, 1e-15);
}

TEST(QualityStats, PerRegionAndHistogram) {
  const PolyMesh m = box_grid(3, 1, 1, true);  // regions 0, 1, 2
  std::vector<double> qs{0.1, 0.5, 0.95};
  const auto by = quality_by_region(m, qs, {90, 80, 70}, {0, 5, 10});
  ASSERT_EQ(by.size(), 3u);
  EXPECT_EQ(by[1].name, "transition");
  EXPECT_EQ(by[1].cells, 1);
  EXPECT_EQ(by[1].q_s.mean, 0.5);
  EXPECT_EQ(by[2].q_o.min, 70);
  const Stats s = stats_of(qs);
  EXPECT_EQ(s.count, 3);
  EXPECT_NEAR(s.mean, 0.5166666666666667, 1e-15);
  const auto h = histogram(qs, {}, 0.0, 1.0, 10);
  EXPECT_EQ(h[1], 1);
  EXPECT_EQ(h[5], 1);
  EXPECT_EQ(h[9], 1);
}

// ---------------------------------------------------------------- run_fvcheck and reports
TEST(RunFvcheck, GoodGridHoldsAndReportsHaveTheDocumentedShape) {
  const PolyMesh m = box_grid(3, 2, 2, true);
  const FvReport r = run_fvcheck(m, {});
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(r.cells, 12);
  const nlohmann::json j = report_json(r);
  EXPECT_TRUE(j["ok"].get<bool>());
  for (const char* k : {"convexity", "conformity", "closure", "volume", "orthogonality", "auto_centering", "planarity"}) {
    ASSERT_TRUE(j["checks"].contains(k)) << k;
    EXPECT_EQ(j["checks"][k]["violations"].get<int>(), 0) << k;
    EXPECT_TRUE(j["checks"][k].contains("worst_ids")) << k;
  }
  EXPECT_NEAR(j["checks"]["orthogonality"]["min_deg"].get<double>(), 90.0, 1e-12);
  EXPECT_NEAR(j["checks"]["planarity"]["max_deg"].get<double>(), 0.0, 1e-12);
  EXPECT_NEAR(j["quality"]["Q_S"]["min"].get<double>(), 1.0, 1e-15);
  EXPECT_EQ(j["quality"]["by_region"]["well"]["cells"].get<int>(), 4);
  EXPECT_FALSE(j.contains("transmissibility"));  // the caller adds it
  const std::string html = report_html(r);
  EXPECT_NE(html.find("<svg"), std::string::npos);
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("src="), std::string::npos);
  EXPECT_NE(html.find("ALL CHECKS HOLD"), std::string::npos);
}

TEST(RunFvcheck, BrokenStructureSkipsChecksAndFails) {
  PolyMesh m = box_grid(2, 1, 1);
  m.face_nodes[0] = 1000;  // out of range
  const FvReport r = run_fvcheck(m, {});
  EXPECT_FALSE(r.structure.ok);
  EXPECT_FALSE(r.ok());
  ASSERT_EQ(r.checks.size(), 7u);
  for (const CheckResult& c : r.checks) EXPECT_TRUE(c.skipped);
  const nlohmann::json j = report_json(r);
  EXPECT_FALSE(j["ok"].get<bool>());
  EXPECT_TRUE(j["checks"]["convexity"]["skipped"].get<bool>());
  EXPECT_NE(report_html(r).find("checks were skipped"), std::string::npos);
}

TEST(RunFvcheck, CentreOutsideFailsOnlyAutoCentering) {
  PolyMesh m = box_grid(2, 1, 1);
  m.cell_fv_center[1] = {2.5, 0.5, 0.5};
  const FvReport r = run_fvcheck(m, {});
  EXPECT_FALSE(r.ok());
  for (const CheckResult& c : r.checks) {
    if (c.name == "auto_centering") {
      EXPECT_EQ(c.violations, 1);
      ASSERT_FALSE(c.worst_ids.empty());
      EXPECT_EQ(c.worst_ids[0], 1);
    } else if (c.name != "orthogonality") {
      EXPECT_TRUE(c.ok()) << c.name;
    }
  }
  EXPECT_NE(report_html(r).find("Failed checks"), std::string::npos);
  EXPECT_NE(report_summary_text(r).find("FAILED"), std::string::npos);
}

// checkMesh's view of a mesh's skewness: the largest value and its face, and the faces strictly above 4
// (checkMesh's test is `> 4`); a NaN is no value.
TEST(SkewnessSummary, CountsFacesAboveCheckMeshLimit) {
  const SkewnessSummary s = summarize_skewness({1.0, 4.0, 4.5, NAN, 9.0, 0.2});
  EXPECT_EQ(s.max, 9.0);
  EXPECT_EQ(s.worst_face, 4);
  EXPECT_EQ(s.above_limit, 2);
  const SkewnessSummary none = summarize_skewness({});
  EXPECT_EQ(none.worst_face, -1);
  EXPECT_EQ(none.above_limit, 0);
}

// fvcheck reports checkMesh's skewness beside the FV checks (it does not fail the report): a Cartesian
// grid's faces have none; one node moved skews the faces around it, as openfoam_face_skewness says.
TEST(RunFvcheck, ReportsCheckMeshSkewness) {
  PolyMesh m = box_grid(3, 2, 2);
  const FvReport straight = run_fvcheck(m, {});
  EXPECT_NEAR(straight.openfoam_skewness.max, 0.0, 1e-12);
  EXPECT_EQ(straight.openfoam_skewness.above_limit, 0);
  EXPECT_NE(report_summary_text(straight).find("no face above checkMesh's limit of 4"), std::string::npos);
  m.nodes[5] = m.nodes[5] + Vec3{0.3, 0.2, 0.1};
  const FvReport moved = run_fvcheck(m, {});
  const std::vector<double> skew = openfoam_face_skewness(m);
  const double worst = *std::max_element(skew.begin(), skew.end());
  EXPECT_GT(worst, 0.01);
  EXPECT_EQ(moved.openfoam_skewness.max, worst);
  EXPECT_EQ(skew[moved.openfoam_skewness.worst_face], worst);
  const nlohmann::json j = report_json(moved);
  EXPECT_EQ(j["quality"]["openfoam_skewness"]["max"].get<double>(), worst);
  EXPECT_EQ(j["quality"]["openfoam_skewness"]["faces_above_checkmesh_limit"].get<int64_t>(), 0);
  EXPECT_EQ(j["quality"]["openfoam_skewness"]["checkmesh_limit"].get<double>(), 4.0);
  EXPECT_NE(report_html(moved).find("checkMesh skewness"), std::string::npos);
}

// checkMesh's non-orthogonality summary: its maximum is the arccosine of the smallest cosine, its average
// the arccosine of the mean cosine over the interior faces only (a boundary face's 1 would lower it), a
// face above 70 degrees is severe (a warning) and one at a cosine of at most OpenFOAM's SMALL an error.
TEST(NonOrthogonalitySummary, CountsInteriorFacesAsCheckMeshDoes) {
  const PolyMesh m = box_grid(4, 1, 1);  // three interior faces
  std::vector<double> cosine(m.n_faces(), 1.0);
  std::vector<int> interior;
  for (int f = 0; f < m.n_faces(); ++f)
    if (m.face_neighbour[f] >= 0) interior.push_back(f);
  ASSERT_EQ(interior.size(), 3u);
  const double deg = M_PI / 180;
  cosine[interior[0]] = std::cos(75 * deg);
  cosine[interior[1]] = std::cos(20 * deg);
  cosine[interior[2]] = 1e-16;
  const NonOrthogonalitySummary s = summarize_nonorthogonality(m, cosine);
  EXPECT_NEAR(s.max, 90.0, 1e-12);
  EXPECT_EQ(s.worst_face, interior[2]);
  const double mean = (std::cos(75 * deg) + std::cos(20 * deg) + 1e-16) / 3;
  EXPECT_NEAR(s.average, std::acos(mean) / deg, 1e-12);
  EXPECT_EQ(s.severe, 1);
  EXPECT_EQ(s.errors, 1);
  // fvcheck's line, and meshgen's warning for the OpenFOAM export, name both counts.
  const std::string text = openfoam_nonorthogonality_text(s);
  EXPECT_NE(text.find("1 face above its warning threshold of 70"), std::string::npos) << text;
  EXPECT_NE(text.find("1 face at 90 deg or more: checkMesh reports it"), std::string::npos) << text;
  const NonOrthogonalitySummary none = summarize_nonorthogonality(box_grid(1, 1, 1), std::vector<double>(6, 1.0));
  EXPECT_EQ(none.worst_face, -1);
  EXPECT_EQ(none.max, 0);
}

// fvcheck reports checkMesh's non-orthogonality beside the FV checks: two unit cubes, the second sheared
// along y by s = 1 (its far face moved by s), have centroids (0.5, 0.5, 0.5) and (1.5, 1, 0.5), so their
// shared face x = 1 is atan(0.5) = 26.565 degrees off the line between them; the one interior face is also
// the average. Unsheared, both are 0.
TEST(RunFvcheck, ReportsCheckMeshNonOrthogonality) {
  PolyMesh m = box_grid(2, 1, 1);
  EXPECT_NEAR(run_fvcheck(m, {}).openfoam_nonorthogonality.max, 0.0, 1e-12);
  for (Vec3& p : m.nodes)
    if (p.x == 2.0) p.y += 1.0;
  const FvReport r = run_fvcheck(m, {});
  const double expected = std::atan(0.5) * 180 / M_PI;
  EXPECT_NEAR(r.openfoam_nonorthogonality.max, expected, 1e-12);
  EXPECT_NEAR(r.openfoam_nonorthogonality.average, expected, 1e-12);
  EXPECT_EQ(r.openfoam_nonorthogonality.severe, 0);
  EXPECT_EQ(r.openfoam_nonorthogonality.errors, 0);
  EXPECT_NE(report_summary_text(r).find("checkMesh non-orthogonality: max 26.5651, average 26.5651 deg"),
            std::string::npos)
      << report_summary_text(r);
  const nlohmann::json j = report_json(r);
  EXPECT_NEAR(j["quality"]["openfoam_nonorthogonality_deg"]["max"].get<double>(), expected, 1e-12);
  EXPECT_EQ(j["quality"]["openfoam_nonorthogonality_deg"]["error_faces"].get<int64_t>(), 0);
  EXPECT_NE(report_html(r).find("checkMesh non-orthogonality"), std::string::npos);
}

TEST(TransmissibilitySummary, CountsNegativeAndNonFinite) {
  const TransmissibilitySummary s = summarize_transmissibilities({0.0, 2.0, -1.0, 5.0, NAN});
  EXPECT_TRUE(s.present);
  EXPECT_EQ(s.count, 3);
  EXPECT_EQ(s.min, -1.0);
  EXPECT_EQ(s.max, 5.0);
  EXPECT_EQ(s.negative, 2);
  EXPECT_EQ(s.negative_faces, (std::vector<int32_t>{2, 4}));
}

// The checks run in parallel (TBB) but reduce in index order: one thread and every thread give
// the same values, counts, worst ids and example ids, bit for bit. The grid (24k cells, many
// parallel chunks) has jittered nodes so that the values differ from cell to cell.
TEST(RunFvcheck, OneThreadAndAllThreadsGiveIdenticalReports) {
  PolyMesh m = box_grid(40, 30, 20);
  for (size_t v = 0; v < m.nodes.size(); ++v) {
    const double s = static_cast<double>((v * 2654435761u) % 1000) / 1000.0 - 0.5;
    m.nodes[v] += Vec3{0.02 * s, -0.015 * s, 0.01 * s};
  }
  auto run = [&](int threads) {
    const ThreadLimit limit(threads);
    return run_fvcheck(m, CheckOptions{}, {});
  };
  const FvReport one = run(1), all = run(0);
  ASSERT_EQ(one.checks.size(), all.checks.size());
  for (size_t i = 0; i < one.checks.size(); ++i) {
    const CheckResult &a = one.checks[i], &b = all.checks[i];
    SCOPED_TRACE(a.name);
    EXPECT_EQ(a.violations, b.violations);
    EXPECT_EQ(a.worst, b.worst);
    EXPECT_EQ(a.worst_ids, b.worst_ids);
    EXPECT_EQ(a.values, b.values);
    EXPECT_EQ(a.counts, b.counts);
    EXPECT_EQ(a.id_lists, b.id_lists);
  }
  EXPECT_EQ(one.q_s, all.q_s);
  EXPECT_EQ(one.q_o_cell, all.q_o_cell);
  // Not vacuous: the jitter makes the values differ across cells.
  const CheckResult* planarity = one.find("planarity");
  ASSERT_NE(planarity, nullptr);
  EXPECT_GT(*std::max_element(planarity->values.begin(), planarity->values.end()), 0.01);
}
