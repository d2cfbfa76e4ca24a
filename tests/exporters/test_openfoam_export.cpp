// OpenFOAM polyMesh export: ordering rules, checkMesh acceptance, error statuses.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "exporter_test_support.hpp"
#include "exporters/openfoam/openfoam_case.hpp"
#include "meshgen/core/fv_quality.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"

namespace {

using namespace hmtest;

hm::CaseSpec small_box() { return box_case({0, 10, 25, 45, 60}, {0, 12, 30, 50}, {1000, 1004, 1010, 1018}); }

hm::CaseSpec box_with_two_wells() {
  hm::CaseSpec cs = box_case({0, 30, 50, 60, 70, 90, 120}, {0, 25, 45, 55, 65, 90}, {1000, 1005, 1012, 1020, 1030});
  add_vertical_well(cs, "INJ", hm::WellType::Injector, 2, 2, 260, 0.1);
  add_vertical_well(cs, "PROD", hm::WellType::Producer, 4, 3, 150, 0.1);
  return cs;
}

// Swaps owner and neighbour of every other interior face (reversing its cycle): still a valid
// PolyMesh, but one where owner > neighbour, which OpenFOAM forbids and the writer must fix.
void flip_every_other_interior_face(hm::PolyMesh& mesh) {
  int k = 0;
  for (int f = 0; f < mesh.n_faces(); ++f) {
    if (mesh.face_neighbour[f] < 0 || (k++ % 2) != 0) continue;
    std::swap(mesh.face_owner[f], mesh.face_neighbour[f]);
    std::reverse(mesh.face_nodes.begin() + mesh.face_node_ptr[f], mesh.face_nodes.begin() + mesh.face_node_ptr[f + 1]);
  }
}

bool skip_without_checkmesh() { return !have_executable("checkMesh"); }
#define REQUIRE_CHECKMESH()                                                                        \
  if (skip_without_checkmesh()) GTEST_SKIP() << "checkMesh (Debian package openfoam) is not installed; " \
                                                "scripts/install-deps.sh --validators installs it"

// Checks the OpenFOAM order invariants on the written order (independent of checkMesh).
void expect_foam_order(const hm::PolyMesh& mesh, const hm::OpenFoamInfo& info) {
  ASSERT_EQ(static_cast<int>(info.face_order.size()), mesh.n_faces());
  std::vector<int> seen(mesh.n_faces(), 0);
  for (int32_t f : info.face_order) ++seen[f];
  for (int f = 0; f < mesh.n_faces(); ++f) ASSERT_EQ(seen[f], 1) << "face " << f;
  int32_t prev_owner = -1, prev_nbr = -1;
  for (int i = 0; i < info.n_internal_faces; ++i) {
    const int32_t f = info.face_order[i];
    ASSERT_GE(mesh.face_neighbour[f], 0);
    const int32_t own = std::min(mesh.face_owner[f], mesh.face_neighbour[f]);
    const int32_t nbr = std::max(mesh.face_owner[f], mesh.face_neighbour[f]);
    ASSERT_TRUE(own > prev_owner || (own == prev_owner && nbr >= prev_nbr)) << "foam face " << i;
    ASSERT_EQ(info.face_flipped[i] != 0, mesh.face_owner[f] != own);
    prev_owner = own;
    prev_nbr = nbr;
  }
  int32_t start = info.n_internal_faces;
  for (const hm::OpenFoamPatch& p : info.patches) {
    ASSERT_EQ(p.start_face, start) << p.name;
    for (int32_t i = p.start_face; i < p.start_face + p.n_faces; ++i)
      ASSERT_EQ(mesh.face_patch[info.face_order[i]], p.code) << p.name;
    start += p.n_faces;
  }
  ASSERT_EQ(start, mesh.n_faces());
}

TEST(OpenFoamOrder, InternalFacesUpperTriangularBoundaryGroupedByPatch) {
  const hm::CaseSpec cs = box_with_two_wells();
  hm::BuildReport rep;
  hm::PolyMesh mesh = build_box_with_vertical_wells(cs, &rep);
  ASSERT_TRUE(rep.ok);
  flip_every_other_interior_face(mesh);
  ASSERT_TRUE(hm::check_csr_invariants(mesh).ok);
  hm::OpenFoamOptions opt;
  opt.well_names = {"INJ", "PROD"};
  hm::OpenFoamInfo info;
  std::string error;
  ASSERT_TRUE(hm::make_openfoam_order(mesh, opt, &info, &error)) << error;
  expect_foam_order(mesh, info);
  ASSERT_EQ(info.patches.size(), 3u);
  EXPECT_EQ(info.patches[0].name, "outer");
  EXPECT_EQ(info.patches[1].name, "wellbore_INJ");
  EXPECT_EQ(info.patches[2].name, "wellbore_PROD");
  // Each hole has 4 wall faces per layer.
  EXPECT_EQ(info.patches[1].n_faces, 4 * 4);
  EXPECT_EQ(info.patches[2].n_faces, 4 * 4);
  // Half the internal faces had owner > neighbour: the writer flipped exactly those.
  int flipped = 0;
  for (int i = 0; i < info.n_internal_faces; ++i) flipped += info.face_flipped[i];
  EXPECT_EQ(flipped, (info.n_internal_faces + 1) / 2);
}

TEST(OpenFoamOrder, UnknownPatchIsAnError) {
  const hm::CaseSpec cs = box_with_two_wells();
  hm::BuildReport rep;
  hm::PolyMesh mesh = build_box_with_vertical_wells(cs, &rep);
  hm::OpenFoamOptions opt;
  opt.n_wells = 1;  // the mesh has faces of well 1 too
  hm::OpenFoamInfo info;
  std::string error;
  EXPECT_FALSE(hm::make_openfoam_order(mesh, opt, &info, &error));
  EXPECT_NE(error.find("unknown patch 2"), std::string::npos) << error;
  opt.n_wells = 2;
  EXPECT_TRUE(hm::make_openfoam_order(mesh, opt, &info, &error)) << error;
}

TEST(OpenFoamOrder, InvalidWellNameIsAnError) {
  const hm::CaseSpec cs = box_with_two_wells();
  hm::BuildReport rep;
  const hm::PolyMesh mesh = build_box_with_vertical_wells(cs, &rep);
  hm::OpenFoamOptions opt;
  opt.well_names = {"INJ", "bad name"};
  TempDir tmp("foam_badname");
  const hm::WriteStatus st = hm::write_openfoam_case((tmp.path / "case").string(), mesh, opt);
  EXPECT_FALSE(st.ok);
  EXPECT_NE(st.message.find("patch name 'wellbore_bad name' is not a valid OpenFOAM word"), std::string::npos)
      << st.message;
  EXPECT_TRUE(list_files(tmp.path).empty());
}

class CheckMeshBox : public ::testing::TestWithParam<bool> {};

TEST_P(CheckMeshBox, CartesianBoxPasses) {
  REQUIRE_CHECKMESH();
  const hm::CaseSpec cs = small_box();
  hm::BuildReport rep;
  const hm::PolyMesh mesh = build_box_mesh(cs, &rep);
  ASSERT_TRUE(rep.ok);
  const hm::MeshGeometry geo = hm::compute_geometry(mesh);
  TempDir tmp("foam_box");
  hm::OpenFoamOptions opt;
  opt.binary = GetParam();
  const hm::WriteStatus st = hm::write_openfoam_case(tmp.str(), mesh, opt);
  ASSERT_TRUE(st.ok) << st.message;
  const CheckMeshResult r = run_check_mesh(tmp.path);
  ASSERT_TRUE(r.ran) << r.output;
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(r.mesh_ok) << r.output;
  EXPECT_TRUE(r.failures.empty()) << r.failures.front();
  EXPECT_EQ(r.cells, mesh.n_cells());
  EXPECT_NEAR(r.total_volume, hm::total_volume(geo), 1e-12 * hm::total_volume(geo)) << r.output;
  EXPECT_DOUBLE_EQ(hm::total_volume(geo), 60.0 * 50.0 * 18.0);
}

TEST_P(CheckMeshBox, BoxWithVerticalWellHolesPasses) {
  REQUIRE_CHECKMESH();
  const hm::CaseSpec cs = box_with_two_wells();
  hm::BuildReport rep;
  hm::PolyMesh mesh = build_box_with_vertical_wells(cs, &rep);
  ASSERT_TRUE(rep.ok);
  flip_every_other_interior_face(mesh);
  const hm::MeshGeometry geo = hm::compute_geometry(mesh);
  // Box minus two diamond holes of half-diagonal 0.1 (area 2 r^2) through the 30 m thickness.
  EXPECT_NEAR(hm::total_volume(geo), 120.0 * 90.0 * 30.0 - 2 * (2 * 0.01) * 30.0, 1e-9);
  TempDir tmp("foam_holes");
  hm::OpenFoamOptions opt;
  opt.binary = GetParam();
  opt.well_names = {"INJ", "PROD"};
  const hm::WriteStatus st = hm::write_openfoam_case(tmp.str(), mesh, opt);
  ASSERT_TRUE(st.ok) << st.message;
  const std::string boundary = read_text(tmp.path / "constant/polyMesh/boundary");
  EXPECT_NE(boundary.find("wellbore_PROD"), std::string::npos);
  const CheckMeshResult r = run_check_mesh(tmp.path);
  ASSERT_TRUE(r.ran) << r.output;
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_TRUE(r.mesh_ok) << r.output;
  EXPECT_TRUE(r.failures.empty()) << r.failures.front();
  EXPECT_EQ(r.cells, mesh.n_cells());
  EXPECT_NEAR(r.total_volume, hm::total_volume(geo), 1e-12 * hm::total_volume(geo)) << r.output;
}

TEST_P(CheckMeshBox, BoxWithRadialWellBlockPasses) {
  REQUIRE_CHECKMESH();
  hm::CaseSpec cs = box_case({0, 20, 30, 40, 50, 60, 70, 80, 100}, {0, 20, 30, 40, 50, 60, 70, 80, 100},
                             {1000, 1010, 1016, 1022, 1028, 1034, 1040, 1050});
  hm::WellSpec w;
  w.name = "P1";
  w.trajectory = {{50, 50, 1012}, {50, 50, 1030}, {58, 50, 1040}};
  w.radius = 0.1;
  w.drainage_radius = 5;
  w.rings = 4;
  w.sectors = 12;
  w.segment_length = 4;
  cs.wells.push_back(w);
  hm::BuildReport rep;
  const hm::PolyMesh mesh = build_box_with_radial_block(cs, 1.0, &rep);
  int radial = 0;
  for (int c = 0; c < mesh.n_cells(); ++c) radial += mesh.cell_region[c] == hm::kWell;
  ASSERT_GT(radial, 4 * 12 * 5);
  const hm::MeshGeometry geo = hm::compute_geometry(mesh);
  TempDir tmp("foam_radial");
  hm::OpenFoamOptions opt;
  opt.binary = GetParam();
  opt.well_names = {"P1"};
  hm::OpenFoamInfo info;
  const hm::WriteStatus st = hm::write_openfoam_case(tmp.str(), mesh, opt, &info);
  ASSERT_TRUE(st.ok) << st.message;
  expect_foam_order(mesh, info);
  ASSERT_EQ(info.patches.size(), 2u);
  EXPECT_GT(info.patches[1].n_faces, 0);
  const CheckMeshResult r = run_check_mesh(tmp.path);
  ASSERT_TRUE(r.ran) << r.output;
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_TRUE(r.mesh_ok) << r.output;
  EXPECT_TRUE(r.failures.empty()) << r.failures.front();
  EXPECT_EQ(r.cells, mesh.n_cells());
  EXPECT_NEAR(r.total_volume, hm::total_volume(geo), 1e-9 * hm::total_volume(geo)) << r.output;
}

INSTANTIATE_TEST_SUITE_P(AsciiAndBinary, CheckMeshBox, ::testing::Values(false, true),
                         [](const auto& info) { return info.param ? "Binary" : "Ascii"; });

// OpenFOAM's face skewness (primitiveMeshTools::faceSkewness, checkMesh fails above 4) computed from
// our geometry: the distance from the face centre to the line joining the two cell centroids,
// over the face's extent in that direction (at least 0.2 of the centroid distance).
double openfoam_skewness(const hm::PolyMesh& mesh, const hm::MeshGeometry& geo, int f) {
  const Vec3 own = geo.cell_centroid[mesh.face_owner[f]], nei = geo.cell_centroid[mesh.face_neighbour[f]];
  const Vec3 cpf = geo.face_centroid[f] - own, d = nei - own, a = geo.face_area[f];
  const Vec3 sv = cpf - (dot(a, cpf) / (dot(a, d) + 1e-150)) * d;
  const Vec3 sv_hat = sv / (hm::norm(sv) + 1e-150);
  double fd = 0.2 * hm::norm(d) + 1e-150;
  for (const int32_t* v = mesh.face_begin(f); v != mesh.face_end(f); ++v)
    fd = std::max(fd, std::abs(dot(sv_hat, mesh.nodes[*v] - geo.face_centroid[f])));
  return hm::norm(sv) / fd;
}

// The shipped examples through the pipeline (accuracy_bent: hemispherical end caps and a bend;
// layered_grdecl: a corner-point deck): checkMesh accepts the whole hybrid mesh with the right cell
// count and our total volume; one wellbore patch per well. meshgen's mesh of layered_grdecl had a
// face at skewness 4.25 until session 41 (docs/optimization.md, "Removals that undid each other").
void expect_check_mesh_passes(const std::string& name, const hm::CaseSpec& cs) {
  const hm::HybridMesh hybrid = hm::build_hybrid_mesh(cs);
  const hm::PolyMesh& mesh = hybrid.mesh;
  hm::OpenFoamOptions opt;
  opt.binary = true;
  for (const hm::WellSpec& w : cs.wells) opt.well_names.push_back(w.name);
  TempDir tmp("foam_" + name);
  hm::OpenFoamInfo info;
  const auto t0 = std::chrono::steady_clock::now();
  const hm::WriteStatus st = hm::write_openfoam_case(tmp.str(), mesh, opt, &info);
  const double write_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(st.ok) << st.message;
  expect_foam_order(mesh, info);
  ASSERT_EQ(info.patches.size(), cs.wells.size() + 1);
  for (size_t p = 1; p < info.patches.size(); ++p) {
    EXPECT_EQ(info.patches[p].name, "wellbore_" + cs.wells[p - 1].name);
    EXPECT_GT(info.patches[p].n_faces, 0);
  }
  const auto t1 = std::chrono::steady_clock::now();
  const CheckMeshResult r = run_check_mesh(tmp.path);
  const double check_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  ASSERT_TRUE(r.ran) << r.output;
  const double vol = hm::total_volume(hybrid.geometry);
  std::printf("[ figures  ] %s: checkMesh cells %lld (ours %d), total volume %.15g (ours %.15g, rel %.3g); write %.3f s, "
              "checkMesh %.2f s\n",
              name.c_str(), r.cells, mesh.n_cells(), r.total_volume, vol, std::abs(r.total_volume - vol) / vol, write_s,
              check_s);
  // Skewness is a property of the mesh (cell centroids), not of the file: count it ourselves.
  int skewed = 0;
  double max_skew = 0;
  std::map<std::string, int> by_regions;
  const char* region_name[3] = {"reservoir", "transition", "well"};
  // The optimiser's own skewness (what its control bounds) follows OpenFOAM's face and cell
  // centres: its maximum must be checkMesh's (compared below).
  const std::vector<double> optimiser_skew = hm::openfoam_face_skewness(mesh);
  ASSERT_EQ(optimiser_skew.size(), static_cast<size_t>(mesh.n_faces()));
  double optimiser_max = 0;
  for (int f = 0; f < mesh.n_faces(); ++f)
    if (mesh.face_neighbour[f] >= 0) optimiser_max = std::max(optimiser_max, optimiser_skew[f]);
  for (int f = 0; f < mesh.n_faces(); ++f) {
    if (mesh.face_neighbour[f] < 0) continue;
    const double sk = openfoam_skewness(mesh, hybrid.geometry, f);
    max_skew = std::max(max_skew, sk);
    if (sk > 4) {
      ++skewed;
      int a = mesh.cell_region[mesh.face_owner[f]], b = mesh.cell_region[mesh.face_neighbour[f]];
      if (a > b) std::swap(a, b);
      ++by_regions[std::string(region_name[a]) + "/" + region_name[b]];
    }
  }
  std::printf("[ figures  ] %s: faces with OpenFOAM skewness > 4 (ours): %d, max %.4g;", name.c_str(), skewed, max_skew);
  for (const auto& [k, v] : by_regions) std::printf(" %s %d", k.c_str(), v);
  std::printf("\n");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.cells, mesh.n_cells());
  EXPECT_NEAR(r.total_volume, vol, 1e-9 * vol);
  // Issue #6: every check passes, skewness included (the optimiser keeps every face within
  // checkMesh's limit of 4, docs/optimization.md); our own count of skewed faces agrees.
  EXPECT_EQ(skewed, 0);
  EXPECT_LE(max_skew, 4.0);
  EXPECT_TRUE(r.mesh_ok) << r.output;
  EXPECT_TRUE(r.failures.empty()) << r.failures.front() << "\n" << r.output;
  const std::regex skew_re(R"(Max skewness = ([0-9.eE+-]+) OK)");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.output, m, skew_re)) << r.output;
  // OpenFOAM's face centres (triangle fan about the point average) differ from ours on the
  // faces the optimiser leaves non-planar (up to omega_p = 10 deg): 0.11 % measured, 1 % allowed.
  EXPECT_NEAR(std::stod(m[1]), max_skew, 1e-2 * max_skew);
  // measured 3e-5 and 8e-5 (flat ends), 1.7e-4 (accuracy_bent: a triangle next to a cap's pole)
  EXPECT_NEAR(std::stod(m[1]), optimiser_max, 5e-4 * optimiser_max);
  // checkMesh's non-orthogonality, between OpenFOAM's cell centres (fvcheck's and meshgen's figure,
  // checkmesh_figures): the same maximum and average; the issue asks 1e-4, the files are binary.
  const hm::NonOrthogonalitySummary ortho = hm::checkmesh_figures(mesh).nonorthogonality;
  const std::regex ortho_re(R"(Mesh non-orthogonality Max: ([0-9.eE+-]+) average: ([0-9.eE+-]+))");
  ASSERT_TRUE(std::regex_search(r.output, m, ortho_re)) << r.output;
  std::printf("[ figures  ] %s: checkMesh non-orthogonality max %s average %s, ours %.15g %.15g\n", name.c_str(),
              m[1].str().c_str(), m[2].str().c_str(), ortho.max, ortho.average);
  EXPECT_NEAR(std::stod(m[1]), ortho.max, 1e-6 * ortho.max);
  EXPECT_NEAR(std::stod(m[2]), ortho.average, 1e-6 * ortho.average);
  EXPECT_EQ(ortho.errors, 0);
}

class CheckMeshExample : public ::testing::TestWithParam<const char*> {};

TEST_P(CheckMeshExample, HybridMeshPasses) {
  REQUIRE_CHECKMESH();
  const std::string name = GetParam();
  expect_check_mesh_passes(name, hm::load_case(std::string(HM_SOURCE_DIR) + "/examples/" + name + ".yaml"));
}

INSTANTIATE_TEST_SUITE_P(Examples, CheckMeshExample, ::testing::Values("paper_single_well", "three_wells", "accuracy_bent", "readme_example", "layered_grdecl"),
                         [](const auto& info) { return std::string(info.param); });

// The same examples meshed K-orthogonal (`metric: permeability` added to the case, issue 15): checkMesh
// measures the written cells, which the frame shears. readme_example, layered_grdecl and three_wells
// failed its skewness until the optimiser's rounds measured it at the written positions and stepped
// the skewed faces' neighbours too (docs/anisotropy.md, "The shipped examples with metric: permeability").
class CheckMeshExampleInPermeabilityFrame : public ::testing::TestWithParam<const char*> {};

TEST_P(CheckMeshExampleInPermeabilityFrame, HybridMeshPasses) {
  REQUIRE_CHECKMESH();
  const std::string name = GetParam(), dir = std::string(HM_SOURCE_DIR) + "/examples";
  std::ifstream in(dir + "/" + name + ".yaml");
  ASSERT_TRUE(in.good()) << name;
  std::stringstream text;
  text << "metric: permeability\n" << in.rdbuf();
  const hm::CaseSpec cs = hm::parse_case(text.str(), dir);
  ASSERT_EQ(cs.metric, hm::MeshMetric::Permeability);
  expect_check_mesh_passes(name + " (metric: permeability)", cs);
}

INSTANTIATE_TEST_SUITE_P(Examples, CheckMeshExampleInPermeabilityFrame,
                         ::testing::Values("paper_single_well", "three_wells", "readme_example", "layered_grdecl"),
                         [](const auto& info) { return std::string(info.param); });

// The fail half of the pair: the same gate rejects a mesh with an inverted cell, so passing it
// above means something.
TEST(CheckMeshGate, RejectsAMeshWithAnInvertedCell) {
  REQUIRE_CHECKMESH();
  const hm::CaseSpec cs = small_box();
  hm::BuildReport rep;
  hm::PolyMesh mesh = build_box_mesh(cs, &rep);
  // Push one interior lattice node through its neighbours: the cells around it fold over.
  int moved = -1;
  for (int n = 0; n < mesh.n_nodes(); ++n)
    if (mesh.nodes[n].x == 25 && mesh.nodes[n].y == 30 && mesh.nodes[n].z == 1010) moved = n;
  ASSERT_GE(moved, 0);
  mesh.nodes[moved].z += 30;
  TempDir tmp("foam_bad");
  ASSERT_TRUE(hm::write_openfoam_case(tmp.str(), mesh).ok);
  const CheckMeshResult r = run_check_mesh(tmp.path);
  ASSERT_TRUE(r.ran);
  EXPECT_FALSE(r.mesh_ok) << r.output;
  ASSERT_FALSE(r.failures.empty()) << r.output;
  EXPECT_NE(r.output.find("Error in face pyramids"), std::string::npos) << r.output;
}

TEST(OpenFoamWriteErrors, DirectoryUnderARegularFileFailsCleanly) {
  const hm::CaseSpec cs = small_box();
  hm::BuildReport rep;
  const hm::PolyMesh mesh = build_box_mesh(cs, &rep);
  TempDir tmp("foam_err");
  std::ofstream(tmp.path / "plain_file") << "x";
  const std::string dir = (tmp.path / "plain_file" / "case").string();
  const hm::WriteStatus st = hm::write_openfoam_case(dir, mesh);
  EXPECT_FALSE(st.ok);
  EXPECT_NE(st.message.find("write_openfoam_case " + dir + ": cannot create directory"), std::string::npos)
      << st.message;
  EXPECT_EQ(list_files(tmp.path), std::vector<std::string>{"plain_file"});
}

TEST(OpenFoamWriteErrors, FailureWhileCommittingLeavesNoCase) {
  const hm::CaseSpec cs = small_box();
  hm::BuildReport rep;
  const hm::PolyMesh mesh = build_box_mesh(cs, &rep);
  TempDir tmp("foam_err2");
  // `owner` (renamed last) cannot replace a non-empty directory: the commit fails at the end.
  fs::create_directories(tmp.path / "constant/polyMesh/owner/keep");
  const hm::WriteStatus st = hm::write_openfoam_case(tmp.str(), mesh);
  EXPECT_FALSE(st.ok);
  EXPECT_NE(st.message.find("cannot rename"), std::string::npos) << st.message;
  // Nothing but the pre-existing directory: no points/faces/... and no temporary files.
  EXPECT_TRUE(list_files(tmp.path).empty()) << list_files(tmp.path).front();
}

TEST(OpenFoamWriteErrors, NonConformingMeshIsRejected) {
  const hm::CaseSpec cs = small_box();
  hm::BuildReport rep;
  hm::PolyMesh mesh = build_box_mesh(cs, &rep);
  mesh.face_patch[0] = hm::kUnmatchedFace;
  TempDir tmp("foam_err3");
  const hm::WriteStatus st = hm::write_openfoam_case(tmp.str(), mesh);
  EXPECT_FALSE(st.ok);
  EXPECT_FALSE(st.message.empty());
  EXPECT_TRUE(list_files(tmp.path).empty());
}

}  // namespace
