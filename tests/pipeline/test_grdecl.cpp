// Reservoir models read with OPM (reservoir.grdecl): a Cartesian model written as GRDECL reads as
// its axes and rock and meshes to the same mesh as its box form; the Reek corner-point model reads
// with its dimensions, ACTNUM and MAPAXES, and is refused with the reason (not meshed yet).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "../exporters/flow_test_support.hpp"
#include "corner_point_test_models.hpp"
#include "exporters/eclipse/eclipse_deck.hpp"
#include "meshgen/case/grdecl.hpp"
#include "fvcheck/lib/transmissibility.hpp"
#include "meshgen/grids/corner_point_grid.hpp"
#include "meshgen/grids/corner_point_multipliers.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"
#include "meshgen/pipeline/local_frame.hpp"

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

// The same box with MULTZ 0.5 on every cell: its multipliers need faces to act on, so it is meshed as a
// corner-point model (its own cells), and the transmissibility of every vertical pair is half the box
// form's, every horizontal pair's the same (docs/corner-point.md, "Transmissibility multipliers").
TEST(Grdecl, CartesianModelWithMultipliersIsMeshedAsItsCellsAndTheyAct) {
  TempDir tmp;
  const size_t n = (kX.size() - 1) * (kY.size() - 1) * (kZ.size() - 1);
  write(tmp.path / "BOX.GRDECL", grdecl_of_box(kX, kY, kZ, false));
  write(tmp.path / "BOXM.GRDECL", grdecl_of_box(kX, kY, kZ, false) + "MULTZ\n" + std::to_string(n) + "*0.5 /\n");
  const CaseSpec plain = load_case(write(tmp.path / "a.yaml", "name: g\nreservoir: {grdecl: BOX.GRDECL}\n"));
  const CaseSpec mult = load_case(write(tmp.path / "b.yaml", "name: g\nreservoir: {grdecl: BOXM.GRDECL}\n"));
  EXPECT_FALSE(plain.reservoir.corner_point);
  ASSERT_TRUE(mult.reservoir.corner_point);
  using Pair = std::pair<std::array<int32_t, 3>, std::array<int32_t, 3>>;
  auto pair_values = [](const HybridMesh& h) {
    const Transmissibilities t = compute_transmissibilities(h.mesh, h.geometry, deck_transmissibility_options());
    std::map<Pair, double> out;
    for (int f = 0; f < h.mesh.n_faces(); ++f) {
      const int32_t o = h.mesh.face_owner[f], nb = h.mesh.face_neighbour[f];
      if (nb < 0) continue;
      Pair p{h.mesh.cell_ijk[o], h.mesh.cell_ijk[nb]};
      if (p.second < p.first) std::swap(p.first, p.second);
      out[p] += t.face[f];
    }
    return out;
  };
  const std::map<Pair, double> a = pair_values(build_hybrid_mesh(plain)), b = pair_values(build_hybrid_mesh(mult));
  ASSERT_EQ(a.size(), b.size());
  int vertical = 0;
  for (const auto& [p, t] : a) {
    ASSERT_EQ(b.count(p), 1u);
    const bool z_pair = p.first[2] != p.second[2];
    vertical += z_pair;
    EXPECT_NEAR(b.at(p) / t, z_pair ? 0.5 : 1.0, 1e-12) << p.first[0] << "," << p.first[1] << "," << p.first[2];
  }
  EXPECT_GT(vertical, 100);
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
  for (size_t c = 0; c < m.n_cells(); ++c) {
    if (!m.actnum[c]) continue;
    for (const Vec3& p : cell_corners(m, c)) zmin = std::min(zmin, p.z), zmax = std::max(zmax, p.z);
    if (m.permx[c] > 0) kv_kh += m.permz[c] / m.permx[c], ++n;
  }
  EXPECT_GT(zmin, 1500);
  EXPECT_LT(zmax, 2000);
  EXPECT_LT(kv_kh / n, 0.5);
  // Sloping, faulted pillars: not a rectilinear grid (meshed as its corner-point cells instead).
  EXPECT_FALSE(is_rectilinear(m));
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

// ---------------------------------------------------------------------------------------------
// Corner-point models: the model's cells are the mesh's reservoir cells.

namespace {

// A synthetic faulted corner-point model as a geomodeller writes it: inclined, non-parallel pillars;
// layers dipping in x and y; a fault along the pillar line i = fault_i whose throw grows from
// throw0 to throw1 along it (the -i side up, so edges of the two sides cross on the fault); layer 1
// pinching out toward +x (wedge cells, then cells of zero thickness); one inactive cell.
struct SyntheticCpg {
  int nx = 6, ny = 5, nz = 4, fault_i = 3;
  double throw0 = 8, throw1 = 12;
  double dx = 100, dy = 80;
  bool inactive_cell = true;
  bool vertical_pillars = false;  // parallel vertical pillars: every column face is planar

  double pillar_x(int I) const { return dx * I; }
  double pillar_y(int J) const { return dy * J; }
  // Depth of surface k (0 = top of layer 0) of column i at pillar (I, J).
  double surface(int i, int I, int J, int k) const {
    const double x = pillar_x(I), y = pillar_y(J);
    const double thickness[4] = {5.0, std::max(0.0, 4.0 * (1.0 - x / (0.6 * dx * nx))), 6.0, 4.0 + 0.01 * y};
    double z = 1500 + 0.08 * x + 0.03 * y;
    if (i >= fault_i) z += throw0 + (throw1 - throw0) * y / (dy * ny);
    for (int l = 0; l < k; ++l) z += thickness[l];
    return z;
  }
  std::string text() const {
    std::ostringstream o;
    o << "SPECGRID\n " << nx << " " << ny << " " << nz << " 1 F /\nCOORD\n";
    hmtest::write_pillars(o, nx, ny, 1400, 1700, [&](int I, int J) {
      const double x = pillar_x(I), y = pillar_y(J);
      return vertical_pillars ? std::array<double, 4>{x, y, x, y}
                              : std::array<double, 4>{x, y, x + 6 + 0.01 * x, y + 3 - 0.005 * y};
    });
    o << "/\nZCORN\n";
    hmtest::write_zcorn(o, nx, ny, nz, [&](int i, int I, int J, int k) { return surface(i, I, J, k); });
    const int n = nx * ny * nz;
    o << "/\nACTNUM\n";
    for (int c = 0; c < n; ++c) o << (inactive_cell && c == 1 + nx * (3 + ny * 2) ? 0 : 1) << "\n";
    o << "/\nPERMX\n";
    for (int c = 0; c < n; ++c) o << 50 + (c % 7) * 30 << "\n";
    o << "/\nPERMY\n" << n << "*120 /\nPERMZ\n" << n << "*12 /\nPORO\n" << n << "*0.22 /\n";
    return o.str();
  }
};

struct CpgRun {
  CaseSpec cs;
  HybridMesh out;
};

CpgRun mesh_of(const TempDir& tmp, const std::string& grdecl, const std::string& wells = "") {
  write(tmp.path / "CPG.GRDECL", grdecl);
  CpgRun r;
  r.cs = load_case(write(tmp.path / "cpg.yaml", "name: cpg\nreservoir: {grdecl: CPG.GRDECL}\n" + wells));
  r.out = build_hybrid_mesh(r.cs);
  return r;
}

// Sum of the mesh's cell volumes, and the model's active volume as OPM computes it.
std::pair<double, double> volumes(const CpgRun& r) {
  double mesh = 0, opm = 0;
  for (int c = 0; c < r.out.mesh.n_cells(); ++c) mesh += r.out.geometry.cell_volume[c];
  const CornerPointModel& m = *r.cs.reservoir.corner_point;
  for (size_t c = 0; c < m.actnum.size(); ++c)
    if (m.actnum[c]) opm += m.opm_volume[c];
  return {mesh, opm};
}

// Boundary faces of the mesh cut by the fault plane i = fault_i, between the pillar lines.
int64_t interior_faces_between_columns(const HybridMesh& out, int i0, int i1) {
  int64_t n = 0;
  for (int f = 0; f < out.mesh.n_faces(); ++f) {
    const int32_t o = out.mesh.face_owner[f], nb = out.mesh.face_neighbour[f];
    if (nb < 0) continue;
    const int a = out.mesh.cell_ijk[o][0], b = out.mesh.cell_ijk[nb][0];
    if ((a == i0 && b == i1) || (a == i1 && b == i0)) ++n;
  }
  return n;
}

}  // namespace

// metric: permeability is taken on a true corner-point model (meshed in the frame of K, its nodes put
// back: CornerPointWells.PermeabilityMetricMakesTheNearWellCellsKOrthogonal) and on a model of
// axis-aligned boxes, which is meshed as its axes.
TEST(CornerPoint, PermeabilityMetricIsTakenOnBothKindsOfModel) {
  TempDir tmp;
  write(tmp.path / "CPG.GRDECL", SyntheticCpg{}.text());
  write(tmp.path / "BOX.GRDECL", grdecl_of_box(kX, kY, kZ, false));
  const CaseSpec cpg = load_case(write(tmp.path / "cpg.yaml", "name: cpg\nmetric: permeability\nreservoir: {grdecl: CPG.GRDECL}\n"));
  EXPECT_TRUE(cpg.reservoir.corner_point);
  EXPECT_EQ(cpg.metric, MeshMetric::Permeability);
  const CaseSpec box = load_case(write(tmp.path / "box.yaml", "name: box\nmetric: permeability\nreservoir: {grdecl: "
                                                              "BOX.GRDECL}\n" + std::string(kGrdeclWell)));
  EXPECT_FALSE(box.reservoir.corner_point);
  EXPECT_EQ(box.metric, MeshMetric::Permeability);
}

// The synthetic faulted model meshes as its own cells: one mesh cell per active cell of non-zero
// volume, every face matched (the self-check's conformity, closure and volume checks pass: they
// would throw), the fault faces split where the two sides' edges cross, and the total volume
// equal to OPM's active volume.
TEST(CornerPoint, FaultedPinchedModelMeshesAsItsCells) {
  TempDir tmp;
  const SyntheticCpg g;
  const CpgRun r = mesh_of(tmp, g.text());
  ASSERT_TRUE(r.cs.reservoir.corner_point);
  const CornerPointModel& m = *r.cs.reservoir.corner_point;
  int zero = 0;
  for (int c = 0; c < m.nx * m.ny * m.nz; ++c) {
    if (!m.actnum[c]) continue;
    bool thick = false;
    for (int q = 0; q < 4; ++q) thick = thick || corner_depth(m, c, q) != corner_depth(m, c, q + 4);
    zero += !thick;
  }
  EXPECT_GT(zero, 0) << "the model should have fully pinched cells";
  EXPECT_EQ(r.out.mesh.n_cells(), m.n_active() - zero);
  EXPECT_TRUE(r.out.build_report.ok);
  EXPECT_TRUE(r.out.self_check.ok()) << r.out.self_check.message;
  EXPECT_TRUE(check_csr_invariants(r.out.mesh).ok);
  for (int c = 0; c < r.out.mesh.n_cells(); ++c) ASSERT_GT(r.out.geometry.cell_volume[c], 0) << c;
  const auto [mesh_volume, opm_volume] = volumes(r);
  std::printf("[ figures  ] synthetic corner-point model: %d cells, %d faces, volume %.6f m3 vs OPM %.6f m3 "
              "(rel %.2e)\n",
              r.out.mesh.n_cells(), r.out.mesh.n_faces(), mesh_volume, opm_volume, mesh_volume / opm_volume - 1);
  EXPECT_NEAR(mesh_volume / opm_volume, 1.0, 1e-6);
  // Across the fault more faces than cells of a column (the overlaps), and as many on every
  // non-faulted plane as there are cell pairs.
  const int64_t across = interior_faces_between_columns(r.out, g.fault_i - 1, g.fault_i);
  const int64_t plain = interior_faces_between_columns(r.out, 0, 1);
  EXPECT_GT(across, plain);
  bool notes_faults = false;
  for (const std::string& n : r.out.notes) notes_faults = notes_faults || n.find("fault faces") != std::string::npos;
  EXPECT_TRUE(notes_faults);
}

// Per cell, the mesh cell has the model cell's volume (OPM's EclipseGrid::getCellVolume), to the
// difference between our face surfaces (triangle fans) and OPM's: measured and bounded.
TEST(CornerPoint, CellVolumesMatchOpm) {
  TempDir tmp;
  const CpgRun r = mesh_of(tmp, SyntheticCpg{}.text());
  const CornerPointModel& m = *r.cs.reservoir.corner_point;
  double worst = 0;
  for (int c = 0; c < r.out.mesh.n_cells(); ++c) {
    const int model_cell = r.out.reservoir_cell_of[c];
    worst = std::max(worst, std::abs(r.out.geometry.cell_volume[c] / m.opm_volume[model_cell] - 1));
  }
  std::printf("[ figures  ] worst per-cell volume difference to OPM: %.2e\n", worst);
  EXPECT_LT(worst, 1e-6);
}

// The fault split conforms: without the throw's growth along the fault (a constant throw equal
// to a layer thickness stack) the sides' edges do not cross, and with it they do; both mesh.
TEST(CornerPoint, ConstantThrowHasNoCrossingsGrowingThrowHas) {
  TempDir tmp;
  SyntheticCpg g;
  g.throw0 = g.throw1 = 10;
  MeshBuilder b1, b2;
  write(tmp.path / "A.GRDECL", g.text());
  const CornerPointModel flat = read_corner_point_model((tmp.path / "A.GRDECL").string(), "k");
  const ReservoirSpec rs1 = corner_point_reservoir(std::make_shared<CornerPointModel>(flat), "k");
  const CornerPointCells c1 = add_corner_point_cells(flat, rs1, std::vector<char>(flat.actnum.size(), 1), b1);
  EXPECT_EQ(c1.crossing_nodes, 0);
  EXPECT_GT(c1.fault_faces, 0);
  const SyntheticCpg grow;
  write(tmp.path / "B.GRDECL", grow.text());
  const CornerPointModel m2 = read_corner_point_model((tmp.path / "B.GRDECL").string(), "k");
  const ReservoirSpec rs2 = corner_point_reservoir(std::make_shared<CornerPointModel>(m2), "k");
  const CornerPointCells c2 = add_corner_point_cells(m2, rs2, std::vector<char>(m2.actnum.size(), 1), b2);
  EXPECT_GT(c2.crossing_nodes, 0);
  BuildReport rep1, rep2;
  b1.finish(&rep1);
  b2.finish(&rep2);
  EXPECT_TRUE(rep1.ok);
  EXPECT_TRUE(rep2.ok);
}

namespace {

using Pt = std::array<double, 2>;

double polygon_area(const std::vector<Pt>& p) {
  double a = 0;
  for (size_t i = 0; i < p.size(); ++i) a += p[i][0] * p[(i + 1) % p.size()][1] - p[i][1] * p[(i + 1) % p.size()][0];
  return 0.5 * a;
}

// Sutherland-Hodgman: convex polygon p clipped by convex counter-clockwise polygon q.
std::vector<Pt> clip(std::vector<Pt> p, const std::vector<Pt>& q) {
  for (size_t e = 0; e < q.size() && !p.empty(); ++e) {
    const Pt a = q[e], b = q[(e + 1) % q.size()];
    auto side = [&](const Pt& x) { return (b[0] - a[0]) * (x[1] - a[1]) - (b[1] - a[1]) * (x[0] - a[0]); };
    std::vector<Pt> out;
    for (size_t i = 0; i < p.size(); ++i) {
      const Pt u = p[i], v = p[(i + 1) % p.size()];
      const double su = side(u), sv = side(v);
      if (su >= 0) out.push_back(u);
      if ((su >= 0) != (sv >= 0)) {
        const double t = su / (su - sv);
        out.push_back({u[0] + t * (v[0] - u[0]), u[1] + t * (v[1] - u[1])});
      }
    }
    p = std::move(out);
  }
  return p;
}

}  // namespace

// With vertical pillars the faces on the fault plane are planar quads in (y, z): the mesh's faces
// between two cells of the two sides have, together, exactly the area of the two quads' intersection
// computed independently (polygon clipping), and a pair shares faces exactly when that area is > 0.
TEST(CornerPoint, FaultFacesAreTheOverlapsOfTheTwoCellsFaces) {
  TempDir tmp;
  SyntheticCpg g;
  g.vertical_pillars = true;
  g.throw0 = 3;  // throws of 3..17 m along the fault: edges of the two sides cross on it
  g.throw1 = 17;
  const CpgRun r = mesh_of(tmp, g.text());
  const CornerPointModel& m = *r.cs.reservoir.corner_point;
  std::map<std::pair<int, int>, double> mesh_area;
  for (int f = 0; f < r.out.mesh.n_faces(); ++f) {
    if (r.out.mesh.face_neighbour[f] < 0) continue;
    int a = r.out.reservoir_cell_of[r.out.mesh.face_owner[f]], b = r.out.reservoir_cell_of[r.out.mesh.face_neighbour[f]];
    if (a % m.nx == g.fault_i) std::swap(a, b);  // a on the -i side
    if (a % m.nx == g.fault_i - 1 && b % m.nx == g.fault_i) mesh_area[{a, b}] += norm(r.out.geometry.face_area[f]);
  }
  // A cell's face on the plane x = fault_i * dx, counter-clockwise in (y, z).
  auto quad = [&](int c, bool plus_i) {
    const int j = (c / m.nx) % m.ny;
    const double y0 = g.pillar_y(j), y1 = g.pillar_y(j + 1);
    const int o = plus_i ? 1 : 0;
    std::vector<Pt> q{{y0, corner_depth(m, c, o)}, {y1, corner_depth(m, c, o + 2)}, {y1, corner_depth(m, c, o + 6)}, {y0, corner_depth(m, c, o + 4)}};
    if (polygon_area(q) < 0) std::reverse(q.begin(), q.end());
    return q;
  };
  auto meshed = [&](int c) { return m.actnum[c] && corner_depth(m, c, 0) + corner_depth(m, c, 1) + corner_depth(m, c, 2) + corner_depth(m, c, 3) <
                                                       corner_depth(m, c, 4) + corner_depth(m, c, 5) + corner_depth(m, c, 6) + corner_depth(m, c, 7); };
  int pairs = 0, crossing_pairs = 0;
  double worst = 0;
  for (int j = 0; j < m.ny; ++j)
    for (int ka = 0; ka < m.nz; ++ka)
      for (int kb = 0; kb < m.nz; ++kb) {
        const int a = g.fault_i - 1 + m.nx * (j + m.ny * ka), b = g.fault_i + m.nx * (j + m.ny * kb);
        if (!meshed(a) || !meshed(b)) continue;
        const double want = std::abs(polygon_area(clip(quad(a, true), quad(b, false))));
        const auto it = mesh_area.find({a, b});
        const double got = it == mesh_area.end() ? 0.0 : it->second;
        if (want < 1e-9 * 400) {
          EXPECT_EQ(got, 0.0) << "cells " << a << ", " << b << " share " << got << " m2, the overlap is " << want;
          continue;
        }
        ++pairs;
        crossing_pairs += clip(quad(a, true), quad(b, false)).size() > 4;
        ASSERT_GT(got, 0) << "cells " << a << " and " << b << " overlap by " << want << " m2 but share no face";
        worst = std::max(worst, std::abs(got / want - 1));
      }
  std::printf("[ figures  ] %d overlapping pairs across the fault (%d with more than 4 vertices), worst area %.2e\n",
              pairs, crossing_pairs, worst);
  EXPECT_GT(pairs, 20);
  EXPECT_GT(crossing_pairs, 0);
  EXPECT_LT(worst, 1e-9);
}

// A fault whose throw is a whole layer: both sides' layer boundaries are one depth, written with a
// rounding (1000 + dz k + throw against 1000 + dz (k + 1)). As read they are up to a few ulps apart and
// the fault's faces overlapped by 1e-13 m slivers, with nodes the self-check finds hanging (the
// horizontal sweep's seeds 9 and 15, session 28); made one, the two sides meet face to face.
TEST(CornerPoint, DepthsEqualUpToARoundingAreOneNode) {
  TempDir tmp;
  hmtest::LayeredModel g;
  g.nx = 6, g.ny = 4, g.nz = 10, g.dx = g.dy = 107.4, g.dz = 1.95, g.dip_deg = 6.5, g.fault_i = 3, g.throw_m = g.dz;
  write(tmp.path / "CPG.GRDECL", g.text());
  const CornerPointModel as_read = read_corner_point_model((tmp.path / "CPG.GRDECL").string(), "reservoir.grdecl");
  // Depth pairs across the fault's pillars that are one number but for a rounding.
  auto rounded_pairs = [&](const CornerPointModel& m) {
    int n = 0;
    for (int j = 0; j < m.ny; ++j)
      for (int k = 0; k + 1 < m.nz; ++k)
        for (int b : {0, 2}) {
          const double left = m.zcorn[zcorn_index(m, g.fault_i - 1, j, k + 1, 1 | b)];
          const double right = m.zcorn[zcorn_index(m, g.fault_i, j, k, b)];
          n += left != right && std::abs(left - right) <= 8 * std::numeric_limits<double>::epsilon() * left;
        }
    return n;
  };
  ASSERT_GT(rounded_pairs(as_read), 0) << "the model no longer has rounded depths: the test tests nothing";
  CornerPointModel merged = as_read;
  EXPECT_GT(merge_rounded_depths(merged), 0);
  EXPECT_EQ(rounded_pairs(merged), 0);
  EXPECT_EQ(merge_rounded_depths(merged), 0);  // idempotent
  // The model as read fails the conformity check; as load_case gives it (merged), the mesh is sound.
  const CpgRun r = mesh_of(tmp, g.text());
  EXPECT_TRUE(check_conformity(r.out.mesh, r.out.geometry).ok());
  const auto [mesh_volume, opm_volume] = volumes(r);
  EXPECT_NEAR(mesh_volume / opm_volume, 1.0, 1e-9);
  CaseSpec raw = r.cs;
  raw.reservoir.corner_point = std::make_shared<const CornerPointModel>(as_read);
  try {
    build_hybrid_mesh(raw);
    ADD_FAILURE() << "the model as read meshed soundly: the test tests nothing";
  } catch (const std::exception& e) {
    std::printf("[ figures  ] %d rounded depth pairs across the fault; as read: %s\n", rounded_pairs(as_read), e.what());
    EXPECT_NE(std::string(e.what()).find("conformity"), std::string::npos) << e.what();
  }
}

// The mesh does not depend on where the model sits: moved by UTM-sized offsets, the same cells
// with the same volumes (to round-off of the larger coordinates).
TEST(CornerPoint, TranslatedModelMeshesToTheSameCells) {
  TempDir tmp;
  const CpgRun r = mesh_of(tmp, SyntheticCpg{}.text());
  CaseSpec moved = r.cs;
  moved.reservoir.corner_point =
      std::make_shared<const CornerPointModel>(translated_model(*r.cs.reservoir.corner_point, {456000, 5926000, 0}));
  const HybridMesh out = build_hybrid_mesh(moved);
  ASSERT_EQ(out.mesh.n_cells(), r.out.mesh.n_cells());
  ASSERT_EQ(out.mesh.n_faces(), r.out.mesh.n_faces());
  EXPECT_EQ(out.mesh.face_nodes, r.out.mesh.face_nodes);
  for (int c = 0; c < out.mesh.n_cells(); ++c)
    ASSERT_NEAR(out.geometry.cell_volume[c] / r.out.geometry.cell_volume[c], 1.0, 1e-9) << c;
}

// meshgen meshes a field model in its local frame holding it once (build_hybrid_mesh_in_local_frame):
// the user's copy is released and made again from the local one, so it must come back bit for bit,
// and a shift that does not round-trip must keep the user's copy itself. Both meshes are the local
// frame's.
TEST(CornerPoint, MeshingInTheLocalFrameGivesTheUsersModelBackBitForBit) {
  TempDir tmp;
  const CpgRun r = mesh_of(tmp, SyntheticCpg{}.text());
  auto same_bits = [](const std::vector<double>& a, const std::vector<double>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
  };
  int released = 0, kept = 0;
  for (const Vec3 shift : {Vec3{456000, 5926000, 0}, Vec3{0.1, 0.3, 0}}) {
    CaseSpec field = translated_case(r.cs, shift);
    const CornerPointModel given = *field.reservoir.corner_point;  // a deep copy to compare with
    const CornerPointModel* const users = field.reservoir.corner_point.get();
    const bool round_trips = translation_round_trips(given, -1.0 * case_origin(field));
    (round_trips ? released : kept) += 1;
    const HybridMesh h = build_hybrid_mesh_in_local_frame(field);
    const CornerPointModel& back = *field.reservoir.corner_point;
    if (!round_trips) {
      EXPECT_EQ(&back, users) << "a model that does not round-trip was copied back";
    }
    EXPECT_TRUE(same_bits(back.coord, given.coord)) << shift.x;
    EXPECT_TRUE(same_bits(back.zcorn, given.zcorn)) << shift.x;
    // and so the corners, computed from them
    EXPECT_TRUE(back.nx == given.nx && back.ny == given.ny && back.nz == given.nz) << shift.x;
    EXPECT_TRUE(same_bits(back.permx, given.permx) && same_bits(back.poro, given.poro));
    EXPECT_EQ(back.actnum, given.actnum);
    ASSERT_EQ(h.mesh.n_cells(), r.out.mesh.n_cells()) << shift.x;
    EXPECT_EQ(h.mesh.face_nodes, r.out.mesh.face_nodes) << shift.x;
    // The self-check judged the coordinates the files get: every node is where the written one
    // comes back to in the local frame (round_to_written_frame; exactly so where the origin
    // round-trips).
    if (round_trips) {
      const Vec3 origin = case_origin(field);
      int64_t off_grid = 0;
      for (const Vec3& p : h.mesh.nodes) off_grid += !((p + origin) - origin == p);
      EXPECT_EQ(off_grid, 0) << shift.x;
    }
  }
  EXPECT_EQ(released, 1) << "UTM offsets should round-trip: the release is not tested";
  EXPECT_EQ(kept, 1) << "offsets of 0.1 m should not round-trip on every value: the fallback is not tested";
}

// Bad geometry and wells: input errors naming the key and the reason (exit 2).
TEST(CornerPoint, InvertedCellAndWellsAreRefusedWithTheReason) {
  TempDir tmp;
  // OPM's EclipseGrid makes ZCORN monotone down each pillar (as flow does), so a deck's inverted
  // corner reaches us repaired; the check guards the model we mesh: a cell turned inside out on one
  // pillar, and a cell reaching into the one below, are refused with the cell named (1-based).
  write(tmp.path / "CPG.GRDECL", SyntheticCpg{}.text());
  CornerPointModel m = read_corner_point_model((tmp.path / "CPG.GRDECL").string(), "reservoir.grdecl");
  EXPECT_NO_THROW(check_corner_point_geometry(m, "reservoir.grdecl"));
  const int c = 1 + m.nx * (2 + m.ny * 2);  // cell (2, 3, 3)
  {
    CornerPointModel bad = m;
    std::swap(bad.zcorn[zcorn_index(bad, 1, 2, 2, 3)], bad.zcorn[zcorn_index(bad, 1, 2, 2, 7)]);
    try {
      check_corner_point_geometry(bad, "reservoir.grdecl");
      ADD_FAILURE() << "an inverted cell was accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("reservoir.grdecl: cell (2, 3, 3): its top corner lies below", 0), 0u) << e.what();
    }
  }
  {
    CornerPointModel bad = m;
    bad.zcorn[zcorn_index(bad, 1, 2, 1, 7)] = corner_depth(bad, c, 7) - 0.5;  // bottom of (2, 3, 2) into (2, 3, 3)
    try {
      check_corner_point_geometry(bad, "reservoir.grdecl");
      ADD_FAILURE() << "overlapping cells were accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("overlaps the active cell above it"), std::string::npos) << e.what();
    }
  }
  write(tmp.path / "CPG.GRDECL", SyntheticCpg{}.text());
  // A path inside the model 2 m under its dipping top: the block (R = 5 m) would cross the top. Its ends
  // are moved back as a crossing path's are (docs/corner-point.md), and none of it keeps the gap.
  try {
    load_case(write(tmp.path / "w.yaml",
                    "name: w\nreservoir: {grdecl: CPG.GRDECL}\nwells:\n  - {name: P1, trajectory: "
                    "[[230, 200, 1526.4], [270, 200, 1529.6]], radius: 0.1, drainage_radius: 5, bhp: 150}\n"));
    ADD_FAILURE() << "a well block through the top of a corner-point model was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("wells[0].trajectory: only 0 m of its", 0), 0u) << what;
    EXPECT_NE(what.find("from the model's surface"), std::string::npos) << what;
  }
  // Ends deep enough, the middle 2 m under the top: the block crosses it there.
  const CaseSpec cs = load_case(write(tmp.path / "v.yaml",
                                      "name: v\nreservoir: {grdecl: CPG.GRDECL}\nwells:\n  - {name: P1, trajectory: "
                                      "[[200, 200, 1531], [240, 200, 1527.2], [280, 200, 1537.4]], radius: 0.1, "
                                      "drainage_radius: 5, end_caps: flat, bhp: 150}\n"));
  ASSERT_TRUE(cs.notes.empty()) << "the path was cut: " << cs.notes.front();
  try {
    build_hybrid_mesh(cs);
    ADD_FAILURE() << "a well block through the top of a corner-point model was meshed";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("reaches outside the meshed cells of the corner-point model"), std::string::npos)
        << e.what();
  }
}

// Reek (40 x 64 x 14, faults, 35817 active cells) meshes as its cells without wells: the
// self-check passes (it would throw), the total volume is OPM's active volume and each cell's volume
// is its OPM volume to the fault faces' geometry (docs/mesh-layout.md, "Corner-point reservoir cells").
TEST(CornerPoint, ReekMeshesAsItsCells) {
  if (!fs::exists(reek_deck())) GTEST_SKIP() << "no " << reek_deck();
  CpgRun r;
  r.cs = parse_case("name: reek\nreservoir: {grdecl: " + reek_deck().string() + "}\n");
  r.out = build_hybrid_mesh(r.cs);
  EXPECT_TRUE(r.out.self_check.ok()) << r.out.self_check.message;
  EXPECT_EQ(r.out.mesh.n_cells(), r.cs.reservoir.corner_point->n_active());
  const auto [mesh_volume, opm_volume] = volumes(r);
  const CornerPointModel& m = *r.cs.reservoir.corner_point;
  double worst = 0;
  int above_0p1_percent = 0;
  for (int c = 0; c < r.out.mesh.n_cells(); ++c) {
    const double e = std::abs(r.out.geometry.cell_volume[c] / m.opm_volume[r.out.reservoir_cell_of[c]] - 1);
    worst = std::max(worst, e);
    above_0p1_percent += e > 1e-3;
  }
  for (const std::string& n : r.out.notes) std::printf("[ note     ] %s\n", n.c_str());
  std::printf("[ figures  ] Reek: %d cells, %d faces, volume %.9e m3 vs OPM %.9e m3 (rel %.2e); per cell worst %.2e, "
              "%d cells above 1e-3\n",
              r.out.mesh.n_cells(), r.out.mesh.n_faces(), mesh_volume, opm_volume, mesh_volume / opm_volume - 1, worst,
              above_0p1_percent);
  EXPECT_NEAR(mesh_volume / opm_volume, 1.0, 1e-5);
  EXPECT_LT(worst, 0.02);
}

// The exported deck is the model: OPM Flow reads the model's COORD/ZCORN and computes its own
// connections (fault NNCs included). Every cell pair flow connects is a pair of mesh cells sharing a
// face, and every face-sharing pair is connected by flow except across a layer of zero thickness,
// which OPM connects only with PINCH (the mesh's cells touch there).
namespace {

// Writes the deck of r and reads it back with OPM: the same COORD and ZCORN (bit for bit), ACTNUM 1
// exactly on the mesh's cells, their rock, and OPM's multipliers as the model had them.
void expect_deck_is_the_model(const CpgRun& r, const fs::path& deck, const std::string& name) {
  const Transmissibilities trans = compute_transmissibilities(r.out.mesh, r.out.geometry);
  ASSERT_TRUE(write_eclipse_deck(deck.string(), r.cs, r.out.mesh, r.out.geometry, trans).ok);
  const CornerPointModel& m = *r.cs.reservoir.corner_point;
  const CornerPointModel back = read_corner_point_model((deck / (name + ".DATA")).string(), "deck");
  ASSERT_EQ(back.nx, m.nx);
  ASSERT_EQ(back.ny, m.ny);
  ASSERT_EQ(back.nz, m.nz);
  EXPECT_TRUE(back.coord == m.coord);
  EXPECT_TRUE(back.zcorn == m.zcorn);
  std::vector<int> meshed(m.actnum.size(), 0);
  for (int c = 0; c < r.out.mesh.n_cells(); ++c) meshed[r.out.reservoir_cell_of[c]] = 1;
  EXPECT_TRUE(back.actnum == meshed);
  for (int c = 0; c < r.out.mesh.n_cells(); ++c) {
    const int g = r.out.reservoir_cell_of[c];
    ASSERT_NEAR(back.permx[g], r.out.mesh.cell_perm[c].x, 1e-9 * r.out.mesh.cell_perm[c].x) << g;
    ASSERT_NEAR(back.poro[g] * back.ntg[g], r.out.mesh.cell_porosity[c], 1e-12) << g;
    for (int d = 0; d < 6; ++d) ASSERT_EQ(back.trans_mult[d][g], m.trans_mult[d][g]) << g << " direction " << d;
  }
}

}  // namespace

TEST(CornerPoint, ExportedDeckIsTheModel) {
  TempDir tmp;
  expect_deck_is_the_model(mesh_of(tmp, SyntheticCpg{}.text()), tmp.path / "deck", "CPG");
  if (!fs::exists(reek_deck())) GTEST_SKIP() << "no " << reek_deck();
  CpgRun r;
  r.cs = parse_case("name: reek\nreservoir: {grdecl: " + reek_deck().string() + "}\n");
  r.out = build_hybrid_mesh(r.cs);
  int faulted = 0;  // Reek's FAULTS/MULTFLT and MULTZ reach the multipliers
  for (int d = 0; d < 6; ++d)
    for (double v : r.cs.reservoir.corner_point->trans_mult[d]) faulted += v != 1.0;
  EXPECT_GT(faulted, 0);
  expect_deck_is_the_model(r, tmp.path / "reek", "REEK");
}

namespace {

struct FlowPairs {
  std::set<std::pair<int, int>> mesh, flow;
  std::map<std::pair<int, int>, double> flow_value, ours;  ///< flow's INIT value, ours (deck options), per pair
};

// Exports the deck of r, runs flow as typed and collects the cell pairs (natural indices) that share a
// mesh face carrying flow (a multiplier not 0) and that flow connects (INIT TRANX/Y/Z > 0: TRANZ to the
// next active cell down the column, which PINCH connects across layers of zero thickness; TRANNNC > 0).
FlowPairs flow_and_mesh_pairs(const CpgRun& r, const fs::path& deck, const std::string& name) {
  FlowPairs out;
  const Transmissibilities trans = compute_transmissibilities(r.out.mesh, r.out.geometry);
  const Transmissibilities deck_trans =
      compute_transmissibilities(r.out.mesh, r.out.geometry, deck_transmissibility_options());
  EclipseDeckInfo info;
  const WriteStatus st = write_eclipse_deck(deck.string(), r.cs, r.out.mesh, r.out.geometry, trans, {}, &info);
  EXPECT_TRUE(st.ok) << st.message;
  EXPECT_NE(hmtest::read_text(deck / (name + "_GRID.INC")).find("ZCORN"), std::string::npos);
  const hmtest::FlowRun run = hmtest::run_flow(deck, name);
  EXPECT_EQ(run.flow.exit_code, 0) << run.flow.output.substr(0, 2000);
  if (run.flow.exit_code != 0 || run.results.is_null()) return out;
  std::printf("[ figures  ] flow ran %s in %.1f s wall\n", name.c_str(), run.seconds);
  const CornerPointModel& m = *r.cs.reservoir.corner_point;
  const int nx = m.nx, nxy = m.nx * m.ny;
  const std::vector<double>& mult = r.out.mesh.face_trans_mult;
  for (int f = 0; f < r.out.mesh.n_faces(); ++f)
    if (r.out.mesh.face_neighbour[f] >= 0 && (mult.empty() || mult[f] != 0)) {
      const int a = r.out.reservoir_cell_of[r.out.mesh.face_owner[f]], b = r.out.reservoir_cell_of[r.out.mesh.face_neighbour[f]];
      out.mesh.insert({std::min(a, b), std::max(a, b)});
      out.ours[{std::min(a, b), std::max(a, b)}] += deck_trans.face[f];
    }
  std::vector<int> active;
  std::vector<char> is_active(info.layout.deck_cell.size(), 0);
  for (size_t c = 0; c < info.layout.deck_cell.size(); ++c)
    if (info.layout.deck_cell[c] >= 0) active.push_back(static_cast<int>(c)), is_active[c] = 1;
  const auto& init = run.results["init"];
  const char* keys[3] = {"tranx", "trany", "tranz"};
  const int step[3] = {1, nx, nxy};
  for (int d = 0; d < 3; ++d) {
    EXPECT_EQ(init[keys[d]].size(), active.size());
    for (size_t a = 0; a < active.size() && a < init[keys[d]].size(); ++a) {
      const double v = init[keys[d]][a].get<double>();
      if (!(v > 0)) continue;
      int b = active[a] + step[d];
      while (d == 2 && b < static_cast<int>(is_active.size()) && !is_active[b]) b += step[d];
      out.flow.insert({active[a], b});
      out.flow_value[{active[a], b}] += v;
    }
  }
  for (size_t k = 0; k < init["trannnc"].size(); ++k)
    if (init["trannnc"][k].get<double>() > 0) {
      const int a = init["nnc1"][k].get<int>() - 1, b = init["nnc2"][k].get<int>() - 1;
      out.flow.insert({std::min(a, b), std::max(a, b)});
      out.flow_value[{std::min(a, b), std::max(a, b)}] += init["trannnc"][k].get<double>();
    }
  return out;
}

// The pairs of one column the mesh joins across layers of zero thickness (natural indices).
std::set<std::pair<int, int>> pinch_pairs(const CpgRun& r) {
  std::set<std::pair<int, int>> out;
  const CornerPointModel& m = *r.cs.reservoir.corner_point;
  for (int f = 0; f < r.out.mesh.n_faces(); ++f)
    if (r.out.mesh.face_neighbour[f] >= 0) {
      const int a = r.out.reservoir_cell_of[r.out.mesh.face_owner[f]], b = r.out.reservoir_cell_of[r.out.mesh.face_neighbour[f]];
      if (across_pinched_layers(m, a, b)) out.insert({std::min(a, b), std::max(a, b)});
    }
  return out;
}

}  // namespace

// The exported deck is the model: OPM Flow reads the model's COORD/ZCORN and computes its own
// connections (fault NNCs included). The cell pairs flow connects are exactly the pairs of mesh cells
// sharing a face that carries flow: across the layer of zero thickness (the mesh's cells touch there)
// only with PINCH, which the deck then carries; there flow's transmissibility is ours.
TEST(CornerPoint, FlowConnectsExactlyTheCellsTheMeshJoins) {
  REQUIRE_FLOW();
  const SyntheticCpg g;
  std::ostringstream multz;  // 0.8 on layer 0, 0.5 on the pinching layer 1: MULTZ option ALL takes 0.5 across it
  multz << "MULTZ\n";
  for (int c = 0; c < g.nx * g.ny * g.nz; ++c) multz << (c / (g.nx * g.ny) == 0 ? 0.8 : c / (g.nx * g.ny) == 1 ? 0.5 : 1.0) << "\n";
  multz << "/\n";
  for (const int variant : {0, 1, 2}) {  // no PINCH; PINCH; PINCH with MULTZ option ALL and MULTZ
    const bool pinch = variant > 0;
    TempDir tmp;
    const std::string pinch_kw = variant == 1 ? "PINCH\n 0.4 NOGAP 1* TOPBOT TOP /\n" : variant == 2 ? "PINCH\n 1* GAP 1* TOPBOT ALL /\n" : "";
    const CpgRun r = mesh_of(tmp, pinch_kw + g.text() + (variant == 2 ? multz.str() : ""));
    const FlowPairs p = flow_and_mesh_pairs(r, tmp.path / "deck", "CPG");
    const std::set<std::pair<int, int>> across = pinch_pairs(r);
    EXPECT_EQ(across.size(), 10u);
    for (const auto& pair : across) EXPECT_EQ(p.mesh.count(pair), pinch ? 1u : 0u) << pair.first << " " << pair.second;
    for (const auto& pair : p.mesh) EXPECT_TRUE(p.flow.count(pair)) << "flow does not connect " << pair.first << " " << pair.second;
    for (const auto& pair : p.flow) EXPECT_TRUE(p.mesh.count(pair)) << "flow connects " << pair.first << " " << pair.second;
    double worst = 0;  // flow's float32 INIT and its Darcy constant against ours (docs/export-eclipse.md)
    for (const auto& pair : across)
      if (p.flow_value.count(pair)) worst = std::max(worst, std::abs(p.ours.at(pair) / p.flow_value.at(pair) - 1));
    std::printf("[ figures  ] %s: flow connects %zu cell pairs, the mesh %zu (%zu across the pinched-out layer, %s); "
                "there ours vs flow's at most %.2e\n",
                variant == 0 ? "no PINCH" : variant == 1 ? "PINCH" : "PINCH, MULTZ option ALL", p.flow.size(), p.mesh.size(), across.size(),
                pinch ? "connected" : "no flow", worst);
    EXPECT_LT(worst, 1e-6);
    EXPECT_GT(p.flow.size(), 200u);
  }
}

// MINPV removes the active cells whose OPM pore volume is below it, as OPM Flow does (opm_minpv, a port of
// opm-grid's MinpvProcessor): they are inactive in the model and not cells of the mesh, whose volume is
// the rest's; a note says how many and how many connections flow makes across them. Without MINPV none.
TEST(CornerPoint, CellsBelowMinpvAreRemovedAndNoted) {
  for (const double minpv : {0.0, 3000.0}) {
    TempDir tmp;
    const std::string text = (minpv > 0 ? "MINPV\n " + num(minpv) + " /\n" : std::string()) + SyntheticCpg{}.text();
    const CpgRun plain = mesh_of(tmp, SyntheticCpg{}.text());
    const CpgRun r = mesh_of(tmp, text);
    const CornerPointModel &m = *r.cs.reservoir.corner_point, &p = *plain.cs.reservoir.corner_point;
    std::set<int64_t> expected;
    for (size_t c = 0; c < p.actnum.size(); ++c)
      if (p.actnum[c] && p.opm_volume[c] * p.poro[c] * p.ntg[c] < minpv) expected.insert(static_cast<int64_t>(c));
    EXPECT_EQ(m.below_minpv, static_cast<int64_t>(expected.size())) << minpv;
    EXPECT_EQ(std::set<int64_t>(m.minpv_removed.begin(), m.minpv_removed.end()), expected);
    double removed_volume = 0;
    for (const int64_t c : expected) {
      EXPECT_EQ(m.actnum[static_cast<size_t>(c)], 0) << c;
      removed_volume += p.opm_volume[static_cast<size_t>(c)];
    }
    for (int c = 0; c < r.out.mesh.n_cells(); ++c) {
      const auto& ijk = r.out.mesh.cell_ijk[c];
      EXPECT_EQ(expected.count(ijk[0] + int64_t(m.nx) * (ijk[1] + int64_t(m.ny) * ijk[2])), 0u) << c;
    }
    // The mesh's volume is the plain model's less the removed cells' (OPM's volumes of the same cells).
    const double v = total_volume(r.out.geometry), v0 = total_volume(plain.out.geometry);
    EXPECT_NEAR(v, v0 - removed_volume, 1e-9 * v0);
    bool noted = false;
    for (const std::string& note : r.out.notes) noted = noted || note.find("below the model's MINPV") != std::string::npos;
    EXPECT_EQ(noted, !expected.empty()) << minpv;
    if (minpv > 0) {
      EXPECT_FALSE(expected.empty());
    }
    std::printf("[ figures  ] MINPV %g: %lld active cells removed (%.4g rm3 of %.6g), %zu connections across them, "
                "%d connections without a face in the mesh; volume %.6f = %.6f - %.6f\n",
                minpv, static_cast<long long>(m.below_minpv), m.below_minpv_pore_volume, m.active_pore_volume,
                m.minpv_connections.size(), r.out.mesh.n_nncs(), v, v0, removed_volume);
  }
}

// The connections MINPV makes across its removed cells on the faulted model whose layer 1 pinches out
// (wedge cells, some touching the cells above and below where they have no thickness): flow, given the
// model with MINPV as a user gives it, removes the same cells and connects each upper cell to the cell
// below the gap with our connection's transmissibility (its INIT TRANZ), to 1e-6.
TEST(CornerPoint, MinpvConnectionsAreFlowsOnAFaultedPinchingModel) {
  REQUIRE_FLOW();
  TempDir tmp;
  const CpgRun plain = mesh_of(tmp, SyntheticCpg{}.text());
  {
    const Transmissibilities t = compute_transmissibilities(plain.out.mesh, plain.out.geometry, deck_transmissibility_options());
    const WriteStatus st = write_eclipse_deck((tmp.path / "user").string(), plain.cs, plain.out.mesh, plain.out.geometry, t, {}, nullptr);
    ASSERT_TRUE(st.ok) << st.message;
    std::ofstream(tmp.path / "user" / "CPG_GRID.INC", std::ios::app) << "\nMINPV\n 3000 /\n";
  }
  const hmtest::FlowRun run = hmtest::run_flow(tmp.path / "user", "CPG");
  ASSERT_EQ(run.flow.exit_code, 0) << run.flow.output.substr(0, 2000);
  ASSERT_FALSE(run.results.is_null());
  const CpgRun r = mesh_of(tmp, "MINPV\n 3000 /\n" + SyntheticCpg{}.text());
  const CornerPointModel& m = *r.cs.reservoir.corner_point;
  const auto& porv = run.results["init"]["porv"];
  const auto& tranz = run.results["init"]["tranz"];
  ASSERT_EQ(porv.size(), m.actnum.size());
  std::vector<int64_t> active_index(m.actnum.size(), -1);
  int64_t a = 0;
  for (size_t c = 0; c < m.actnum.size(); ++c)
    if (porv[c].get<double>() > 0) active_index[c] = a++;
  for (size_t c = 0; c < m.actnum.size(); ++c) EXPECT_EQ(active_index[c] >= 0, m.actnum[c] != 0) << c;
  ASSERT_EQ(r.out.mesh.n_nncs(), static_cast<int>(m.minpv_connections.size()));
  double worst = 0;
  for (int k = 0; k < r.out.mesh.n_nncs(); ++k) {
    const auto& u = r.out.mesh.cell_ijk[r.out.mesh.nnc_cells[k][0]];
    const int64_t upper = u[0] + int64_t(m.nx) * (u[1] + int64_t(m.ny) * u[2]);
    ASSERT_GE(active_index[upper], 0);
    const double theirs = tranz[active_index[upper]].get<double>();
    if (std::getenv("HM_DEBUG_MINPV"))
      std::printf("upper (%d,%d,%d) lower k %d: ours %.9g flow %.9g; between: volume %.9g\n", u[0], u[1], u[2],
                  r.out.mesh.cell_ijk[r.out.mesh.nnc_cells[k][1]][2], r.out.mesh.nnc_trans[k], theirs,
                  m.opm_volume[static_cast<size_t>(upper + m.nx * m.ny)]);
    worst = std::max(worst, std::abs(r.out.mesh.nnc_trans[k] - theirs) / theirs);
  }
  // And flow connects no other pair across removed cells (its TRANZ to the next active cell below a gap).
  std::set<int64_t> ours_upper;
  for (int k = 0; k < r.out.mesh.n_nncs(); ++k) {
    const auto& u = r.out.mesh.cell_ijk[r.out.mesh.nnc_cells[k][0]];
    ours_upper.insert(u[0] + int64_t(m.nx) * (u[1] + int64_t(m.ny) * u[2]));
  }
  const int64_t nxy = int64_t(m.nx) * m.ny;
  int flow_across = 0;
  for (int64_t c = 0; c + nxy < static_cast<int64_t>(m.actnum.size()); ++c) {
    if (active_index[c] < 0 || !(tranz[active_index[c]].get<double>() > 0) || active_index[c + nxy] >= 0) continue;
    ++flow_across;
    EXPECT_EQ(ours_upper.count(c), 1u) << "flow connects cell " << c << " across removed cells, the mesh does not";
  }
  EXPECT_EQ(flow_across, r.out.mesh.n_nncs());
  std::printf("[ figures  ] MINPV 3000 on the faulted, pinching model: %lld cells removed (flow: the same), %d "
              "connections across them (flow: %d), ours vs flow's TRANZ max rel %.3g\n",
              static_cast<long long>(m.below_minpv), r.out.mesh.n_nncs(), flow_across, worst);
  EXPECT_GT(r.out.mesh.n_nncs(), 0);
  EXPECT_LT(worst, 1e-6);
}

// MULTPV (OPM's pore volume other than volume x PORO x NTG, the mesh's porosity): the cells are counted and
// named in a note, and carried as the cells' pore-volume multiplier, so that the mesh's pore volume is
// OPM's; without MULTPV no note and no multiplier (the same doubles: no rounding counted).
TEST(CornerPoint, PoreVolumesOtherThanTheRocksAreCarried) {
  const SyntheticCpg g;
  const int n = g.nx * g.ny * g.nz;
  for (const bool multpv : {false, true}) {
    TempDir tmp;
    std::ostringstream text;
    text << g.text();
    if (multpv) {
      text << "MULTPV\n";
      for (int c = 0; c < n; ++c) text << (c % 10 == 0 ? 2.5 : 1.0) << "\n";
      text << "/\n";
    }
    const CpgRun r = mesh_of(tmp, text.str());
    const CornerPointModel& m = *r.cs.reservoir.corner_point;
    int64_t expected = 0;
    for (int c = 0; c < n; ++c) expected += multpv && c % 10 == 0 && m.actnum[c] && m.opm_volume[c] > 0;
    EXPECT_EQ(m.other_pore_volume, expected);
    if (multpv) {
      EXPECT_GT(expected, 0);
      EXPECT_NEAR(m.other_pore_volume_opm / m.other_pore_volume_ours, 2.5, 1e-12);
    }
    bool noted = false;
    for (const std::string& note : r.out.notes) noted = noted || note.find("other than volume x PORO x NTG") != std::string::npos;
    EXPECT_EQ(noted, multpv);
    // The multiplier per cell, and the mesh's pore volume against OPM's (as its volume against OPM's).
    EXPECT_EQ(m.pore_volume_mult.empty(), !multpv);
    const PolyMesh& mesh = r.out.mesh;
    EXPECT_EQ(mesh.cell_pore_volume_mult.empty(), !multpv);
    double pv = 0, pv_rock_only = 0;
    for (int c = 0; c < mesh.n_cells(); ++c) {
      const auto& ijk = mesh.cell_ijk[c];
      const int cell = ijk[0] + g.nx * (ijk[1] + g.ny * ijk[2]);
      const double want = multpv && cell % 10 == 0 && m.opm_volume[cell] > 0 ? 2.5 : 1.0;
      EXPECT_NEAR(mesh.pore_volume_mult(c), want, 1e-12 * want) << cell;
      pv += r.out.geometry.cell_volume[c] * mesh.cell_porosity[c] * mesh.pore_volume_mult(c);
      pv_rock_only += r.out.geometry.cell_volume[c] * mesh.cell_porosity[c];
    }
    const auto [mesh_volume, opm_volume] = volumes(r);
    std::printf("[ figures  ] %s: mesh pore volume / OPM's %.9f (volume %.9f); without the multiplier %.6f\n",
                multpv ? "MULTPV" : "none", pv / m.active_pore_volume, mesh_volume / opm_volume,
                pv_rock_only / m.active_pore_volume);
    EXPECT_NEAR(pv / m.active_pore_volume, 1.0, 1e-6);
    if (multpv) {
      EXPECT_GT(std::abs(pv_rock_only / m.active_pore_volume - 1), 1e-2);
    }
  }
}

// NNC and EDITNNC of the model's deck: NNC as OPM reads it (an EDITNNC of the pair folded in, METRIC
// units) carried as the mesh's connections without a face between the cells it names; EDITNNC kept as OPM
// keeps it and noted with the faces it reaches; without them no note and no connection.
TEST(CornerPoint, DeckNncIsCarriedAndEditnncNoted) {
  for (const bool with : {false, true}) {
    TempDir tmp;
    std::string text = SyntheticCpg{}.text();
    // OPM folds an EDITNNC on a deck NNC into that NNC and ignores one between logical neighbours
    // (opm-common NNC::load_edit): of these three, only the pair (1,1,1)-(3,1,1) is kept as an edit.
    if (with)
      text += "NNC\n 1 1 1 3 3 3 0.5 /\n 2 1 1 4 2 3 1.25 /\n/\nEDIT\nEDITNNC\n 1 1 1 3 1 1 0.1 /\n 1 1 1 3 3 3 0.5 /\n"
              " 1 1 1 2 1 1 0.1 /\n/\n";
    const CpgRun r = mesh_of(tmp, text);
    const CornerPointModel& m = *r.cs.reservoir.corner_point;
    ASSERT_EQ(m.nnc.size(), with ? 2u : 0u);
    EXPECT_EQ(m.deck_editnnc, with ? 1 : 0);
    const PolyMesh& mesh = r.out.mesh;
    ASSERT_EQ(mesh.n_nncs(), with ? 2 : 0);
    EXPECT_TRUE(check_csr_invariants(mesh).ok);
    // (i, j, k) pair -> transmissibility (cP.rm3/day/bar): 0.5 x the folded EDITNNC 0.5, and 1.25.
    std::map<std::pair<std::array<int32_t, 3>, std::array<int32_t, 3>>, double> expected{
        {{{0, 0, 0}, {2, 2, 2}}, 0.25}, {{{1, 0, 0}, {3, 1, 2}}, 1.25}};
    for (int k = 0; k < mesh.n_nncs(); ++k) {
      auto a = mesh.cell_ijk[mesh.nnc_cells[k][0]], b = mesh.cell_ijk[mesh.nnc_cells[k][1]];
      if (b < a) std::swap(a, b);
      ASSERT_EQ(expected.count({a, b}), 1u) << k;
      const double want = expected[{a, b}];
      EXPECT_NEAR(mesh.nnc_trans[k], want, 1e-12);
      EXPECT_EQ(mesh.cell_region[mesh.nnc_cells[k][0]], kReservoir);
    }
    // The transmissibilities of the connections: the deck's in METRIC, without the Darcy constant in mD.m.
    const Transmissibilities t = compute_transmissibilities(mesh, r.out.geometry, deck_transmissibility_options());
    EXPECT_EQ(t.nnc, mesh.nnc_trans);
    TransmissibilityOptions md;
    md.metric_units = false;
    const Transmissibilities t_md = compute_transmissibilities(mesh, r.out.geometry, md);
    for (int k = 0; k < mesh.n_nncs(); ++k) EXPECT_NEAR(t_md.nnc[k] * kDarcyMetric, mesh.nnc_trans[k], 1e-15);
    bool noted_nnc = false, noted_edit = false;
    for (const std::string& note : r.out.notes) {
      noted_nnc = noted_nnc || note.find("the deck's NNC connects 2 of its 2 cell pairs in the mesh") != std::string::npos;
      // (1,1,1)-(3,1,1) share no face: EDITNNC has nothing to act on, as in OPM Flow.
      noted_edit = noted_edit || note.find("EDITNNC names 1 cell pairs; it multiplies the 0 faces between 0 of them; "
                                           "1 share no face") != std::string::npos;
    }
    EXPECT_EQ(noted_nnc, with);
    EXPECT_EQ(noted_edit, with);
    EXPECT_EQ(m.edit_nnc.size(), with ? 1u : 0u);
    if (with) {
      EXPECT_EQ(m.edit_nnc.begin()->second, 0.1);
    }
  }
}

// Two cells of a column touching across a layer of zero thickness are connected as OPM Flow connects
// them: not without PINCH (multiplier 0), with PINCH by MULTZ of the upper cell (MULTZ option TOP) or
// the smallest MULTZ down to the last pinched cell (ALL).
TEST(CornerPoint, PinchedOutLayerCarriesFlowOnlyWithPinch) {
  const SyntheticCpg g;
  const int n = g.nx * g.ny * g.nz, nxy = g.nx * g.ny;
  std::ostringstream multz;  // 0.5 on the pinching layer 1, 0.8 on layer 0
  multz << "MULTZ\n";
  for (int c = 0; c < n; ++c) multz << (c / nxy == 1 ? 0.5 : c / nxy == 0 ? 0.8 : 1.0) << "\n";
  multz << "/\n";
  struct Variant {
    std::string pinch;
    bool multz;
    double expected;
    const char* note;
  };
  for (const Variant& v : {Variant{"", false, 0.0, "carry no flow"}, Variant{"0.4 NOGAP 1* TOPBOT TOP", false, 1.0, "MULTZ option TOP"},
                           Variant{"1* GAP 1* TOPBOT TOP", true, 0.8, "MULTZ option TOP"},
                           Variant{"1* GAP 1* TOPBOT ALL", true, 0.5, "MULTZ option ALL"}}) {
    TempDir tmp;
    const std::string text = (v.pinch.empty() ? "" : "PINCH\n " + v.pinch + " /\n") + g.text() + (v.multz ? multz.str() : "");
    const CpgRun r = mesh_of(tmp, text);
    ASSERT_TRUE(r.out.self_check.ok()) << r.out.self_check.message;
    const PolyMesh& m = r.out.mesh;
    ASSERT_EQ(m.face_trans_mult.size(), static_cast<size_t>(m.n_faces())) << v.pinch;
    int across = 0;
    for (int f = 0; f < m.n_faces(); ++f) {
      if (m.face_neighbour[f] < 0) continue;
      const int a = r.out.reservoir_cell_of[m.face_owner[f]], b = r.out.reservoir_cell_of[m.face_neighbour[f]];
      if (!across_pinched_layers(*r.cs.reservoir.corner_point, a, b)) continue;
      ++across;
      EXPECT_EQ(std::abs(a - b), 2 * nxy);
      EXPECT_DOUBLE_EQ(m.face_trans_mult[f], v.expected) << v.pinch << ": cells " << a << ", " << b;
    }
    EXPECT_GE(across, 10) << v.pinch;
    bool noted = false;
    for (const std::string& note : r.out.notes) noted = noted || note.find(v.note) != std::string::npos;
    EXPECT_TRUE(noted) << v.pinch;
    const Transmissibilities t = compute_transmissibilities(m, r.out.geometry, deck_transmissibility_options());
    for (int f = 0; f < m.n_faces(); ++f) {
      if (m.face_neighbour[f] >= 0 && m.face_trans_mult[f] == 0) {
        EXPECT_EQ(t.face[f], 0.0);
      }
    }
  }
}

// Reek (HM_LONG_TESTS=1: flow takes ~2 min): every connection flow makes is a face of the mesh; the
// mesh joins a few more pairs on faults (small overlaps OPM's grid processing does not connect).
TEST(CornerPoint, ReekFlowConnectionsAreMeshFaces) {
  if (!std::getenv("HM_LONG_TESTS")) GTEST_SKIP() << "HM_LONG_TESTS=1 runs it";
  if (!fs::exists(reek_deck())) GTEST_SKIP() << "no " << reek_deck();
  REQUIRE_FLOW();
  TempDir tmp;
  CpgRun r;
  r.cs = parse_case("name: reek\nreservoir: {grdecl: " + reek_deck().string() + "}\n");
  r.out = build_hybrid_mesh(r.cs);
  const FlowPairs p = flow_and_mesh_pairs(r, tmp.path / "deck", "REEK");
  size_t flow_only = 0, mesh_only = 0;
  for (const auto& pair : p.flow) flow_only += !p.mesh.count(pair);
  for (const auto& pair : p.mesh) mesh_only += !p.flow.count(pair);
  std::printf("[ figures  ] Reek: flow connects %zu cell pairs, the mesh %zu; flow only %zu, mesh only %zu\n",
              p.flow.size(), p.mesh.size(), flow_only, mesh_only);
  EXPECT_EQ(flow_only, 0u);
  EXPECT_LT(mesh_only, p.mesh.size() / 500);
}
