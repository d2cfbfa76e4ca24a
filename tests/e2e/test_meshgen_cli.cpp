// End-to-end: the meshgen executable on good and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>
#include <utility>

#include <nlohmann/json.hpp>

#include "run_command.hpp"
#include "small_case.hpp"

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

// Two solver_demo outputs agree: the same cells, pressure min / max / mean within pressure_rel, and
// every well's rate within rate_abs + rate_rel |rate|.
void expect_same_solution(const fs::path& dir_a, const fs::path& dir_b, double pressure_rel, double rate_abs,
                          double rate_rel) {
  const auto a = nlohmann::json::parse(slurp(dir_a / "solution.json"));
  const auto b = nlohmann::json::parse(slurp(dir_b / "solution.json"));
  EXPECT_EQ(a["cells"], b["cells"]);
  for (const char* k : {"min", "max", "mean"}) {
    const double x = a["pressure"][k].get<double>(), y = b["pressure"][k].get<double>();
    EXPECT_LE(std::fabs(x - y), pressure_rel * std::fabs(x)) << k;
  }
  ASSERT_EQ(a["wells"].size(), b["wells"].size());
  for (size_t w = 0; w < a["wells"].size(); ++w) {
    const double x = a["wells"][w]["rate_m3_per_day"].get<double>(), y = b["wells"][w]["rate_m3_per_day"].get<double>();
    EXPECT_LE(std::fabs(x - y), rate_abs + rate_rel * std::fabs(x)) << w;
  }
}

using hm::test::kSmallCase;
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

// meshgen runs itself again with glibc's huge pages (meshgen/core/malloc_tunables.hpp) unless the
// environment already says otherwise: the run that does and the one that keeps glibc's defaults
// write the same mesh.vtu, byte for byte.
TEST(MeshgenCli, HugePagesChangeNoResult) {
  const fs::path d = fresh_dir("hugepages");
  std::ofstream(d / "case.yaml") << kSmallCase;
  const std::string args = " '" + (d / "case.yaml").string() + "' --quiet -o '";
  const auto with = run_command(kMeshgen + args + (d / "with").string() + "'");
  const auto without = run_command("env GLIBC_TUNABLES=glibc.malloc.hugetlb=0 " + kMeshgen + args + (d / "without").string() + "'");
  ASSERT_EQ(with.exit_code, 0) << with.err;
  ASSERT_EQ(without.exit_code, 0) << without.err;
  const std::string a = slurp(d / "with" / "mesh.vtu"), b = slurp(d / "without" / "mesh.vtu");
  EXPECT_GT(a.size(), 1000u);
  EXPECT_TRUE(a == b) << "mesh.vtu differs with and without huge pages";
}

// solver_demo --mesh: the mesh file meshgen wrote is solved without re-meshing and gives the same
// pressures (cell by cell, read back from pressure.vtu) and well rates as the run that meshes, to
// the iterative solver's tolerance (relative residual 1e-12; the faces are numbered differently,
// so the CG iterates differ in rounding; measured 1.3e-12); a mesh file without the mesh arrays
// is refused (exit 2).
TEST(SolverDemoCli, MeshFileGivesTheSamePressures) {
  const fs::path d = fresh_dir("solver_mesh_file");
  const std::string solver = std::string(HM_BIN_DIR) + "/solver_demo ";
  const std::string yaml = kExamples + "readme_example.yaml";
  ASSERT_EQ(run_command(kMeshgen + " " + yaml + " -o '" + (d / "mesh").string() + "'").exit_code, 0);
  const auto a = run_command(solver + yaml + " -o '" + (d / "yaml").string() + "'");
  ASSERT_EQ(a.exit_code, 0) << a.err;
  const auto b = run_command(solver + yaml + " --mesh '" + (d / "mesh" / "mesh.vtu").string() + "' -o '" +
                             (d / "file").string() + "'");
  ASSERT_EQ(b.exit_code, 0) << b.err;
  // The single producer's steady rate is ~0 (hydrostatic): rates compared at the solver's mass balance.
  expect_same_solution(d / "yaml", d / "file", 1e-10, 1e-8, 1e-9);
  // Cell by cell: both pressure.vtu files hold the same pressures (same cell order).
  const std::string cmp = "/usr/bin/python3 -c \"import sys, vtk\n"
                          "def p(f):\n r = vtk.vtkXMLUnstructuredGridReader(); r.SetFileName(f); r.Update()\n"
                          " a = r.GetOutput().GetCellData().GetArray('pressure'); return [a.GetValue(i) for i in range(a.GetNumberOfTuples())]\n"
                          "x, y = p(sys.argv[1]), p(sys.argv[2])\n"
                          "print(len(x) == len(y) and max(abs(u - v) / abs(u) for u, v in zip(x, y)) <= 1e-10)\" ";
  if (std::system("/usr/bin/python3 -c 'import vtk' > /dev/null 2>&1") == 0) {
    const auto c = run_command(cmp + "'" + (d / "yaml" / "pressure.vtu").string() + "' '" +
                               (d / "file" / "pressure.vtu").string() + "'");
    EXPECT_EQ(c.out, "True\n") << c.err;
  }
  // Fail half: a VTU without the mesh arrays (VTK's corpus file) is refused.
  const auto bad = run_command(solver + yaml + " --mesh '" + std::string(HM_SOURCE_DIR) +
                               "/tests/fuzz/corpus_vtu/ascii.vtu' -o '" + (d / "bad").string() + "'");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("cell array"), std::string::npos) << bad.err;
}

// A result does not depend on where the model sits: solver_demo on the README example and on the same
// case moved to field coordinates (x + 456000, y + 5926000 m: UTM values) meshes in a local frame as
// meshgen does and gives the same cells, pressures and rates, to the rounding of the files' coordinates.
TEST(SolverDemoCli, FieldCoordinatesGiveTheSameSolution) {
  const fs::path d = fresh_dir("solver_field_coordinates");
  const std::string solver = std::string(HM_BIN_DIR) + "/solver_demo ";
  auto reservoir_case = [](double dx, double dy) {
    const double axis[] = {0, 40, 70, 90, 100, 105, 110, 115, 120, 125, 130, 135, 140, 150, 170, 200};
    std::ostringstream os;
    os.precision(17);
    os << "name: moved\nreservoir:\n";
    for (auto [key, shift] : {std::pair{"x", dx}, std::pair{"y", dy}}) {
      os << "  " << key << ": [";
      for (size_t i = 0; i < std::size(axis); ++i) os << (i ? ", " : "") << axis[i] + shift;
      os << "]\n";
    }
    os << "  z: [980, 995, 1005, 1010, 1015, 1020, 1025, 1030, 1035, 1040, 1045, 1050, 1055, 1065, 1080]\n"
          "  permeability: [100, 100, 10]\n  porosity: 0.2\n  initial_pressure: 200\n"
          "wells:\n  - name: P1\n    trajectory: [["
       << 120 + dx << ", " << 120 + dy << ", 1018], [" << 120 + dx << ", " << 120 + dy << ", 1032], [" << 128 + dx
       << ", " << 120 + dy << ", 1042]]\n    radius: 0.1\n    drainage_radius: 4\n    bhp: 150\n";
    return os.str();
  };
  std::ofstream(d / "here.yaml") << reservoir_case(0, 0);
  std::ofstream(d / "field.yaml") << reservoir_case(456000, 5926000);
  for (const char* name : {"here", "field"}) {
    const auto r = run_command(solver + "'" + (d / (std::string(name) + ".yaml")).string() + "' -o '" +
                               (d / name).string() + "'");
    ASSERT_EQ(r.exit_code, 0) << name << ": " << r.err;
  }
  expect_same_solution(d / "here", d / "field", 1e-9, 1e-6, 1e-7);
}
