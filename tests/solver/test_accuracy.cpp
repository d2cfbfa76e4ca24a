// The near-well accuracy study on the four shipped cases (examples/accuracy_*.yaml).
// Default run: every case at its own resolution (a few seconds each), with the issue #7
// acceptance criteria. The three-level refinement study is long (minutes, 2+ GB): it runs only
// when the environment has HM_LONG_TESTS=1 (docs/accuracy.md says how to run it).
#include <gtest/gtest.h>


#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "meshgen/pipeline/hybrid_mesh.hpp"
#include "solver_demo/lib/accuracy.hpp"
#include "solver_demo/lib/peaceman.hpp"

using namespace hm;

namespace {

const char* const kCases[] = {"vertical", "deviated45", "horizontal", "bent"};

CaseSpec accuracy_case(const std::string& name) {
  return load_case(std::string(HM_SOURCE_DIR) + "/examples/accuracy_" + name + ".yaml");
}

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
  // the block's fillet (docs/architecture.md): radius rho = 1.5 R, k wedges (at most 30 degrees,
  // none longer than a segment on the outside of the bend, at radius rho + R), tangents
  // t = rho tan(beta/2) replaced by k chords 2 rho sin(beta / 2k).
  const WellSpec& w = cs.wells[0];
  const std::vector<Vec3>& t = w.trajectory;
  const Vec3 d1 = normalized(t[1] - t[0]), d2 = normalized(t[2] - t[1]);
  const double beta = std::atan2(norm(cross(d1, d2)), dot(d1, d2)), rho = 1.5 * w.drainage_radius;
  const int k = std::max(static_cast<int>(std::ceil(beta / (M_PI / 6))),
                         static_cast<int>(std::ceil((rho + w.drainage_radius) * beta / w.segment_length)));
  const double length = norm(t[1] - t[0]) + norm(t[2] - t[1]) - 2 * rho * std::tan(beta / 2) +
                        k * 2 * rho * std::sin(beta / (2 * k));
  EXPECT_EQ(k, 4);  // the 40-degree bend of accuracy_bent: 20 m x 0.70 rad / 4 m = 3.5 -> 4
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
  try {
    make_accuracy_setup(cs);
    FAIL() << "anisotropic permeability accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "reservoir.permeability: the accuracy study needs isotropic permeability (kx = ky = kz)");
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
  // A writer reports a path it cannot write instead of throwing.
  EXPECT_FALSE(write_accuracy_json((dir / "no_such_dir" / "a.json").string(), st).ok);
  std::filesystem::remove_all(dir);
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
