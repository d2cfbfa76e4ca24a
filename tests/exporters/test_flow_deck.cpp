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
  std::printf("[ figures  ] %s: max rel pressure %.3g, max rel rate %.3g, PORV %.3g, depth %.3g m, "
              "connections %zu (flow: %zu, %zu of them TRANNNC, max rel %.3g), flow %.2f s (CPU %.2f s, %d Newton)\n",
              what, c.max_rel_pressure, c.max_rel_rate, c.max_rel_porv, c.max_depth_diff, c.our_connections,
              c.flow_connections, c.flow_nnc, c.max_rel_connection, run.seconds, run.cpu_seconds, run.newton);
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
  EXPECT_LT(c.max_rel_connection, 1e-6);
  EXPECT_EQ(c.flow_connections, c.our_connections);
  EXPECT_EQ(c.dropped_by_flow, c.expected_dropped);
}

// The optional path: the steady deck (EclipseSchedule::Steady) run with
// flow_steady_state_options() agrees just as well (docs/export-eclipse.md).
TEST(FlowDeck, SteadyDeckWithTheOptionsMatchesOurSolve) {
  REQUIRE_FLOW();
  const hm::CaseSpec cs = two_well_box();
  hm::BuildReport rep;
  const hm::PolyMesh mesh = build_box_with_vertical_wells(cs, &rep);
  ASSERT_TRUE(rep.ok);
  const hm::MeshGeometry geo = hm::compute_geometry(mesh);
  const hm::Transmissibilities trans = hm::compute_transmissibilities(mesh, geo);
  const TpfaSolution ours = reference_tpfa_solve(cs, mesh, trans);
  TempDir tmp("flow_box_single");
  hm::EclipseDeckOptions opt;
  opt.schedule = hm::EclipseSchedule::Steady;
  hm::EclipseDeckInfo info;
  ASSERT_TRUE(hm::write_eclipse_deck(tmp.str(), cs, mesh, geo, trans, opt, &info).ok);
  EXPECT_EQ(info.end_days, opt.tstep_days);
  const FlowRun run = run_flow(tmp.path, "TWO_WELLS", FlowInvocation::WithOptions);
  ASSERT_EQ(run.flow.exit_code, 0) << run.flow.output;
  ASSERT_EQ(run.reader.exit_code, 0) << run.reader.output;
  const hm::EclipseConnections conn = hm::make_eclipse_connections(mesh, info.layout, trans);
  const FlowComparison c = compare_flow(cs, mesh, geo, info, ours, conn, run.results);
  ASSERT_TRUE(c.problem.empty()) << c.problem;
  report("two-well box, steady deck with the options", c, run);
  EXPECT_LT(c.max_rel_pressure, 1e-5);
  EXPECT_LT(c.max_rel_rate, 1e-5);
}

// The fail half of the pair: the same comparison flags a deck whose transmissibilities are not
// the ones we solved with (one NNC face doubled), so the agreement above is not vacuous.
TEST(FlowDeck, ComparisonDetectsADeckWithOneWrongTransmissibility) {
  REQUIRE_FLOW();
  const hm::CaseSpec cs = two_well_box();
  hm::BuildReport rep;
  const hm::PolyMesh mesh = build_box_with_vertical_wells(cs, &rep);
  const hm::MeshGeometry geo = hm::compute_geometry(mesh);
  const hm::Transmissibilities trans = hm::compute_transmissibilities(mesh, geo);
  const TpfaSolution ours = reference_tpfa_solve(cs, mesh, trans);
  // Double the transmissibility of a face between a cell on the producer's wellbore and a
  // reservoir cell (the faces between the cells around the hole carry no flow by symmetry).
  hm::Transmissibilities wrong = trans;
  const auto wells = hm::well_connection_factors(mesh, trans, 2);
  const int32_t cell = wells[1][0].first;
  int32_t face = -1;
  for (const int32_t* f = mesh.cell_begin(cell); f != mesh.cell_end(cell); ++f)
    if (mesh.face_neighbour[*f] >= 0 &&
        mesh.cell_region[mesh.face_owner[*f] == cell ? mesh.face_neighbour[*f] : mesh.face_owner[*f]] == hm::kReservoir)
      face = *f;
  ASSERT_GE(face, 0);
  wrong.face[face] *= 2;
  TempDir tmp("flow_wrong");
  hm::EclipseDeckInfo info;
  ASSERT_TRUE(hm::write_eclipse_deck(tmp.str(), cs, mesh, geo, wrong, {}, &info).ok);
  const FlowRun run = run_flow(tmp.path, "TWO_WELLS");
  ASSERT_EQ(run.flow.exit_code, 0) << run.flow.output;
  const hm::EclipseConnections conn = hm::make_eclipse_connections(mesh, info.layout, trans);
  const FlowComparison c = compare_flow(cs, mesh, geo, info, ours, conn, run.results);
  ASSERT_TRUE(c.problem.empty()) << c.problem;
  report("two-well box, one face doubled in the deck", c, run);
  EXPECT_GT(c.max_rel_connection, 0.99);  // the doubled face, seen in flow's INIT
  // ... and beyond the 1e-5 gate of the tests above, in pressures and rates.
  EXPECT_GT(c.max_rel_pressure, 1e-4);
  EXPECT_GT(c.max_rel_rate, 2e-5);
}

// A larger non-uniform box with four wells (two injectors, two producers) and strong gravity:
// the flow options must converge to the same accuracy on ~9,000 cells.
TEST(FlowDeck, LargerBoxWithFourWellsMatchesOurSolve) {
  REQUIRE_FLOW();
  std::vector<double> x{0}, y{0}, z{1500};
  for (int i = 0; i < 30; ++i) x.push_back(x.back() + 8 + (i % 5));
  for (int j = 0; j < 25; ++j) y.push_back(y.back() + 9 + (j % 3));
  for (int k = 0; k < 12; ++k) z.push_back(z.back() + 2 + 0.5 * k);
  hm::CaseSpec cs = box_case(x, y, z);
  cs.name = "four_wells";
  cs.reservoir.permeability = {300, 150, 20};
  add_vertical_well(cs, "I1", hm::WellType::Injector, 5, 5, 330, 0.1);
  add_vertical_well(cs, "I2", hm::WellType::Injector, 25, 20, 320, 0.12);
  add_vertical_well(cs, "P1", hm::WellType::Producer, 24, 6, 250, 0.1);
  add_vertical_well(cs, "P2", hm::WellType::Producer, 6, 19, 260, 0.08);
  cs.fluid.viscosity = 1.3;
  cs.fluid.density = 1100;
  hm::BuildReport rep;
  const hm::PolyMesh mesh = build_box_with_vertical_wells(cs, &rep);
  ASSERT_TRUE(rep.ok);
  const hm::MeshGeometry geo = hm::compute_geometry(mesh);
  const hm::Transmissibilities trans = hm::compute_transmissibilities(mesh, geo);
  const TpfaSolution ours = reference_tpfa_solve(cs, mesh, trans);
  TempDir tmp("flow_four");
  hm::EclipseDeckInfo info;
  const hm::WriteStatus st = hm::write_eclipse_deck(tmp.str(), cs, mesh, geo, trans, {}, &info);
  ASSERT_TRUE(st.ok) << st.message;
  dump_ours_if_kept(tmp.path, cs, info.layout, ours);
  const FlowRun run = run_flow(tmp.path, "FOUR_WELLS");
  ASSERT_FALSE(run.flow.timed_out);
  ASSERT_EQ(run.flow.exit_code, 0) << run.flow.output;
  ASSERT_EQ(run.reader.exit_code, 0) << run.reader.output;
  const hm::EclipseConnections conn = hm::make_eclipse_connections(mesh, info.layout, trans);
  const FlowComparison c = compare_flow(cs, mesh, geo, info, ours, conn, run.results);
  ASSERT_TRUE(c.problem.empty()) << c.problem;
  report("four-well box", c, run);
  EXPECT_LT(c.max_rel_pressure, 1e-5);
  EXPECT_LT(c.max_rel_rate, 1e-5);
  EXPECT_LT(c.max_rel_porv, 1e-6);
  EXPECT_LT(c.max_rel_connection, 1e-6);
  EXPECT_EQ(c.flow_connections, c.our_connections);
  EXPECT_EQ(c.dropped_by_flow, c.expected_dropped);
}

}  // namespace
