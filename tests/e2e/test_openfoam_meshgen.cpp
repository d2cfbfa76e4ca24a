// End-to-end: `meshgen --export openfoam` writes a case that OpenFOAM's checkMesh reads with the
// cell count and total volume of meshgen's summary.json. (The library-level tests in
// tests/exporters/test_openfoam_export.cpp also cross-check checkMesh's skewness figures.)
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>

#include "run_command.hpp"

namespace fs = std::filesystem;
using hm_test::fresh_dir;
using hm_test::q;
using hm_test::RemoveAtExit;
using hm_test::run_command;
using hm_test::slurp;

namespace {

const std::string kMeshgen = std::string(HM_BIN_DIR) + "/meshgen";


void check_example(const std::string& example) {
  if (run_command("sh -c 'command -v checkMesh'", 10).exit_code != 0)
    GTEST_SKIP() << "checkMesh (Debian package openfoam) is not installed; scripts/install-deps.sh --validators "
                    "installs it";
  const fs::path d = fresh_dir("foam_" + example);
  const RemoveAtExit cleanup{d};
  const auto mg = run_command(kMeshgen + " " + q(std::string(HM_SOURCE_DIR) + "/examples/" + example + ".yaml") +
                                  " -o " + q(d / "mesh") + " --export openfoam",
                              900);
  if (mg.exit_code == 2 && mg.err.find("--export") != std::string::npos)
    GTEST_SKIP() << "meshgen does not accept --export openfoam yet: " << mg.err;
  ASSERT_EQ(mg.exit_code, 0) << mg.out << mg.err;
  const nlohmann::json summary = nlohmann::json::parse(slurp(d / "mesh" / "summary.json"));
  for (const char* f : {"points", "faces", "owner", "neighbour", "boundary"})
    ASSERT_TRUE(fs::exists(d / "mesh" / "openfoam" / "constant" / "polyMesh" / f)) << f;
  // checkMesh writes sets into the case: run it on a copy.
  fs::copy(d / "mesh" / "openfoam", d / "copy", fs::copy_options::recursive);
  const auto cm = run_command("sh -c 'WM_PROJECT_DIR=/usr/share/openfoam checkMesh -case " + q(d / "copy") + "'", 900);
  ASSERT_EQ(cm.exit_code, 0) << cm.out << cm.err;
  long long cells = -1;
  double volume = -1;
  std::vector<std::string> failures;
  std::istringstream in(cm.out);
  std::string line;
  std::smatch m;
  while (std::getline(in, line)) {
    const size_t first = line.find_first_not_of(" \t");
    if (first != std::string::npos && line.compare(first, 3, "***") == 0) failures.push_back(line);
    if (std::regex_search(line, m, std::regex(R"(^\s*cells:\s+(\d+))"))) cells = std::stoll(m[1]);
    if (std::regex_search(line, m, std::regex(R"(Total volume = ([0-9.eE+-]+))"))) volume = std::stod(m[1]);
  }
  EXPECT_EQ(cells, summary["cells"]["total"].get<long long>());
  const double ours = summary["mesh_volume"].get<double>();
  EXPECT_NEAR(volume, ours, 1e-9 * ours);
  // Issue #6: `Mesh OK.` and no line starting with `***` (skewness included).
  EXPECT_TRUE(failures.empty()) << failures.front() << "\n" << cm.out;
  EXPECT_NE(cm.out.find("Mesh OK."), std::string::npos) << cm.out;
  std::printf("[ figures  ] %s: checkMesh cells %lld, total volume %.15g (summary %.15g)%s%s\n", example.c_str(), cells,
              volume, ours, failures.empty() ? ", Mesh OK" : ", ", failures.empty() ? "" : failures[0].c_str());
}

TEST(OpenFoamMeshgen, PaperSingleWellCaseReadsInCheckMesh) { check_example("paper_single_well"); }
TEST(OpenFoamMeshgen, ThreeWellsCaseReadsInCheckMesh) { check_example("three_wells"); }
// Wells through the reservoir boundary (issue 12).
TEST(OpenFoamMeshgen, VerticalThroughCaseReadsInCheckMesh) { check_example("vertical_through"); }
TEST(OpenFoamMeshgen, DeviatedThroughTopCaseReadsInCheckMesh) { check_example("deviated_through_top"); }
TEST(OpenFoamMeshgen, HorizontalThroughSidesCaseReadsInCheckMesh) { check_example("horizontal_through_sides"); }
// Perforations: the closed wellbore is a wall patch of its own.
TEST(OpenFoamMeshgen, PerforatedSurveyCaseReadsInCheckMesh) { check_example("perforated_survey"); }

}  // namespace
