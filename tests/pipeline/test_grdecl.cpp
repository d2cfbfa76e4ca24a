// Reservoir models read with OPM (reservoir.grdecl): a Cartesian model written as GRDECL reads as
// its axes and rock and meshes to the same mesh as its box form; the Reek corner-point model reads
// with its dimensions, ACTNUM and MAPAXES, and is refused with the reason (not meshed yet).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "meshgen/case/grdecl.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"

using namespace hm;
namespace fs = std::filesystem;

namespace {

const std::vector<double> kX{0, 30, 45, 50, 55, 60, 65, 70, 85, 100};
const std::vector<double> kY{0, 25, 40, 45, 50, 55, 60, 75, 100};
const std::vector<double> kZ{980, 996, 1008, 1012, 1016, 1020, 1024, 1028, 1032, 1036, 1040, 1052, 1068};

std::string num(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

// COORD/ZCORN of the rectilinear grid on axes x, y, z, with per-cell PERMX = f(cell), PORO, NTG.
std::string grdecl_of_box(const std::vector<double>& x, const std::vector<double>& y, const std::vector<double>& z,
                          bool varied_rock) {
  const size_t nx = x.size() - 1, ny = y.size() - 1, nz = z.size() - 1, n = nx * ny * nz;
  std::ostringstream o;
  o << "SPECGRID\n " << nx << " " << ny << " " << nz << " 1 F /\nCOORD\n";
  for (size_t j = 0; j <= ny; ++j)
    for (size_t i = 0; i <= nx; ++i)
      o << num(x[i]) << " " << num(y[j]) << " " << num(z.front()) << " " << num(x[i]) << " " << num(y[j]) << " "
        << num(z.back()) << "\n";
  o << "/\nZCORN\n";
  for (size_t k = 0; k < nz; ++k)
    for (int surface = 0; surface < 2; ++surface)
      o << 4 * nx * ny << "*" << num(z[k + surface]) << "\n";
  o << "/\nPERMX\n";
  for (size_t c = 0; c < n; ++c) o << (varied_rock ? 10.0 + double(c % 17) * 7.5 : 100.0) << "\n";
  o << "/\nPERMY\n" << n << "*100 /\nPERMZ\n" << n << "*10 /\nPORO\n" << n << "*0.25 /\nNTG\n"
    << n << "*" << (varied_rock ? "0.8" : "1") << " /\n";
  return o.str();
}

struct TempDir {
  fs::path path = fs::temp_directory_path() / ("hm_grdecl_" + std::to_string(::getpid()));
  TempDir() { fs::create_directories(path); }
  ~TempDir() { fs::remove_all(path); }
};

std::string write(const fs::path& p, const std::string& text) {
  std::ofstream(p) << text;
  return p.string();
}

const char* kGrdeclWell =
    "wells:\n  - {name: P1, trajectory: [[50, 50, 1018], [50, 50, 1030]], radius: 0.1, drainage_radius: 4.0,"
    " bhp: 150}\n";

}  // namespace

TEST(Grdecl, CartesianModelReadsAsItsAxesAndRock) {
  TempDir tmp;
  write(tmp.path / "BOX.GRDECL", grdecl_of_box(kX, kY, kZ, true));
  const CaseSpec cs = load_case(write(tmp.path / "case.yaml",
                                      std::string("name: g\nreservoir: {grdecl: BOX.GRDECL}\n") + kGrdeclWell));
  EXPECT_EQ(cs.reservoir.x, kX);
  EXPECT_EQ(cs.reservoir.y, kY);
  EXPECT_EQ(cs.reservoir.z, kZ);
  const size_t n = (kX.size() - 1) * (kY.size() - 1) * (kZ.size() - 1);
  ASSERT_EQ(cs.reservoir.cell_permx.size(), n);
  for (size_t c = 0; c < n; ++c) {
    // NTG 0.8 folds into the horizontal permeabilities and the porosity (as OPM's TRANX and PORV use it).
    EXPECT_NEAR(cs.reservoir.cell_permx[c], 0.8 * (10.0 + double(c % 17) * 7.5), 1e-9) << c;
    EXPECT_NEAR(cs.reservoir.cell_permy[c], 80.0, 1e-9);
    EXPECT_NEAR(cs.reservoir.cell_permz[c], 10.0, 1e-9);
    EXPECT_NEAR(cs.reservoir.cell_poro[c], 0.2, 1e-12);
  }
  // The rock a radial or transition cell takes is that of the model cell around its centre.
  const int c = reservoir_cell_at(cs.reservoir, {52, 47, 1017});
  EXPECT_EQ(c, 3 + 9 * (3 + 8 * 4));  // x in [50, 55), y in [45, 50), z in [1016, 1020)
  EXPECT_EQ(reservoir_permeability(cs.reservoir, c).x, cs.reservoir.cell_permx[c]);
}

TEST(Grdecl, CartesianModelMeshesToTheMeshOfItsBoxForm) {
  TempDir tmp;
  write(tmp.path / "BOX.GRDECL", grdecl_of_box(kX, kY, kZ, false));
  const CaseSpec from_file = load_case(write(tmp.path / "case.yaml",
                                             std::string("name: g\nreservoir: {grdecl: BOX.GRDECL}\n") + kGrdeclWell));
  std::ostringstream box;
  box << "name: g\nreservoir:\n  permeability: [100, 100, 10]\n  porosity: 0.25\n";
  for (auto [key, axis] : {std::pair{"x", &kX}, {"y", &kY}, {"z", &kZ}}) {
    box << "  " << key << ": [";
    for (size_t i = 0; i < axis->size(); ++i) box << (i ? ", " : "") << num((*axis)[i]);
    box << "]\n";
  }
  const CaseSpec from_box = parse_case(box.str() + kGrdeclWell);
  PipelineOptions opts;
  opts.optimize = false;
  const HybridMesh a = build_hybrid_mesh(from_file, opts), b = build_hybrid_mesh(from_box, opts);
  ASSERT_EQ(a.mesh.n_cells(), b.mesh.n_cells());
  ASSERT_EQ(a.mesh.n_faces(), b.mesh.n_faces());
  ASSERT_EQ(a.mesh.n_nodes(), b.mesh.n_nodes());
  EXPECT_EQ(a.mesh.face_nodes, b.mesh.face_nodes);
  EXPECT_EQ(a.mesh.cell_faces, b.mesh.cell_faces);
  for (int v = 0; v < a.mesh.n_nodes(); ++v) ASSERT_EQ(a.mesh.nodes[v], b.mesh.nodes[v]) << v;
  for (int c = 0; c < a.mesh.n_cells(); ++c) {
    ASSERT_EQ(a.mesh.cell_perm[c], b.mesh.cell_perm[c]) << c;
    ASSERT_EQ(a.mesh.cell_porosity[c], b.mesh.cell_porosity[c]) << c;
  }
}

// MAPAXES (rotated 30 degrees, origin at UTM values): the wells are given in map coordinates and
// land where they are in the grid frame, where the mesh is built (OPM's convention: COORD is in the
// grid frame, MAPAXES places it on the map).
TEST(Grdecl, WellsInMapCoordinatesAreBroughtIntoTheGridFrame) {
  TempDir tmp;
  const double th = 30 * M_PI / 180, L = 1000;
  const Vec3 o{456510.608, 5926880.031, 0}, ux{std::cos(th), std::sin(th), 0}, uy{-std::sin(th), std::cos(th), 0};
  auto map = [&](double gx, double gy) { return o + gx * ux + gy * uy; };
  const Vec3 ypt = map(0, L), xpt = map(L, 0);
  write(tmp.path / "BOX.GRDECL", "MAPUNITS\n 'METRES' /\nMAPAXES\n " + num(ypt.x) + " " + num(ypt.y) + " " + num(o.x) +
                                     " " + num(o.y) + " " + num(xpt.x) + " " + num(xpt.y) + " /\n" +
                                     grdecl_of_box(kX, kY, kZ, false));
  const Vec3 a = map(50, 50), b = map(50, 50);
  const std::string well = "wells:\n  - {name: P1, trajectory: [[" + num(a.x) + ", " + num(a.y) + ", 1018], [" + num(b.x) +
                           ", " + num(b.y) + ", 1030]], radius: 0.1, drainage_radius: 4.0, bhp: 150}\n";
  const CaseSpec cs = load_case(write(tmp.path / "case.yaml", "name: g\nreservoir: {grdecl: BOX.GRDECL}\n" + well));
  ASSERT_TRUE(cs.reservoir.has_map_axes);
  EXPECT_NEAR(cs.reservoir.map_origin.x, o.x, 1e-6);
  EXPECT_NEAR(cs.reservoir.map_origin.y, o.y, 1e-6);
  for (const Vec3& p : cs.wells[0].trajectory) {
    EXPECT_NEAR(p.x, 50, 1e-6);
    EXPECT_NEAR(p.y, 50, 1e-6);
  }
  // Without MAPAXES the same map coordinates are far outside the grid: refused as input.
  write(tmp.path / "PLAIN.GRDECL", grdecl_of_box(kX, kY, kZ, false));
  EXPECT_THROW(load_case(write(tmp.path / "case2.yaml", "name: g\nreservoir: {grdecl: PLAIN.GRDECL}\n" + well)),
               InputError);
}

namespace {
fs::path reek_deck() { return fs::path(HM_SOURCE_DIR) / ".." / "shared" / "data" / "reek" / "REEK_GRID.DATA"; }
}  // namespace

TEST(Grdecl, ReekReadsWithItsDimensionsActiveCellsAndMapAxes) {
  if (!fs::exists(reek_deck())) GTEST_SKIP() << "no " << reek_deck();
  const CornerPointModel m = read_corner_point_model(reek_deck().string(), "reservoir.grdecl");
  EXPECT_EQ(m.nx, 40);
  EXPECT_EQ(m.ny, 64);
  EXPECT_EQ(m.nz, 14);
  EXPECT_EQ(m.n_active(), 35817);  // as OPM's Python EclipseState says
  ASSERT_TRUE(m.has_mapaxes);
  EXPECT_NEAR(m.map_origin[0], 456510.608, 1e-3);
  EXPECT_NEAR(m.map_origin[1], 5926880.031, 1e-3);
  // Depths 1577-1950 m, PERMZ multiplied by 0.3 in the deck (MULTIPLY): kz/kx well below 1.
  double zmin = 1e30, zmax = -1e30, kv_kh = 0;
  int n = 0;
  for (size_t c = 0; c < m.corners.size(); ++c) {
    if (!m.actnum[c]) continue;
    for (const Vec3& p : m.corners[c]) zmin = std::min(zmin, p.z), zmax = std::max(zmax, p.z);
    if (m.permx[c] > 0) kv_kh += m.permz[c] / m.permx[c], ++n;
  }
  EXPECT_GT(zmin, 1500);
  EXPECT_LT(zmax, 2000);
  EXPECT_LT(kv_kh / n, 0.5);
  // Sloping, faulted pillars: not a rectilinear grid, refused with the cell and the reason.
  try {
    rectilinear_reservoir(m, "reservoir.grdecl");
    ADD_FAILURE() << "Reek accepted as rectilinear";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("reservoir.grdecl: cell (1, 1, 1)"), std::string::npos) << e.what();
  }
}

TEST(Grdecl, BadModelsAreInputErrorsNamingTheKey) {
  TempDir tmp;
  auto error_of = [&](const std::string& reservoir) {
    try {
      load_case(write(tmp.path / "case.yaml", "name: g\nreservoir: " + reservoir + "\n" + kGrdeclWell));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(error_of("{grdecl: NOPE.GRDECL}").rfind("reservoir.grdecl: no such file: ", 0), 0u);
  write(tmp.path / "BOX.GRDECL", grdecl_of_box(kX, kY, kZ, false));
  EXPECT_EQ(error_of("{grdecl: BOX.GRDECL, x: [0, 1]}"),
            "reservoir.x: not with reservoir.grdecl (the model gives the grid and its rock)");
  std::string no_poro = grdecl_of_box(kX, kY, kZ, false);
  no_poro = no_poro.substr(0, no_poro.find("PORO"));
  write(tmp.path / "NOPORO.GRDECL", no_poro);
  EXPECT_EQ(error_of("{grdecl: NOPORO.GRDECL}"),
            "reservoir.grdecl: the model has no active cell (ACTNUM, PORO, MINPV, PINCH)");
}
