// The shipped examples, meshed by the pipeline, exported, run by OPM Flow: its steady pressures
// and well rates equal our TPFA solve on every cell and well.
#include <gtest/gtest.h>

#include "flow_test_support.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"

namespace {

using namespace hmtest;

struct ExampleRun {
  hm::CaseSpec cs;
  hm::HybridMesh hybrid;
  TpfaSolution ours;
  hm::EclipseDeckInfo info;
  FlowRun run;
  FlowComparison c;
  double mesh_s = 0, write_s = 0;
};

hm::CaseSpec load_example(const std::string& name) {
  return hm::load_case(std::string(HM_SOURCE_DIR) + "/examples/" + name + ".yaml");
}

// Meshes, solves, exports, runs flow, compares; fails the test (ASSERT) on any structural problem.
void run_example(const hm::CaseSpec& cs, const std::string& label, ExampleRun* r) {
  r->cs = cs;
  const auto t0 = std::chrono::steady_clock::now();
  r->hybrid = hm::build_hybrid_mesh(cs);
  r->mesh_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const hm::PolyMesh& mesh = r->hybrid.mesh;
  const hm::MeshGeometry& geo = r->hybrid.geometry;
  const hm::Transmissibilities trans = hm::compute_transmissibilities(mesh, geo);
  r->ours = reference_tpfa_solve(cs, mesh, trans);
  TempDir tmp("flow_" + label);
  const auto t1 = std::chrono::steady_clock::now();
  const hm::WriteStatus st = hm::write_eclipse_deck(tmp.str(), cs, mesh, geo, trans, {}, &r->info);
  r->write_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  ASSERT_TRUE(st.ok) << st.message;
  for (const std::string& w : r->info.warnings) std::printf("[ warning  ] %s\n", w.c_str());
  dump_ours_if_kept(tmp.path, cs, r->info.layout, r->ours);
  r->run = run_flow(tmp.path, hm::eclipse_deck_name(cs));
  ASSERT_FALSE(r->run.flow.timed_out);
  ASSERT_EQ(r->run.flow.exit_code, 0) << r->run.flow.output;
  ASSERT_EQ(r->run.reader.exit_code, 0) << r->run.reader.output;
  const hm::EclipseConnections conn = hm::make_eclipse_connections(mesh, r->info.layout, trans);
  r->c = compare_flow(cs, mesh, geo, r->info, r->ours, conn, r->run.results);
  ASSERT_TRUE(r->c.problem.empty()) << r->c.problem;
  const FlowComparison& c = r->c;
  const hm::EclipseLayout& L = r->info.layout;
  std::printf("[ figures  ] %s: %d cells (deck %dx%dx%d, %d extra columns), %d NNC records; mesh %.2f s, deck write "
              "%.3f s, flow %.2f s\n",
              label.c_str(), mesh.n_cells(), L.deck_nx, L.ny, L.nz, L.extra_columns, r->info.nnc, r->mesh_s, r->write_s,
              r->run.seconds);
  std::printf("[ figures  ] %s: max rel pressure %.3g, max rel rate %.3g, PORV %.3g, depth %.3g m, connections %zu "
              "(flow %zu, %zu TRANNNC, max rel %.3g; %zu below flow's threshold dropped, sum %.3g)\n",
              label.c_str(), c.max_rel_pressure, c.max_rel_rate, c.max_rel_porv, c.max_depth_diff, c.our_connections,
              c.flow_connections, c.flow_nnc, c.max_rel_connection, c.dropped_by_flow, c.dropped_sum);
  for (size_t w = 0; w < cs.wells.size(); ++w)
    std::printf("[ figures  ] %s: well %s rate %.6g rm3/day (ours)\n", label.c_str(), cs.wells[w].name.c_str(),
                r->ours.well_rate[w]);
}

void expect_match(const FlowComparison& c) {
  EXPECT_LT(c.max_rel_pressure, 1e-5);
  EXPECT_LT(c.max_rel_rate, 1e-5);
  EXPECT_LT(c.max_rel_porv, 1e-6);
  EXPECT_LT(c.max_depth_diff, 1e-3);
  EXPECT_LT(c.max_rel_connection, 1e-6) << c.worst_connection;
  EXPECT_EQ(c.flow_connections, c.our_connections);
  EXPECT_EQ(c.dropped_by_flow, c.expected_dropped);
}

// One producer in a closed reservoir: the steady state is hydrostatic at the BHP (rate ~0).
TEST(FlowExamples, PaperSingleWellMatchesOurSolve) {
  REQUIRE_FLOW();
  ExampleRun r;
  run_example(load_example("paper_single_well"), "paper_single_well", &r);
  if (HasFatalFailure()) return;
  expect_match(r.c);
}

// three_wells with a slightly compressible fluid (1e-8 /bar, the steady model's incompressible
// limit): flow must match on every cell and well.
TEST(FlowExamples, ThreeWellsMatchesOurSolve) {
  REQUIRE_FLOW();
  hm::CaseSpec cs = load_example("three_wells");
  cs.fluid.compressibility = 1e-8;
  ExampleRun r;
  run_example(cs, "three_wells", &r);
  if (HasFatalFailure()) return;
  expect_match(r.c);
}

// three_wells as shipped (Cw = 4e-5 /bar): flow's water density is rho_s (1 + Cw (p - pref)) in the
// gravity terms, ours is constant, so pressures differ by about Cw * (p spread) * (gravity head).
// The deck carries the case's Cw; the difference is this physics and stays below that bound.
TEST(FlowExamples, ThreeWellsWithTheCaseCompressibilityDiffersOnlyByTheDensityTerm) {
  REQUIRE_FLOW();
  const hm::CaseSpec cs = load_example("three_wells");
  ASSERT_EQ(cs.fluid.compressibility, 4e-5);
  ExampleRun r;
  run_example(cs, "three_wells_cw", &r);
  if (HasFatalFailure()) return;
  const auto [pmin, pmax] = std::minmax_element(r.ours.pressure.begin(), r.ours.pressure.end());
  const auto& z = cs.reservoir.z;
  const double head = cs.fluid.density * kGravity * kBarPerPa * (z.back() - z.front());
  const double bound = cs.fluid.compressibility * (*pmax - *pmin) * head / *pmin;
  std::printf("[ figures  ] three_wells_cw: density-term bound on the relative pressure difference %.3g\n", bound);
  EXPECT_LT(r.c.max_rel_pressure, bound);
  EXPECT_LT(r.c.max_rel_porv, 1e-6);
  EXPECT_LT(r.c.max_rel_connection, 1e-6);
  EXPECT_EQ(r.c.flow_connections, r.c.our_connections);
  EXPECT_EQ(r.c.dropped_by_flow, r.c.expected_dropped);
}

}  // namespace
