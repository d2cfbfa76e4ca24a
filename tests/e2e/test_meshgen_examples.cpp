// End-to-end: meshgen on the bundled examples; the outputs' properties are checked from
// the files (summary.json, mesh.vtu read back with our reader).
#include <gtest/gtest.h>

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
  const auto& cells = j["cells"];
  EXPECT_EQ(cells["reservoir"].get<int>() + cells["transition"].get<int>() + cells["well"].get<int>(),
            cells["total"].get<int>());
  EXPECT_GT(cells["transition"].get<int>(), 0);
  // One transition cell per internal site.
  EXPECT_EQ(j["transition"]["sites"]["internal"].get<int>(), cells["transition"].get<int>());
  EXPECT_EQ(j["transition"]["hidden_sites"].get<int>(), 0);
  EXPECT_EQ(j["transition"]["before"]["cells"].get<int>(), cells["transition"].get<int>());
  EXPECT_GT(j["timings_s"]["total"].get<double>(), 0.0);
}

INSTANTIATE_TEST_SUITE_P(Examples, MeshgenExample,
                         ::testing::Values(Example{"paper_single_well", 1, 1}, Example{"three_wells", 2, 3},
                                           Example{"readme_example", 1, 1}),
                         [](const auto& info) { return info.param.name; });

}  // namespace
