// Properties of the site optimiser (docs/optimization.md): its output is a power diagram
// again, so every face stays planar, every face between two transition cells stays
// orthogonal to the segment of their sites, the cavity polygons and the structured grids are
// untouched, and the result is deterministic; and it does improve Q_S.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "fvcheck/lib/checks.hpp"
#include "meshgen/case/case.hpp"
#include "meshgen/core/fv_quality.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"
#include "meshgen/pipeline/local_frame.hpp"
#include "scaling_case.hpp"
#include "short_edges.hpp"
#include "uniform_nodes.hpp"

using namespace hm;
using hm::test::transition_edges_shorter_than;
using hm::test::uniform_nodes;

namespace {

// A small deviated well in 4 m cells (a few hundred transition cells: seconds, not minutes).
CaseSpec small_case() {
  CaseSpec cs;
  cs.name = "site_opt";
  cs.reservoir.x = uniform_nodes(0, 60, 4);
  cs.reservoir.y = uniform_nodes(0, 60, 4);
  cs.reservoir.z = uniform_nodes(1000, 1040, 4);
  WellSpec w;
  w.name = "P1";
  w.trajectory = {{25, 27, 1015}, {35, 33, 1025}};
  w.radius = 0.1;
  w.drainage_radius = 4;
  w.rings = 3;
  w.sectors = 8;
  w.segment_length = 4;
  cs.wells.push_back(w);
  return cs;
}

HybridMesh build(const CaseSpec& cs, bool optimize) {
  PipelineOptions o;
  o.optimize = optimize;
  return build_hybrid_mesh(cs, o);
}

struct Figures {
  double max_q_p = 0;            // over faces of transition cells (deg)
  double min_q_o_internal = 90;  // over faces between two transition cells (deg)
  double mean_q_s = 0;
  int transition_cells = 0;
  int skewed_faces = 0;  // OpenFOAM skewness above checkMesh's 4 (faces of transition cells)
  double max_skewness = 0;
};

Figures figures(const HybridMesh& h) {
  const PolyMesh& m = h.mesh;
  const std::vector<double> q_p = face_planarity(m, h.geometry), q_o = face_orthogonality(m, h.geometry);
  const std::vector<double> q_s = cell_shape_quality(m, h.cell_h_ref);
  Figures f;
  for (int face = 0; face < m.n_faces(); ++face) {
    const int o = m.face_owner[face], n = m.face_neighbour[face];
    const bool t_o = m.cell_region[o] == kTransition, t_n = n >= 0 && m.cell_region[n] == kTransition;
    if (t_o || t_n) f.max_q_p = std::max(f.max_q_p, q_p[face]);
    if (t_o && t_n) f.min_q_o_internal = std::min(f.min_q_o_internal, q_o[face]);
  }
  const std::vector<double> skew = openfoam_face_skewness(m);
  for (int face = 0; face < m.n_faces(); ++face) {
    const int o = m.face_owner[face], n = m.face_neighbour[face];
    if (n < 0 || (m.cell_region[o] != kTransition && m.cell_region[n] != kTransition)) continue;
    f.max_skewness = std::max(f.max_skewness, skew[face]);
    f.skewed_faces += skew[face] > 4 ? 1 : 0;
  }
  for (int c = 0; c < m.n_cells(); ++c)
    if (m.cell_region[c] == kTransition) f.mean_q_s += q_s[c], ++f.transition_cells;
  f.mean_q_s /= std::max(1, f.transition_cells);
  return f;
}

TEST(SiteOptimizer, KeepsAPowerDiagramAndImprovesShape) {
  const CaseSpec cs = small_case();
  const HybridMesh raw = build(cs, false), opt = build(cs, true);
  ASSERT_TRUE(opt.optimized);
  ASSERT_TRUE(opt.build_report.ok);
  const Figures fr = figures(raw), fo = figures(opt);
  std::printf("[ figures  ] %d transition cells: mean Q_S %.4f -> %.4f, max Q_P %.3g -> %.3g deg, min internal Q_O "
              "%.6f -> %.6f deg; skewed faces %d -> %d (max %.3g -> %.3g); %d moves kept of %d\n",
              fo.transition_cells, fr.mean_q_s, fo.mean_q_s, fr.max_q_p, fo.max_q_p, fr.min_q_o_internal,
              fo.min_q_o_internal, fr.skewed_faces, fo.skewed_faces, fr.max_skewness, fo.max_skewness, opt.optimize_report.kept, opt.optimize_report.proposed);
  EXPECT_EQ(fo.transition_cells, fr.transition_cells);  // sites are moved, never removed
  EXPECT_GT(opt.optimize_report.kept, 0);
  EXPECT_GT(fo.mean_q_s, fr.mean_q_s);
  EXPECT_GT(opt.transition_after.q_s.mean, opt.transition_before.q_s.mean);
  EXPECT_LT(opt.transition_after.vertices, opt.transition_before.vertices);  // removals merge vertices
  // A power diagram: planar faces (the raw diagram is planar to ~1e-6 deg) and faces between
  // two transition cells normal to their site segment.
  EXPECT_LE(fo.max_q_p, 1e-3);
  EXPECT_GE(fo.min_q_o_internal, 90 - 1e-5);  // asin near 90 deg: ~1e-6 of rounding
  // Closed, conforming, the domain's volume, every check of fvcheck.
  const double domain = 60.0 * 60 * 40;  // less the wellbore
  EXPECT_NEAR(total_volume(opt.geometry), total_volume(raw.geometry), 1e-9 * domain);
  EXPECT_LT(total_volume(opt.geometry), domain);
  for (const CheckResult& r :
       {check_convexity(opt.mesh, opt.geometry), check_conformity(opt.mesh, opt.geometry, {}, &opt.build_report),
        check_closure(opt.mesh, opt.geometry), check_volume(opt.mesh, opt.geometry),
        check_orthogonality(opt.mesh, opt.geometry), check_auto_centering(opt.mesh, opt.geometry),
        check_planarity(opt.mesh, opt.geometry)})
    EXPECT_TRUE(r.ok()) << r.name << ": " << r.violations << " violations, worst " << r.worst;
}

TEST(SiteOptimizer, LeavesTheStructuredGridsUntouched) {
  const CaseSpec cs = small_case();
  const HybridMesh raw = build(cs, false), opt = build(cs, true);
  // Reservoir and well cells: same count, same node coordinates, same volumes.
  std::map<int, std::vector<double>> vol_raw, vol_opt;
  for (int c = 0; c < raw.mesh.n_cells(); ++c)
    if (raw.mesh.cell_region[c] != kTransition) vol_raw[raw.mesh.cell_region[c]].push_back(raw.geometry.cell_volume[c]);
  for (int c = 0; c < opt.mesh.n_cells(); ++c)
    if (opt.mesh.cell_region[c] != kTransition) vol_opt[opt.mesh.cell_region[c]].push_back(opt.geometry.cell_volume[c]);
  ASSERT_EQ(vol_raw.size(), vol_opt.size());
  for (const auto& [region, v] : vol_raw) {
    ASSERT_EQ(v.size(), vol_opt[region].size()) << "region " << region;
    for (size_t i = 0; i < v.size(); ++i) EXPECT_EQ(v[i], vol_opt[region][i]) << "region " << region << " cell " << i;
  }
}

TEST(SiteOptimizer, IsDeterministic) {
  const CaseSpec cs = small_case();
  const HybridMesh a = build(cs, true), b = build(cs, true);
  ASSERT_EQ(a.mesh.n_nodes(), b.mesh.n_nodes());
  ASSERT_EQ(a.mesh.face_nodes, b.mesh.face_nodes);
  for (int v = 0; v < a.mesh.n_nodes(); ++v) {
    EXPECT_EQ(a.mesh.nodes[v].x, b.mesh.nodes[v].x);
    EXPECT_EQ(a.mesh.nodes[v].y, b.mesh.nodes[v].y);
    EXPECT_EQ(a.mesh.nodes[v].z, b.mesh.nodes[v].z);
  }
}

// The 1M benchmark's well W9 (bench/scaling_case.hpp) in its 165 x 165 x 20 grid of 13.6 m cells (545k
// cells), meshed as meshgen does (local frame). The optimiser left an edge of 1.6e-7 m between two free
// vertices, at 2 degrees to a neighbouring face: fvcheck's conformity read its end as a hanging node
// (5e-9 m from that face) and the self-check refused the mesh (session 29; the sliver pass's first
// removal of it was refused, so the pass now tries a sliver's next site). Since session 41 the
// optimiser's removals no longer undo each other within a round (transition_optimize.cpp,
// sphere_movers) and it leaves no sliver there for the pass. It must mesh with no sliver edge.
TEST(SiteOptimizer, Bench545kWellNineLeavesNoSliverEdge) {
  CaseSpec cs = bench::scaling_case(165);
  cs.wells = {cs.wells[8]};
  HybridMesh h;
  ASSERT_NO_THROW(h = build_hybrid_mesh_in_local_frame(cs)) << "the self-check refused the mesh";
  // No edge of a transition cell shorter than kSliverEdge (1e-5) of the cell's reference length is left.
  EXPECT_EQ(transition_edges_shorter_than(h, 1e-5), 0);
}

// The benchmark's per-well rows (bench_scaling --per-well) assume that the same wells, at the same place
// relative to the grid's cells, get the same near-well cells in a larger reservoir: the cost of a well is
// then comparable across sizes. Two of its wells in 80 x 80 and 112 x 112 columns of 10 m cells (the
// wells 160 m further from the origin in the larger one): the same cell counts per region, and the same
// raw diagram (transition volume, Q_S before optimisation) to rounding. The optimised Q_S is not compared:
// the wells' nodes round differently 160 m away, which decides some exactly co-spherical site sets and
// so some micro-edges of the raw diagram, and the optimiser's kept moves follow (docs/performance.md,
// "Session 32").
TEST(SiteOptimizer, SameWellsInALargerReservoirGetTheSameCells) {
  struct Figures {
    int reservoir = 0, transition = 0, well = 0;
    double transition_volume = 0, raw_q_s_mean = 0;
  };
  auto figures_of = [](int lateral) {
    const HybridMesh h = build_hybrid_mesh(bench::fixed_cell_case(lateral, 2));
    Figures f;
    for (int c = 0; c < h.mesh.n_cells(); ++c) {
      const int32_t r = h.mesh.cell_region[c];
      (r == kReservoir ? f.reservoir : r == kTransition ? f.transition : f.well) += 1;
      if (r == kTransition) f.transition_volume += h.geometry.cell_volume[c];
    }
    f.raw_q_s_mean = h.transition_before.q_s.mean;
    return f;
  };
  const Figures small = figures_of(80), large = figures_of(112);
  ASSERT_GT(small.transition, 0);
  EXPECT_EQ(large.reservoir - small.reservoir, (112 * 112 - 80 * 80) * 20);
  EXPECT_EQ(large.transition, small.transition);
  EXPECT_EQ(large.well, small.well);
  EXPECT_NEAR(large.transition_volume, small.transition_volume, 1e-9 * small.transition_volume);
  EXPECT_NEAR(large.raw_q_s_mean, small.raw_q_s_mean, 1e-8);
}

// A sliver removal may not trade the sliver for a face that checkMesh fails: on accuracy_bent one
// removal left a 4 mm x 2 cm triangle of skewness 21 (checkMesh's limit is 4; the optimiser had left
// the mesh at 3.9). Removals that raise the count of faces above the limit around them are refused.
TEST(SiteOptimizer, SliverPassLeavesNoFaceAboveCheckMeshSkewness) {
  CaseSpec cs = load_case(std::string(HM_SOURCE_DIR) + "/examples/accuracy_bent.yaml");
  HybridMesh h;
  ASSERT_NO_THROW(h = build_hybrid_mesh_in_local_frame(cs));
  int slivers_removed = 0;
  for (const TransitionReport& r : h.transition_reports) slivers_removed += r.sliver_removals;
  EXPECT_GT(slivers_removed, 0);
  double worst = 0;
  for (double s : openfoam_face_skewness(h.mesh)) worst = std::max(worst, s);
  EXPECT_LE(worst, 4.0);
}

// The fail half: the planarity and orthogonality measures used above do see a bent face
// (one node of a transition face moved off its plane), so passing them means something.
TEST(SiteOptimizer, MeasuresSeeABentFace) {
  const CaseSpec cs = small_case();
  HybridMesh h = build(cs, true);
  int face = -1;
  for (int f = 0; f < h.mesh.n_faces() && face < 0; ++f) {
    const int o = h.mesh.face_owner[f], n = h.mesh.face_neighbour[f];
    if (n >= 0 && h.mesh.cell_region[o] == kTransition && h.mesh.cell_region[n] == kTransition && h.mesh.face_size(f) >= 4)
      face = f;
  }
  ASSERT_GE(face, 0);
  const int32_t v = h.mesh.face_begin(face)[0];
  h.geometry = compute_geometry(h.mesh);
  const Vec3 n = h.geometry.face_area[face] / norm(h.geometry.face_area[face]);
  const double size = std::sqrt(norm(h.geometry.face_area[face]));
  h.mesh.nodes[v] += 0.2 * size * n;
  h.geometry = compute_geometry(h.mesh);
  const Figures f = figures(h);
  EXPECT_GT(f.max_q_p, 1.0);
  EXPECT_LT(f.min_q_o_internal, 90 - 1e-3);
}

}  // namespace
