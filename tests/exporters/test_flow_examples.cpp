// The shipped examples as shipped, meshed by the pipeline, exported, run by OPM Flow: its steady
// pressures and well rates equal, on every cell and well, the steady state of the deck's slightly
// compressible water (PVTW), solved here independently of solver_demo's library.
#include <gtest/gtest.h>

#include <set>

#include <eigen3/Eigen/SparseCholesky>  // this target does not link Eigen3::Eigen

#include "flow_test_support.hpp"
#include "meshgen/case/near_well_layers.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"

namespace {

using namespace hmtest;

struct ExampleRun {
  hm::CaseSpec cs;
  hm::HybridMesh hybrid;
  TpfaSolution ours;        ///< the deck's compressible water
  TpfaSolution incompressible;  ///< constant density and b = 1 (the fail half)
  hm::EclipseDeckInfo info;
  FlowRun run;
  FlowComparison c;
  double mesh_s = 0, write_s = 0;
};

/// The steady state of the deck's water: PVTW `Pref 1.0 Cw mu 0` with Pref = initial pressure and
/// Cw = max(case Cw, 1e-8) as the exporter writes it, b(p) = 1 + X + X^2/2, X = Cw (p - Pref),
/// density rho_s b, face density the mean of the two cells', mobility b/mu of the upstream cell;
/// connections CF/mu b_cell (p_cell - p_conn), p_conn the still wellbore column from (z_ref, BHP),
/// integrated here by RK4 (solver_demo has a closed form); rates in surface m3/day.
/// Picard iteration (b, rho and upstream frozen; symmetric steps) with a sparse LDLT.
TpfaSolution compressible_reference_solve(const hm::CaseSpec& cs, const hm::PolyMesh& mesh,
                                          const hm::Transmissibilities& trans) {
  const int n = mesh.n_cells();
  const double mu = cs.fluid.viscosity, rho_s = cs.fluid.density, gf = kGravity * kBarPerPa;
  const double cw = std::max(cs.fluid.compressibility, 1e-8), pref = cs.reservoir.initial_pressure;
  auto b = [&](double p) {
    const double x = cw * (p - pref);
    return 1 + x + x * x / 2;
  };
  const auto wells = hm::well_connection_factors(mesh, trans, static_cast<int>(cs.wells.size()));
  auto column = [&](size_t w, int c) {
    const int steps = 200;
    const double h = (mesh.cell_fv_center[c].z - cs.wells[w].trajectory.front().z) / steps;
    auto f = [&](double p) { return rho_s * b(p) * gf; };
    double p = cs.wells[w].bhp;
    for (int i = 0; i < steps; ++i) {
      const double k1 = f(p), k2 = f(p + h / 2 * k1), k3 = f(p + h / 2 * k2), k4 = f(p + h * k3);
      p += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
    return p;
  };
  std::map<std::pair<size_t, int>, double> conn_pressure;
  for (size_t w = 0; w < wells.size(); ++w)
    for (const auto& wc : wells[w]) conn_pressure[{w, wc.first}] = column(w, wc.first);
  auto p_conn = [&](size_t w, int c) { return conn_pressure.at({w, c}); };
  std::vector<double> p(n, pref);
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
  bool converged = false;
  for (int it = 0; it < 30 && !converged; ++it) {
    std::vector<Eigen::Triplet<double>> trip;
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
    for (int f = 0; f < mesh.n_faces(); ++f) {
      const int i = mesh.face_owner[f], j = mesh.face_neighbour[f];
      if (j < 0) continue;
      const double drop = rho_s * (b(p[i]) + b(p[j])) / 2 * gf * (mesh.cell_fv_center[i].z - mesh.cell_fv_center[j].z);
      const double t = trans.face[f] / mu * b(p[i] - p[j] - drop >= 0 ? p[i] : p[j]);
      trip.emplace_back(i, i, t);
      trip.emplace_back(j, j, t);
      trip.emplace_back(i, j, -t);
      trip.emplace_back(j, i, -t);
      rhs[i] += t * drop;
      rhs[j] -= t * drop;
    }
    for (size_t w = 0; w < wells.size(); ++w)
      for (const auto& [c, cf] : wells[w]) {
        const double t = cf / mu * b(p[c]);
        trip.emplace_back(c, c, t);
        rhs[c] += t * p_conn(w, c);
      }
    Eigen::SparseMatrix<double> A(n, n);
    A.setFromTriplets(trip.begin(), trip.end());
    if (it == 0) ldlt.analyzePattern(A);
    ldlt.factorize(A);
    Eigen::VectorXd x = ldlt.solve(rhs);
    x += ldlt.solve(rhs - A * x);  // one refinement step: very different transmissibilities
    double change = 0;
    for (int c = 0; c < n; ++c) change = std::max(change, std::abs(x[c] - p[c]));
    p.assign(x.data(), x.data() + n);
    converged = change < 1e-9 * pref;
  }
  EXPECT_TRUE(converged) << "the reference Picard iteration did not converge in 30 steps";
  TpfaSolution s;
  s.pressure = p;
  s.well_rate.assign(wells.size(), 0.0);
  for (size_t w = 0; w < wells.size(); ++w)
    for (const auto& [c, cf] : wells[w]) s.well_rate[w] += cf / mu * b(p[c]) * (p[c] - p_conn(w, c));
  return s;
}

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
  r->ours = compressible_reference_solve(cs, mesh, trans);
  r->incompressible = reference_tpfa_solve(cs, mesh, trans);
  TempDir tmp("flow_" + label);
  const auto t1 = std::chrono::steady_clock::now();
  const hm::WriteStatus st = hm::write_eclipse_deck(tmp.str(), cs, mesh, geo, trans, {}, &r->info);
  r->write_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  ASSERT_TRUE(st.ok) << st.message;
  for (const std::string& w : r->info.warnings) std::printf("[ warning  ] %s\n", w.c_str());
  dump_ours_if_kept(tmp.path, cs, r->info.layout, r->ours);
  r->run = run_flow(tmp.path, hm::eclipse_deck_name(cs));  // as typed: no options
  // Measurement aid (issue 16): HM_FLOW_COMPARE_TUNED=1 also runs the steady deck with the
  // optional flow options, right after, and prints both runs' times and Newton iterations.
  if (std::getenv("HM_FLOW_COMPARE_TUNED") != nullptr) {
    TempDir tuned_dir("flow_tuned_" + label);
    hm::EclipseDeckOptions single;
    single.schedule = hm::EclipseSchedule::Steady;
    hm::EclipseDeckInfo tuned_info;
    ASSERT_TRUE(hm::write_eclipse_deck(tuned_dir.str(), cs, mesh, geo, trans, single, &tuned_info).ok);
    const FlowRun tuned = run_flow(tuned_dir.path, hm::eclipse_deck_name(cs), FlowInvocation::WithOptions);
    ASSERT_EQ(tuned.flow.exit_code, 0) << tuned.flow.output;
    const FlowComparison tc = compare_flow(cs, mesh, geo, tuned_info, r->ours,
                                           hm::make_eclipse_connections(mesh, tuned_info.layout, trans), tuned.results);
    std::printf("[ figures  ] %s: as typed: %.2f s wall, %.2f s CPU, %d Newton, end %.4g days (relaxation %.3g days); "
                "tuned: %.2f s wall, %.2f s CPU, %d Newton, max rel pressure %.3g, rate %.3g; CPU ratio %.2f\n",
                label.c_str(), r->run.seconds, r->run.cpu_seconds, r->run.newton, r->info.end_days,
                r->info.relaxation_time_days, tuned.seconds, tuned.cpu_seconds, tuned.newton, tc.max_rel_pressure,
                tc.max_rel_rate, r->run.cpu_seconds / tuned.cpu_seconds);
  }
  ASSERT_FALSE(r->run.flow.timed_out);
  ASSERT_EQ(r->run.flow.exit_code, 0) << r->run.flow.output;
  ASSERT_EQ(r->run.reader.exit_code, 0) << r->run.reader.output;
  const hm::EclipseConnections conn = hm::make_eclipse_connections(mesh, r->info.layout, trans);
  r->c = compare_flow(cs, mesh, geo, r->info, r->ours, conn, r->run.results);
  ASSERT_TRUE(r->c.problem.empty()) << r->c.problem;
  const FlowComparison& c = r->c;
  const hm::EclipseLayout& L = r->info.layout;
  std::printf("[ figures  ] %s: %d cells (deck %dx%dx%d, %d extra columns), %d NNC records; mesh %.2f s, deck write "
              "%.3f s, flow as typed %.2f s (CPU %.2f s, %d Newton)\n",
              label.c_str(), mesh.n_cells(), L.deck_nx, L.ny, L.nz, L.extra_columns, r->info.nnc, r->mesh_s, r->write_s,
              r->run.seconds, r->run.cpu_seconds, r->run.newton);
  std::printf("[ figures  ] %s: max rel pressure %.3g, max rel rate %.3g, PORV %.3g, depth %.3g m, connections %zu "
              "(flow %zu, %zu TRANNNC, max rel %.3g; %zu below flow's threshold dropped, sum %.3g)\n",
              label.c_str(), c.max_rel_pressure, c.max_rel_rate, c.max_rel_porv, c.max_depth_diff, c.our_connections,
              c.flow_connections, c.flow_nnc, c.max_rel_connection, c.dropped_by_flow, c.dropped_sum);
  for (size_t w = 0; w < cs.wells.size(); ++w)
    std::printf("[ figures  ] %s: well %s rate %.6g sm3/day (ours)\n", label.c_str(), cs.wells[w].name.c_str(),
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

// One producer in a closed reservoir, as shipped (Cw = 1e-8 /bar): the steady state is
// hydrostatic at the BHP (rate ~0).
TEST(FlowExamples, PaperSingleWellMatchesOurSolve) {
  REQUIRE_FLOW();
  ExampleRun r;
  run_example(load_example("paper_single_well"), "paper_single_well", &r);
  if (HasFatalFailure()) return;
  expect_match(r.c);
}

// three_wells as shipped (Cw = 4e-5 /bar, realistic water): flow matches the compressible steady
// state on every cell and well. Fail half: the same flow run against the incompressible solve
// (constant density, b = 1) differs by more than the gate, so the gate sees the physics.
TEST(FlowExamples, ThreeWellsAsShippedMatchesTheCompressibleSolve) {
  REQUIRE_FLOW();
  const hm::CaseSpec cs = load_example("three_wells");
  ASSERT_EQ(cs.fluid.compressibility, 4e-5);
  ExampleRun r;
  run_example(cs, "three_wells", &r);
  if (HasFatalFailure()) return;
  expect_match(r.c);
  const hm::EclipseConnections conn = hm::make_eclipse_connections(r.hybrid.mesh, r.info.layout,
                                                                    hm::compute_transmissibilities(r.hybrid.mesh, r.hybrid.geometry));
  const FlowComparison inc =
      compare_flow(cs, r.hybrid.mesh, r.hybrid.geometry, r.info, r.incompressible, conn, r.run.results);
  ASSERT_TRUE(inc.problem.empty()) << inc.problem;
  std::printf("[ figures  ] three_wells: flow vs the incompressible solve: max rel pressure %.3g, rate %.3g\n",
              inc.max_rel_pressure, inc.max_rel_rate);
  EXPECT_GT(inc.max_rel_pressure, 1e-5);
  EXPECT_GT(inc.max_rel_rate, 1e-5);
}

// A GRDECL model read with OPM (per-cell rock over three orders of magnitude, NTG, kv/kh 0.1): the
// radial and transition cells take the rock of the model cells around them, and flow, reading the
// exported deck, agrees with our solve on every cell and well.
TEST(FlowExamples, LayeredGrdeclModelMatchesTheCompressibleSolve) {
  REQUIRE_FLOW();
  const hm::CaseSpec cs = load_example("layered_grdecl");
  ASSERT_FALSE(cs.reservoir.cell_permx.empty());
  ExampleRun r;
  run_example(cs, "layered_grdecl", &r);
  if (HasFatalFailure()) return;
  expect_match(r.c);
  // The near-well cells carry the model's rock, not one value: several permeabilities among them.
  std::set<double> near_well_k;
  for (int c = 0; c < r.hybrid.mesh.n_cells(); ++c)
    if (r.hybrid.mesh.cell_region[c] != hm::kReservoir) near_well_k.insert(r.hybrid.mesh.cell_perm[c].x);
  EXPECT_GE(near_well_k.size(), 5u);
}

// Wells through the reservoir boundary (issue 12): a producer and an injector each, fully
// penetrating (vertical_through), entering through the top at 30 degrees (deviated_through_top),
// horizontal from side to side in a reservoir 2.5 drainage radii thick (horizontal_through_sides).
// The blocks' end faces in the boundary planes and the transition cells' faces there are no-flow.
TEST(FlowExamples, VerticalThroughMatchesTheCompressibleSolve) {
  REQUIRE_FLOW();
  ExampleRun r;
  run_example(load_example("vertical_through"), "vertical_through", &r);
  if (HasFatalFailure()) return;
  expect_match(r.c);
  EXPECT_GT(std::abs(r.ours.well_rate[0]), 1.0);  // the injector drives a real flow
}

TEST(FlowExamples, DeviatedThroughTopMatchesTheCompressibleSolve) {
  REQUIRE_FLOW();
  ExampleRun r;
  run_example(load_example("deviated_through_top"), "deviated_through_top", &r);
  if (HasFatalFailure()) return;
  expect_match(r.c);
  EXPECT_GT(std::abs(r.ours.well_rate[0]), 1.0);
}

TEST(FlowExamples, HorizontalThroughSidesMatchesTheCompressibleSolve) {
  REQUIRE_FLOW();
  ExampleRun r;
  run_example(load_example("horizontal_through_sides"), "horizontal_through_sides", &r);
  if (HasFatalFailure()) return;
  expect_match(r.c);
  EXPECT_GT(std::abs(r.ours.well_rate[0]), 1.0);
}

// Meshes `cs` (anisotropic rock, permeability metric), runs flow on its deck and compares with our
// compressible solve on every cell and well.
void expect_anisotropic_deck_matches(const hm::CaseSpec& cs) {
  ExampleRun r;
  run_example(cs, cs.name, &r);
  if (::testing::Test::HasFatalFailure()) return;
  EXPECT_FALSE(r.hybrid.frame.identity());
  expect_match(r.c);
  EXPECT_GT(std::abs(r.ours.well_rate[0]), 1.0);
}

hm::CaseSpec anisotropic_example(const std::string& example, const std::string& name, hm::Vec3 k) {
  hm::CaseSpec cs = load_example(example);
  cs.name = name;
  cs.reservoir.permeability = k;
  cs.metric = hm::MeshMetric::Permeability;
  return cs;
}

// Anisotropic rock with the permeability metric (issue 15, docs/anisotropy.md): kv/kh 0.01 and
// kx/ky 3 around the producer and the injector of vertical_through, meshed K-orthogonal (elliptic
// blocks); flow reading the exported deck (transmissibilities of the scaled frame) agrees with our
// solve on every cell and well.
TEST(FlowExamples, AnisotropicKvKh001PermeabilityMetricMatchesTheCompressibleSolve) {
  REQUIRE_FLOW();
  expect_anisotropic_deck_matches(anisotropic_example("vertical_through", "vertical_kvkh001", {300, 100, 1}));
}

// The same for horizontal_through_sides at kv/kh 0.01 with its layers split near the well as
// load_case splits them (meshgen/case/near_well_layers.hpp; before the split its transition failed
// the self-check in the scaled frame): the deck carries the split grid (12 layers for 4) and flow
// reading it agrees with our solve.
TEST(FlowExamples, AnisotropicKvKh001OnLayersSplitNearTheWellMatchesTheCompressibleSolve) {
  REQUIRE_FLOW();
  hm::CaseSpec cs = anisotropic_example("horizontal_through_sides", "horizontal_kvkh001", {100, 100, 1});
  const size_t user_layers = cs.reservoir.z.size() - 1;
  hm::split_layers_near_wells(cs);
  ASSERT_GT(cs.reservoir.z.size() - 1, user_layers);
  expect_anisotropic_deck_matches(cs);
}

}  // namespace
