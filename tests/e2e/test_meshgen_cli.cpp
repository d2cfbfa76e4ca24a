// End-to-end: the meshgen executable on good and bad input.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "run_command.hpp"

namespace fs = std::filesystem;
using hm_test::fresh_dir;
using hm_test::run_command;
using hm_test::slurp;

namespace {
const std::string kMeshgen = std::string(HM_BIN_DIR) + "/meshgen";
const std::string kExamples = std::string(HM_SOURCE_DIR) + "/examples/";

// Writes a case file and returns (exit code, stderr) of meshgen on it.
hm_test::CommandResult mesh_text(const std::string& name, const std::string& yaml) {
  const fs::path d = fresh_dir(name);
  std::ofstream(d / "case.yaml") << yaml;
  return run_command(kMeshgen + " '" + (d / "case.yaml").string() + "' -o '" + (d / "out").string() + "'");
}

const char* kSmallCase = R"(name: small
reservoir:
  x: [0, 20, 40, 50, 55, 60, 65, 70, 80, 100, 120]
  y: [0, 20, 40, 50, 55, 60, 65, 70, 80, 100, 120]
  z: [1000, 1010, 1020, 1025, 1030, 1035, 1040, 1045, 1050, 1060, 1070]
  permeability: [100, 100, 10]
  porosity: 0.2
  initial_pressure: 200
wells:
  - name: P1
    trajectory: [[60, 60, 1027], [60, 60, 1043]]
    radius: 0.1
    drainage_radius: 3
    rings: 3
    sectors: 8
    segment_length: 4
    bhp: 150
)";
}  // namespace

TEST(MeshgenCli, BadArgumentsExitWithCode2) {
  auto r = run_command(kMeshgen);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("no case file given"), std::string::npos) << r.err;
  r = run_command(kMeshgen + " " + kExamples + "paper_single_well.yaml");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("-o OUTDIR"), std::string::npos) << r.err;
  r = run_command(kMeshgen + " /nonexistent/case.yaml -o /tmp/x");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("case file: cannot open"), std::string::npos) << r.err;
  r = run_command(kMeshgen + " " + kExamples + "paper_single_well.yaml -o /tmp/x --frobnicate");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("unknown option '--frobnicate'"), std::string::npos) << r.err;
}

TEST(MeshgenCli, BadCaseFieldExitsWithCode2AndNamesTheField) {
  std::string yaml = kSmallCase;
  yaml.replace(yaml.find("radius: 0.1"), 11, "radius: -1");
  const auto r = mesh_text("badradius", yaml);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("wells[0].radius: must be > 0"), std::string::npos) << r.err;
}

TEST(MeshgenCli, UnwritableOutputExitsWithCode2) {
  const fs::path d = fresh_dir("unwritable");
  std::ofstream(d / "case.yaml") << kSmallCase;
  std::ofstream(d / "file") << "x";  // a file where a directory is wanted
  const auto r = run_command(kMeshgen + " '" + (d / "case.yaml").string() + "' -o '" + (d / "file" / "out").string() + "'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("-o: cannot create directory"), std::string::npos) << r.err;
}
