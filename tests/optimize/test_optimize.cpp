// Properties of the transition optimisation (paper 6.2) on real hybrid meshes.
#include <gtest/gtest.h>

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

void check_optimisation(const CaseSpec& cs) {
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
  std::printf("[ optimise  ] vertices %d -> %d, faces %d -> %d, mean Q_S %.3f -> %.3f, Q_O min %.1f -> %.1f\n",
              qb.vertices, qa.vertices, qb.faces, qa.faces, qb.q_s.mean, qa.q_s.mean, qb.q_o.min, qa.q_o.min);
  // Deterministic.
  OptimizeReport rep2;
  const PolyMesh again = optimize_transition(h.mesh, h.cell_h_ref, p, &rep2);
  EXPECT_EQ(again.face_nodes, out.face_nodes);
  EXPECT_EQ(again.nodes.size(), out.nodes.size());
}

}  // namespace

TEST(Optimize, VerticalWell) { check_optimisation(small_case({{40, 40, 1020}, {40, 40, 1040}})); }

TEST(Optimize, BentWell) { check_optimisation(small_case({{38, 40, 1016}, {38, 40, 1030}, {48, 42, 1042}})); }
