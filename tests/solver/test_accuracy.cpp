// The near-well accuracy study on the four shipped cases (examples/accuracy_*.yaml).
// Default run: every case at its own resolution (a few seconds each), with the issue #7
// acceptance criteria. The three-level refinement study is long (minutes, 2+ GB): it runs only
// when the environment has HM_LONG_TESTS=1 (docs/accuracy.md says how to run it).
#include <gtest/gtest.h>


#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "fvcheck/lib/transmissibility.hpp"
#include "meshgen/grids/well_block.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"
#include "meshgen/pipeline/permeability_frame.hpp"
#include "solver_demo/lib/accuracy.hpp"
#include "solver_demo/lib/line_source.hpp"
#include "solver_demo/lib/peaceman.hpp"

using namespace hm;

namespace {

constexpr double kPi = 3.14159265358979323846;

const char* const kCases[] = {"vertical", "deviated45", "horizontal", "bent"};

CaseSpec accuracy_case(const std::string& name) {
  return load_case(std::string(HM_SOURCE_DIR) + "/examples/accuracy_" + name + ".yaml");
}

double cs_radius(const CaseSpec& cs) { return cs.wells.at(0).radius; }

bool long_tests_enabled() {
  const char* v = std::getenv("HM_LONG_TESTS");
  return v != nullptr && std::string(v) == "1";
}

class AccuracyCase : public ::testing::TestWithParam<const char*> {};

// Every case meshes, both models solve to the tight tolerance, the errors are measured over a
// non-empty near-well region, and (issue #7) the hybrid rate and near-well pressure errors are
// within 0.5 % and the near-well error is below Cartesian + Peaceman's on the same grid.
TEST_P(AccuracyCase, HybridWithinHalfAPercentAndBetterThanPeaceman) {
  const AccuracyStudy st = run_accuracy_study(accuracy_case(GetParam()), 1);
  for (const AccuracyErrors* e : {&st.hybrid, &st.peaceman}) {
    EXPECT_GT(e->near_well_cells, 100);
    EXPECT_LT(e->relative_residual, 1e-11);
    EXPECT_TRUE(std::isfinite(e->near_well_pressure_rel_error));
    EXPECT_GT(e->near_well_pressure_rel_error, 0.0);
    EXPECT_GE(e->near_well_pressure_rel_error, e->l2_pressure_rel_error);
  }
  EXPECT_LT(std::fabs(st.hybrid.rate_rel_error), 0.005);
  EXPECT_LE(st.hybrid.near_well_pressure_rel_error, 0.005);
  EXPECT_LT(st.hybrid.near_well_pressure_rel_error, st.peaceman.near_well_pressure_rel_error);
  std::printf("%s: hybrid rate %+.3f %%, near-well %.3f %% (lateral %.3f %%, beyond the ends %.3f %%); "
              "Peaceman rate %+.3f %%, near-well %.3f %%\n",
              GetParam(), 100 * st.hybrid.rate_rel_error, 100 * st.hybrid.near_well_pressure_rel_error,
              100 * st.hybrid.near_well_max_lateral, 100 * st.hybrid.near_well_max_beyond_ends,
              100 * st.peaceman.rate_rel_error, 100 * st.peaceman.near_well_pressure_rel_error);
}

INSTANTIATE_TEST_SUITE_P(Shipped, AccuracyCase, ::testing::ValuesIn(kCases));

// The exact rate is q' x source length, and the source stops r_w short of both trajectory ends.
TEST(AccuracySetup, ExactRateAndSourceFollowTheCase) {
  const CaseSpec cs = accuracy_case("bent");
  const AccuracySetup s = make_accuracy_setup(cs);
  // The source follows the meshed axis: the trajectory with its bend cut along the chords of
  // the block's fillet (docs/architecture.md): radius rho = 1.5 R, k wedges (the block's),
  // tangents t = rho tan(beta/2) replaced by k chords 2 rho sin(beta / 2k).
  const WellSpec& w = cs.wells[0];
  const std::vector<Vec3>& t = w.trajectory;
  const Vec3 d1 = normalized(t[1] - t[0]), d2 = normalized(t[2] - t[1]);
  const double beta = std::atan2(norm(cross(d1, d2)), dot(d1, d2)), rho = 1.5 * w.drainage_radius;
  const WellBlock block = make_gabriel_well_block(cs, 0);
  const int k = static_cast<int>(std::count_if(block.layer_bend.begin(), block.layer_bend.end(),
                                               [](int b) { return b >= 0; })) - 1;
  const double length = norm(t[1] - t[0]) + norm(t[2] - t[1]) - 2 * rho * std::tan(beta / 2) +
                        k * 2 * rho * std::sin(beta / (2 * k));
  // The 40-degree bend of accuracy_bent: 7 wedges keep its faces within 1 degree of orthogonal
  // (well_block.cpp, bend_lean; 4 before, from a segment's length on the outside of the bend).
  EXPECT_EQ(k, 7);
  EXPECT_NEAR(s.field.source_length(), length - 2 * w.radius, 1e-9);
  EXPECT_NEAR(s.drawdown, 50.0, 1e-12);
  EXPECT_NEAR(s.near_radius, 24.0, 1e-12);
  AccuracyOptions tips;
  tips.source_to_tips = true;
  EXPECT_NEAR(make_accuracy_setup(cs, tips).field.source_length(), length, 1e-9);
  EXPECT_GT(s.exact_rate, 0.0);  // a producer (bhp < initial pressure)
}

TEST(AccuracySetup, RejectsWhatTheStudyCannotDo) {
  CaseSpec cs = accuracy_case("vertical");
  cs.reservoir.permeability = {100, 100, 10};
  EXPECT_NO_THROW(make_accuracy_setup(cs));  // a uniform diagonal k: the scaled line source
  cs.reservoir.cell_permx.assign(10, 100.0);
  try {
    make_accuracy_setup(cs);
    FAIL() << "per-cell permeability accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "reservoir.grdecl: the accuracy study needs a uniform permeability (reservoir.permeability), "
              "not per-cell values");
  }
  cs = accuracy_case("vertical");
  cs.wells.push_back(cs.wells[0]);
  EXPECT_THROW(make_accuracy_setup(cs), InputError);
  cs.wells.clear();
  EXPECT_THROW(make_accuracy_setup(cs), InputError);
}

TEST(AccuracySetup, RefinedCaseSplitsEveryIntervalAndTheBlock) {
  const CaseSpec cs = accuracy_case("vertical");
  const CaseSpec r = refine_case(cs, 3);
  EXPECT_EQ(r.reservoir.x.size(), 3 * (cs.reservoir.x.size() - 1) + 1);
  EXPECT_EQ(r.reservoir.z.front(), cs.reservoir.z.front());
  EXPECT_EQ(r.reservoir.z.back(), cs.reservoir.z.back());
  EXPECT_NEAR(r.reservoir.x[1], cs.reservoir.x[1] / 3, 1e-12);
  EXPECT_EQ(r.wells[0].rings, 3 * cs.wells[0].rings);
  EXPECT_EQ(r.wells[0].sectors, 3 * cs.wells[0].sectors);
  EXPECT_NEAR(r.wells[0].segment_length, cs.wells[0].segment_length / 3, 1e-12);
}

TEST(AccuracyReport, JsonAndSvgAreWritten) {
  const AccuracyStudy st = run_accuracy_study(accuracy_case("horizontal"), 1);
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "hm_test_accuracy_report";
  std::filesystem::create_directories(dir);
  ASSERT_TRUE(write_accuracy_json((dir / "accuracy.json").string(), st).ok);
  ASSERT_TRUE(write_accuracy_svg((dir / "accuracy.svg").string(), st).ok);
  std::ifstream in(dir / "accuracy.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  for (const char* model : {"hybrid", "cartesian_peaceman"})
    for (const char* key : {"rate_rel_error", "near_well_pressure_rel_error", "l2_pressure_rel_error"})
      EXPECT_TRUE(j[model][key].is_number()) << model << "." << key;
  EXPECT_EQ(j["refinement"].size(), 1u);
  EXPECT_DOUBLE_EQ(j["hybrid"]["rate_rel_error"].get<double>(), st.hybrid.rate_rel_error);
  std::ifstream svg(dir / "accuracy.svg");
  const std::string text((std::istreambuf_iterator<char>(svg)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("<svg"), std::string::npos);
  EXPECT_NE(text.find("</svg>"), std::string::npos);
  EXPECT_NE(text.find("<polyline"), std::string::npos);  // the exact curve
  // cells.csv: one row per near-well cell; its error column holds the study's maximum.
  ASSERT_TRUE(write_accuracy_cells_csv((dir / "cells.csv").string(), st).ok);
  std::ifstream csv(dir / "cells.csv");
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "cell,region,x,y,z,distance,scaled_distance,to_end,pressure,exact,error,residual");
  int rows = 0;
  double max_error = 0;
  bool finite = true;
  while (std::getline(csv, line)) {
    std::vector<std::string> col;
    std::stringstream ls(line);
    for (std::string c; std::getline(ls, c, ',');) col.push_back(c);
    ASSERT_EQ(col.size(), 12u) << line;
    max_error = std::max(max_error, std::fabs(std::stod(col[10])));
    finite = finite && std::isfinite(std::stod(col[11]));
    ++rows;
  }
  EXPECT_EQ(rows, st.hybrid.near_well_cells);
  EXPECT_NEAR(max_error, st.hybrid.near_well_pressure_rel_error, 1e-8 * st.hybrid.near_well_pressure_rel_error);
  EXPECT_TRUE(finite);
  // A writer reports a path it cannot write instead of throwing.
  EXPECT_FALSE(write_accuracy_json((dir / "no_such_dir" / "a.json").string(), st).ok);
  std::filesystem::remove_all(dir);
}

// ---------------------------------------------------------------- anisotropic permeability (issue 15)

TEST(AnisotropicCase, KeepsKhAndSetsTheRatios) {
  const CaseSpec cs = accuracy_case("horizontal");  // k = 100 mD isotropic
  const CaseSpec a = anisotropic_case(cs, 0.01, 3);
  const Vec3 k = a.reservoir.permeability;
  EXPECT_NEAR(std::sqrt(k.x * k.y), 100, 1e-12);
  EXPECT_NEAR(k.x / k.y, 3, 1e-12);
  EXPECT_NEAR(k.z, 1, 1e-12);
  EXPECT_EQ(a.name, "accuracy_horizontal_kvkh0p01_kxky3");
  EXPECT_EQ(anisotropic_case(cs, 1, 1).name, cs.name);
  EXPECT_THROW(anisotropic_case(cs, 0, 1), InputError);
  EXPECT_THROW(anisotropic_case(cs, 1, -3), InputError);
}

// The scale s = sqrt(k / k0) has det 1, and div(K grad p) = 0 for the scaled line source: the
// K-weighted Laplacian by finite differences vanishes, the gradient is the field's.
TEST(AnisotropicLineSource, IsKHarmonicWithTheRightGradient) {
  const Vec3 k{300, 100, 2};
  const Vec3 s = frame_scale(k);
  EXPECT_NEAR(s.x * s.y * s.z, 1.0, 1e-14);
  EXPECT_NEAR(s.x * s.x / (s.z * s.z), k.x / k.z, 1e-12);
  const std::vector<Vec3> poly = {{0, 0, 0}, {0, 0, 10}, {6, 2, 18}};
  const LineSourceField f = make_line_source_field(poly, 0.1, 150, 200, 24, 0.1, s);
  const double h = 1e-3;
  for (Vec3 x : {Vec3{0.3, 0.1, 4}, Vec3{2, -1, 13}, Vec3{-3, 2, -2}, Vec3{5, 5, 25}}) {
    double klap = 0, scale = 0;
    Vec3 fd;
    for (int d = 0; d < 3; ++d) {
      Vec3 e;
      e[d] = h;
      const double pp = f.pressure(x + e), pm = f.pressure(x - e), p0 = f.pressure(x);
      klap += k[d] * (pp - 2 * p0 + pm) / (h * h);
      scale += k[d] * std::fabs(pp - 2 * p0 + pm) / (h * h);
      fd[d] = (pp - pm) / (2 * h);
    }
    EXPECT_LT(std::fabs(klap), 1e-4 * scale) << x.x;
    EXPECT_LT(norm(f.pressure_gradient(x) - fd), 1e-4 * norm(fd)) << x.x;
    // The plain Laplacian does not vanish: the test can fail.
    double lap = 0, size = 0;
    for (int d = 0; d < 3; ++d) {
      Vec3 e;
      e[d] = h;
      const double second = (f.pressure(x + e) - 2 * f.pressure(x) + f.pressure(x - e)) / (h * h);
      lap += second, size += std::fabs(second);
    }
    EXPECT_GT(std::fabs(lap), 1e-2 * size) << x.x;
  }
}

// The exact rate of the study, q' x scaled source length, is the Darcy flux of the field through
// a closed box around the whole source (K grad p integrated over the box faces).
TEST(AnisotropicLineSource, DarcyFluxThroughABoxIsTheExactRate) {
  CaseSpec cs = anisotropic_case(accuracy_case("bent"), 0.1, 3);
  const AccuracySetup st = make_accuracy_setup(cs);
  const Vec3 k = st.permeability_tensor;
  Vec3 lo{1e30, 1e30, 1e30}, hi{-1e30, -1e30, -1e30};
  for (Vec3 p : st.field.polyline)
    for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], p[d] - 7), hi[d] = std::max(hi[d], p[d] + 7);
  const int n = 200;
  double flux = 0;  // mD bar / m * m2, outward
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
      const double w1 = (hi[a1] - lo[a1]) / n, w2 = (hi[a2] - lo[a2]) / n;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          Vec3 x;
          x[axis] = side ? hi[axis] : lo[axis];
          x[a1] = lo[a1] + (i + 0.5) * w1;
          x[a2] = lo[a2] + (j + 0.5) * w2;
          flux -= k[axis] * st.field.pressure_gradient(x)[axis] * (side ? 1 : -1) * w1 * w2;
        }
    }
  const double rate = kDarcyMetric * flux / st.viscosity;  // produced: the flux goes into the source
  EXPECT_NEAR(-rate / st.exact_rate, 1.0, 2e-4);
}

// The equivalent radius of an elliptic wellbore image against sampled points of the physical
// circle: (max + min) / 2 of their scaled distances to the scaled axis, for a deviated axis.
TEST(AnisotropicLineSource, EquivalentRadiusIsTheMeanSemiAxisOfTheImage) {
  const Vec3 s = frame_scale({300, 100, 1});
  for (Vec3 d : {Vec3{0, 0, 1}, Vec3{1, 0, 0}, Vec3{1, 0.5, 0.7}}) {
    const Vec3 dn = normalized(d), u = perpendicular_unit(dn), v = cross(dn, u);
    const Vec3 e = normalized(to_scaled(dn, s));
    double dmin = 1e30, dmax = 0;
    for (int i = 0; i < 20000; ++i) {
      const double th = 2 * kPi * i / 20000;
      const Vec3 y = to_scaled(0.1 * (std::cos(th) * u + std::sin(th) * v), s);
      const double r = norm(y - dot(y, e) * e);
      dmin = std::min(dmin, r), dmax = std::max(dmax, r);
    }
    EXPECT_NEAR(equivalent_wellbore_radius(s, d, 0.1), 0.5 * (dmin + dmax), 1e-6) << d.x;
  }
  EXPECT_EQ(equivalent_wellbore_radius({1, 1, 1}, {1, 2, 3}, 0.1), 0.1);
}

// Peaceman (1983), anisotropic: WI = 2 pi sqrt(kx ky) h / ln(r_eq / r_w) with
// r_eq = 0.28 sqrt(sqrt(ky/kx) dx^2 + sqrt(kx/ky) dy^2) / ((ky/kx)^1/4 + (kx/ky)^1/4). It is the
// isotropic 0.14 sqrt(dx'^2 + dy'^2) in the scaled frame over the wellbore's equivalent radius
// there: ln(r_eq / r_w) = ln(r_o' / r_w'), in any scaled frame (the 2D one, k = sqrt(kx ky), or the
// 3D one of the study, k0 = cbrt(kx ky kz)).
TEST(PeacemanAnisotropic, EquivalentRadiusIsPeacemans1983AndTheScaledFrames) {
  const double dx = 10, dy = 6, kx = 300, ky = 100, kz = 7, r_w = 0.1;
  const double r_eq = 0.28 * std::sqrt(std::sqrt(ky / kx) * dx * dx + std::sqrt(kx / ky) * dy * dy) /
                      (std::pow(ky / kx, 0.25) + std::pow(kx / ky, 0.25));
  EXPECT_NEAR(peaceman_radius(dx, dy, kx, ky), r_eq, 1e-14 * r_eq);
  for (Vec3 s : {Vec3{std::pow(kx / ky, 0.25), std::pow(ky / kx, 0.25), 1.0}, frame_scale({kx, ky, kz})}) {
    const double r_o = 0.14 * std::hypot(dx / s.x, dy / s.y);
    EXPECT_NEAR(std::log(r_eq / r_w), std::log(r_o / equivalent_wellbore_radius(s, {0, 0, 1}, r_w)), 1e-12);
  }
  const double wi = peaceman_connection_factor({dx, dy, 4}, {kx, ky, kz}, {0, 0, 4}, r_w);
  EXPECT_NEAR(wi, kDarcyMetric * 2 * kPi * std::sqrt(kx * ky) * 4 / std::log(r_eq / r_w), 1e-12 * wi);
}

// One layer, vertical well in the centre cell, kx / ky = 3, 10 x 6 m cells, the exact elliptic
// p (radial in the scaled frame, p_w at the equivalent radius) on the sides: Peaceman's
// anisotropic index gets the rate within 0.1 %; the isotropic equivalent radius on the same cells
// (0.14 sqrt(dx^2 + dy^2)) misses it by more than 1 %.
double anisotropic_peaceman_rate_error(bool isotropic_radius) {
  const int n = 41;
  const double dx = 10, dy = 6, h = 10, kx = 300, ky = 100, mu = 1, r_w = 0.1, p_w = 150, q = 1000;
  ReservoirSpec spec;
  for (int i = 0; i <= n; ++i) spec.x.push_back(i * dx), spec.y.push_back(i * dy);
  spec.z = {1000, 1000 + h};
  spec.permeability = {kx, ky, 50};
  const CartesianMesh cm = make_cartesian_mesh(spec);
  const double cx = n * dx / 2, cy = n * dy / 2;
  WellSpec ws;
  ws.trajectory = {{cx, cy, 1000}, {cx, cy, 1000 + h}};
  ws.radius = r_w;
  std::vector<WellConnection> conn = peaceman_connections(cm, ws, 0);
  EXPECT_EQ(conn.size(), 1u);
  const double k = std::sqrt(kx * ky);
  if (isotropic_radius) conn[0].cf = kDarcyMetric * 2 * kPi * k * h / std::log(peaceman_radius(dx, dy, 1, 1) / r_w);
  const Vec3 s{std::pow(kx / ky, 0.25), std::pow(ky / kx, 0.25), 1.0};
  const double r_w_eq = equivalent_wellbore_radius(s, {0, 0, 1}, r_w);
  auto p_exact = [&](Vec3 x) {
    const double r = std::hypot((x.x - cx) / s.x, (x.y - cy) / s.y);
    return p_w + q * mu / (2 * kPi * kDarcyMetric * k * h) * std::log(r / r_w_eq);
  };
  FlowProblem pb;
  pb.mesh = &cm.mesh;
  pb.geo = &cm.geo;
  pb.viscosity_cp = mu;
  pb.gravity = false;
  pb.connections = conn;
  pb.wells = {{0, p_w, 1000}};
  pb.outer_dirichlet = [&](Vec3 x) { return (x.z == 1000 || x.z == 1000 + h) ? std::nan("") : p_exact(x); };
  const FlowSolution sol = solve_tpfa(pb, compute_transmissibilities(cm.mesh, cm.geo));
  return sol.well_rate_m3_per_day[0] / q - 1;
}

TEST(PeacemanAnisotropic, EllipticFlowRateWithinATenthOfAPercent) {
  const double e = anisotropic_peaceman_rate_error(false), wrong = anisotropic_peaceman_rate_error(true);
  std::printf("Peaceman kx/ky = 3: rate error %+.4f %%; with the isotropic r_o %+.3f %%\n", 100 * e, 100 * wrong);
  EXPECT_LT(std::fabs(e), 1e-3);
  EXPECT_LT(wrong, -0.01);
}

// The one anisotropic accuracy case of the default run (the sweep is scripts/accuracy_anisotropic.py):
// horizontal well, kv/kh = 0.1, level 1, both metrics. The K-orthogonal mesh (metric: permeability,
// block of the user's cross-section area) reproduces the scaled line source within issue 15's
// 0.5 % of the drawdown and of the rate (measured 0.445 % and -0.281 %; 0.99 % and -1.27 % with
// the inscribed block radius R / max(s), docs/accuracy.md) and beats Cartesian + Peaceman; today's
// Euclidean-orthogonal mesh on the same rock misses it by more than 5 times as much (11.7 %: its
// radial block assumes circular flow), the fail half.
TEST(AnisotropicAccuracy, KOrthogonalMeshFollowsTheScaledLineSourceTheEuclideanOneDoesNot) {
  AccuracyOptions opt;
  opt.compare_metrics = true;
  const AccuracyStudy st = run_accuracy_study(anisotropic_case(accuracy_case("horizontal"), 0.1, 1), 1, opt);
  ASSERT_EQ(st.refinement.size(), 1u);
  const RefinementLevel& lv = st.refinement[0];
  ASSERT_TRUE(lv.has_euclidean);
  EXPECT_EQ(st.metric, MeshMetric::Permeability);
  for (const AccuracyErrors* e : {&lv.hybrid, &lv.hybrid_euclidean, &lv.peaceman}) {
    EXPECT_GT(e->near_well_cells, 100);
    EXPECT_LT(e->relative_residual, 1e-11);
  }
  // The K-orthogonal mesh's wellbore is the scaled circle of the equivalent radius; the
  // Euclidean one the physical circle r_w.
  EXPECT_NEAR(st.setup.field.wellbore_radius, st.setup.equivalent_radius, 1e-12);
  EXPECT_EQ(st.setup_euclidean.field.wellbore_radius, cs_radius(accuracy_case("horizontal")));
  EXPECT_LT(std::fabs(lv.hybrid.rate_rel_error), 0.005);
  EXPECT_LT(lv.hybrid.near_well_pressure_rel_error, 0.005);
  EXPECT_LT(lv.hybrid.near_well_pressure_rel_error, lv.peaceman.near_well_pressure_rel_error);
  EXPECT_GT(lv.hybrid_euclidean.near_well_pressure_rel_error, 5 * lv.hybrid.near_well_pressure_rel_error);
  std::printf("horizontal kv/kh 0.1: K-orthogonal rate %+.3f %%, near-well %.3f %%; Euclidean rate %+.3f %%, "
              "near-well %.3f %%; Peaceman rate %+.3f %%, near-well %.3f %%\n",
              100 * lv.hybrid.rate_rel_error, 100 * lv.hybrid.near_well_pressure_rel_error,
              100 * lv.hybrid_euclidean.rate_rel_error, 100 * lv.hybrid_euclidean.near_well_pressure_rel_error,
              100 * lv.peaceman.rate_rel_error, 100 * lv.peaceman.near_well_pressure_rel_error);
}

// Where the layers decided the error (docs/anisotropy.md, "Layers near the wells"): the vertical
// well at kv/kh 0.1, level 1, is within 0.5 % once the layers near it are split (its mesh and
// Peaceman's on the split grid); the same study with the split off (near_well_layer_aspect 0) is not.
TEST(AnisotropicAccuracy, LayersSplitNearTheWellBringTheVerticalWellWithinHalfAPercent) {
  CaseSpec cs = anisotropic_case(accuracy_case("vertical"), 0.1, 1);
  cs.metric = MeshMetric::Permeability;
  const AccuracyStudy split = run_accuracy_study(cs, 1);
  cs.reservoir.near_well_layer_aspect = 0;
  const AccuracyStudy whole = run_accuracy_study(cs, 1);
  ASSERT_EQ(split.refinement.size(), 1u);
  EXPECT_GT(split.refinement[0].cartesian_cells, whole.refinement[0].cartesian_cells);  // the split grid
  EXPECT_LT(std::fabs(split.hybrid.rate_rel_error), 0.005);
  EXPECT_LT(split.hybrid.near_well_pressure_rel_error, 0.005);
  EXPECT_LT(split.hybrid.relative_residual, 1e-11);
  EXPECT_GT(whole.hybrid.near_well_pressure_rel_error, 0.005);
  std::printf("vertical kv/kh 0.1: layers split: rate %+.3f %%, near-well %.3f %% (%d cells); not split: rate %+.3f %%, "
              "near-well %.3f %% (%d cells)\n",
              100 * split.hybrid.rate_rel_error, 100 * split.hybrid.near_well_pressure_rel_error,
              split.refinement[0].hybrid_cells, 100 * whole.hybrid.rate_rel_error,
              100 * whole.hybrid.near_well_pressure_rel_error, whole.refinement[0].hybrid_cells);
}

// ---------------------------------------------------------------- long: issue #7 acceptance

// The other half of the pair above: the same vertical case with flat ends (no cap, uniform
// segments) misses the 0.5 % at the tips (docs/accuracy.md: ~1.1 %), where the flow is 3D.
TEST(AccuracyEnds, FlatEndsMissHalfAPercentAtTheTips) {
  CaseSpec cs = accuracy_case("vertical");
  cs.wells[0].end_caps = EndCaps::Flat;
  const AccuracyStudy st = run_accuracy_study(cs, 1);
  EXPECT_GT(st.hybrid.near_well_pressure_rel_error, 0.005);
  EXPECT_EQ(st.hybrid.near_well_pressure_rel_error, st.hybrid.near_well_max_beyond_ends);
  std::printf("vertical, flat ends: near-well %.3f %% (beyond the ends %.3f %%, lateral %.3f %%)\n",
              100 * st.hybrid.near_well_pressure_rel_error, 100 * st.hybrid.near_well_max_beyond_ends,
              100 * st.hybrid.near_well_max_lateral);
}

class AccuracyAcceptance : public ::testing::TestWithParam<const char*> {};

TEST_P(AccuracyAcceptance, RefinementLowersTheHybridError) {
  if (!long_tests_enabled()) GTEST_SKIP() << "long test: set HM_LONG_TESTS=1";
  const AccuracyStudy st = run_accuracy_study(accuracy_case(GetParam()), 3);
  ASSERT_EQ(st.refinement.size(), 3u);
  for (size_t i = 1; i < st.refinement.size(); ++i) {
    EXPECT_LT(st.refinement[i].hybrid.near_well_pressure_rel_error,
              st.refinement[i - 1].hybrid.near_well_pressure_rel_error)
        << "factor " << st.refinement[i].factor;
    EXPECT_LT(st.refinement[i].hybrid.l2_pressure_rel_error, st.refinement[i - 1].hybrid.l2_pressure_rel_error)
        << "factor " << st.refinement[i].factor;
  }
}

INSTANTIATE_TEST_SUITE_P(Shipped, AccuracyAcceptance, ::testing::ValuesIn(kCases));

}  // namespace
