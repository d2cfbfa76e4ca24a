// Properties of the transition optimisation (paper 6.2) on real hybrid meshes.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <set>

#include "fvcheck/lib/checks.hpp"
#include "fvcheck/lib/quality.hpp"
#include "meshgen/optimize/optimize.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"

using namespace hm;

namespace {

std::vector<double> lattice(double lo, double hi, double h) {
  std::vector<double> v;
  const int n = static_cast<int>(std::round((hi - lo) / h));
  for (int i = 0; i <= n; ++i) v.push_back(lo + (hi - lo) * i / n);
  return v;
}

CaseSpec small_case(std::vector<Vec3> trajectory) {
  CaseSpec cs;
  cs.name = "opt";
  cs.reservoir.x = lattice(0, 80, 4);
  cs.reservoir.y = lattice(0, 80, 4);
  cs.reservoir.z = lattice(1000, 1060, 4);
  WellSpec w;
  w.name = "P1";
  w.trajectory = std::move(trajectory);
  w.radius = 0.1;
  w.drainage_radius = 5;
  w.rings = 4;
  w.sectors = 12;
  w.segment_length = 4;
  cs.wells.push_back(w);
  return cs;
}

struct Measured {
  std::vector<double> q_o, q_p, q_s;
  CheckResult centred, convex;
  double volume = 0;
};

Measured measure(const PolyMesh& m, const std::vector<double>& h_ref) {
  Measured r;
  const MeshGeometry geo = compute_geometry(m);
  r.q_o = cell_min_of_faces(m, face_orthogonality(m, geo));
  r.q_p = cell_max_of_faces(m, face_planarity(m, geo));
  r.q_s = cell_shape_quality(m, h_ref);
  r.centred = check_auto_centering(m, geo);
  r.convex = check_convexity(m, geo);
  r.volume = total_volume(geo);
  return r;
}

// Coordinates of the nodes of reservoir and well cells, keyed by a cell-local signature
// (cell id, position in its face list) so that they can be compared across renumbering.
// A prism over a convex xy polygon (counter-clockwise, collinear points allowed so that a
// side can be split between neighbours), z in [0, 1]; node ids by coordinates.
int32_t add_prism(MeshBuilder* b, std::map<std::array<double, 3>, int32_t>* ids,
                  const std::vector<std::array<double, 2>>& poly, Region region) {
  auto node = [&](double x, double y, double z) {
    const std::array<double, 3> key{x, y, z};
    const auto it = ids->find(key);
    if (it != ids->end()) return it->second;
    const int32_t id = b->add_node({x, y, z});
    (*ids)[key] = id;
    return id;
  };
  const size_t n = poly.size();
  std::vector<CellFace> faces;
  CellFace bottom, top;
  for (size_t i = 0; i < n; ++i) {
    bottom.nodes.push_back(node(poly[n - 1 - i][0], poly[n - 1 - i][1], 0));
    top.nodes.push_back(node(poly[i][0], poly[i][1], 1));
  }
  bottom.patch = top.patch = 0;
  faces.push_back(bottom);
  faces.push_back(top);
  for (size_t i = 0; i < n; ++i) {
    const auto& p = poly[i];
    const auto& q = poly[(i + 1) % n];
    CellFace side;
    side.nodes = {node(p[0], p[1], 0), node(q[0], q[1], 0), node(q[0], q[1], 1), node(p[0], p[1], 1)};
    side.patch = 0;
    faces.push_back(side);
  }
  CellAttributes at;
  at.region = region;
  return b->add_cell(faces, at);
}

// The face shared by cells a and b.
int shared_face(const PolyMesh& m, int a, int b) {
  for (int f = 0; f < m.n_faces(); ++f)
    if ((m.face_owner[f] == a && m.face_neighbour[f] == b) || (m.face_owner[f] == b && m.face_neighbour[f] == a))
      return f;
  return -1;
}

std::map<std::pair<int, int>, Vec3> constrained_nodes(const PolyMesh& m) {
  std::map<std::pair<int, int>, Vec3> out;
  for (int c = 0; c < m.n_cells(); ++c) {
    if (m.cell_region[c] == kTransition) continue;
    int k = 0;
    for (const int32_t* f = m.cell_begin(c); f != m.cell_end(c); ++f)
      for (const int32_t* v = m.face_begin(*f); v != m.face_end(*f); ++v) out[{c, k++}] = m.nodes[*v];
  }
  return out;
}

// no_skewed_after: a case whose every face must end within checkMesh's skewness limit.
void check_optimisation(const CaseSpec& cs, bool no_skewed_after = false) {
  PipelineOptions opts;
  opts.optimize = false;
  const HybridMesh h = build_hybrid_mesh(cs, opts);
  OptimizeParams p;
  OptimizeReport rep;
  const PolyMesh out = optimize_transition(h.mesh, h.cell_h_ref, p, &rep);
  const Measured before = measure(h.mesh, h.cell_h_ref), after = measure(out, h.cell_h_ref);

  ASSERT_EQ(out.n_cells(), h.mesh.n_cells());
  EXPECT_TRUE(check_csr_invariants(out).ok);
  EXPECT_EQ(out.cell_region, h.mesh.cell_region);
  // Constrained vertices never move; total volume is preserved.
  EXPECT_EQ(constrained_nodes(out), constrained_nodes(h.mesh));
  EXPECT_NEAR(after.volume, before.volume, 1e-9 * before.volume);
  // It did something, and made the shape quality better on average.
  EXPECT_GT(rep.removed_below_g1 + rep.removed_below_g2 + rep.expanded, 0);
  const TransitionQuality qb = transition_quality(h.mesh, compute_geometry(h.mesh), h.cell_h_ref);
  const TransitionQuality qa = transition_quality(out, compute_geometry(out), h.cell_h_ref);
  EXPECT_LT(qa.vertices, qb.vertices);
  EXPECT_GT(qa.q_s.mean, qb.q_s.mean);
  // FV controls, cell by cell: orthogonality never below min(omega_o, initial), planarity
  // never above max(omega_p, initial), a centred cell stays centred, a convex one convex.
  std::set<int32_t> uncentred(after.centred.worst_ids.begin(), after.centred.worst_ids.end());
  for (int c = 0; c < out.n_cells(); ++c) {
    if (out.cell_region[c] != kTransition) continue;
    EXPECT_GE(after.q_o[c], std::min(p.omega_o, before.q_o[c]) - 1e-9) << "cell " << c;
    EXPECT_LE(after.q_p[c], std::max(p.omega_p, before.q_p[c]) + 1e-9) << "cell " << c;
  }
  EXPECT_LE(after.centred.violations, before.centred.violations);
  EXPECT_LE(after.convex.violations, before.convex.violations);
  // OpenFOAM skewness: a face of a transition cell within the limit before stays within it
  // (faces are matched by their owner and neighbour: the cells keep their ids), and the
  // number of skewed faces does not grow.
  const std::vector<double> sk_before = openfoam_face_skewness(h.mesh), sk_after = openfoam_face_skewness(out);
  auto skewed_pairs = [](const PolyMesh& m, const std::vector<double>& sk, std::set<std::pair<int, int>>* within) {
    int n = 0;
    for (int f = 0; f < m.n_faces(); ++f) {
      const int o = m.face_owner[f], nb = m.face_neighbour[f];
      if (m.cell_region[o] != kTransition && (nb < 0 || m.cell_region[nb] != kTransition)) continue;
      if (sk[f] > kOpenFoamSkewnessLimit) ++n;
      else if (within && nb >= 0) within->insert({o, nb});
    }
    return n;
  };
  std::set<std::pair<int, int>> within_before;
  const int skewed_before = skewed_pairs(h.mesh, sk_before, &within_before);
  const int skewed_after = skewed_pairs(out, sk_after, nullptr);
  EXPECT_LE(skewed_after, skewed_before);
  if (no_skewed_after) {
    for (int f = 0; f < out.n_faces(); ++f) EXPECT_LE(sk_after[f], kOpenFoamSkewnessLimit) << "face " << f;
  }
  EXPECT_EQ(skewed_after, rep.skewed_faces);
  for (int f = 0; f < out.n_faces(); ++f) {
    if (out.face_neighbour[f] >= 0 && within_before.count({out.face_owner[f], out.face_neighbour[f]})) {
      EXPECT_LE(sk_after[f], kOpenFoamSkewnessLimit) << "face " << f;
    }
  }
  std::printf("[ optimise  ] vertices %d -> %d, faces %d -> %d, mean Q_S %.3f -> %.3f, Q_O min %.1f -> %.1f, "
              "skewed faces %d -> %d\n",
              qb.vertices, qa.vertices, qb.faces, qa.faces, qb.q_s.mean, qa.q_s.mean, qb.q_o.min, qa.q_o.min,
              skewed_before, skewed_after);
  // Deterministic.
  OptimizeReport rep2;
  const PolyMesh again = optimize_transition(h.mesh, h.cell_h_ref, p, &rep2);
  EXPECT_EQ(again.face_nodes, out.face_nodes);
  EXPECT_EQ(again.nodes.size(), out.nodes.size());
}

}  // namespace

// OpenFOAM's skewness by hand: the line between the two centroids crosses the face plane
// at X; skewness = |X - face centre| / max(0.2 |d|, the face's extent along X - centre).
TEST(OpenFoamSkewness, AlignedBoxesHaveNone) {
  MeshBuilder b;
  std::map<std::array<double, 3>, int32_t> ids;
  const int a = add_prism(&b, &ids, {{0, 0}, {1, 0}, {1, 1}, {0, 1}}, kTransition);
  const int c = add_prism(&b, &ids, {{1, 0}, {3, 0}, {3, 1}, {1, 1}}, kTransition);
  BuildReport rep;
  const PolyMesh m = b.finish(&rep);
  ASSERT_TRUE(rep.ok);
  const std::vector<double> sk = openfoam_face_skewness(m);
  for (int f = 0; f < m.n_faces(); ++f) EXPECT_NEAR(sk[f], 0.0, 1e-12) << "face " << f;
  EXPECT_GE(shared_face(m, a, c), 0);
}

TEST(OpenFoamSkewness, OffsetBoxes) {
  // A = [0,1]^2, B = [1,3] x [0.5,1.5] (z in [0,1]): centroids (0.5,0.5), (2,1); d = (1.5,0.5).
  // The shared face x = 1, y in [0.5,1] has centre y = 0.75; the line meets x = 1 at
  // y = 0.5 + 0.5/3, so |sv| = 1/12; extent along y 0.25 < 0.2 |d| = 0.2 sqrt(2.5).
  MeshBuilder b;
  std::map<std::array<double, 3>, int32_t> ids;
  const int a = add_prism(&b, &ids, {{0, 0}, {1, 0}, {1, 0.5}, {1, 1}, {0, 1}}, kTransition);
  const int c = add_prism(&b, &ids, {{1, 0.5}, {3, 0.5}, {3, 1.5}, {1, 1.5}, {1, 1}}, kTransition);
  BuildReport rep;
  const PolyMesh m = b.finish(&rep);
  ASSERT_TRUE(rep.ok);
  const int f = shared_face(m, a, c);
  ASSERT_GE(f, 0);
  EXPECT_NEAR(openfoam_face_skewness(m)[f], (1.0 / 12) / (0.2 * std::sqrt(2.5)), 1e-12);
}

TEST(OpenFoamSkewness, NeedleTipFaceIsSkewed) {
  // The transition's failure mode: a needle A = [0,10] x [0,0.2] whose top touches the
  // triangle B = (9.8,0.2) (10,0.2) (0,5) only at its tip. Centroids (5,0.1) and (6.6,1.8):
  // the line meets y = 0.2 at x = 5 + 1.6/17, 9.9 - that from the face centre, over
  // 0.2 |d| = 0.2 sqrt(1.6^2 + 1.7^2).
  MeshBuilder b;
  std::map<std::array<double, 3>, int32_t> ids;
  const int a = add_prism(&b, &ids, {{0, 0}, {10, 0}, {10, 0.2}, {9.8, 0.2}, {0, 0.2}}, kTransition);
  const int c = add_prism(&b, &ids, {{9.8, 0.2}, {10, 0.2}, {0, 5}}, kTransition);
  BuildReport rep;
  const PolyMesh m = b.finish(&rep);
  ASSERT_TRUE(rep.ok);
  const int f = shared_face(m, a, c);
  ASSERT_GE(f, 0);
  const double expected = (9.9 - (5 + 1.6 / 17)) / (0.2 * std::sqrt(1.6 * 1.6 + 1.7 * 1.7));
  EXPECT_GT(expected, 4);
  EXPECT_NEAR(openfoam_face_skewness(m)[f], expected, 1e-9);
}

// A vertical well: the optimised mesh must pass checkMesh's skewness test everywhere.
TEST(Optimize, VerticalWell) { check_optimisation(small_case({{40, 40, 1020}, {40, 40, 1040}}), true); }

TEST(Optimize, BentWell) { check_optimisation(small_case({{38, 40, 1016}, {38, 40, 1030}, {48, 42, 1042}})); }
