// End-to-end: meshgen on the bundled examples; the outputs' properties are checked from
// the files (summary.json, mesh.vtu read back with our reader).
#include <gtest/gtest.h>

#include <cstdlib>
#include <nlohmann/json.hpp>

#include "run_command.hpp"

namespace fs = std::filesystem;

namespace {

struct Example {
  std::string name;
  int cavities;
  int wells;
};

class MeshgenExample : public ::testing::TestWithParam<Example> {};

TEST_P(MeshgenExample, MeshesAndReportsConsistently) {
  const Example ex = GetParam();
  const fs::path out = hm_test::fresh_dir("example_" + ex.name);
  const std::string cmd = std::string(HM_BIN_DIR) + "/meshgen " + HM_SOURCE_DIR + "/examples/" + ex.name +
                          ".yaml -o '" + out.string() + "'";
  const auto r = hm_test::run_command(cmd);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_TRUE(fs::exists(out / "mesh.vtu"));
  ASSERT_TRUE(fs::exists(out / "summary.json"));
  for (int k = 0; k < ex.cavities; ++k) EXPECT_TRUE(fs::exists(out / ("cavity_" + std::to_string(k) + ".obj")));
  EXPECT_FALSE(fs::exists(out / ("cavity_" + std::to_string(ex.cavities) + ".obj")));
  for (const auto& e : fs::directory_iterator(out))
    EXPECT_EQ(e.path().string().find(".tmp"), std::string::npos) << "left-over temporary " << e.path();

  const auto j = nlohmann::json::parse(hm_test::slurp(out / "summary.json"));
  EXPECT_EQ(j["cavities"].get<int>(), ex.cavities);
  EXPECT_EQ(j["wells"].size(), static_cast<size_t>(ex.wells));
  // end_caps: auto keeps the hemispherical caps on every shipped example.
  for (const auto& w : j["wells"]) EXPECT_EQ(w["end_caps"].get<std::string>(), "hemisphere") << w.dump();
  const auto& cells = j["cells"];
  EXPECT_EQ(cells["reservoir"].get<int>() + cells["transition"].get<int>() + cells["well"].get<int>(),
            cells["total"].get<int>());
  EXPECT_GT(cells["transition"].get<int>(), 0);
  // One transition cell per internal site.
  EXPECT_EQ(j["transition"]["sites"]["internal"].get<int>(), cells["transition"].get<int>());
  EXPECT_EQ(j["transition"]["hidden_sites"].get<int>(), 0);
  EXPECT_EQ(j["transition"]["before"]["cells"].get<int>(), cells["transition"].get<int>());
  EXPECT_GT(j["timings_s"]["total"].get<double>(), 0.0);

  // fvcheck passes on the optimised mesh (issue #4): every check, paper defaults, exit 0,
  // and its JSON agrees; the raw power diagram (--no-optimize) passes too.
  const std::string fvcheck = std::string(HM_BIN_DIR) + "/fvcheck ";
  const auto fv = hm_test::run_command(fvcheck + "'" + (out / "mesh.vtu").string() + "' --json '" +
                                       (out / "fvcheck.json").string() + "'");
  EXPECT_EQ(fv.exit_code, 0) << fv.out << fv.err;
  const auto report = nlohmann::json::parse(hm_test::slurp(out / "fvcheck.json"));
  EXPECT_TRUE(report["ok"].get<bool>());
  EXPECT_EQ(report["cells"].get<int>(), cells["total"].get<int>());
  const fs::path raw = hm_test::fresh_dir("example_raw_" + ex.name);
  ASSERT_EQ(hm_test::run_command(std::string(HM_BIN_DIR) + "/meshgen " + HM_SOURCE_DIR + "/examples/" + ex.name +
                                 ".yaml --no-optimize -o '" + raw.string() + "'")
                .exit_code,
            0);
  const auto fv_raw = hm_test::run_command(fvcheck + "'" + (raw / "mesh.vtu").string() + "'");
  EXPECT_EQ(fv_raw.exit_code, 0) << fv_raw.out << fv_raw.err;
}

INSTANTIATE_TEST_SUITE_P(Examples, MeshgenExample,
                         ::testing::Values(Example{"paper_single_well", 1, 1}, Example{"three_wells", 2, 3},
                                           Example{"readme_example", 1, 1}, Example{"layered_grdecl", 2, 2}),
                         [](const auto& info) { return info.param.name; });

}  // namespace

// The Reek example (../shared/data/reek beside the checkout): meshgen exits 0 only when its
// self-check passed (fvcheck's checks on every near-well cell; the model's cells are the user's);
// its report says the model was refined near the well and the cells add up.
TEST(MeshgenReekExample, MeshesAfterNearWellRefinement) {
  if (!fs::exists(fs::path(HM_SOURCE_DIR) / ".." / "shared" / "data" / "reek" / "REEK_GRID.DATA"))
    GTEST_SKIP() << "no ../shared/data/reek beside the checkout";
  const fs::path out = hm_test::fresh_dir("example_reek_steep_well");
  const auto r = hm_test::run_command(std::string(HM_BIN_DIR) + "/meshgen " + HM_SOURCE_DIR +
                                      "/examples/reek_steep_well.yaml -o '" + out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(hm_test::slurp(out / "summary.json"));
  EXPECT_EQ(j["corner_point"]["model"], nlohmann::json::array({40, 64, 14}));
  EXPECT_GT(j["corner_point"]["meshed"][0].get<int>(), 40);
  EXPECT_GT(j["corner_point"]["meshed"][1].get<int>(), 64);
  const auto& cells = j["cells"];
  EXPECT_EQ(cells["reservoir"].get<int>() + cells["transition"].get<int>() + cells["well"].get<int>(),
            cells["total"].get<int>());
  EXPECT_GT(cells["transition"].get<int>(), 0);
  EXPECT_EQ(j["transition"]["sites"]["internal"].get<int>(), cells["transition"].get<int>());
  EXPECT_EQ(j["cavities"].get<int>(), 1);
}

// examples/reek_wells.yaml (Reek's well OP_3 from its COMPDAT cells, a 600 m horizontal producer in
// layer 8 and an injector; ~0.7M cells, ~2 min, 2 GB): meshgen exits 0 only when its self-check
// passed; the three wells are meshed, OP_3's path is cut to the model. HM_LONG_TESTS=1.
TEST(MeshgenReekExample, ReekWellsExampleMeshes) {
  if (std::getenv("HM_LONG_TESTS") == nullptr) GTEST_SKIP() << "set HM_LONG_TESTS=1 (Reek with three wells: ~2 min)";
  if (!fs::exists(fs::path(HM_SOURCE_DIR) / ".." / "shared" / "data" / "reek" / "REEK_GRID.DATA"))
    GTEST_SKIP() << "no ../shared/data/reek beside the checkout";
  const fs::path out = hm_test::fresh_dir("example_reek_wells");
  const auto r = hm_test::run_command(std::string(HM_BIN_DIR) + "/meshgen " + HM_SOURCE_DIR +
                                          "/examples/reek_wells.yaml -o '" + out.string() + "'",
                                      1800);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(hm_test::slurp(out / "summary.json"));
  const auto& cells = j["cells"];
  EXPECT_EQ(cells["reservoir"].get<int>() + cells["transition"].get<int>() + cells["well"].get<int>(),
            cells["total"].get<int>());
  int wells = 0;
  for (const auto& c : j["cavity_list"]) wells += static_cast<int>(c["wells"].size());
  EXPECT_EQ(wells, 3);
  EXPECT_NE(r.out.find("wells[0] (OP_3): its path crosses the corner-point model's surface"), std::string::npos) << r.out;
  fs::remove_all(out);
}
