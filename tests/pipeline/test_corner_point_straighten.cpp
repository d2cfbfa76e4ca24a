// Upright pillars near wells (meshgen/case/corner_point_straighten.hpp, docs/corner-point.md "Upright
// pillars near wells"). What can fail: the pillars within reach are not vertical, pillars beyond the
// blend move, a corner leaves its layer's surface, the layers' volumes change, a cell takes the rock
// of a model cell its centre does not lie in, a fault in the region goes unnoticed, and the
// obliquely sheared case that the transition refuses with the model's pillars does not mesh soundly.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "../exporters/exporter_test_support.hpp"
#include "corner_point_test_models.hpp"
#include "meshgen/case/corner_point_refine.hpp"
#include "meshgen/case/corner_point_straighten.hpp"
#include "meshgen/case/grdecl.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"

using namespace hm;
using hmtest::TempDir;
namespace fs = std::filesystem;

namespace {

// LayeredModel's pillars lean 56 degrees toward an azimuth 20 degrees off the i axis (Reek around
// OP_1: 52-60 degrees, 20 off i); its layers are planes (layer_surface).
hmtest::LayeredModel oblique_model() {
  hmtest::LayeredModel g;
  g.pillar_deg = 56;
  g.pillar_azimuth_deg = 20;
  return g;
}

// LayeredModel's depth of layer surface k at pillar (I, J) is 1000 + dz k + tan(dip) dx I + 0.01 dy J,
// and the pillar passes (dx I, dy J) at depth 1000 leaning (lx, ly) per metre: solved for z at (x, y),
// a plane.
double layer_surface(const hmtest::LayeredModel& g, int k, double x, double y) {
  const double lean = std::tan(g.pillar_deg * M_PI / 180), az = g.pillar_azimuth_deg * M_PI / 180;
  const double a = std::tan(g.dip_deg * M_PI / 180), b = 0.01, lx = lean * std::cos(az), ly = lean * std::sin(az);
  return (1000 + g.dz * k + a * x + b * y + (a * lx + b * ly) * 1000) / (1 + a * lx + b * ly);
}

// The model cell (natural index of the model as read) holding point p: pillars at depth z are
// x = dx I + lx (z - 1000) (LayeredModel's COORD), layers from the planes above. -1 on a boundary.
int64_t model_cell_at(const hmtest::LayeredModel& g, Vec3 p) {
  const double lean = std::tan(g.pillar_deg * M_PI / 180), az = g.pillar_azimuth_deg * M_PI / 180;
  const double u = (p.x - lean * std::cos(az) * (p.z - 1000)) / g.dx, v = (p.y - lean * std::sin(az) * (p.z - 1000)) / g.dy;
  const int I = static_cast<int>(std::floor(u)), J = static_cast<int>(std::floor(v));
  int k = -1;
  for (int l = 0; l < g.nz; ++l)
    if (p.z > layer_surface(g, l, p.x, p.y) && p.z < layer_surface(g, l + 1, p.x, p.y)) k = l;
  if (std::abs(u - std::round(u)) < 1e-6 || std::abs(v - std::round(v)) < 1e-6 || k < 0) return -1;
  return I + int64_t(g.nx) * (J + int64_t(g.ny) * k);
}

// The model's cells meshed alone: total volume and volume per layer.
std::vector<double> layer_volumes(const CornerPointModel& m) {
  CaseSpec cs;
  cs.name = "m";
  cs.reservoir = corner_point_reservoir(std::make_shared<const CornerPointModel>(m), "reservoir.grdecl");
  const HybridMesh out = build_hybrid_mesh(cs);
  EXPECT_TRUE(out.build_report.ok);
  std::vector<double> v(m.nz, 0.0);
  for (int c = 0; c < out.mesh.n_cells(); ++c) {
    EXPECT_GT(out.geometry.cell_volume[c], 0.0) << "cell " << c;
    v[out.mesh.cell_ijk[c][2]] += out.geometry.cell_volume[c];
  }
  return v;
}

const Vec3 kWellTop{350, 350, 1080}, kWellBottom{350, 350, 1092};

}  // namespace

TEST(UprightPillars, LayersKeptPillarsUprightRockFromTheCellHoldingTheCentre) {
  TempDir tmp("upright");
  const hmtest::LayeredModel g = oblique_model();
  std::ofstream(tmp.path / "M.GRDECL") << g.text();
  const CornerPointModel model = read_corner_point_model((tmp.path / "M.GRDECL").string(), "reservoir.grdecl");
  const RefinementRequest ask{{kWellTop, kWellBottom}, 5, 17.5, true};
  const CornerPointModel m = refined_model(model, near_well_splits(model, {ask}));
  const StraightenRequest req{{kWellTop, kWellBottom}, 27.5};
  std::vector<StraightenOutcome> outcome;
  const CornerPointModel r = straightened_model(m, {req}, &outcome);
  ASSERT_EQ(outcome.size(), 1u);
  ASSERT_TRUE(outcome[0].straightened) << outcome[0].refused;
  EXPECT_NEAR(outcome[0].max_lean_deg, 56, 1e-9);
  ASSERT_GT(outcome[0].blend, 0);

  // Pillars: vertical within reach (measured at the pivot depth, 1086), the model's beyond the blend.
  int vertical = 0, kept = 0, turned = 0;
  for (int p = 0; p < (m.nx + 1) * (m.ny + 1); ++p) {
    const double* a = &m.coord[6 * size_t(p)];
    const double* b = &r.coord[6 * size_t(p)];
    const Vec3 at = pillar_point(m, p, 1086);
    const double d = std::hypot(at.x - kWellTop.x, at.y - kWellTop.y);
    if (d <= req.reach) {
      EXPECT_EQ(b[0], b[3]) << "pillar " << p;
      EXPECT_EQ(b[1], b[4]) << "pillar " << p;
      ++vertical;
    } else if (d > req.reach + outcome[0].blend + 1e-6) {
      for (int q = 0; q < 6; ++q) EXPECT_EQ(a[q], b[q]) << "pillar " << p;
      ++kept;
    }
    turned += !std::equal(a, a + 6, b);
  }
  EXPECT_GT(vertical, 20);
  EXPECT_GT(kept, 0);
  EXPECT_EQ(turned, outcome[0].pillars);

  // Every corner on its layer's plane (the top of layer k, the bottom = the top of k + 1).
  double worst = 0;
  for (int k = 0; k < r.nz; ++k)
    for (int J = 0; J < r.ny; ++J)
      for (int I = 0; I < r.nx; ++I)
        for (int q = 0; q < 8; ++q) {
          const Vec3 x = corner(r, I + size_t(r.nx) * (J + size_t(r.ny) * k), q);
          worst = std::max(worst, std::abs(x.z - layer_surface(g, k + (q >> 2), x.x, x.y)));
          EXPECT_EQ(x.z, r.zcorn[zcorn_index(r, I, J, k, q)]);
        }
  EXPECT_LT(worst, 1e-9);

  // Volume: each layer's as before (planar layers; the region's outer boundary is the model's).
  const std::vector<double> before = layer_volumes(m), after = layer_volumes(r);
  double total_before = 0, total_after = 0;
  for (int k = 0; k < m.nz; ++k) {
    EXPECT_NEAR(after[k] / before[k], 1.0, 1e-11) << "layer " << k;
    total_before += before[k], total_after += after[k];
  }
  EXPECT_NEAR(total_after / total_before, 1.0, 1e-12);

  // Rock and parent: the model cell each turned cell's centre lies in, found from the model's own
  // geometry (not through the code's walk).
  int checked = 0;
  for (size_t c = 0; c < r.n_cells(); ++c) {
    const std::array<Vec3, 8> corners = cell_corners(r, c);
    if (corners == cell_corners(m, c)) {
      EXPECT_EQ(r.parent_cell[c], m.parent_cell[c]);
      continue;
    }
    Vec3 centre{0, 0, 0};
    for (const Vec3& x : corners) centre += x / 8.0;
    const int64_t p = model_cell_at(g, centre);
    if (p < 0) continue;
    ++checked;
    EXPECT_EQ(r.parent_cell[c], p) << "cell " << c;
    EXPECT_EQ(r.permx[c], model.permx[p]) << "cell " << c;
    EXPECT_EQ(r.poro[c], model.poro[p]);
  }
  EXPECT_GT(checked, 1000);
  std::printf("[ figures  ] 56 deg at 20 deg: %d of %d pillars turned (%d upright), blend %.1f m, %d cells' rock checked, "
              "corners off their plane %.2e m\n",
              turned, (m.nx + 1) * (m.ny + 1), vertical, outcome[0].blend, checked, worst);
}

// Where the model sits does not matter: the model and the well moved by UTM-sized offsets turn the same
// pillars to the same lines (to rounding of the coordinates) and give every cell the same rock.
TEST(UprightPillars, TranslatedModelTurnsTheSamePillars) {
  TempDir tmp("upright_shift");
  std::ofstream(tmp.path / "M.GRDECL") << oblique_model().text();
  const CornerPointModel model = read_corner_point_model((tmp.path / "M.GRDECL").string(), "reservoir.grdecl");
  const CornerPointModel m = refined_model(model, near_well_splits(model, {{{kWellTop, kWellBottom}, 5, 17.5, true}}));
  const Vec3 shift{456510.608, 5926880.031, 1500};
  std::vector<StraightenOutcome> here, there;
  const CornerPointModel a = straightened_model(m, {{{kWellTop, kWellBottom}, 27.5}}, &here);
  const CornerPointModel b =
      straightened_model(translated_model(m, shift), {{{kWellTop + shift, kWellBottom + shift}, 27.5}}, &there);
  ASSERT_TRUE(here[0].straightened && there[0].straightened);
  EXPECT_EQ(here[0].pillars, there[0].pillars);
  EXPECT_NEAR(here[0].blend, there[0].blend, 1e-6);
  double worst = 0;
  for (size_t i = 0; i < a.coord.size(); ++i) worst = std::max(worst, std::abs(a.coord[i] + shift[static_cast<int>(i % 3)] - b.coord[i]));
  for (size_t i = 0; i < a.zcorn.size(); ++i) worst = std::max(worst, std::abs(a.zcorn[i] + shift.z - b.zcorn[i]));
  EXPECT_LT(worst, 1e-6);
  EXPECT_EQ(a.parent_cell, b.parent_cell);
  EXPECT_EQ(a.permx, b.permx);
  EXPECT_EQ(a.actnum, b.actnum);
  std::printf("[ figures  ] moved by (456510.608, 5926880.031, 1500): %d pillars turned both ways, coordinates within %.1e m\n",
              there[0].pillars, worst);
}

// A fault in the region (ZCORN not continuous across a column edge) keeps the model as it is, and the
// outcome says why; pillars leaning along a grid axis (i-walls and j-walls at right angles) are not
// turned at all, however steep.
TEST(UprightPillars, FaultInTheRegionAndSteepPillarsKeepTheModel) {
  TempDir tmp("upright_fault");
  hmtest::LayeredModel g = oblique_model();
  g.fault_i = 3, g.throw_m = 6;
  std::ofstream(tmp.path / "M.GRDECL") << g.text();
  const CornerPointModel as_read = read_corner_point_model((tmp.path / "M.GRDECL").string(), "reservoir.grdecl");
  const CornerPointModel faulted = refined_model(as_read, near_well_splits(as_read, {{{kWellTop, kWellBottom}, 5, 17.5, true}}));
  std::vector<StraightenOutcome> outcome;
  const CornerPointModel r = straightened_model(faulted, {{{kWellTop, kWellBottom}, 27.5}}, &outcome);
  ASSERT_EQ(outcome.size(), 1u);
  EXPECT_FALSE(outcome[0].straightened);
  EXPECT_NE(outcome[0].refused.find("fault"), std::string::npos) << outcome[0].refused;
  EXPECT_EQ(r.coord, faulted.coord);
  EXPECT_EQ(r.zcorn, faulted.zcorn);

  hmtest::LayeredModel steep;
  steep.pillar_deg = 56, steep.pillar_azimuth_deg = 0;
  std::ofstream(tmp.path / "S.GRDECL") << steep.text();
  const CornerPointModel s_read = read_corner_point_model((tmp.path / "S.GRDECL").string(), "reservoir.grdecl");
  const CornerPointModel s = refined_model(s_read, near_well_splits(s_read, {{{kWellTop, kWellBottom}, 5, 17.5, true}}));
  const CornerPointModel rs = straightened_model(s, {{{kWellTop, kWellBottom}, 27.5}}, &outcome);
  EXPECT_FALSE(outcome[0].straightened);
  EXPECT_TRUE(outcome[0].refused.empty());
  EXPECT_NEAR(outcome[0].max_lean_deg, 56, 1e-9);
  EXPECT_NEAR(outcome[0].wall_angle_deg, 90, 1e-6);
  EXPECT_EQ(rs.coord, s.coord);
}

// The obliquely sheared case (NearWellRefinement.ObliquelyShearedCellsAreRefusedWithTheReason):
// refused at the transition with the model's pillars (upright_pillars: off), and meshed soundly with
// them turned upright (the default): the self-check passes and the volume is the turned model's minus
// the wellbore hole.
TEST(UprightPillars, ObliquelyShearedCellsMeshWithUprightPillars) {
  TempDir tmp("upright_mesh");
  std::ofstream(tmp.path / "M.GRDECL") << oblique_model().text();
  auto case_text = [](const std::string& extra) {
    return "name: m\nreservoir: {grdecl: M.GRDECL" + extra +
           "}\nwells:\n  - {name: P1, trajectory: [[350, 350, 1080], [350, 350, 1092]], radius: 0.1, drainage_radius: 5, "
           "end_caps: flat, bhp: 150}\n";
  };
  std::ofstream(tmp.path / "off.yaml") << case_text(", upright_pillars: off");
  std::ofstream(tmp.path / "auto.yaml") << case_text("");
  try {
    build_hybrid_mesh(load_case((tmp.path / "off.yaml").string()));
    ADD_FAILURE() << "meshed with the model's pillars: the oblique-shear limit is lifted, say so in docs/corner-point.md";
  } catch (const MeshingError& e) {
    EXPECT_EQ(e.stage, "transition");
    EXPECT_NE(std::string(e.what()).find("not Delaunay admissible"), std::string::npos) << e.what();
  }

  const CaseSpec cs = load_case((tmp.path / "auto.yaml").string());
  bool noted = false;
  for (const std::string& n : cs.notes) noted = noted || n.find("turned upright") != std::string::npos;
  EXPECT_TRUE(noted);
  HybridMesh out;
  ASSERT_NO_THROW(out = build_hybrid_mesh(cs));
  ASSERT_TRUE(out.self_check.ok()) << out.self_check.message;
  double v = 0, v0 = 0;
  for (int c = 0; c < out.mesh.n_cells(); ++c) v += out.geometry.cell_volume[c];
  for (double l : layer_volumes(*cs.reservoir.corner_point)) v0 += l;
  const double hole = exact_wellbore_hole_volume(cs, 0, out.blocks[0].sectors);
  EXPECT_NEAR(v / (v0 - hole), 1.0, 1e-9);
  int transition = 0;
  for (int c = 0; c < out.mesh.n_cells(); ++c) transition += out.mesh.cell_region[c] == kTransition;
  EXPECT_GT(transition, 100);
  std::printf("[ figures  ] 56 deg at 20 deg, R = 5 m, upright pillars: %d cells (%d transition)\n", out.mesh.n_cells(),
              transition);
}
