// The deck proves itself: OPM Flow runs it and its steady pressures and well rates equal our
// TPFA solve (same transmissibilities, pore volumes, depths, connection factors).
#include <gtest/gtest.h>

#include "flow_test_support.hpp"

namespace {

using namespace hmtest;

// Non-uniform box, 6 x 5 x 4 layers over 30 m (gravity matters), an injector and a producer.
hm::CaseSpec two_well_box() {
  hm::CaseSpec cs = box_case({0, 30, 50, 60, 70, 90, 120}, {0, 25, 45, 55, 65, 90}, {1000, 1005, 1012, 1020, 1030});
  cs.name = "two_wells";
  add_vertical_well(cs, "INJ", hm::WellType::Injector, 2, 2, 260, 0.1);
  add_vertical_well(cs, "PROD", hm::WellType::Producer, 4, 3, 150, 0.1);
  cs.fluid.viscosity = 0.7;
  cs.fluid.density = 1030;
  cs.fluid.compressibility = 1e-8;
  return cs;
}

void report(const char* what, const FlowComparison& c, const FlowRun& run) {
  std::printf("[ figures  ] %s: max rel pressure %.3g, max rel rate %.3g, PORV %.3g, depth %.3g m, TRAN %.3g, "
              "NNC %zu (max rel %.3g), flow %.2f s\n",
              what, c.max_rel_pressure, c.max_rel_rate, c.max_rel_porv, c.max_depth_diff, c.max_rel_tran, c.flow_nnc,
              c.max_rel_nnc, run.seconds);
}

TEST(FlowDeck, BoxWithTwoVerticalWellsAndGravityMatchesOurSolve) {
  REQUIRE_FLOW();
  const hm::CaseSpec cs = two_well_box();
  hm::BuildReport rep;
  const hm::PolyMesh mesh = build_box_with_vertical_wells(cs, &rep);
  ASSERT_TRUE(rep.ok);
  const hm::MeshGeometry geo = hm::compute_geometry(mesh);
  const hm::Transmissibilities trans = hm::compute_transmissibilities(mesh, geo);
  ASSERT_EQ(trans.negative, 0);
  const TpfaSolution ours = reference_tpfa_solve(cs, mesh, trans);
  // The case is not trivial: water flows from INJ to PROD and gravity shapes the pressures.
  ASSERT_LT(ours.well_rate[0], -1.0);
  ASSERT_GT(ours.well_rate[1], 1.0);

  TempDir tmp("flow_box");
  hm::EclipseDeckInfo info;
  const hm::WriteStatus st = hm::write_eclipse_deck(tmp.str(), cs, mesh, geo, trans, {}, &info);
  ASSERT_TRUE(st.ok) << st.message;
  ASSERT_GT(info.layout.extra_columns, 0);  // the well cells sit in extra columns, joined by NNC
  dump_ours_if_kept(tmp.path, cs, info.layout, ours);
  const FlowRun run = run_flow(tmp.path, "TWO_WELLS");
  ASSERT_FALSE(run.flow.timed_out);
  ASSERT_EQ(run.flow.exit_code, 0) << run.flow.output;
  ASSERT_EQ(run.reader.exit_code, 0) << run.reader.output;
  const hm::EclipseConnections conn = hm::make_eclipse_connections(mesh, info.layout, trans);
  const FlowComparison c = compare_flow(cs, mesh, geo, info, ours, conn, run.results);
  ASSERT_TRUE(c.problem.empty()) << c.problem;
  report("two-well box", c, run);
  EXPECT_LT(c.max_rel_pressure, 1e-5);
  EXPECT_LT(c.max_rel_rate, 1e-5);
  EXPECT_LT(c.max_rel_porv, 1e-6);
  EXPECT_LT(c.max_depth_diff, 1e-3);
  EXPECT_LT(c.max_rel_tran, 1e-6);
  EXPECT_LT(c.max_rel_nnc, 1e-6);
  EXPECT_EQ(c.flow_nnc, conn.nnc.size());
}

}  // namespace
