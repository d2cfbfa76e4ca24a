// Wells in a corner-point model (docs/corner-point.md): synthetic models made here (gently tilted,
// curved layers; a fault), a vertical well inside. What can fail: the job meshes and passes the
// self-check (fvcheck's checks; it throws otherwise), the total volume is the model's meshed
// volume minus the wellbore hole, every model face toward the cavity appears exactly once in the
// mesh as its constrained triangles between its active cell and one transition cell, the
// transition cells take the rock of the model cell around their centre, and a well reaching the
// model's outer surface is refused with the reason.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "meshgen/case/grdecl.hpp"
#include "meshgen/cavity/cavity_corner_point.hpp"
#include "meshgen/grids/corner_point_grid.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"
#include "../exporters/exporter_test_support.hpp"
#include "corner_point_test_models.hpp"
#include "fvcheck/lib/transmissibility.hpp"

using namespace hm;
namespace fs = std::filesystem;

namespace {

std::string num(double v) { return hmtest::grdecl_number(v); }

using hmtest::TiltedModel;
using hmtest::TempDir;

CaseSpec case_of(const TempDir& tmp, const TiltedModel& m, const std::string& wells) {
  std::ofstream(tmp.path / "M.GRDECL") << m.text();
  std::ofstream(tmp.path / "m.yaml") << "name: m\nreservoir: {grdecl: M.GRDECL}\n" << wells;
  return load_case((tmp.path / "m.yaml").string());
}

std::string vertical_well(double x, double y, double z0, double z1) { return hmtest::vertical_well_yaml(x, y, z0, z1); }

double total_volume(const HybridMesh& out) {
  double v = 0;
  for (int c = 0; c < out.mesh.n_cells(); ++c) v += out.geometry.cell_volume[c];
  return v;
}

// The properties of a meshed case with wells (see the file's comment).
void expect_sound_mesh(const CaseSpec& cs, const HybridMesh& out) {
  ASSERT_TRUE(out.self_check.ok()) << out.self_check.message;
  EXPECT_TRUE(out.build_report.ok);
  int transition = 0;
  for (int c = 0; c < out.mesh.n_cells(); ++c) {
    ASSERT_GT(out.geometry.cell_volume[c], 0) << c;
    transition += out.mesh.cell_region[c] == kTransition;
  }
  EXPECT_GT(transition, 0);
  // Volume: the model without wells, minus the wellbore holes.
  CaseSpec no_wells = cs;
  no_wells.wells.clear();
  const HybridMesh bare = build_hybrid_mesh(no_wells);
  double hole = 0;
  for (size_t w = 0; w < cs.wells.size(); ++w) hole += exact_wellbore_hole_volume(cs, static_cast<int>(w), out.blocks[w].sectors);
  const double v = total_volume(out), v0 = total_volume(bare);
  std::printf("[ figures  ] corner-point with wells: %d cells (%d transition), volume %.9f vs model - wellbore %.9f "
              "(rel %.2e)\n",
              out.mesh.n_cells(), transition, v, v0 - hole, v / (v0 - hole) - 1);
  EXPECT_NEAR(v / (v0 - hole), 1.0, 1e-9);
  // Each constrained triangle of a reservoir side: exactly one mesh face, between the model cell
  // outside and a transition cell; and no other face joins a model cell to a transition cell.
  std::map<std::array<double, 3>, int32_t> node_at;
  for (int32_t v = 0; v < out.mesh.n_nodes(); ++v) node_at[{out.mesh.nodes[v].x, out.mesh.nodes[v].y, out.mesh.nodes[v].z}] = v;
  std::map<std::vector<int32_t>, std::vector<int32_t>> faces_of;
  for (int32_t f = 0; f < out.mesh.n_faces(); ++f) {
    std::vector<int32_t> key(out.mesh.face_begin(f), out.mesh.face_end(f));
    std::sort(key.begin(), key.end());
    faces_of[key].push_back(f);
  }
  const CornerPointModel& m = *cs.reservoir.corner_point;
  size_t triangles = 0;
  for (const Cavity& cav : out.cavities.cavities)
    for (const ConstrainedFace& cf : cav.faces) {
      if (cf.side != FaceSide::Reservoir) continue;
      ++triangles;
      ASSERT_EQ(cf.nodes.size(), 3u);
      std::vector<int32_t> key;
      for (int32_t v : cf.nodes) {
        const Vec3 p = out.cavity_node_coords[v];
        key.push_back(node_at.at({p.x, p.y, p.z}));
      }
      std::sort(key.begin(), key.end());
      const auto it = faces_of.find(key);
      ASSERT_NE(it, faces_of.end()) << "a constrained triangle is no face of the mesh";
      ASSERT_EQ(it->second.size(), 1u) << "a constrained triangle is in the mesh more than once";
      const int32_t f = it->second[0], o = out.mesh.face_owner[f], n = out.mesh.face_neighbour[f];
      ASSERT_GE(n, 0);
      const int32_t res = out.mesh.cell_region[o] == kReservoir ? o : n, tr = res == o ? n : o;
      EXPECT_EQ(out.mesh.cell_region[tr], kTransition);
      ASSERT_EQ(out.mesh.cell_region[res], kReservoir);
      const auto& ijk = out.mesh.cell_ijk[res];
      EXPECT_EQ(ijk[0] + m.nx * (ijk[1] + m.ny * ijk[2]), cf.outside_cell);
    }
  size_t joins = 0;
  for (int32_t f = 0; f < out.mesh.n_faces(); ++f) {
    const int32_t o = out.mesh.face_owner[f], n = out.mesh.face_neighbour[f];
    if (n < 0) continue;
    const int a = out.mesh.cell_region[o], b = out.mesh.cell_region[n];
    joins += (a == kReservoir && b == kTransition) || (a == kTransition && b == kReservoir);
  }
  // Two-point halves: negative ones (an FV centre beyond the face's plane in the K metric) only on
  // the model cells' side (the user's cells, exempt from the shape checks; tilted layers with a
  // diagonal K make them, docs/corner-point.md), never on a radial or transition cell's.
  const Transmissibilities tr = compute_transmissibilities(out.mesh, out.geometry);
  int model_negative = 0;
  for (int32_t f = 0; f < out.mesh.n_faces(); ++f) {
    const int32_t o = out.mesh.face_owner[f], n = out.mesh.face_neighbour[f];
    if (!(tr.half_owner[f] > 0) && n >= 0) {
      EXPECT_EQ(out.mesh.cell_region[o], kReservoir) << "face " << f;
      ++model_negative;
    }
    if (n >= 0 && !(tr.half_neighbour[f] > 0)) {
      EXPECT_EQ(out.mesh.cell_region[n], kReservoir) << "face " << f;
      ++model_negative;
    }
  }
  std::printf("[ figures  ] non-positive two-point halves on the model cells' side: %d\n", model_negative);
  EXPECT_GT(triangles, 0u);
  EXPECT_EQ(joins, triangles);
  // Rock: a transition cell's permeability is that of the deactivated model cell around its centre.
  std::set<int32_t> dead;
  for (const Cavity& cav : out.cavities.cavities) dead.insert(cav.deactivated_cells.begin(), cav.deactivated_cells.end());
  std::set<double> perms;
  for (int32_t c : dead) perms.insert(m.permx[c]);
  for (int c = 0; c < out.mesh.n_cells(); ++c)
    if (out.mesh.cell_region[c] != kReservoir) {
      EXPECT_TRUE(perms.count(out.mesh.cell_perm[c].x)) << c;
    }
}

}  // namespace

// One vertical well in gently tilted, twisted layers (20 x 20 m cells, 4.5 m layers, 5 degree dip).
TEST(CornerPointWells, VerticalWellInTiltedLayersMeshes) {
  TempDir tmp("cpwells");
  const TiltedModel g;
  const CaseSpec cs = case_of(tmp, g, vertical_well(90, 90, 1034, 1046));
  ASSERT_TRUE(cs.reservoir.corner_point);
  HybridMesh out;
  ASSERT_NO_THROW(out = build_hybrid_mesh(cs));  // gtest prints the exception's what()
  expect_sound_mesh(cs, out);
  for (const Cavity& cav : out.cavities.cavities) EXPECT_FALSE(cav.cells_are_boxes);
  // Deterministic: the same case meshes to the same mesh.
  const HybridMesh again = build_hybrid_mesh(cs);
  EXPECT_EQ(again.mesh.face_nodes, out.mesh.face_nodes);
  EXPECT_EQ(again.mesh.cell_faces, out.mesh.cell_faces);
  EXPECT_EQ(again.mesh.nodes, out.mesh.nodes);
}

// A deviated well across columns, with inclined, non-parallel pillars (no model face is planar).
TEST(CornerPointWells, DeviatedWellWithInclinedPillarsMeshes) {
  TempDir tmp("cpwells");
  TiltedModel g;
  g.nz = 22, g.inclined_pillars = true;
  const std::string well = hmtest::deviated_well_yaml();
  const CaseSpec cs = case_of(tmp, g, well);
  HybridMesh out;
  ASSERT_NO_THROW(out = build_hybrid_mesh(cs));  // gtest prints the exception's what()
  expect_sound_mesh(cs, out);
}

// A well whose cavity reaches the model's top is refused (exit 2) with the reason.
TEST(CornerPointWells, WellReachingTheTopIsRefusedWithTheReason) {
  TempDir tmp("cpwells");
  const CaseSpec cs = case_of(tmp, TiltedModel{}, vertical_well(90, 90, 1012, 1030));
  try {
    build_hybrid_mesh(cs);
    ADD_FAILURE() << "a cavity reaching the model's top was meshed";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("reaches the outer surface of the corner-point model"), std::string::npos)
        << e.what();
  }
}

// Constrained triangles: a face's triangles cover it (area) with its own nodes and orientation.
TEST(CornerPointWells, FaceTrianglesCoverTheFaceWithItsNodes) {
  const std::vector<Vec3> coords{{0, 0, 0}, {10, 0, 0}, {20, 0, 0.5}, {20, 5, 0}, {10, 5, 0.2}, {0, 5, 0}, {5, 0, 0}};
  // A pentagon-like cycle with a station (node 6) on its first edge.
  const std::vector<int32_t> cycle{0, 6, 1, 2, 3, 4, 5};
  const auto tris = face_triangles(cycle, coords);
  ASSERT_EQ(tris.size(), cycle.size() - 2);
  Vec3 area{0, 0, 0}, area_fan{0, 0, 0};
  for (const auto& t : tris) {
    const Vec3 a = cross(coords[t[1]] - coords[t[0]], coords[t[2]] - coords[t[0]]);
    EXPECT_GT(norm(a), 1e-6) << "a degenerate triangle";
    EXPECT_GT(a.z, 0) << "a triangle turned over";
    area += 0.5 * a;
  }
  for (size_t i = 1; i + 1 < cycle.size(); ++i)
    area_fan += 0.5 * cross(coords[cycle[i]] - coords[cycle[0]], coords[cycle[i + 1]] - coords[cycle[0]]);
  EXPECT_NEAR(area.z, area_fan.z, 1e-9);
}

// A fault of 10 m throw (2.2 layers) crossed by a deviated well: the cavity's boundary has fault
// overlaps 1 m and 3.5 m high beside whole faces; the site correction does not converge on the walls'
// triangles (sites pressed to their minimal height) and the local enlargements reach the model's
// surface. Measured, and refused with the reason, never a bad mesh (docs/corner-point.md, "Faults").
TEST(CornerPointWells, WellAcrossAFaultOfTenMetresIsRefusedWithTheReason) {
  TempDir tmp("cpwells");
  TiltedModel g;
  g.nz = 22, g.fault_i = 5, g.throw_m = 10;
  const std::string well = hmtest::deviated_well_yaml();
  const CaseSpec cs = case_of(tmp, g, well);
  try {
    build_hybrid_mesh(cs);
    ADD_FAILURE() << "the faulted case meshed: check it with expect_sound_mesh and update docs/corner-point.md";
  } catch (const MeshingError& e) {
    std::printf("[ figures  ] fault of 10 m: %s\n", e.what());
    EXPECT_EQ(e.stage, "transition");
    EXPECT_NE(std::string(e.what()).find("site correction did not converge"), std::string::npos) << e.what();
  }
}

// Reek (docs/corner-point.md, "Reek"): a vertical well in the column of OP_1 (29, 28), in layers 6-9
// of 14 (3 m thick, cells ~100-160 m wide), drainage radius 10 m. What happens is measured and printed;
// the property: a sound mesh or a refusal with the reason, never a bad mesh.
TEST(CornerPointWells, ReekWellIsMeshedSoundlyOrRefusedWithTheReason) {
  // The shared data beside the checkout (or beside a worktree's parent folder).
  fs::path deck = fs::path(HM_SOURCE_DIR) / ".." / "shared" / "data" / "reek" / "REEK_GRID.DATA";
  if (!fs::exists(deck)) deck = fs::path(HM_SOURCE_DIR) / ".." / ".." / "shared" / "data" / "reek" / "REEK_GRID.DATA";
  if (!fs::exists(deck)) GTEST_SKIP() << "no " << deck;
  const CornerPointModel m = read_corner_point_model(deck.string(), "reservoir.grdecl");
  const int i = 28, j = 27;
  auto centre = [&](int k, bool bottom) {
    const int c = i + m.nx * (j + m.ny * k);
    Vec3 p{0, 0, 0};
    for (int q = 0; q < 4; ++q) p += 0.25 * model_cell_corner(m, c, q + (bottom ? 4 : 0));
    return p;
  };
  const Vec3 a = centre(5, false), b = centre(8, true);
  auto map = [&](Vec3 p) {
    return Vec3{m.map_origin[0] + p.x * m.map_unit_x[0] + p.y * m.map_unit_y[0],
                m.map_origin[1] + p.x * m.map_unit_x[1] + p.y * m.map_unit_y[1], p.z};
  };
  const Vec3 ma = map(a), mb = map(b);
  TempDir tmp("cpwells");
  std::ofstream(tmp.path / "reek.yaml") << "name: reek\nreservoir: {grdecl: " << deck.string()
                                        << "}\nwells:\n  - {name: OP1, trajectory: [[" << num(ma.x) << ", " << num(ma.y)
                                        << ", " << num(ma.z) << "], [" << num(mb.x) << ", " << num(mb.y) << ", "
                                        << num(mb.z) << "]], radius: 0.1, drainage_radius: 10, end_caps: flat, bhp: 150}\n";
  const CaseSpec cs = load_case((tmp.path / "reek.yaml").string());
  try {
    const HybridMesh out = build_hybrid_mesh(cs);
    std::printf("[ figures  ] Reek, one well: meshed, %d cells\n", out.mesh.n_cells());
    expect_sound_mesh(cs, out);
  } catch (const InputError& e) {
    std::printf("[ figures  ] Reek, one well: refused (input): %s\n", e.what());
    EXPECT_GT(std::string(e.what()).size(), 20u);
  } catch (const MeshingError& e) {
    std::printf("[ figures  ] Reek, one well: refused at stage %s: %s\n", e.stage.c_str(), e.what());
    EXPECT_GT(std::string(e.what()).size(), 20u);
  }
}
