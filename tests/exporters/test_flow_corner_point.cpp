// A corner-point model with wells, exported and run by OPM Flow (docs/export-eclipse.md, "A corner-point
// model"): the synthetic tilted, twisted model of tests/pipeline/test_corner_point_wells.cpp
// (tests/support/corner_point_test_models.hpp) with a producer and an injector is meshed, exported with
// `write_eclipse_deck`, run as typed; flow's pressures (every cell) and well rates must equal those of
// solver_demo's library solve (`solve_tpfa` of `deck_flow_problem`) on the same mesh. What can fail: the
// deck's model columns are not the model's (COORD/ZCORN bit for bit, ACTNUM 0 exactly on the cavity's
// cells), flow connects other pairs or with other values than ours (per pair, INIT), an NNC is dropped
// (TRANNNC count), the pressures or rates differ by more than 1e-6.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "corner_point_test_models.hpp"
#include "flow_test_support.hpp"
#include "meshgen/case/grdecl.hpp"
#include "meshgen/grids/corner_point_multipliers.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"
#include "solver_demo/lib/case_problem.hpp"

namespace {

using namespace hmtest;

// The producer of the pipeline test and an injector 57 m away (both at least two layers from the top
// and bottom, so that their cavities stay inside the model).
std::string two_wells_yaml() { return vertical_well_yaml(90, 90, 1034, 1046) + injector_yaml(50, 130, 1030, 1042); }

struct CornerPointFlowRun {
  hm::CaseSpec cs;
  hm::HybridMesh out;
  hm::Transmissibilities trans;
  hm::FlowSolution ours;
  hm::EclipseDeckInfo info;
  FlowRun run;
  FlowComparison c;
};

// Meshes the model with `wells`, solves with solver_demo's library, exports, runs flow, compares.
void run_case(const TempDir& tmp, const TiltedModel& model, const std::string& wells, CornerPointFlowRun* r) {
  std::ofstream(tmp.path / "M.GRDECL") << model.text();
  std::ofstream(tmp.path / "cpw.yaml") << "name: cpw\nreservoir: {grdecl: M.GRDECL, initial_pressure: 200}\n"
                                       << "fluid: {viscosity: 0.5, density: 1000, compressibility: 4.0e-5}\n"
                                       << wells;
  r->cs = hm::load_case((tmp.path / "cpw.yaml").string());
  ASSERT_TRUE(r->cs.reservoir.corner_point);
  try {
    r->out = hm::build_hybrid_mesh(r->cs);
  } catch (const std::exception& e) {
    FAIL() << "meshing failed: " << e.what();
  }
  const hm::PolyMesh& mesh = r->out.mesh;
  r->trans = hm::compute_transmissibilities(mesh, r->out.geometry, hm::deck_transmissibility_options());
  // The deck's equation: without the connections flow leaves out (none of them is then in the deck).
  std::string no_layout;
  hm::FlowDroppedConnections dropped;
  ASSERT_TRUE(hm::drop_connections_flow_ignores(r->cs.reservoir, mesh, {}, &r->trans, &dropped, &no_layout)) << no_layout;
  r->ours = hm::solve_tpfa(hm::deck_flow_problem(r->cs, mesh, r->out.geometry), r->trans);
  const fs::path deck = tmp.path / "deck";
  const hm::WriteStatus st = hm::write_eclipse_deck(deck.string(), r->cs, mesh, r->out.geometry, r->trans, {}, &r->info);
  ASSERT_TRUE(st.ok) << st.message;
  for (const std::string& w : r->info.warnings) std::printf("[ warning  ] %s\n", w.c_str());
  r->run = run_flow(deck, "CPW");
  ASSERT_FALSE(r->run.flow.timed_out);
  ASSERT_EQ(r->run.flow.exit_code, 0) << r->run.flow.output.substr(0, 3000);
  ASSERT_EQ(r->run.reader.exit_code, 0) << r->run.reader.output;
  TpfaSolution ours;
  ours.pressure = r->ours.pressure;
  ours.well_rate = r->ours.well_rate_m3_per_day;
  const hm::EclipseConnections conn = hm::make_eclipse_connections(mesh, r->info.layout, r->trans);
  r->c = compare_flow(r->cs, mesh, r->out.geometry, r->info, ours, conn, r->run.results);
  ASSERT_TRUE(r->c.problem.empty()) << r->c.problem;
  EXPECT_EQ(r->c.dropped_by_flow, 0u) << "flow left out connections the deck carries";
}

// OPM's deck parser reads some 17-digit decimals one ulp off (measured: "51.449999999999996", the
// shortest text of that double, comes back as 51.450000000000003). A model's values as OPM read them
// in the first place come back bit for bit; the interpolated pillars and depths of a model refined
// near the wells (meshgen/case/corner_point_refine.hpp) within that ulp.
bool same_as_opm_reads(double back, double written) {
  return back == written || std::abs(back - written) <= std::numeric_limits<double>::epsilon() * std::abs(written);
}

// The deck's model columns: the model's pillars and corner depths (read back by OPM, see above), and
// ACTNUM 0 exactly on the model's cells the cavities replaced.
void expect_model_columns(const CornerPointFlowRun& r, const fs::path& data) {
  const hm::CornerPointModel& m = *r.cs.reservoir.corner_point;
  const hm::CornerPointModel back = hm::read_corner_point_model(data.string(), "deck");
  const hm::EclipseLayout& L = r.info.layout;
  ASSERT_EQ(back.nx, L.deck_nx);
  ASSERT_GT(L.deck_nx, m.nx + 1);
  ASSERT_EQ(back.ny, m.ny);
  ASSERT_EQ(back.nz, m.nz);
  size_t coord_diff = 0, zcorn_diff = 0;
  for (int J = 0; J <= m.ny; ++J)
    for (int I = 0; I <= m.nx; ++I)
      for (int q = 0; q < 6; ++q)
        coord_diff += !same_as_opm_reads(back.coord[6 * (I + (back.nx + 1) * J) + q], m.coord[6 * (I + (m.nx + 1) * J) + q]);
  for (int k = 0; k < m.nz; ++k)
    for (int j = 0; j < m.ny; ++j)
      for (int i = 0; i < m.nx; ++i)
        for (int q = 0; q < 8; ++q)
          zcorn_diff += !same_as_opm_reads(back.zcorn[hm::zcorn_index(back, i, j, k, q)], m.zcorn[hm::zcorn_index(m, i, j, k, q)]);
  EXPECT_EQ(coord_diff, 0u);
  EXPECT_EQ(zcorn_diff, 0u);
  // ACTNUM of the model's columns: the model's active cells minus exactly the cavities' cells.
  std::set<int> cavity, meshed;
  for (const hm::Cavity& cav : r.out.cavities.cavities) cavity.insert(cav.deactivated_cells.begin(), cav.deactivated_cells.end());
  ASSERT_FALSE(cavity.empty());
  for (int c = 0; c < r.out.mesh.n_cells(); ++c)
    if (r.out.mesh.cell_region[c] == hm::kReservoir) {
      const auto& ijk = r.out.mesh.cell_ijk[c];
      meshed.insert(ijk[0] + m.nx * (ijk[1] + m.ny * ijk[2]));
    }
  size_t wrong = 0, off = 0;
  for (int k = 0; k < m.nz; ++k)
    for (int j = 0; j < m.ny; ++j)
      for (int i = 0; i < m.nx; ++i) {
        const int c = i + m.nx * (j + m.ny * k), g = i + L.deck_nx * (j + m.ny * k);
        // Active cells of zero thickness (a pinched-out layer) are not meshed: ACTNUM 0 too.
        const bool flat = m.actnum[c] && !cavity.count(c) && !meshed.count(c);
        const int expected = m.actnum[c] && !cavity.count(c) && !flat ? 1 : 0;
        wrong += back.actnum[g] != expected;
        off += back.actnum[g] == 0 && m.actnum[c] && !flat;
      }
  EXPECT_EQ(wrong, 0u);
  EXPECT_EQ(off, cavity.size());
  std::printf("[ figures  ] ACTNUM 0 on the %zu cavity cells of the model's columns (%zu wrong)\n", cavity.size(), wrong);
  // The separator column is inactive; every near-well cell is active in the extra columns.
  size_t extra_active = 0;
  for (int k = 0; k < m.nz; ++k)
    for (int j = 0; j < m.ny; ++j) {
      EXPECT_EQ(back.actnum[m.nx + L.deck_nx * (j + m.ny * k)], 0);
      for (int i = m.nx + 1; i < L.deck_nx; ++i) extra_active += back.actnum[i + L.deck_nx * (j + m.ny * k)];
    }
  size_t near_well = 0;
  for (int c = 0; c < r.out.mesh.n_cells(); ++c) near_well += r.out.mesh.cell_region[c] != hm::kReservoir;
  EXPECT_EQ(extra_active, near_well);
}

// TRANNNC entries flow must list: our NNC records except those flow merges into TRANX/Y/Z, which it
// decides by the natural indices alone (difference 1, NX or NX NY: two boxes stacked in an extra
// column, or two boxes of rows J and J + 8 in consecutive layers, whose indices differ by NX).
size_t expected_trannnc(const hm::EclipseLayout& L, const hm::EclipseConnections& conn) {
  size_t n = 0;
  for (const auto& r : conn.nnc) {
    const int32_t d = r.b - r.a;
    n += d != 1 && d != L.deck_nx && d != L.deck_nx * L.ny;
  }
  return n;
}

void report(const char* label, const CornerPointFlowRun& r, size_t trannnc_expected) {
  const hm::EclipseLayout& L = r.info.layout;
  int near_well = 0;
  for (int c = 0; c < r.out.mesh.n_cells(); ++c) near_well += r.out.mesh.cell_region[c] != hm::kReservoir;
  std::printf("[ figures  ] %s: %d cells (%d near-well), deck %dx%dx%d (%d extra columns), %d NNC records, "
              "%d TRANX/Y/Z; flow as typed %.2f s wall (CPU %.2f s, %d Newton)\n",
              label, r.out.mesh.n_cells(), near_well, L.deck_nx, L.ny, L.nz, L.extra_columns, r.info.nnc,
              r.info.tran_connections, r.run.seconds, r.run.cpu_seconds, r.run.newton);
  std::printf("[ figures  ] %s: flow vs solver_demo: max rel pressure %.3g, max rel rate %.3g, PORV %.3g, depth %.3g m; "
              "connections %zu (flow %zu), max rel %.3g; TRANNNC %zu (expected %zu), %zu dropped by flow\n",
              label, r.c.max_rel_pressure, r.c.max_rel_rate, r.c.max_rel_porv, r.c.max_depth_diff, r.c.our_connections,
              r.c.flow_connections, r.c.max_rel_connection, r.c.flow_nnc, trannnc_expected, r.c.dropped_by_flow);
  for (size_t w = 0; w < r.cs.wells.size(); ++w)
    std::printf("[ figures  ] %s: well %s rate %.9g sm3/day (solver_demo)\n", label, r.cs.wells[w].name.c_str(),
                r.ours.well_rate_m3_per_day[w]);
}

// The gate sees the model's own connections: solver_demo's solve with the transmissibilities of the
// model-model faces scaled by 1.01 misses flow's run by more than the gate.
double pressure_miss_with_scaled_model_faces(const CornerPointFlowRun& r) {
  hm::Transmissibilities scaled = r.trans;
  const hm::PolyMesh& mesh = r.out.mesh;
  for (int f = 0; f < mesh.n_faces(); ++f) {
    const int32_t o = mesh.face_owner[f], n = mesh.face_neighbour[f];
    if (n >= 0 && mesh.cell_region[o] == hm::kReservoir && mesh.cell_region[n] == hm::kReservoir) scaled.face[f] *= 1.01;
  }
  const hm::FlowSolution s = hm::solve_tpfa(hm::deck_flow_problem(r.cs, mesh, r.out.geometry), scaled);
  TpfaSolution other;
  other.pressure = s.pressure;
  other.well_rate = s.well_rate_m3_per_day;
  const FlowComparison c = compare_flow(r.cs, mesh, r.out.geometry, r.info, other,
                                        hm::make_eclipse_connections(mesh, r.info.layout, r.trans), r.run.results);
  return std::max(c.max_rel_pressure, c.max_rel_rate);
}

void expect_flow_is_solver_demo(const CornerPointFlowRun& r) {
  EXPECT_LT(r.c.max_rel_pressure, 1e-6);
  EXPECT_LT(r.c.max_rel_rate, 1e-6);
  EXPECT_LT(r.c.max_rel_porv, 1e-6);
  EXPECT_LT(r.c.max_depth_diff, 1e-3);
  EXPECT_LT(r.c.max_rel_connection, 1e-6) << r.c.worst_connection;
  EXPECT_EQ(r.c.flow_connections, r.c.our_connections);
  EXPECT_EQ(r.c.dropped_by_flow, r.c.expected_dropped);
  // Both wells flow: the comparison is not of a hydrostatic rest state.
  for (double q : r.ours.well_rate_m3_per_day) EXPECT_GT(std::abs(q), 1.0);
  const double miss = pressure_miss_with_scaled_model_faces(r);
  std::printf("[ figures  ] fail half: model-model transmissibilities x 1.01 in solver_demo: flow differs by %.3g\n", miss);
  EXPECT_GT(miss, 1e-5);
}

// Every check of a run (deck = tmp/deck/CPW.DATA).
void expect_corner_point_run(const char* label, const TempDir& tmp, const CornerPointFlowRun& r) {
  const hm::EclipseConnections conn = hm::make_eclipse_connections(r.out.mesh, r.info.layout, r.trans);
  const size_t trannnc = expected_trannnc(r.info.layout, conn);
  report(label, r, trannnc);
  EXPECT_EQ(r.trans.negative, 0);  // the deck's form (OPM's on the model's side) is never negative
  std::printf("[ figures  ] model-side halves negative in the checker's signed two-point form: %d\n",
              hm::compute_transmissibilities(r.out.mesh, r.out.geometry).negative);
  expect_model_columns(r, tmp.path / "deck" / "CPW.DATA");
  EXPECT_EQ(r.c.flow_nnc, trannnc);
  EXPECT_GT(trannnc, 100u);
  expect_flow_is_solver_demo(r);
}

}  // namespace

TEST(FlowCornerPoint, TiltedModelWithTwoVerticalWellsMatchesSolverDemo) {
  REQUIRE_FLOW();
  TempDir tmp("flow_cpw");
  CornerPointFlowRun r;
  run_case(tmp, TiltedModel{}, two_wells_yaml(), &r);
  if (HasFatalFailure()) return;
  expect_corner_point_run("tilted, two vertical wells", tmp, r);
  // The signed transmissibilities (the checker's): the model-side halves of some constrained
  // triangles are negative, flow would zero those NNCs; the exporter refuses with the reason.
  const hm::Transmissibilities signed_trans = hm::compute_transmissibilities(r.out.mesh, r.out.geometry);
  ASSERT_GT(signed_trans.negative, 0);
  const hm::WriteStatus refused =
      hm::write_eclipse_deck((tmp.path / "signed").string(), r.cs, r.out.mesh, r.out.geometry, signed_trans);
  EXPECT_FALSE(refused.ok);
  EXPECT_NE(refused.message.find("negative transmissibility, which OPM Flow sets to zero"), std::string::npos)
      << refused.message;
  EXPECT_FALSE(fs::exists(tmp.path / "signed" / "CPW.DATA"));
}

// Inclined, non-parallel pillars (no model face planar), 22 layers, the deviated producer of
// CornerPointWells.DeviatedWellWithInclinedPillarsMeshes across two columns, and a vertical injector.
TEST(FlowCornerPoint, InclinedPillarsWithADeviatedWellMatchesSolverDemo) {
  REQUIRE_FLOW();
  TempDir tmp("flow_cpw_inclined");
  TiltedModel g;
  g.nz = 22, g.inclined_pillars = true;
  CornerPointFlowRun r;
  run_case(tmp, g, deviated_well_yaml() + injector_yaml(50, 130, 1040, 1052), &r);
  if (HasFatalFailure()) return;
  expect_corner_point_run("inclined pillars, deviated well", tmp, r);
}

// The model's transmissibility multipliers (MULTX..MULTZ-, FAULTS/MULTFLT) with near-well cells
// (docs/corner-point.md, "Transmissibility multipliers"): MULTX, MULTY-, MULTZ on every layer (0.02 on
// the producer's layer 6, inside its cavity) and a fault of 6 m throw between the wells with MULTFLT
// 0.05, MULTREGT between three MULTNUM regions (region_multiplier_keywords) and EDITNNC on the connections
// across the fault (edit_nnc_keywords). The mesh carries them on
// the faces between model cells and on the cavity walls; flow runs the deck and matches solver_demo. Fail
// half: solver_demo without the multipliers misses flow.
TEST(FlowCornerPoint, ModelWithMultipliersAndWellsMatchesSolverDemo) {
  REQUIRE_FLOW();
  TempDir tmp("flow_cpw_mult");
  TiltedModel g;
  g.fault_i = 8, g.throw_m = 6;
  g.keywords = multiplier_keywords(g, 6) + region_multiplier_keywords(g) + edit_nnc_keywords(g);
  CornerPointFlowRun r;
  run_case(tmp, g, two_wells_yaml(), &r);
  if (HasFatalFailure()) return;
  const hm::PolyMesh& mesh = r.out.mesh;
  ASSERT_EQ(mesh.face_trans_mult.size(), static_cast<size_t>(mesh.n_faces()));
  int wall = 0, model = 0;
  for (int f = 0; f < mesh.n_faces(); ++f) {
    const int32_t n = mesh.face_neighbour[f];
    if (n < 0 || mesh.face_trans_mult[f] == 1.0) continue;
    const bool ro = mesh.cell_region[mesh.face_owner[f]] == hm::kReservoir, rn = mesh.cell_region[n] == hm::kReservoir;
    (ro && rn ? model : wall) += 1;
  }
  std::printf("[ figures  ] multipliers on %d model faces and %d cavity-wall faces\n", model, wall);
  EXPECT_GT(wall, 50);
  EXPECT_GT(model, 1000);
  expect_corner_point_run("tilted, fault, multipliers", tmp, r);
  hm::PolyMesh plain = mesh;
  plain.face_trans_mult.clear();
  const hm::FlowSolution s = hm::solve_tpfa(hm::deck_flow_problem(r.cs, plain, r.out.geometry),
                                            hm::compute_transmissibilities(plain, r.out.geometry,
                                                                           hm::deck_transmissibility_options()));
  double miss = 0;
  for (size_t w = 0; w < s.well_rate_m3_per_day.size(); ++w)
    miss = std::max(miss, std::abs(s.well_rate_m3_per_day[w] / r.ours.well_rate_m3_per_day[w] - 1));
  std::printf("[ figures  ] fail half: without the multipliers the well rates differ by %.3g\n", miss);
  EXPECT_GT(miss, 1e-3);
}

// A fail half: solver_demo on the run's mesh without its connections without a face; the largest relative
// differences from the run's solve, in cell pressure and in well rate.
struct Miss {
  double pressure = 0, rate = 0;
};
Miss miss_without_connections_without_a_face(const CornerPointFlowRun& r) {
  hm::PolyMesh plain = r.out.mesh;
  plain.nnc_cells.clear();
  plain.nnc_trans.clear();
  const hm::FlowSolution s = hm::solve_tpfa(hm::deck_flow_problem(r.cs, plain, r.out.geometry),
                                            hm::compute_transmissibilities(plain, r.out.geometry,
                                                                           hm::deck_transmissibility_options()));
  Miss m;
  for (size_t c = 0; c < s.pressure.size(); ++c)
    m.pressure = std::max(m.pressure, std::abs(s.pressure[c] / r.ours.pressure[c] - 1));
  for (size_t w = 0; w < s.well_rate_m3_per_day.size(); ++w)
    m.rate = std::max(m.rate, std::abs(s.well_rate_m3_per_day[w] / r.ours.well_rate_m3_per_day[w] - 1));
  return m;
}

// The model's NNC (nnc_keywords: four connections between cells that share no face, one a conduit
// between the two wells' surroundings; docs/corner-point.md, "NNC and EDITNNC") become the mesh's
// connections without a face, between the cells they name with the deck's values; the deck's NNC records
// carry them, flow runs it and matches solver_demo. Fail half: solver_demo without them misses flow.
TEST(FlowCornerPoint, ModelNncIsCarriedAndMatchesSolverDemo) {
  REQUIRE_FLOW();
  TempDir tmp("flow_cpw_nnc");
  TiltedModel g;
  g.keywords = nnc_keywords();
  CornerPointFlowRun r;
  run_case(tmp, g, two_wells_yaml(), &r);
  if (HasFatalFailure()) return;
  const hm::PolyMesh& mesh = r.out.mesh;
  std::map<std::pair<std::array<int32_t, 3>, std::array<int32_t, 3>>, double> expected;
  for (const auto& e : nnc_records()) {
    std::array<int32_t, 3> a{int(e[0]) - 1, int(e[1]) - 1, int(e[2]) - 1}, b{int(e[3]) - 1, int(e[4]) - 1, int(e[5]) - 1};
    expected[{std::min(a, b), std::max(a, b)}] = e[6];
  }
  ASSERT_EQ(mesh.n_nncs(), static_cast<int>(expected.size()));
  for (int k = 0; k < mesh.n_nncs(); ++k) {
    const auto a = mesh.cell_ijk[mesh.nnc_cells[k][0]], b = mesh.cell_ijk[mesh.nnc_cells[k][1]];
    const auto it = expected.find({std::min(a, b), std::max(a, b)});
    ASSERT_NE(it, expected.end()) << "connection " << k << " joins cells the deck does not name";
    EXPECT_NEAR(mesh.nnc_trans[k], it->second, 1e-12 * it->second);
  }
  expect_corner_point_run("tilted, NNC", tmp, r);
  const Miss miss = miss_without_connections_without_a_face(r);
  std::printf("[ figures  ] fail half: without the NNC the well rates differ by %.3g, the pressures by %.3g\n", miss.rate,
              miss.pressure);
  EXPECT_GT(miss.rate, 1e-3);
}

// The same MINPV model with a producer and an injector: flow runs the deck (the removed cells inactive,
// the connections across them NNC records) and matches solver_demo. Fail half: solver_demo without the
// connections across the removed cells misses flow.
TEST(FlowCornerPoint, MinpvModelWithWellsMatchesSolverDemo) {
  REQUIRE_FLOW();
  TempDir tmp("flow_cpw_minpv");
  TiltedModel g;
  g.pinch_k = 5, g.pinch_x = 180;
  g.keywords = "MINPV\n 120 /\n";
  CornerPointFlowRun r;
  run_case(tmp, g, two_wells_yaml(), &r);
  if (HasFatalFailure()) return;
  const hm::PolyMesh& mesh = r.out.mesh;
  ASSERT_GT(mesh.n_nncs(), 0);
  expect_corner_point_run("tilted, MINPV", tmp, r);
  const Miss miss = miss_without_connections_without_a_face(r);
  std::printf("[ figures  ] fail half: without the %d connections across the removed cells solver_demo differs by "
              "%.3g in pressure, %.3g in rate\n",
              mesh.n_nncs(), miss.pressure, miss.rate);
  EXPECT_GT(std::max(miss.pressure, miss.rate), 1e-5);
}

// A fault of 10 m throw (2.2 layers) crossed by the deviated producer, an injector beyond it, and the MINPV
// model's pinching layer: the cells near the producer are split at the fault's steps (docs/corner-point.md,
// "Fault steps"), the others keep their thickness beside children of none; the deck carries the split
// model (the connections across those children and across the removed cells, between the meshed
// children), flow runs it as typed and matches solver_demo.
// The injector at (40, 150) sits beside the producer's refined rows (its own columns refined to its size
// since session 25: "Near-well refinement", two wells).
TEST(FlowCornerPoint, ModelSplitAtFaultStepsMatchesSolverDemo) {
  REQUIRE_FLOW();
  TiltedModel g;
  g.fault_i = 5, g.throw_m = 10;
  g.pinch_k = 5, g.pinch_x = 180;
  g.keywords = "MINPV\n 120 /\n";
  for (const auto& [x, y] : {std::pair{170.0, 170.0}, {40.0, 150.0}}) {
    const std::string where = "tilted, fault steps split, MINPV, injector at (" + hmtest::grdecl_number(x) + ", " +
                              hmtest::grdecl_number(y) + ")";
    SCOPED_TRACE(where);
    TempDir tmp("flow_cpw_steps");
    CornerPointFlowRun r;
    run_case(tmp, g, hmtest::deviated_well_yaml() + injector_yaml(x, y, 1045, 1057), &r);
    if (HasFatalFailure()) return;
    ASSERT_GT(r.cs.reservoir.corner_point->nz, g.nz);
    ASSERT_GT(r.out.mesh.n_nncs(), 0);
    std::printf("[ figures  ] fault steps: %d -> %d layers, %d cells\n", g.nz, r.cs.reservoir.corner_point->nz,
                r.out.mesh.n_cells());
    expect_corner_point_run(where.c_str(), tmp, r);
    if (HasFatalFailure()) return;
  }
}

// Pore volumes other than volume x PORO x NTG (MULTPV: an aquifer column x 1000, every seventh cell x 2.5;
// docs/corner-point.md, "Pore volumes"). With near-well cells the deck's PORV carries them (flow's INIT PORV
// equals ours, the multiplier included, on every cell; the near-well cells take their model cell's), the
// transient runs to the same steady state. The model alone: the deck's MULTPV makes flow's own pore
// volumes OPM's of the model as read. Fail halves: without the multiplier both miss by far more.
TEST(FlowCornerPoint, PoreVolumeMultipliersAreCarried) {
  REQUIRE_FLOW();
  TiltedModel g;
  g.keywords = pore_volume_keywords(g);
  {
    TempDir tmp("flow_cpw_multpv");
    CornerPointFlowRun r;
    run_case(tmp, g, two_wells_yaml(), &r);
    if (HasFatalFailure()) return;
    const hm::PolyMesh& mesh = r.out.mesh;
    ASSERT_EQ(mesh.cell_pore_volume_mult.size(), static_cast<size_t>(mesh.n_cells()));
    int model = 0, near_well = 0;
    double miss_without = 0;
    for (int c = 0; c < mesh.n_cells(); ++c) {
      if (mesh.cell_pore_volume_mult[c] == 1.0) continue;
      (mesh.cell_region[c] == hm::kReservoir ? model : near_well) += 1;
      miss_without = std::max(miss_without, std::abs(mesh.cell_pore_volume_mult[c] - 1));
    }
    std::printf("[ figures  ] pore-volume multipliers on %d model cells and %d near-well cells; flow against ours: "
                "PORV %.3g, pressure %.3g, rate %.3g relative at most\n",
                model, near_well, r.c.max_rel_porv, r.c.max_rel_pressure, r.c.max_rel_rate);
    EXPECT_GT(model, 100);
    EXPECT_GT(near_well, 10);
    expect_flow_is_solver_demo(r);  // PORV to 1e-6 with the multiplier (compare_flow)
    EXPECT_GE(miss_without, 1.5);   // fail half: PORV without it would miss by this much
  }
  TempDir tmp("flow_cpm_multpv");
  std::ofstream(tmp.path / "M.GRDECL") << g.text();
  std::ofstream(tmp.path / "cpm.yaml") << "name: cpm\nreservoir: {grdecl: M.GRDECL}\n";
  const hm::CaseSpec cs = hm::load_case((tmp.path / "cpm.yaml").string());
  const hm::CornerPointModel& m = *cs.reservoir.corner_point;
  for (const bool carried : {true, false}) {
    hm::HybridMesh out = hm::build_hybrid_mesh(cs);
    if (!carried) out.mesh.cell_pore_volume_mult.clear();
    const hm::Transmissibilities trans =
        hm::compute_transmissibilities(out.mesh, out.geometry, hm::deck_transmissibility_options());
    const fs::path dir = tmp.path / (carried ? "deck" : "deck_without");
    const hm::WriteStatus st = hm::write_eclipse_deck(dir.string(), cs, out.mesh, out.geometry, trans);
    ASSERT_TRUE(st.ok) << st.message;
    const FlowRun run = run_flow(dir, "CPM");
    ASSERT_EQ(run.flow.exit_code, 0) << run.flow.output.substr(0, 2000);
    const auto& porv = run.results["init"]["porv"];
    ASSERT_EQ(porv.size(), m.actnum.size());
    double worst = 0, total_flow = 0;
    for (size_t c = 0; c < m.actnum.size(); ++c) {
      if (!m.actnum[c]) continue;
      const double opm = m.opm_volume[c] * m.poro[c] * m.ntg[c] * (m.pore_volume_mult.empty() ? 1.0 : m.pore_volume_mult[c]);
      worst = std::max(worst, std::abs(porv[c].get<double>() / opm - 1));
      total_flow += porv[c].get<double>();
    }
    std::printf("[ figures  ] model alone%s: flow's PORV against OPM's of the model as read: %.3g relative at most, "
                "total %.6g against %.6g\n", carried ? "" : " (fail half: no MULTPV)", worst, total_flow,
                m.active_pore_volume);
    if (carried) {
      EXPECT_LT(worst, 1e-6);
      EXPECT_NEAR(total_flow / m.active_pore_volume, 1.0, 1e-6);
    } else {
      EXPECT_GT(worst, 0.5);  // the aquifer column at 1/1000, the others at 1/2.5
    }
  }
}

// A layer pinching out beside the producer (zero thickness from x = 110 m, thinning from 70 m): without PINCH
// the cells above and below it carry no flow where they touch, with PINCH they do, near-well cells and
// cavity walls included; flow runs both decks and matches solver_demo. The two runs' rates differ by far
// more than flow and solver_demo do (the pinch-out is a barrier only without PINCH).
TEST(FlowCornerPoint, PinchedOutLayerWithWellsMatchesSolverDemo) {
  REQUIRE_FLOW();
  double rate[2] = {0, 0};
  for (const bool pinch : {false, true}) {
    TempDir tmp(pinch ? "flow_cpw_pinch" : "flow_cpw_nopinch");
    TiltedModel g;
    g.pinch_k = 7, g.pinch_x = 110;
    if (pinch) g.keywords = "PINCH\n 0.4 NOGAP 1* TOPBOT TOP /\n";
    CornerPointFlowRun r;
    run_case(tmp, g, two_wells_yaml(), &r);
    if (HasFatalFailure()) return;
    const hm::PolyMesh& mesh = r.out.mesh;
    ASSERT_EQ(mesh.face_trans_mult.size(), static_cast<size_t>(mesh.n_faces()));
    int across = 0, zero = 0;
    const hm::CornerPointModel& m = *r.cs.reservoir.corner_point;
    for (int f = 0; f < mesh.n_faces(); ++f) {
      const int32_t n = mesh.face_neighbour[f];
      if (n < 0 || mesh.cell_region[mesh.face_owner[f]] != hm::kReservoir || mesh.cell_region[n] != hm::kReservoir) continue;
      const auto& a = mesh.cell_ijk[mesh.face_owner[f]];
      const auto& b = mesh.cell_ijk[n];
      const int64_t ga = a[0] + int64_t(m.nx) * (a[1] + int64_t(m.ny) * a[2]), gb = b[0] + int64_t(m.nx) * (b[1] + int64_t(m.ny) * b[2]);
      if (!hm::across_pinched_layers(m, ga, gb)) continue;
      ++across;
      zero += mesh.face_trans_mult[f] == 0;
    }
    std::printf("[ figures  ] %s: %d model faces across the pinched-out layer, %d of them with multiplier 0\n",
                pinch ? "PINCH" : "no PINCH", across, zero);
    int flat_columns = 0;  // columns (of the model refined near the wells) where the layer has zero thickness
    for (int c = g.pinch_k * m.nx * m.ny; c < (g.pinch_k + 1) * m.nx * m.ny; ++c) {
      bool flat = true;
      for (int q = 0; q < 4; ++q) flat = flat && corner(m, c, q).z == corner(m, c, q + 4).z;
      flat_columns += flat;
    }
    EXPECT_GT(flat_columns, 0);
    EXPECT_EQ(across, flat_columns);
    EXPECT_EQ(zero, pinch ? 0 : across);
    expect_corner_point_run(pinch ? "pinched-out layer, PINCH" : "pinched-out layer, no PINCH", tmp, r);
    rate[pinch] = r.ours.well_rate_m3_per_day[0];
  }
  std::printf("[ figures  ] producer rate without PINCH %.6g, with %.6g sm3/day\n", rate[0], rate[1]);
  EXPECT_GT(std::abs(rate[1] / rate[0] - 1), 1e-5);
}

// A mesh that does not carry the model's multipliers (built before they were set) is not written as a
// deck with near-well cells: refused with the reason, nothing left behind.
TEST(FlowCornerPoint, MeshWithoutTheModelsMultipliersIsRefusedWithTheReason) {
  TempDir tmp("cpw_mult");
  std::ofstream(tmp.path / "M.GRDECL") << TiltedModel{}.text();
  std::ofstream(tmp.path / "cpw.yaml") << "name: cpw\nreservoir: {grdecl: M.GRDECL}\n" << two_wells_yaml();
  hm::CaseSpec cs = hm::load_case((tmp.path / "cpw.yaml").string());
  hm::HybridMesh out;
  ASSERT_NO_THROW(out = hm::build_hybrid_mesh(cs));
  EXPECT_TRUE(out.mesh.face_trans_mult.empty());
  const hm::Transmissibilities trans =
      hm::compute_transmissibilities(out.mesh, out.geometry, hm::deck_transmissibility_options());
  ASSERT_TRUE(hm::write_eclipse_deck((tmp.path / "plain").string(), cs, out.mesh, out.geometry, trans).ok);
  auto with_mult = std::make_shared<hm::CornerPointModel>(*cs.reservoir.corner_point);
  with_mult->trans_mult[4][0] = 0.1;  // MULTZ of cell (1, 1, 1), far from the wells
  cs.reservoir.corner_point = with_mult;
  const hm::WriteStatus st = hm::write_eclipse_deck((tmp.path / "mult").string(), cs, out.mesh, out.geometry, trans);
  EXPECT_FALSE(st.ok);
  EXPECT_NE(st.message.find("transmissibility multipliers (MULTX..MULTZ-"), std::string::npos) << st.message;
  EXPECT_FALSE(fs::exists(tmp.path / "mult" / "CPW.DATA"));
}

namespace {

// Our transmissibilities of a corner-point model's connections (deck_transmissibility_options, what the
// deck with near-well cells carries) against the ones flow computes itself for the model's own deck
// (no wells: flow's corner-point TPFA), per cell pair. Returns the relative differences (ours - flow) /
// flow over the pairs both connect; counts the pairs only one side connects.
struct OwnVsOurs {
  std::vector<double> rel;
  std::vector<int> kind;  ///< per entry of rel: 0, 1, 2 logical I, J, K neighbours, 3 any other pair (NNC)
  size_t only_ours = 0, only_flow = 0;
};

// deck_case: the case whose deck flow runs, when not cs (a fail half: ours without what the deck keeps).
OwnVsOurs compare_with_flows_own(const hm::CaseSpec& cs, const fs::path& dir, bool drop_multipliers = false,
                                 const hm::CaseSpec* deck_case = nullptr) {
  OwnVsOurs out;
  const hm::HybridMesh hm_out = hm::build_hybrid_mesh(cs);
  hm::PolyMesh ours_mesh = hm_out.mesh;  // the fail half's: the model's multipliers left out of ours
  if (drop_multipliers) ours_mesh.face_trans_mult.clear();
  const hm::Transmissibilities trans =
      hm::compute_transmissibilities(ours_mesh, hm_out.geometry, hm::deck_transmissibility_options());
  hm::EclipseDeckInfo info;
  const hm::WriteStatus st =
      hm::write_eclipse_deck(dir.string(), deck_case ? *deck_case : cs, hm_out.mesh, hm_out.geometry, trans, {}, &info);
  EXPECT_TRUE(st.ok) << st.message;
  const std::string name = hm::eclipse_deck_name(cs);
  const FlowRun run = run_flow(dir, name);
  EXPECT_EQ(run.flow.exit_code, 0);
  if (run.results.is_null()) return out;
  const hm::EclipseLayout& L = info.layout;
  const hm::EclipseConnections conn = hm::make_eclipse_connections(hm_out.mesh, L, trans);
  std::map<std::pair<int32_t, int32_t>, double> ours, flow;
  const int32_t step[3] = {1, L.deck_nx, L.deck_nx * L.ny};
  const std::vector<double>* t[3] = {&conn.tranx, &conn.trany, &conn.tranz};
  const char* keys[3] = {"tranx", "trany", "tranz"};
  const auto& init = run.results["init"];
  std::set<std::pair<int32_t, int32_t>> flow_nnc_pairs;
  for (size_t k = 0; k < init["trannnc"].size(); ++k) {
    const double v = init["trannnc"][k].get<double>();
    const int32_t a = init["nnc1"][k].get<int32_t>() - 1, b = init["nnc2"][k].get<int32_t>() - 1;
    if (v > 0) flow[{std::min(a, b), std::max(a, b)}] += v, flow_nnc_pairs.insert({std::min(a, b), std::max(a, b)});
  }
  const int32_t n_deck = static_cast<int32_t>(L.deck_cell.size());
  for (int d = 0; d < 3; ++d) {
    size_t a = 0;
    for (int32_t g = 0; g < n_deck; ++g) {
      if ((*t[d])[g] != 0) ours[{g, g + step[d]}] += (*t[d])[g];
      if (L.deck_cell[g] < 0) continue;
      const double v = init[keys[d]][a++].get<double>();
      if (v <= 0) continue;
      // flow's INIT TRANZ of a cell is its connection to the next active cell below; across inactive
      // cells (MINPV's removed cells) that is an NNC record flow also lists in TRANNNC: counted once.
      int32_t below = g + step[d];
      if (d == 2)
        while (below < n_deck && L.deck_cell[below] < 0) below += step[d];
      if (below != g + step[d] && flow_nnc_pairs.count({g, below})) continue;
      flow[{g, below}] += v;
    }
  }
  for (const auto& r : conn.nnc) ours[{r.a, r.b}] += r.t;
  for (const auto& [pair, v] : ours) {
    const auto it = flow.find(pair);
    if (it == flow.end()) {
      ++out.only_ours;
      continue;
    }
    out.rel.push_back((v - it->second) / it->second);
    const int32_t d = pair.second - pair.first;
    out.kind.push_back(d == step[0] ? 0 : d == step[1] ? 1 : d == step[2] ? 2 : 3);
  }
  for (const auto& [pair, v] : flow) out.only_flow += !ours.count(pair);
  return out;
}

void print_own_vs_ours(const char* label, const OwnVsOurs& d, int kind = -1) {
  if (kind < 0)
    for (int k = 0; k < 4; ++k) {
      static const char* names[4] = {"I neighbours", "J neighbours", "K neighbours", "other pairs (NNC)"};
      print_own_vs_ours((std::string(label) + ", " + names[k]).c_str(), d, k);
    }
  std::vector<double> a;
  for (size_t i = 0; i < d.rel.size(); ++i)
    if (kind < 0 || d.kind[i] == kind) a.push_back(std::abs(d.rel[i]));
  std::sort(a.begin(), a.end());
  auto q = [&](double f) { return a.empty() ? 0.0 : a[std::min(a.size() - 1, static_cast<size_t>(f * a.size()))]; };
  size_t above_1pct = 0;
  for (double v : a) above_1pct += v > 0.01;
  std::printf("[ figures  ] %s: ours vs flow's own model transmissibilities over %zu pairs: |rel| median %.3g, 95 %% %.3g, "
              "max %.3g, %zu above 1 %%; pairs only ours %zu, only flow's %zu\n",
              label, a.size(), q(0.5), q(0.95), a.empty() ? 0.0 : a.back(), above_1pct, d.only_ours, d.only_flow);
}

}  // namespace

// MINPV as OPM Flow 2022.10 applies it (docs/corner-point.md, "MINPV"): the tilted model's layer 5 thins
// toward its east side (pinch_x 180: the east column's cells 2.25-0 m thick), MINPV 120 rm3 catches them.
// Flow, on the model as a user gives it (MINPV in the deck), removes exactly the cells the mesh does not
// have, and its connection of each upper cell to the cell below the gap (INIT TRANZ) is the mesh's
// connection without a face, to 1e-6. Our model-only deck (those cells inactive, our NNC records) gives
// flow the same pairs and values.
// MINPV on `plain`'s model as flow applies it against ours on `cs` (the same model with `minpv_keyword`):
// flow runs the model-only deck of `plain` with the keyword added (the user's deck); the cells it removes,
// and its TRANZ from each upper cell to the next active cell below a gap (a connection across removed
// cells), against the mesh of `cs`. Returns the number of connections compared.
struct MinpvAgainstFlow {
  int64_t removed_ours = 0, removed_flow = 0, removed_both = 0;
  int connections = 0, flow_across = 0, flow_only = 0;
  double worst = 0;
};
MinpvAgainstFlow minpv_against_flow(const fs::path& dir, const hm::CaseSpec& plain, const hm::CaseSpec& cs,
                                    const std::string& minpv_keyword) {
  MinpvAgainstFlow r;
  const std::string name = hm::eclipse_deck_name(plain);
  {
    const hm::HybridMesh out = hm::build_hybrid_mesh(plain);
    const hm::Transmissibilities t = hm::compute_transmissibilities(out.mesh, out.geometry, hm::deck_transmissibility_options());
    const hm::WriteStatus st = hm::write_eclipse_deck(dir.string(), plain, out.mesh, out.geometry, t, {}, nullptr);
    EXPECT_TRUE(st.ok) << st.message;
    std::ofstream(dir / (name + "_GRID.INC"), std::ios::app) << "\n" << minpv_keyword;
  }
  const FlowRun user = run_flow(dir, name);
  EXPECT_EQ(user.flow.exit_code, 0) << user.flow.output.substr(0, 2000);
  if (user.results.is_null()) return r;
  const auto& porv = user.results["init"]["porv"];
  const auto& tranz = user.results["init"]["tranz"];
  const hm::CornerPointModel &m = *cs.reservoir.corner_point, &pm = *plain.reservoir.corner_point;
  const size_t n = m.actnum.size();
  EXPECT_EQ(porv.size(), n);
  if (porv.size() != n) return r;
  std::vector<int64_t> active_index(n, -1);
  int64_t a = 0;
  for (size_t c = 0; c < n; ++c) {
    if (porv[c].get<double>() > 0) active_index[c] = a++;
    const bool flow_removed = pm.actnum[c] && porv[c].get<double>() == 0;
    r.removed_flow += flow_removed;
    r.removed_both += flow_removed && !m.actnum[c];
  }
  r.removed_ours = static_cast<int64_t>(m.minpv_removed.size());
  const hm::HybridMesh out = hm::build_hybrid_mesh(cs);
  const hm::PolyMesh& mesh = out.mesh;
  std::set<int64_t> ours_upper;
  for (int k = 0; k < mesh.n_nncs(); ++k) {
    const auto& u = mesh.cell_ijk[mesh.nnc_cells[k][0]];
    const int64_t upper = u[0] + int64_t(m.nx) * (u[1] + int64_t(m.ny) * u[2]);
    ours_upper.insert(upper);
    EXPECT_GE(active_index[upper], 0);
    if (active_index[upper] < 0) continue;
    const double theirs = tranz[active_index[upper]].get<double>();
    r.worst = std::max(r.worst, std::abs(mesh.nnc_trans[k] - theirs) / theirs);
    ++r.connections;
  }
  const int64_t nxy = int64_t(m.nx) * m.ny;
  for (int64_t c = 0; c + nxy < static_cast<int64_t>(n); ++c) {
    if (active_index[c] < 0 || !(tranz[active_index[c]].get<double>() > 0) || active_index[c + nxy] >= 0) continue;
    ++r.flow_across;
    r.flow_only += ours_upper.count(c) == 0;
  }
  return r;
}

// MINPV as OPM Flow 2022.10 applies it (docs/corner-point.md, "MINPV"): the tilted model's layer 5 thins
// toward its east side (pinch_x 180: the east column's cells 2.25-0 m thick), MINPV 120 rm3 catches them.
// Flow, on the model as a user gives it (MINPV in the deck), removes exactly the cells the mesh does not
// have, and its connection of each upper cell to the cell below the gap (INIT TRANZ) is the mesh's
// connection without a face, to 1e-6. Our model-only deck (those cells inactive, our NNC records) gives
// flow the same pairs and values. With HM_REEK_DECK (a copy of shared/data/reek/REEK_GRID.DATA and its
// includes, writable) and HM_REEK_MINPV (rm3): the same on Reek, measured and printed.
TEST(FlowCornerPoint, MinpvRemovesAndConnectsTheCellsFlowDoes) {
  REQUIRE_FLOW();
  TempDir tmp("flow_minpv");
  TiltedModel g;
  g.pinch_k = 5, g.pinch_x = 180;
  std::ofstream(tmp.path / "PLAIN.GRDECL") << g.text();
  std::ofstream(tmp.path / "M.GRDECL") << g.text() << "MINPV\n 120 /\n";
  const hm::CaseSpec plain = hm::parse_case("name: cpm\nreservoir: {grdecl: PLAIN.GRDECL}\n", tmp.path.string());
  const hm::CaseSpec cs = hm::parse_case("name: cpm\nreservoir: {grdecl: M.GRDECL}\n", tmp.path.string());
  ASSERT_GT(cs.reservoir.corner_point->below_minpv, 0);
  const MinpvAgainstFlow f = minpv_against_flow(tmp.path / "user", plain, cs, "MINPV\n 120 /\n");
  std::printf("[ figures  ] MINPV 120: %lld cells removed (flow: %lld, both %lld), %d connections across them (flow: "
              "%d, only flow's %d), ours vs flow's TRANZ max rel %.3g\n",
              static_cast<long long>(f.removed_ours), static_cast<long long>(f.removed_flow),
              static_cast<long long>(f.removed_both), f.connections, f.flow_across, f.flow_only, f.worst);
  EXPECT_EQ(f.removed_flow, f.removed_ours);
  EXPECT_EQ(f.removed_both, f.removed_ours);
  EXPECT_GT(f.connections, 0);
  EXPECT_EQ(f.flow_across, f.connections);
  EXPECT_EQ(f.flow_only, 0);
  EXPECT_LT(f.worst, 1e-6);
  // Our model-only deck of it: flow connects the same pairs with our values.
  const OwnVsOurs d = compare_with_flows_own(cs, tmp.path / "ours");
  size_t nnc_pairs = 0;
  double worst_pair = 0;
  for (size_t i = 0; i < d.rel.size(); ++i) {
    nnc_pairs += d.kind[i] == 3;
    worst_pair = std::max(worst_pair, std::abs(d.rel[i]));
  }
  print_own_vs_ours("tilted, MINPV", d, -1);
  EXPECT_EQ(nnc_pairs, static_cast<size_t>(f.connections));
  EXPECT_LT(worst_pair, 1e-6);
  EXPECT_EQ(d.only_flow, 0u);
  EXPECT_EQ(d.only_ours, 0u);

  const char* reek = std::getenv("HM_REEK_DECK");
  const char* reek_minpv = std::getenv("HM_REEK_MINPV");
  if (reek == nullptr || reek_minpv == nullptr) return;
  const std::string keyword = "MINPV\n " + std::string(reek_minpv) + " /\n";
  const fs::path data(reek), with = data.parent_path() / "REEK_MINPV.DATA";
  std::ofstream(with) << hmtest::read_text(data) << "\n" << keyword;
  const hm::CaseSpec reek_plain = hm::parse_case("name: reek\nreservoir: {grdecl: " + data.string() + "}\n");
  const hm::CaseSpec reek_cs = hm::parse_case("name: reek\nreservoir: {grdecl: " + with.string() + "}\n");
  const MinpvAgainstFlow r = minpv_against_flow(tmp.path / "reek", reek_plain, reek_cs, keyword);
  std::printf("[ figures  ] Reek, MINPV %s: %lld cells removed (flow: %lld, both %lld), %d connections across them "
              "(flow: %d, only flow's %d), ours vs flow's TRANZ max rel %.3g\n",
              reek_minpv, static_cast<long long>(r.removed_ours), static_cast<long long>(r.removed_flow),
              static_cast<long long>(r.removed_both), r.connections, r.flow_across, r.flow_only, r.worst);
}

// The transmissibilities the deck with near-well cells carries for the model's own connections are the
// ones flow computes for the model (docs/export-eclipse.md, "A corner-point model"): on the synthetic
// models to 1e-6 on every pair; with HM_REEK_DECK the same figures for Reek (measured, not asserted).
TEST(FlowCornerPoint, OurModelTransmissibilitiesAgainstFlowsOwn) {
  REQUIRE_FLOW();
  for (int variant : {0, 1, 2, 3, 4, 5}) {
    TempDir tmp("cpw_own");
    TiltedModel g;
    g.inclined_pillars = variant == 1;
    g.nz = variant == 1 ? 22 : 16;
    if (variant >= 2 && variant <= 4) {  // a fault of 6 m throw and multipliers on every face (flow applies them)
      g.fault_i = 6, g.throw_m = 6;
      g.keywords = multiplier_keywords(g, 6);
    }
    if (variant == 3) g.keywords += region_multiplier_keywords(g);  // and MULTREGT between MULTNUM regions
    if (variant == 4) g.keywords += edit_nnc_keywords(g);           // and EDITNNC across the fault
    if (variant == 5) g.keywords = nnc_keywords();                  // NNC between cells sharing no face
    std::ofstream(tmp.path / "M.GRDECL") << g.text();
    std::ofstream(tmp.path / "cpm.yaml") << "name: cpm\nreservoir: {grdecl: M.GRDECL}\n";
    const hm::CaseSpec cs = hm::load_case((tmp.path / "cpm.yaml").string());
    const OwnVsOurs d = compare_with_flows_own(cs, tmp.path / "deck");
    static const char* kLabel[6] = {"tilted, vertical pillars", "inclined pillars", "tilted, fault, multipliers",
                                    "tilted, fault, multipliers, MULTREGT", "tilted, fault, multipliers, EDITNNC",
                                    "tilted, NNC"};
    print_own_vs_ours(kLabel[variant], d);
    if (variant == 3) {  // fail half: ours without MULTREGT (the deck keeps it, flow applies it)
      hm::CaseSpec plain = cs;
      auto model = std::make_shared<hm::CornerPointModel>(*cs.reservoir.corner_point);
      model->region_mult.reset();
      plain.reservoir.corner_point = model;
      const OwnVsOurs without = compare_with_flows_own(plain, tmp.path / "deck_without_multregt");
      size_t off = 0;
      for (double r : without.rel) off += std::abs(r) > 0.01;
      std::printf("[ figures  ] fail half: without MULTREGT in ours %zu of %zu pairs differ by more than 1 %%\n", off,
                  without.rel.size());
      EXPECT_GT(off, 100u);
    }
    if (variant == 4) {  // fail half: ours without EDITNNC (the deck keeps it, flow applies it)
      ASSERT_EQ(cs.reservoir.corner_point->edit_nnc.size(), static_cast<size_t>(g.ny * (2 * g.nz - 3)));
      hm::CaseSpec plain = cs;
      auto model = std::make_shared<hm::CornerPointModel>(*cs.reservoir.corner_point);
      model->edit_nnc.clear();
      plain.reservoir.corner_point = model;
      const OwnVsOurs without = compare_with_flows_own(plain, tmp.path / "deck_without_editnnc", false, &cs);
      size_t off = 0;
      for (size_t i = 0; i < without.rel.size(); ++i) off += without.kind[i] == 3 && std::abs(without.rel[i]) > 0.3;
      std::printf("[ figures  ] fail half: without EDITNNC in ours %zu pairs across the fault differ by more than 30 %%\n", off);
      EXPECT_GT(off, static_cast<size_t>(g.ny * (g.nz - 2)));
    }
    if (variant == 2) {  // fail half: ours without the multipliers are not flow's
      const OwnVsOurs without = compare_with_flows_own(cs, tmp.path / "deck_without", true);
      size_t off = 0;
      for (double r : without.rel) off += std::abs(r) > 0.01;
      std::printf("[ figures  ] fail half: without the multipliers %zu of %zu pairs differ by more than 1 %%\n", off,
                  without.rel.size());
      EXPECT_GT(off, without.rel.size() / 2);
      size_t fault_pairs = 0;
      for (int k : d.kind) fault_pairs += k == 3;
      EXPECT_GT(fault_pairs, 50u);
    }
    if (variant == 5) {  // no fault: the pairs that are not logical neighbours are exactly the NNC's
      size_t nnc_pairs = 0;
      double worst_nnc = 0;
      for (size_t i = 0; i < d.rel.size(); ++i)
        if (d.kind[i] == 3) ++nnc_pairs, worst_nnc = std::max(worst_nnc, std::abs(d.rel[i]));
      std::printf("[ figures  ] NNC: %zu pairs, ours vs flow's max rel %.3g\n", nnc_pairs, worst_nnc);
      EXPECT_EQ(nnc_pairs, nnc_records().size());
      EXPECT_LT(worst_nnc, 1e-6);
    }
    EXPECT_GT(d.rel.size(), 1000u);
    EXPECT_EQ(d.only_flow, 0u);
    EXPECT_EQ(d.only_ours, 0u);
    // The deck's model transmissibilities are flow's own: float32 INIT and the Darcy constant's
    // rounding (E300's 0.00852702 against OPM's exact 0.0085270173..., 3.5e-7) are what is left. Pairs
    // across a fault whose throw is not whole layers: the overlaps' centroids stand in for OPM's
    // whole-face centres (docs/export-eclipse.md), up to 2.1 % here; MULTFLT 0.05 missing would be x 20.
    double worst = 0, worst_fault = 0;
    for (size_t i = 0; i < d.rel.size(); ++i)
      (d.kind[i] == 3 ? worst_fault : worst) = std::max(d.kind[i] == 3 ? worst_fault : worst, std::abs(d.rel[i]));
    EXPECT_LT(worst, 1e-6);
    EXPECT_LT(worst_fault, 0.03);
  }
  const char* reek = std::getenv("HM_REEK_DECK");  // e.g. shared/data/reek/REEK_GRID.DATA (flow: ~2 min)
  if (reek == nullptr) return;
  TempDir tmp("reek_own");
  const OwnVsOurs d = compare_with_flows_own(
      hm::parse_case("name: reek\nreservoir: {grdecl: " + std::string(reek) + "}\n"), tmp.path / "deck");
  print_own_vs_ours("Reek", d);
}
