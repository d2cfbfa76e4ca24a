// VTK reads the written .vtu as our geometry: tests/exporters/vtk_agreement.py, run with
// /usr/bin/python3 (python3-vtk9) in a subprocess, measures on the points and faces VTK read
// that every cell has our volume and is convex with outward faces, and that each disagreement
// of VTK 9.1's own cell measures (vtkCellSizeFilter, vtkCellValidator) is one of VTK 9.1's
// documented defects (docs/output-formats.md, "What VTK 9.1 computes from a polyhedron"),
// reproduced cell by cell. Skipped with a message when VTK is absent. The three-well example
// (1.5 min of Python) runs with HM_LONG_TESTS=1.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "../fvcheck/fv_test_meshes.hpp"
#include "exporters/vtu/vtu_writer.hpp"
#include "meshgen/case/case.hpp"
#include "meshgen/core/geometry.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"

namespace {

namespace fs = std::filesystem;

bool have_vtk() { return std::system("/usr/bin/python3 -c 'import vtk, numpy' > /dev/null 2>&1") == 0; }

struct Agreement {
  int exit_code = -1;
  std::map<std::string, double> v;
  std::string err;
  double at(const std::string& k) const {
    const auto it = v.find(k);
    return it == v.end() ? -1.0 : it->second;
  }
};

fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("hm_vtkagree_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// Writes the mesh with our volumes (or `volumes` when given) and runs the script on it.
Agreement measure(const hm::PolyMesh& m, const std::string& name, const std::vector<double>* volumes = nullptr) {
  const fs::path d = temp_dir(name);
  const std::string vtu = (d / "mesh.vtu").string();
  const hm::MeshGeometry g = hm::compute_geometry(m);
  const hm::WriteStatus ws = hm::write_vtu(vtu, m, {hm::VtuCellArray::real("volume", 1, volumes ? *volumes : g.cell_volume)});
  Agreement a;
  if (!ws.ok) {
    a.err = ws.message;
    return a;
  }
  const std::string script = std::string(HM_SOURCE_DIR) + "/tests/exporters/vtk_agreement.py";
  const std::string cmd = "timeout 600 /usr/bin/python3 '" + script + "' '" + vtu + "' > '" + (d / "out.txt").string() +
                          "' 2> '" + (d / "err.txt").string() + "'";
  const int status = std::system(cmd.c_str());
  a.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream out(d / "out.txt");
  std::string line;
  while (std::getline(out, line)) {  // vtkCellValidator's own stdout is skipped
    std::istringstream ls(line);
    std::string tag, key;
    double x;
    if (ls >> tag >> key >> x && tag == "@@") a.v[key] = x;
  }
  std::ifstream err(d / "err.txt");
  std::ostringstream ss;
  ss << err.rdbuf();
  a.err = ss.str();
  if (std::getenv("HM_KEEP_TEST_OUTPUT") == nullptr) fs::remove_all(d);
  return a;
}

void print_figures(const std::string& name, const Agreement& a) {
  std::printf(
      "[ figures  ] %s: %g cells (%g polyhedra); VTK-read faces: volume max rel %.2g, convexity %.2g of the diameter; "
      "vtkCellSizeFilter: %g cells > 1e-6 (max %.3g), %g of them its triangulation's hole; vtkCellValidator: %g invalid "
      "(orientation %g = %g bounding-box centre + %g short edge; non-convex %g = %g centroid + %g seam test; intersecting %g, "
      "%g not on a short edge)\n",
      name.c_str(), a.at("cells"), a.at("polyhedra"), a.at("face_volume_max_rel"), a.at("convexity_max"), a.at("size_bad"),
      a.at("size_max_rel"), a.at("size_hole"), a.at("invalid"), a.at("invalid_orientation"),
      a.at("invalid_orientation_bbox"), a.at("invalid_orientation_short_edge"), a.at("invalid_nonconvex"),
      a.at("invalid_nonconvex_centroid"), a.at("invalid_nonconvex_seam"), a.at("invalid_intersecting"),
      a.at("invalid_intersecting_unexplained"));
}

// What must hold for any mesh we write: VTK reads our volume and a convex cell with outward
// faces, and VTK's own disagreements are the defects named in docs/output-formats.md.
void expect_vtk_reads_ours(const hm::PolyMesh& m, const Agreement& a) {
  ASSERT_EQ(a.exit_code, 0) << a.err;
  EXPECT_EQ(a.err.find("ERROR"), std::string::npos) << a.err;
  EXPECT_EQ(a.at("cells"), m.n_cells());
  EXPECT_LE(a.at("face_volume_max_rel"), 1e-9);
  EXPECT_LE(a.at("convexity_max"), 1e-9);
  EXPECT_EQ(a.at("orientation_bad"), 0);
  // Every vtkCellSizeFilter disagreement is a hole in VTK's point-cloud triangulation.
  EXPECT_EQ(a.at("size_unexplained"), 0);
  EXPECT_EQ(a.at("size_hole"), a.at("size_bad"));
  // Every orientation flag comes from the bounding-box centre lying outside the (convex) cell or
  // a face with an edge shorter than 1e-3 of the cell (ours), and every intersection flag a short edge.
  EXPECT_EQ(a.at("invalid_orientation_unexplained"), 0);
  EXPECT_EQ(a.at("invalid_intersecting_unexplained"), 0);
  EXPECT_EQ(a.at("invalid_other"), 0);
}

class VtkAgreement : public ::testing::TestWithParam<const char*> {};

TEST_P(VtkAgreement, VtkReadsOurVolumesAndConvexCellsAndItsDisagreementsAreItsDefects) {
  if (!have_vtk()) GTEST_SKIP() << "/usr/bin/python3 with vtk and numpy (python3-vtk9) not installed";
  const std::string name = GetParam();
  if (name == "three_wells" && std::getenv("HM_LONG_TESTS") == nullptr)
    GTEST_SKIP() << "three_wells: 1.5 min of Python; run with HM_LONG_TESTS=1";
  const hm::CaseSpec cs = hm::load_case(std::string(HM_SOURCE_DIR) + "/examples/" + name + ".yaml");
  const hm::HybridMesh h = hm::build_hybrid_mesh(cs);
  const Agreement a = measure(h.mesh, name);
  expect_vtk_reads_ours(h.mesh, a);
  print_figures(name, a);
}

INSTANTIATE_TEST_SUITE_P(Examples, VtkAgreement, ::testing::Values("paper_single_well", "three_wells"));

// Fail half: a non-convex cell (the L prism) and a cell given the wrong volume are caught by the
// same measures, so the example's result above is not vacuous.
TEST(VtkAgreementFailHalf, NonConvexCellAndWrongVolumeAreCaught) {
  if (!have_vtk()) GTEST_SKIP() << "/usr/bin/python3 with vtk and numpy (python3-vtk9) not installed";
  const hm::PolyMesh l = fvtest::prism({{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}}, 0, 1, {0.5, 0.5, 0.5});
  const Agreement a = measure(l, "lprism");
  ASSERT_EQ(a.exit_code, 0) << a.err;
  EXPECT_GT(a.at("convexity_max"), 0.1);
  EXPECT_LE(a.at("face_volume_max_rel"), 1e-12);
  const hm::PolyMesh box = fvtest::prism({{0, 0}, {2, 0}, {2, 1}, {0, 1}}, 0, 1, {1, 0.5, 0.5});
  const std::vector<double> wrong{2.0 * 1.001};
  const Agreement b = measure(box, "wrongvolume", &wrong);
  ASSERT_EQ(b.exit_code, 0) << b.err;
  EXPECT_LE(b.at("convexity_max"), 1e-12);
  EXPECT_GT(b.at("face_volume_max_rel"), 5e-4);
}

// VTK 9.1's orientation test is not about orientation: the unit corner tetrahedron, convex and
// outward, is flagged (state 32) because VTK measures from its bounding-box centre (1/2, 1/2, 1/2),
// which lies outside it. Our measures accept it: the defect is VTK's, and the example's flagged
// cells are this case (invalid_orientation_unexplained == 0 above).
TEST(VtkAgreementCounterExample, CornerTetrahedronIsFlaggedByVtkAlthoughValid) {
  if (!have_vtk()) GTEST_SKIP() << "/usr/bin/python3 with vtk and numpy (python3-vtk9) not installed";
  const hm::PolyMesh tet =
      fvtest::single_cell({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}},
                          {0.25, 0.25, 0.25});
  const Agreement a = measure(tet, "cornertet");
  expect_vtk_reads_ours(tet, a);
  EXPECT_EQ(a.at("invalid"), 1);
  EXPECT_EQ(a.at("invalid_orientation"), 1);
  EXPECT_EQ(a.at("size_bad"), 0);
}

}  // namespace
