// Wells in a corner-point model (docs/corner-point.md): synthetic models made here (gently tilted,
// curved layers; a fault), a vertical well inside. What can fail: the job meshes and passes the
// self-check (fvcheck's checks; it throws otherwise), the total volume is the model's meshed
// volume minus the wellbore hole, every model face toward the cavity appears exactly once in the
// mesh as its constrained triangles between its active cell and one transition cell, every face of a
// deactivated cell on the model's outer surface appears exactly once as its triangles, boundary faces
// of transition cells, the model's boundary area is kept, the transition cells take the rock of the
// model cell around their centre; and a well too near the surface for its faces is refused with the reason.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>

#include "exporters/vtu/vtu_reader.hpp"
#include "exporters/vtu/vtu_writer.hpp"
#include "meshgen/case/corner_point_path.hpp"
#include "meshgen/case/grdecl.hpp"
#include "meshgen/cavity/cavity_corner_point.hpp"
#include "meshgen/grids/corner_point_grid.hpp"
#include "meshgen/core/fv_quality.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"
#include "meshgen/pipeline/permeability_frame.hpp"
#include "../exporters/exporter_test_support.hpp"
#include "corner_point_test_models.hpp"
#include "fvcheck/lib/report.hpp"
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

// Every present cell's faces as the pipeline makes them, and the builder's node coordinates (the
// model's nodes keep their ids in the pipeline).
CornerPointCellFaces all_cell_faces(const CornerPointModel& m, std::vector<Vec3>* coords) {
  MeshBuilder scratch;
  CornerPointCellFaces faces = corner_point_cell_faces(m, std::vector<char>(m.actnum.size(), 1), scratch);
  coords->resize(scratch.n_nodes());
  for (int32_t v = 0; v < scratch.n_nodes(); ++v) (*coords)[v] = scratch.node(v);
  return faces;
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
  // In a permeability frame the wellbore is the scaled frame's, mapped back (volumes are kept).
  const CaseSpec meshed = scaled_case(cs, out.frame);
  for (size_t w = 0; w < cs.wells.size(); ++w) hole += exact_wellbore_hole_volume(meshed, static_cast<int>(w), out.blocks[w].sectors);
  const double v = total_volume(out.geometry), v0 = total_volume(bare.geometry);
  std::printf("[ figures  ] corner-point with wells: %d cells (%d transition), volume %.9f vs model - wellbore %.9f "
              "(rel %.2e)\n",
              out.mesh.n_cells(), transition, v, v0 - hole, v / (v0 - hole) - 1);
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
  // Every face once in the mesh, in exactly two cells' lists when interior (two distinct cells), in
  // its owner's only when on the boundary (then in a patch).
  std::vector<int> uses(out.mesh.n_faces(), 0);
  for (int32_t f : out.mesh.cell_faces) ++uses[f];
  for (const auto& [key, fs] : faces_of) ASSERT_EQ(fs.size(), 1u) << "two mesh faces over the same nodes";
  for (int32_t f = 0; f < out.mesh.n_faces(); ++f) {
    const bool interior = out.mesh.face_neighbour[f] >= 0;
    ASSERT_EQ(uses[f], interior ? 2 : 1) << "face " << f;
    ASSERT_EQ(out.mesh.face_patch[f] == kInteriorFace, interior) << "face " << f;
    if (interior) {
      ASSERT_NE(out.mesh.face_owner[f], out.mesh.face_neighbour[f]) << "face " << f;
    }
  }
  const CornerPointModel& m = *cs.reservoir.corner_point;
  auto mesh_face = [&](const std::vector<int32_t>& builder_ids) {
    std::vector<int32_t> key;
    for (int32_t v : builder_ids) {
      const Vec3 p = out.cavity_node_coords[v];
      key.push_back(node_at.at({p.x, p.y, p.z}));
    }
    std::sort(key.begin(), key.end());
    const auto it = faces_of.find(key);
    return it == faces_of.end() ? -1 : it->second[0];
  };
  size_t triangles = 0, surface = 0;
  for (const Cavity& cav : out.cavities.cavities)
    for (const ConstrainedFace& cf : cav.faces) {
      if (cf.side != FaceSide::Reservoir) continue;
      ASSERT_EQ(cf.nodes.size(), 3u);
      const int32_t f = mesh_face(cf.nodes);
      ASSERT_GE(f, 0) << "a constrained triangle is no face of the mesh";
      const int32_t o = out.mesh.face_owner[f], n = out.mesh.face_neighbour[f];
      if (cf.outside_cell < 0) {  // on the model's outer surface: checked below
        ++surface;
        EXPECT_EQ(cf.patch, kOuterBoundary);
        continue;
      }
      ++triangles;
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
  // The model's outer surface (docs/corner-point.md, "Outer surface"): every face of a deactivated
  // cell with no meshed cell across it, cut into triangles over its own nodes, is exactly one mesh
  // face: a boundary face (kOuterBoundary) of a transition cell, outward as the model face. Listed
  // here from the model's faces, not from the cavity.
  std::set<int32_t> dead_cells;
  for (const Cavity& cav : out.cavities.cavities) dead_cells.insert(cav.deactivated_cells.begin(), cav.deactivated_cells.end());
  std::vector<Vec3> builder_coords;
  const CornerPointCellFaces model_faces = all_cell_faces(m, &builder_coords);
  ASSERT_LE(builder_coords.size(), out.cavity_node_coords.size());
  for (size_t v = 0; v < builder_coords.size(); ++v)  // the model's nodes have the pipeline's ids
    ASSERT_EQ(builder_coords[v], out.cavity_node_coords[v]) << v;
  size_t surface_found = 0;
  double surface_triangle_area = 0;  // sum of |area| of those triangles
  // The volume the model's meshed surface (a face as the fan about its node mean, compute_geometry)
  // loses where it becomes the face's triangles: per face, fan minus triangles (divergence theorem,
  // about the face's first node). Zero for planar faces.
  auto fan_volume = [&](const std::vector<int32_t>& poly, Vec3 o) {
    Vec3 g{0, 0, 0};
    for (int32_t v : poly) g += builder_coords[v] / static_cast<double>(poly.size());
    double vol = 0;
    for (size_t i = 0; i < poly.size(); ++i)
      vol += dot(g - o, cross(builder_coords[poly[i]] - o, builder_coords[poly[(i + 1) % poly.size()]] - o)) / 6.0;
    return vol;
  };
  double bent_volume = 0;
  for (int32_t c : dead_cells)
    for (int64_t k = model_faces.face_begin(c); k < model_faces.face_end(c); ++k) {
      if (model_faces.neighbour[k] >= 0 || !model_faces.first_of_its_group(c, k)) continue;
      const int32_t g = model_faces.group[k];
      const std::vector<int32_t> cycle = model_faces.cycle(k);
      const Vec3 o = builder_coords[cycle[0]];
      for (int64_t e = model_faces.face_begin(c); e < model_faces.face_end(c); ++e)  // the face, or every face of its fan
        if (e == k || (g >= 0 && model_faces.group[e] == g)) bent_volume += fan_volume(model_faces.face_nodes(e), o);
      for (const auto& t : face_triangles(cycle, builder_coords)) {
        bent_volume -= fan_volume({t[0], t[1], t[2]}, o);
        ++surface_found;
        const int32_t f = mesh_face({t[0], t[1], t[2]});
        ASSERT_GE(f, 0) << "an outer-surface triangle of deactivated cell " << c << " is no face of the mesh";
        EXPECT_LT(out.mesh.face_neighbour[f], 0);
        EXPECT_EQ(out.mesh.face_patch[f], kOuterBoundary);
        EXPECT_EQ(out.mesh.cell_region[out.mesh.face_owner[f]], kTransition);
        const Vec3 a = 0.5 * cross(builder_coords[t[1]] - builder_coords[t[0]], builder_coords[t[2]] - builder_coords[t[0]]);
        EXPECT_GT(dot(out.geometry.face_area[f], a), 0) << "an outer-surface triangle points into the model";
        surface_triangle_area += norm(out.geometry.face_area[f]);
      }
    }
  EXPECT_EQ(surface_found, surface);
  // Orthogonality of the boundary faces (measured, not asserted): the angle between a face's normal
  // and the segment from its cell's FV centre to the face centroid, transition cells (on the
  // surface triangles) against model cells (their corner mean, on the model's faces).
  double worst_transition = 0, worst_model = 0;
  for (int32_t f = 0; f < out.mesh.n_faces(); ++f) {
    if (out.mesh.face_patch[f] != kOuterBoundary) continue;
    const int32_t o = out.mesh.face_owner[f];
    const Vec3 d = out.geometry.face_centroid[f] - out.mesh.cell_fv_center[o], a = out.geometry.face_area[f];
    const double deg = std::acos(std::clamp(dot(d, a) / (norm(d) * norm(a)), -1.0, 1.0)) * 180 / M_PI;
    (out.mesh.cell_region[o] == kTransition ? worst_transition : worst_model) =
        std::max(out.mesh.cell_region[o] == kTransition ? worst_transition : worst_model, deg);
  }
  std::printf("[ figures  ] outer-boundary faces, worst angle normal / (centroid - FV centre): transition cells %.1f "
              "deg, model cells %.1f deg\n",
              worst_transition, worst_model);
  // The model's boundary area: the sum of |area| of the kOuterBoundary faces is the bare model's, but
  // for the deactivated cells' surface faces, now their triangles (a bent face's triangles have more
  // area than its vector area: the difference is counted, not tolerated).
  auto outer_area = [](const HybridMesh& h) {
    double a = 0;
    for (int32_t f = 0; f < h.mesh.n_faces(); ++f)
      if (h.mesh.face_patch[f] == kOuterBoundary) a += norm(h.geometry.face_area[f]);
    return a;
  };
  double bare_dead_area = 0;
  for (int32_t f = 0; f < bare.mesh.n_faces(); ++f) {
    if (bare.mesh.face_patch[f] != kOuterBoundary) continue;
    const auto& ijk = bare.mesh.cell_ijk[bare.mesh.face_owner[f]];
    if (dead_cells.count(ijk[0] + m.nx * (ijk[1] + m.ny * ijk[2]))) bare_dead_area += norm(bare.geometry.face_area[f]);
  }
  const double a_wells = outer_area(out), a_bare = outer_area(bare), bend = surface_triangle_area - bare_dead_area;
  std::printf("[ figures  ] outer surface: %zu triangles of deactivated cells; boundary area %.9f vs model %.9f "
              "(bent faces' triangles add %.3e relative; the rest differs by %.2e relative)\n",
              surface, a_wells, a_bare, bend / a_bare, (a_wells - a_bare - bend) / a_bare);
  EXPECT_GE(bend, -1e-12 * a_bare);
  EXPECT_NEAR((a_wells - bend) / a_bare, 1.0, 1e-12);
  // Volume: the model without wells, minus the wellbore holes, minus what the triangles of the bent
  // surface faces cut off the model's fans.
  std::printf("[ figures  ] volume vs model - wellbore - bent surface faces %.9f (rel %.2e; the bent faces cut "
              "%.3e m3, %.2e relative)\n",
              v0 - hole - bent_volume, v / (v0 - hole - bent_volume) - 1, bent_volume, bent_volume / v0);
  EXPECT_NEAR(v / (v0 - hole - bent_volume), 1.0, 1e-9);
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

// A vertical well through cells MINPV removes (layer 6 thinning to 0 at x = 100 m, MINPV 120 rm3 removing
// its cells under 1.1 m, the column the well is in among them): the removed cells are holes of the model as
// in OPM Flow; the well meshes soundly (the cavity's walls include the faces toward the holes), and the
// connections across the removed cells outside the cavity are the mesh's connections without a face.
TEST(CornerPointWells, WellThroughCellsMinpvRemovesMeshes) {
  TempDir tmp("cpwells_minpv");
  TiltedModel g;
  g.pinch_k = 6, g.pinch_x = 100;
  g.keywords = "MINPV\n 120 /\n";
  const CaseSpec cs = case_of(tmp, g, vertical_well(90, 90, 1034, 1046));
  const CornerPointModel& m = *cs.reservoir.corner_point;
  const CornerPointModel as_read = read_corner_point_model((tmp.path / "M.GRDECL").string(), "reservoir.grdecl");
  ASSERT_GT(m.below_minpv, 0);
  // The well's cell of layer 6 is below MINPV (removed in the model as read) and kept near the well.
  const size_t well_cell = static_cast<size_t>(4 + m.nx * (4 + m.ny * 6));
  EXPECT_EQ(as_read.actnum[well_cell], 0);
  EXPECT_EQ(m.actnum[well_cell], 1);
  EXPECT_LT(m.minpv_removed.size(), as_read.minpv_removed.size());
  EXPECT_GT(m.minpv_removed.size(), 0u);
  HybridMesh out;
  ASSERT_NO_THROW(out = build_hybrid_mesh(cs));
  expect_sound_mesh(cs, out);
  int connections = 0;
  for (int k = 0; k < out.mesh.n_nncs(); ++k) connections += out.mesh.nnc_trans[k] > 0;
  std::printf("[ figures  ] MINPV: %zu cells below it, %zu kept near the well, %zu pairs, %d connections without a "
              "face in the mesh\n",
              as_read.minpv_removed.size(), as_read.minpv_removed.size() - m.minpv_removed.size(),
              m.minpv_connections.size(), connections);
  EXPECT_GT(connections, 0);
}

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

// The summary's in-mesh Q_O of the transition cells is fvcheck's measure (each face toward its
// neighbour's FV centre, boundary faces toward their flux point), not the paper's Table 2 measure on a
// cavity's own submesh, where a corner-point wall triangle whose circumcentre lies outside it (its
// site's foot) is far from its centroid: there the paper's figure says nothing of the fluxes.
TEST(CornerPointWells, TransitionOrthogonalityInTheMeshIsWhatTheFluxesSee) {
  TempDir tmp("cpwells");
  const TiltedModel g;
  const CaseSpec cs = case_of(tmp, g, vertical_well(90, 90, 1034, 1046));
  const HybridMesh out = build_hybrid_mesh(cs);
  const std::vector<double> q_o = cell_min_of_faces(out.mesh, face_orthogonality(out.mesh, out.geometry));
  std::vector<bool> transition(out.mesh.n_cells());
  for (int c = 0; c < out.mesh.n_cells(); ++c) transition[c] = out.mesh.cell_region[c] == kTransition;
  const Stats expected = stats_of(q_o, transition);
  ASSERT_GT(expected.count, 0);
  EXPECT_EQ(out.transition_q_o_in_mesh.count, expected.count);
  EXPECT_DOUBLE_EQ(out.transition_q_o_in_mesh.min, expected.min);
  EXPECT_NEAR(out.transition_q_o_in_mesh.mean, expected.mean, 1e-12 * expected.mean);
  EXPECT_GE(out.transition_q_o_in_mesh.min, 45.0);  // the self-check's bound
  std::printf("[ Q_O ] transition cells in the mesh: min %.2f mean %.2f deg; the paper's submesh measure: min %.4g mean "
              "%.2f deg\n", out.transition_q_o_in_mesh.min, out.transition_q_o_in_mesh.mean,
              out.transition_after.q_o.min, out.transition_after.q_o.mean);
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

// metric: permeability in a corner-point model (docs/anisotropy.md, "Corner-point models"): the model
// and the wells are meshed in the frame of K, the mesh mapped back. Rock of one anisotropy (kv/kh 0.1,
// PERMX varying by cell) and a deviated well across inclined pillars. What can fail: the mesh is sound
// (expect_sound_mesh: self-check, volume, every model face toward the cavity once); its model cells'
// nodes are the model's corners exactly (the deck's COORD/ZCORN), not their images mapped back; every
// face between two near-well cells is K-orthogonal to round-off (hemispherical caps; flat ends lean a few
// degrees, docs/anisotropy.md), where the Euclidean mesh of the same case is not.
TEST(CornerPointWells, PermeabilityMetricMakesTheNearWellCellsKOrthogonal) {
  TempDir tmp("cpwells");
  TiltedModel g;
  g.nz = 22, g.inclined_pillars = true, g.kv_kh = 0.1;
  std::ofstream(tmp.path / "M.GRDECL") << g.text();
  std::string well = hmtest::deviated_well_yaml();
  well.replace(well.find("end_caps: flat"), 14, "end_caps: hemisphere");  // flat ends lean (docs/anisotropy.md)
  std::ofstream(tmp.path / "e.yaml") << "name: e\nreservoir: {grdecl: M.GRDECL}\n" << well;
  std::ofstream(tmp.path / "k.yaml") << "name: k\nmetric: permeability\nreservoir: {grdecl: M.GRDECL}\n" << well;
  const CaseSpec ce = load_case((tmp.path / "e.yaml").string()), ck = load_case((tmp.path / "k.yaml").string());
  ASSERT_TRUE(ck.reservoir.corner_point);
  HybridMesh k;
  ASSERT_NO_THROW(k = build_hybrid_mesh(ck));  // gtest prints the exception's what()
  expect_sound_mesh(ck, k);
  EXPECT_NEAR(k.frame.scale.z / k.frame.scale.x, std::sqrt(0.1), 1e-12);
  // The model cells' nodes: the model's corners, bit for bit.
  std::vector<Vec3> corners;
  all_cell_faces(*ck.reservoir.corner_point, &corners);
  std::set<std::array<double, 3>> corner_at;
  for (const Vec3& p : corners) corner_at.insert({p.x, p.y, p.z});
  int64_t model_nodes = 0, off = 0;
  for (int c = 0; c < k.mesh.n_cells(); ++c) {
    if (k.mesh.cell_region[c] != kReservoir) continue;
    for (const int32_t* f = k.mesh.cell_begin(c); f != k.mesh.cell_end(c); ++f)
      for (const int32_t* v = k.mesh.face_begin(*f); v != k.mesh.face_end(*f); ++v) {
        const Vec3 p = k.mesh.nodes[*v];
        ++model_nodes;
        off += corner_at.count({p.x, p.y, p.z}) == 0;
      }
  }
  EXPECT_GT(model_nodes, 0);
  EXPECT_EQ(off, 0) << "model nodes moved by the way back from the frame";
  // K-non-orthogonality of the faces between near-well cells, with the cells' own K.
  // Faces below kMicroFace m2 (micro-faces of the power diagram, millimetres wide) have normals that
  // rounding turns by more; they are reported apart.
  constexpr double kMicroFace = 1e-4;
  auto near_well = [](const HybridMesh& h, bool micro) {
    const std::vector<double> angle = face_k_nonorthogonality(h.mesh, h.geometry);
    std::vector<double> values;
    for (int f = 0; f < h.mesh.n_faces(); ++f) {
      const int32_t o = h.mesh.face_owner[f], n = h.mesh.face_neighbour[f];
      if (n >= 0 && h.mesh.cell_region[o] != kReservoir && h.mesh.cell_region[n] != kReservoir &&
          (norm(h.geometry.face_area[f]) < kMicroFace) == micro)
        values.push_back(angle[f]);
    }
    return stats_of(values);
  };
  const HybridMesh e = build_hybrid_mesh(ce);
  const Stats sk = near_well(k, false), se = near_well(e, false), micro = near_well(k, true);
  std::printf("[ K-orth   ] micro-faces (< %g m2) between near-well cells, permeability metric: max %.3g deg (%ld faces)\n",
              kMicroFace, micro.max, static_cast<long>(micro.count));
  EXPECT_LE(micro.max, 1e-4);
  std::printf("[ K-orth   ] faces between near-well cells, K-non-orthogonality max / mean: permeability metric %.3g / %.3g "
              "deg (%ld faces), euclidean %.3g / %.3g deg (%ld faces)\n",
              sk.max, sk.mean, static_cast<long>(sk.count), se.max, se.mean, static_cast<long>(se.count));
  ASSERT_GT(sk.count, 0);
  EXPECT_LE(sk.max, 1e-6);  // round-off
  EXPECT_GT(se.max, 10.0);
}

namespace {

// A tilted, twisted model of small columns (6 x 6 m, 3 m layers): the top triangles' diametral
// spheres (radius 4.2 m) clear a well 8 m below the top, whose cavity (dilation 1.5 x 5 m) reaches it.
TiltedModel small_columns() {
  TiltedModel g;
  g.nx = g.ny = 15, g.nz = 16, g.dx = g.dy = 6, g.dz = 3;
  return g;
}

// Meshes model g with `wells`, checks the mesh (expect_sound_mesh), and that the cavity reaches the
// outer surface only where expected: each of its triangles there is on a cell `where` accepts (model
// cell index) and points into that cell (toward the mean of its corners).
void expect_meshes_reaching_the_surface(const TiltedModel& g, const std::string& wells,
                                        const std::function<bool(const CornerPointModel&, int)>& where) {
  TempDir tmp("cpsurface");
  const CaseSpec cs = case_of(tmp, g, wells);
  HybridMesh out;
  ASSERT_NO_THROW(out = build_hybrid_mesh(cs));
  expect_sound_mesh(cs, out);
  const CornerPointModel& m = *cs.reservoir.corner_point;
  size_t on_surface = 0;
  for (const Cavity& cav : out.cavities.cavities)
    for (const ConstrainedFace& t : cav.faces) {
      if (t.side != FaceSide::Reservoir || t.outside_cell >= 0) continue;
      ++on_surface;
      EXPECT_TRUE(where(m, t.inside_cell)) << "a surface triangle on cell " << t.inside_cell;
      const Vec3 a = out.cavity_node_coords[t.nodes[0]], b = out.cavity_node_coords[t.nodes[1]],
                 c = out.cavity_node_coords[t.nodes[2]];
      Vec3 centre{0, 0, 0};
      for (int q = 0; q < 8; ++q) centre += model_cell_corner(m, t.inside_cell, q) / 8.0;
      EXPECT_GT(dot(cross(b - a, c - a), centre - (a + b + c) / 3.0), 0) << "a surface triangle not oriented into the cavity";
    }
  EXPECT_GT(on_surface, 0u) << "the cavity does not reach the surface: the case tests nothing";
}

}  // namespace

// The cavity reaches the model's top (twisted: no top face is planar): it meshes, the top's triangles
// over the deactivated cells are outer-boundary faces of transition cells (docs/corner-point.md).
TEST(CornerPointSurface, WellReachingTheTopMeshes) {
  expect_meshes_reaching_the_surface(small_columns(), vertical_well(45, 45, 1013, 1025),
                                     [](const CornerPointModel& m, int c) { return c / (m.nx * m.ny) == 0; });
}

// A well in the corner column of the bent-sided model, its cavity reaching the top and the two sides
// x = 0 and y = 0 where they meet (the model's corner: transition cells on three bent surfaces).
TEST(CornerPointSurface, WellReachingACornerMeshes) {
  TiltedModel g = small_columns();
  g.inclined_pillars = true, g.pillar_twist = 0.03;
  expect_meshes_reaching_the_surface(g, vertical_well(14, 14, 1010, 1022), [](const CornerPointModel& m, int c) {
    return c / (m.nx * m.ny) == 0 || c % m.nx == 0 || (c / m.nx) % m.ny == 0;
  });
}

// The same beside a fault of half a layer's throw on pillar line x = 48 m, through the cavity: the top
// steps down 1.5 m across it, and the up-thrown cells' fault faces above the down-thrown top (no cell
// across) are surface triangles too.
TEST(CornerPointSurface, WellReachingTheTopAcrossAFaultStepMeshes) {
  TiltedModel g = small_columns();
  g.fault_i = 8, g.throw_m = 1.5;
  expect_meshes_reaching_the_surface(g, vertical_well(45, 45, 1013, 1025),
                                     [](const CornerPointModel& m, int c) { return c / (m.nx * m.ny) == 0; });
}

// A cavity inside the model beside an inactive cell (ACTNUM 0, 9 m from the well's axis): the faces
// toward it have no meshed cell across and are surface triangles, outer-boundary faces inside the model.
TEST(CornerPointSurface, WellBesideAnInactiveCellMeshes) {
  TiltedModel g = small_columns();
  const int gap = 9 + g.nx * (7 + g.ny * 7);  // (10, 8, 8), beside the cavity's column i = 9
  g.inactive = {gap};
  expect_meshes_reaching_the_surface(g, vertical_well(45, 45, 1023, 1035), [gap](const CornerPointModel& m, int c) {
    return c == gap - 1 || c == gap + 1 || c == gap - m.nx || c == gap + m.nx || c == gap - m.nx * m.ny ||
           c == gap + m.nx * m.ny;
  });
}

// The cavity reaches a side of a model with inclined, non-parallel pillars whose slope varies along
// the side (the side faces are not planar): it meshes likewise.
TEST(CornerPointSurface, WellReachingASideMeshes) {
  TiltedModel g = small_columns();
  g.inclined_pillars = true, g.pillar_twist = 0.03;
  expect_meshes_reaching_the_surface(g, vertical_well(14, 45, 1018, 1030),
                                     [](const CornerPointModel& m, int c) { return c % m.nx == 0; });
}

// A well whose path starts above the model (as a survey from the wellhead does) or ends below it: the
// radial block is built around its part inside the model, its flat end kSurfaceGap x R inside the
// surface, the transition fills the rest to the surface (docs/corner-point.md, "Wells through the
// model's surface"). What can fail: the meshed path is the user's (same line, measured depths carried),
// its crossing end keeps the gap from the model's top under it, the mesh is sound, and it is the mesh of
// the same well given from its meshed start.
TEST(CornerPointSurface, WellFromAboveTheModelIsMeshedFromInsideIt) {
  const TiltedModel g = small_columns();
  const double x = 45, y = 45, z_head = 985, z_end = 1025, R = 5;
  TempDir tmp("cpsurface");
  const CaseSpec cs = case_of(tmp, g, vertical_well(x, y, z_head, z_end));
  const WellSpec& w = cs.wells[0];
  ASSERT_EQ(w.trajectory.size(), 2u);
  const Vec3 start = w.trajectory.front();
  EXPECT_EQ(start.x, x);
  EXPECT_EQ(start.y, y);
  EXPECT_EQ(w.trajectory.back(), (Vec3{x, y, z_end}));
  ASSERT_EQ(w.trajectory_md.size(), 2u);
  EXPECT_NEAR(w.trajectory_md[0], start.z - z_head, 1e-9);
  EXPECT_NEAR(w.trajectory_md[1], z_end - z_head, 1e-9);
  // The model's top under the well: its top-layer cell's top face (planar layers, twisted by 1e-4 x y),
  // bilinear in the column holding (x, y).
  const int I = static_cast<int>(x / g.dx), J = static_cast<int>(y / g.dy);
  const double u = x / g.dx - I, v = y / g.dy - J;
  const double top = (1 - u) * (1 - v) * g.depth(I, I, J, 0) + u * (1 - v) * g.depth(I, I + 1, J, 0) +
                     (1 - u) * v * g.depth(I, I, J + 1, 0) + u * v * g.depth(I, I + 1, J + 1, 0);
  std::printf("[ figures  ] well from z = %g above the top (%.3f under the well): block from z = %.3f (%.3f m = %.3f R "
              "below the top)\n",
              z_head, top, start.z, start.z - top, (start.z - top) / R);
  // The disc's rim keeps the gap from the top, which dips (its slope at the well, from depth()):
  // the axis clears it by gap + R slope, to a step of R / 16.
  const double slope = std::hypot(std::tan(g.dip_deg * M_PI / 180) + 1e-4 * y, 0.01 + 1e-4 * x);
  EXPECT_GE(start.z - top, kSurfaceGap * R);
  EXPECT_LE(start.z - top, (kSurfaceGap + slope) * R * std::sqrt(1 + slope * slope) + R / 16);
  bool noted = false;
  for (const std::string& n : cs.notes) noted = noted || n.find("crosses the corner-point model's surface") != std::string::npos;
  EXPECT_TRUE(noted);
  HybridMesh out;
  ASSERT_NO_THROW(out = build_hybrid_mesh(cs));
  expect_sound_mesh(cs, out);
  EXPECT_EQ(out.notes.front(), cs.notes.front());
  // The same well given from its meshed start: the same mesh.
  TempDir tmp2("cpsurface");
  const CaseSpec inside = case_of(tmp2, g, vertical_well(x, y, start.z, z_end));
  ASSERT_EQ(inside.wells[0].trajectory, w.trajectory);
  const HybridMesh same = build_hybrid_mesh(inside);
  EXPECT_EQ(same.mesh.nodes, out.mesh.nodes);
  EXPECT_EQ(same.mesh.face_nodes, out.mesh.face_nodes);
  EXPECT_EQ(same.mesh.cell_faces, out.mesh.cell_faces);
}

// A deviated well entering through the top at 40 degrees from the vertical and leaving through the
// bottom: both ends are cut back inside, and it meshes soundly.
TEST(CornerPointSurface, DeviatedWellThroughTopAndBottomMeshes) {
  TiltedModel g = small_columns();
  const double dip = std::tan(40 * M_PI / 180);
  const Vec3 a{20, 40, 980}, b{20 + dip * 100, 40, 1080};
  TempDir tmp("cpsurface");
  const CaseSpec cs = case_of(tmp, g,
                              "wells:\n  - {name: P1, trajectory: [[" + num(a.x) + ", " + num(a.y) + ", " + num(a.z) +
                                  "], [" + num(b.x) + ", " + num(b.y) + ", " + num(b.z) +
                                  "]], radius: 0.1, drainage_radius: 5, rings: 4, sectors: 12, segment_length: 4, bhp: 150}\n");
  const WellSpec& w = cs.wells[0];
  EXPECT_EQ(w.end_caps, EndCaps::Flat);  // auto caps: flat where the path is cut
  EXPECT_GT(w.trajectory_md.front(), 20 / std::cos(40 * M_PI / 180));  // the top is >= 1000 deep, 20 m under the head
  EXPECT_LT(w.trajectory_md.back(), norm(b - a));
  std::printf("[ figures  ] deviated 40 deg through top and bottom: meshed from md %.3f to %.3f of %.3f m\n",
              w.trajectory_md.front(), w.trajectory_md.back(), norm(b - a));
  HybridMesh out;
  ASSERT_NO_THROW(out = build_hybrid_mesh(cs));
  expect_sound_mesh(cs, out);
}

// Paths the model cannot take, refused with the reason (exit 2): none of it inside, explicit
// hemispherical caps on a cut path.
TEST(CornerPointSurface, PathsOutsideTheModelAreRefusedWithTheReason) {
  TempDir tmp("cpsurface");
  auto refusal = [&](const std::string& wells) {
    try {
      case_of(tmp, small_columns(), wells);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  std::string what = refusal(vertical_well(45, 45, 900, 990));
  EXPECT_NE(what.find("wells[0].trajectory: no part of it lies inside"), std::string::npos) << what;
  std::string caps = vertical_well(45, 45, 985, 1025);
  caps.replace(caps.find("end_caps: flat"), 14, "end_caps: hemisphere");
  what = refusal(caps);
  EXPECT_NE(what.find("wells[0].end_caps: hemisphere caps need both ends"), std::string::npos) << what;
}

// 20 x 20 m columns: a top triangle's diametral sphere (radius 14 m) holds the well block 2.4 m below
// the top; the top cannot move away (no cell behind it to deactivate): refused (exit 2), naming the
// top-layer cell and the well.
TEST(CornerPointSurface, WellTooNearTheTopForItsFacesIsRefusedWithTheReason) {
  TempDir tmp("cpsurface");
  const CaseSpec cs = case_of(tmp, TiltedModel{}, vertical_well(90, 90, 1012, 1030));
  try {
    build_hybrid_mesh(cs);
    ADD_FAILURE() << "a well inside the diametral spheres of the top's triangles was meshed";
  } catch (const InputError& e) {
    const std::string what = e.what();
    std::printf("[ figures  ] well 2.4 m below a top of 20 m faces: %s\n", e.what());
    EXPECT_NE(what.find("reaches the model's outer surface"), std::string::npos) << what;
    EXPECT_NE(what.find("cannot be made Gabriel"), std::string::npos) << what;
    EXPECT_NE(what.find("wells[0] (P1)"), std::string::npos) << what;
    EXPECT_NE(what.find(", 1), where"), std::string::npos) << "the named cell is not in the top layer: " << what;
  }
}

// A vertical well 3 m beside a fault of 0.96 layer's throw (2.88 m in 3 m layers, 6 m columns), its
// cavity across the fault: the steps of 4 % of a layer that are left are too thin to split; they are
// moved onto the other side's boundaries near the well (snap_thin_fault_steps, with a note) and the
// case meshes soundly.
TEST(CornerPointWells, WellAcrossANearlyWholeLayerThrowMeshesSoundly) {
  TempDir tmp("cpwells");
  TiltedModel g = small_columns();
  g.fault_i = 8, g.throw_m = 0.96 * g.dz;
  const CaseSpec cs = case_of(tmp, g, vertical_well(45, 45, 1023, 1035));
  EXPECT_TRUE(std::any_of(cs.notes.begin(), cs.notes.end(), [](const std::string& n) {
    return n.find("onto the other side's layer boundary") != std::string::npos;
  }));
  const HybridMesh out = build_hybrid_mesh(cs);
  expect_sound_mesh(cs, out);
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

// A fault of 10 m throw (2.2 layers of 4.5 m) crossed by a deviated well, and a layer above it that
// pinches out toward the fault. The cavity's walls had fault overlaps 1 m and 3.5 m high beside whole
// faces, and the site correction did not converge on their triangles (refused, stage transition, until
// session 24). The layers near the well are now split at the other side's boundaries (docs/corner-point.md,
// "Fault steps"): the two sides meet face to face and the case meshes soundly.
// The pinching layer one lower (pinch_k 9) thins to nothing on the fault pillar right above the well's start.
TEST(CornerPointWells, WellAcrossAFaultOfTenMetresMeshesSoundly) {
  for (const int pinch_k : {10, 9}) {
    SCOPED_TRACE("pinch_k " + std::to_string(pinch_k));
    TempDir tmp("cpwells");
    TiltedModel g;
    g.nz = 22, g.fault_i = 5, g.throw_m = 10, g.pinch_k = pinch_k, g.pinch_x = 100;
    const CaseSpec cs = case_of(tmp, g, hmtest::deviated_well_yaml());
    EXPECT_GT(cs.reservoir.corner_point->nz, g.nz);
    EXPECT_TRUE(std::any_of(cs.notes.begin(), cs.notes.end(),
                            [](const std::string& n) { return n.find("\"Fault steps\"") != std::string::npos; }));
    const HybridMesh out = build_hybrid_mesh(cs);
    expect_sound_mesh(cs, out);
    if (HasFatalFailure()) return;
  }
}

// The 10 m fault model of the flow test (a pinching layer, MINPV), the deviated producer across the
// fault, and an injector where the producer's refined rows and columns pass beside it (its own 20 m
// columns are not wider than 4 of its 5 m cells). It failed at all four places (session 24: the cavity's
// walls were cells 3 m wide and 20 m long; and at (150, 150) the cavity was not a 2-manifold across the
// split's zero-thickness layers). The injector's columns are now refined to its size too
// (docs/corner-point.md, "Near-well refinement", two wells); each case meshes soundly.
TEST(CornerPointWells, SecondWellBesideTheFirstOnesChildrenMeshesSoundly) {
  TiltedModel g;
  g.fault_i = 5, g.throw_m = 10, g.pinch_k = 5, g.pinch_x = 180;
  g.keywords = "MINPV\n 120 /\n";
  for (const auto& [x, y] : {std::pair{40.0, 150.0}, {150.0, 150.0}, {150.0, 40.0}, {140.0, 90.0}}) {
    SCOPED_TRACE("injector at (" + num(x) + ", " + num(y) + ")");
    TempDir tmp("cpwells2");
    const CaseSpec cs = case_of(tmp, g, hmtest::deviated_well_yaml() + hmtest::injector_yaml(x, y, 1045, 1057));
    const HybridMesh out = build_hybrid_mesh(cs);
    expect_sound_mesh(cs, out);
    if (HasFatalFailure()) return;
  }
}

// Two deactivated cells that touch only along an edge across a layer of zero thickness (a pinch-out, or
// the children of none that a split at fault steps leaves): in the model's index space they are two
// layers apart, so regularize_deactivated sees nothing, yet the cavity's boundary has an edge of four
// triangles. regularize_cavity_surface deactivates the cells around it: afterwards every edge of the
// boundary is used by exactly two triangles and the deactivated cells are one face-connected set.
TEST(CornerPointWells, CavityAcrossAZeroThicknessLayerIsMadeAManifold) {
  TempDir tmp("cpcavity");
  TiltedModel g;
  g.nx = 5, g.ny = 4, g.nz = 5, g.pinch_k = 2, g.pinch_x = -100;  // layer 2 of no thickness anywhere
  const CaseSpec cs = case_of(tmp, g, "");
  const CornerPointModel& m = *cs.reservoir.corner_point;
  std::vector<Vec3> coords;
  const CornerPointCellFaces cells = all_cell_faces(m, &coords);
  auto cell = [&](int i, int j, int k) { return i + m.nx * (j + m.ny * k); };
  ASSERT_FALSE(cells.meshed[cell(1, 1, 2)]);
  std::vector<char> active(m.actnum.size(), 1);
  active[cell(1, 1, 1)] = active[cell(2, 1, 3)] = 0;
  // The boundary's triangles per undirected edge (the deactivated cells lie inside the model: the
  // active cells' triangles toward them are the whole boundary).
  auto most_used_edge = [&] {
    std::map<std::pair<int32_t, int32_t>, int> uses;
    for (size_t c = 0; c < active.size(); ++c)
      if (cells.meshed[c] && active[c])
        for (const CavityTriangle& t : cavity_triangles(cells, static_cast<int>(c), active, coords))
          for (size_t e = 0; e < 3; ++e) ++uses[{std::min(t.nodes[e], t.nodes[(e + 1) % 3]), std::max(t.nodes[e], t.nodes[(e + 1) % 3])}];
    int most = 0, least = 99;
    for (const auto& [e, n] : uses) most = std::max(most, n), least = std::min(least, n);
    EXPECT_EQ(least, 2);
    return most;
  };
  EXPECT_EQ(most_used_edge(), 4);  // fail half: the two cells' shared edge
  std::vector<char> in_index_space = active;
  EXPECT_EQ(regularize_deactivated(make_reservoir_grid(cs.reservoir), in_index_space), 0);
  const int added = regularize_cavity_surface(cells, active, coords);
  EXPECT_GE(added, 1);
  EXPECT_EQ(most_used_edge(), 2);
  std::vector<int32_t> dead;
  for (size_t c = 0; c < active.size(); ++c)
    if (cells.meshed[c] && !active[c]) dead.push_back(static_cast<int32_t>(c));
  std::set<int32_t> reached{dead[0]};
  std::vector<int32_t> stack{dead[0]};
  while (!stack.empty()) {
    const int32_t c = stack.back();
    stack.pop_back();
    for (int64_t f = cells.face_begin(c); f < cells.face_end(c); ++f)
      if (const int32_t nb = cells.neighbour[f]; nb >= 0 && !active[nb] && reached.insert(nb).second) stack.push_back(nb);
  }
  EXPECT_EQ(reached.size(), dead.size());
  std::printf("[ figures  ] two cells meeting at an edge across a zero-thickness layer: %d cells added, %zu deactivated\n",
              added, dead.size());
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

// The model's transmissibility multipliers on the mesh (docs/corner-point.md, "Transmissibility
// multipliers"), decided here from the geometry, not from the cells' indices: a face of model cell a
// takes OPM's product m_d(a) m_-d(b), d the largest axis of its normal out of a, b the model cell across
// it: the other model cell, or for a cavity-wall face the deactivated cell holding the point 1e-4 m
// beyond its centroid. Faces of near-well cells only: 1. The multipliers between cavity cells (MULTZ
// 0.02 of layer 6 among them) are named in a note, and the multipliers survive mesh.vtu.
TEST(CornerPointWells, ModelMultipliersAreOnTheModelFacesAndTheCavityWalls) {
  TempDir tmp("cpmult");
  TiltedModel g;
  g.keywords = hmtest::multiplier_keywords(g, 6);
  const CaseSpec cs = case_of(tmp, g, vertical_well(90, 90, 1034, 1046));
  const HybridMesh out = build_hybrid_mesh(cs);
  expect_sound_mesh(cs, out);
  const CornerPointModel& model = *cs.reservoir.corner_point;
  const PolyMesh& m = out.mesh;
  ASSERT_EQ(m.face_trans_mult.size(), static_cast<size_t>(m.n_faces()));

  std::vector<Vec3> coords;
  const CornerPointCellFaces faces = all_cell_faces(model, &coords);
  std::vector<int32_t> dead;
  for (const Cavity& cav : out.cavities.cavities) dead.insert(dead.end(), cav.deactivated_cells.begin(), cav.deactivated_cells.end());
  std::sort(dead.begin(), dead.end());
  const CornerPointLocator across(model, faces, dead, coords);
  auto natural = [&](int32_t c) {
    const auto& ijk = m.cell_ijk[c];
    return ijk[0] + model.nx * (ijk[1] + model.ny * ijk[2]);
  };
  int walls = 0, model_faces = 0;
  for (int f = 0; f < m.n_faces(); ++f) {
    const int32_t o = m.face_owner[f], n = m.face_neighbour[f];
    if (n < 0) {
      EXPECT_EQ(m.face_trans_mult[f], 1.0) << f;
      continue;
    }
    const bool ro = m.cell_region[o] == kReservoir, rn = m.cell_region[n] == kReservoir;
    if (!ro && !rn) {
      EXPECT_EQ(m.face_trans_mult[f], 1.0) << f;
      continue;
    }
    const int32_t a = ro ? o : n;
    const Vec3 out_of_a = (a == o ? 1.0 : -1.0) * out.geometry.face_area[f];
    const double comp[3] = {out_of_a.x, out_of_a.y, out_of_a.z};
    int axis = 0;
    for (int d = 1; d < 3; ++d)
      if (std::abs(comp[d]) > std::abs(comp[axis])) axis = d;
    const bool plus = comp[axis] > 0;
    int b = -1;
    if (ro && rn) {
      b = natural(a == o ? n : o);
      ++model_faces;
    } else {
      b = across.cell_at(out.geometry.face_centroid[f] + (1e-4 / norm(out_of_a)) * out_of_a);
      ASSERT_GE(b, 0) << "no cavity cell across wall face " << f;
      ++walls;
    }
    const double expected =
        model.trans_mult[2 * axis + (plus ? 0 : 1)][natural(a)] * model.trans_mult[2 * axis + (plus ? 1 : 0)][b];
    ASSERT_EQ(m.face_trans_mult[f], expected) << "face " << f << " of model cell " << natural(a) << " toward " << b;
  }
  std::printf("[ figures  ] multipliers checked on %d model faces and %d cavity-wall faces\n", model_faces, walls);
  EXPECT_GT(walls, 50);
  const auto note = std::find_if(out.notes.begin(), out.notes.end(), [](const std::string& s) {
    return s.find("model faces between cavity cells carry transmissibility multipliers (0.02 to") != std::string::npos;
  });
  EXPECT_NE(note, out.notes.end());

  // mesh.vtu carries them: the same multiplier on the same face (faces keyed by their nodes).
  const std::string path = (tmp.path / "mesh.vtu").string();
  ASSERT_TRUE(write_vtu(path, m).ok);
  const ReadResult back = read_vtu(path);
  ASSERT_TRUE(back.ok) << back.error;
  ASSERT_EQ(back.mesh.n_faces(), m.n_faces());
  ASSERT_EQ(back.mesh.face_trans_mult.size(), static_cast<size_t>(m.n_faces()));
  std::map<std::vector<int32_t>, double> by_nodes;
  for (int f = 0; f < m.n_faces(); ++f) {
    std::vector<int32_t> key(m.face_begin(f), m.face_end(f));
    std::sort(key.begin(), key.end());
    by_nodes[key] = m.face_trans_mult[f];
  }
  for (int f = 0; f < back.mesh.n_faces(); ++f) {
    std::vector<int32_t> key(back.mesh.face_begin(f), back.mesh.face_end(f));
    std::sort(key.begin(), key.end());
    ASSERT_EQ(by_nodes.count(key), 1u) << f;
    ASSERT_EQ(back.mesh.face_trans_mult[f], by_nodes[key]) << f;
  }
}

// A model's mesh says so (PolyMesh::reservoir_cells_are_model), mesh.vtu carries it, and fvcheck then
// judges the shapes (convexity, orthogonality, auto-centering, planarity) of the near-well cells only,
// as the self-check does: the model's cells are the user's. The same mesh with the flag cleared is
// judged whole.
TEST(CornerPointWells, FvcheckJudgesTheNearWellCellsOfAModelsMeshReadFromItsVtu) {
  TempDir tmp("cpfvcheck");
  TiltedModel g;
  const CaseSpec cs = case_of(tmp, g, vertical_well(90, 90, 1034, 1046));
  const HybridMesh out = build_hybrid_mesh(cs);
  expect_sound_mesh(cs, out);
  ASSERT_TRUE(out.mesh.reservoir_cells_are_model);
  const std::string path = (tmp.path / "mesh.vtu").string();
  ASSERT_TRUE(write_vtu(path, out.mesh).ok);
  const ReadResult back = read_vtu(path);
  ASSERT_TRUE(back.ok) << back.error;
  EXPECT_TRUE(back.mesh.reservoir_cells_are_model);
  int64_t model = 0;
  for (int c = 0; c < back.mesh.n_cells(); ++c) model += back.mesh.cell_region[c] == kReservoir;
  const FvReport judged = run_fvcheck(back.mesh, CheckOptions{});
  EXPECT_EQ(judged.model_cells_not_judged, model);
  EXPECT_TRUE(judged.ok()) << report_summary_text(judged);

  PolyMesh whole = back.mesh;
  whole.reservoir_cells_are_model = false;
  const FvReport all = run_fvcheck(whole, CheckOptions{});
  EXPECT_EQ(all.model_cells_not_judged, 0);
  // Judged whole, the model's twisted cells are measured too: the worst convexity value is theirs.
  EXPECT_GT(all.find("convexity")->worst, judged.find("convexity")->worst);
  std::printf("[ figures  ] tilted model with a well: %lld model cells not judged; judged whole: convexity worst %.3g "
              "(near-well cells %.3g), %lld violations\n",
              static_cast<long long>(model), all.find("convexity")->worst, judged.find("convexity")->worst,
              static_cast<long long>(all.find("convexity")->violations));

  // A mesh without a model (the flag unset) writes no such field: read back, it stays unset.
  PolyMesh plain = out.mesh;
  plain.reservoir_cells_are_model = false;
  ASSERT_TRUE(write_vtu(path, plain).ok);
  EXPECT_FALSE(read_vtu(path).mesh.reservoir_cells_are_model);
}

// A vertical well from above through a model whose wide columns (60 m, R = 5 m) are refined near it:
// each block end keeps the gap the refined surface's faces and the block's end polygons ask
// (surface_gap), less than the kSurfaceGap x R kept where the surface's faces are as wide as the well
// (above), so the block is longer than the 1 R rule gives on the same model; the mesh is sound.
TEST(CornerPointSurface, RefinedSurfaceLetsTheBlockEndNearerToIt) {
  TiltedModel g;
  g.nx = g.ny = 5, g.nz = 10, g.dx = g.dy = 60, g.dz = 3;
  const double x = 150, y = 150, z_head = 980, z_end = 1070, R = 5;
  TempDir tmp("cpsurfacegap");
  const CaseSpec cs = case_of(tmp, g, vertical_well(x, y, z_head, z_end));
  const CornerPointModel& model = *cs.reservoir.corner_point;
  ASSERT_FALSE(model.parent_cell.empty()) << "the model is refined near the well";
  const WellSpec& w = cs.wells[0];
  WellSpec given = w;
  given.trajectory = {{x, y, z_head}, {x, y, z_end}};
  given.trajectory_md = {0, z_end - z_head};
  const ClippedPath by_surface = clip_path_to_model(model, given, "wells[0]", SurfaceGapRule::SurfaceFaces);
  const ClippedPath by_radius = clip_path_to_model(model, given, "wells[0]", SurfaceGapRule::DrainageRadius);
  EXPECT_EQ(w.trajectory, by_surface.points);
  for (int e = 0; e < 2; ++e) {
    EXPECT_GE(by_surface.gap[e], kSurfaceGapMin * R);
    EXPECT_LT(by_surface.gap[e], kSurfaceGap * R);
  }
  const double meshed = by_surface.md.back() - by_surface.md.front(), one_r = by_radius.md.back() - by_radius.md.front();
  std::printf("[ figures  ] refined surface: gaps %.3f and %.3f m (R = %g m); block %.3f m long, %.3f m with 1 R gaps\n",
              by_surface.gap[0], by_surface.gap[1], R, meshed, one_r);
  // 20.6 m against 18.75 with children of equal widths, 20.0 m with graded ones (the faces above the
  // well a little wider: gaps 4.17 m instead of 4.10).
  EXPECT_GT(meshed, one_r + R / 8);
  HybridMesh out;
  ASSERT_NO_THROW(out = build_hybrid_mesh(cs));
  expect_sound_mesh(cs, out);
}

// A well from above that ends inside the model 3 m over its bottom (R = 5 m): its end is moved back as a
// crossing end is, until the end cross-section keeps surface_gap from the bottom, and the case says so;
// the mesh is sound. (Wells of the corner-point sweep ending so, seeds 12, 17 and 20, were refused
// before: their cavity reached the bottom where the surface's triangles held the block's nodes.)
TEST(CornerPointSurface, WellEndingNearTheBottomIsMovedBackAsACrossingEnd) {
  TiltedModel g;
  g.nx = g.ny = 5, g.nz = 10, g.dx = g.dy = 60, g.dz = 3;
  const double x = 150, y = 150, R = 5;
  // The bottom under (x, y): the surface is bilinear in the column, as the depth formula is.
  const double bottom = 1000 + std::tan(g.dip_deg * M_PI / 180) * x + 0.01 * y + 1e-4 * x * y + g.dz * g.nz;
  const double z_end = bottom - 3;
  TempDir tmp("cpendnear");
  const CaseSpec cs = case_of(tmp, g, vertical_well(x, y, 980, z_end));
  const CornerPointModel& model = *cs.reservoir.corner_point;
  WellSpec given = cs.wells[0];
  given.trajectory = {{x, y, 980}, {x, y, z_end}};
  given.trajectory_md = {0, z_end - 980};
  const ClippedPath path = clip_path_to_model(model, given, "wells[0]", SurfaceGapRule::SurfaceFaces);
  EXPECT_TRUE(path.crosses[0]);
  EXPECT_FALSE(path.crosses[1]);
  EXPECT_GT(path.cut[1], 0.0);
  EXPECT_GE(path.gap[1], kSurfaceGapMin * R);
  EXPECT_LE(path.gap[1], kSurfaceGap * R);
  EXPECT_EQ(cs.wells[0].trajectory, path.points);
  EXPECT_LE(path.points.back().z, bottom - path.gap[1]);  // the end cross-section's centre keeps the gap too
  bool noted = false;
  for (const std::string& n : cs.notes) noted = noted || n.find("crosses the corner-point model's surface and ends near it") != std::string::npos;
  EXPECT_TRUE(noted);
  std::printf("[ figures  ] well ending 3 m over the bottom: block end moved back %.3f m (gap %.3f m, R = %g m)\n",
              path.cut[1], path.gap[1], R);
  HybridMesh out;
  ASSERT_NO_THROW(out = build_hybrid_mesh(cs));
  expect_sound_mesh(cs, out);
}

// A horizontal well 2 m over the model's bottom beside its block (R = 5 m, 6 rings: its ends keep the
// gap their end faces need, 1.9 m, "Wells through the model's surface"): the default outer faces
// (12 sectors, 4 m segments: diametral spheres of 2.4 m) would hold the bottom's nodes, which cannot
// move away, and the cavity was refused (exit 2, "cannot be made Gabriel"). The case now gives the
// block more sectors and shorter segments (fit_outer_faces, with a note), and the mesh is sound.
TEST(CornerPointSurface, HorizontalWellNearTheBottomGetsSmallerOuterFaces) {
  TiltedModel g;
  g.nx = g.ny = 20, g.nz = 14, g.dx = g.dy = 2, g.dz = 1.5;
  const double x = 20, R = 5, above = R + 2;
  auto bottom = [&](double y) { return g.depth(0, 10, 0, g.nz) + (0.01 + 1e-4 * x) * y; };  // x = 20 is pillar line 10
  TempDir tmp("cpbottom");
  const std::string wells = "wells:\n  - {name: P1, trajectory: [[" + num(x) + ", 8, " + num(bottom(8) - above) + "], [" +
                            num(x) + ", 32, " + num(bottom(32) - above) + "]], radius: 0.1, drainage_radius: " + num(R) +
                            ", rings: 6, sectors: 12, segment_length: 4, end_caps: flat, bhp: 150}\n";
  const CaseSpec cs = case_of(tmp, g, wells);
  const double clearance = surface_clearance(*cs.reservoir.corner_point, cs.wells[0]);
  EXPECT_NEAR(clearance, 2.0, 1e-3);  // 2 m vertically, the bottom sloping 0.7 degree along the well
  EXPECT_GT(cs.wells[0].sectors, 12);
  EXPECT_LT(cs.wells[0].segment_length, 4.0);
  bool noted = false;
  for (const std::string& n : cs.notes) noted = noted || n.find("its outer faces are made smaller") != std::string::npos;
  EXPECT_TRUE(noted);
  std::printf("[ figures  ] horizontal well %g m over the bottom: %d sectors, segments %.3f m\n", clearance,
              cs.wells[0].sectors, cs.wells[0].segment_length);
  HybridMesh out;
  ASSERT_NO_THROW(out = build_hybrid_mesh(cs));
  expect_sound_mesh(cs, out);
  // The block as the user gave it: refused at the cavity, as every such case was before.
  CaseSpec as_given = cs;
  as_given.wells[0].sectors = 12, as_given.wells[0].segment_length = 4;
  try {
    build_hybrid_mesh(as_given);
    ADD_FAILURE() << "the user's block was meshed: the case does not test the fit";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot be made Gabriel"), std::string::npos) << e.what();
  }
}

// CornerPointLocator tries only the cells of the query's bucket: the same answers as trying every
// cell in order (each cell alone in a locator of its own), on a faulted model with inclined, bent
// pillars and a pinch-out, at random points and at every cell's corner mean.
TEST(CornerPointLocator, BucketsGiveTheAnswerOfTryingEveryCell) {
  TempDir tmp("cplocate");
  TiltedModel g;
  g.nx = 7, g.ny = 6, g.nz = 8, g.fault_i = 3, g.throw_m = 7, g.inclined_pillars = true, g.pillar_twist = 0.3;
  g.pinch_k = 5;
  const CaseSpec cs = case_of(tmp, g, "");
  const CornerPointModel& model = *cs.reservoir.corner_point;
  std::vector<Vec3> coords;
  const CornerPointCellFaces faces = all_cell_faces(model, &coords);
  std::vector<int32_t> among;
  for (int32_t c = 0; c < static_cast<int32_t>(faces.meshed.size()); ++c)
    if (faces.meshed[c]) among.push_back(c);
  std::reverse(among.begin(), among.end());  // the order of `among` decides between cells sharing a face
  const CornerPointLocator locate(model, faces, among, coords);
  std::vector<CornerPointLocator> alone;
  for (int32_t c : among) alone.emplace_back(model, faces, std::vector<int32_t>{c}, coords);
  auto every_cell = [&](Vec3 x) {
    for (const CornerPointLocator& l : alone)
      if (int c = l.cell_at(x); c >= 0) return c;
    return -1;
  };
  Vec3 lo = coords[0], hi = coords[0];
  for (const Vec3& p : coords)
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
  std::vector<Vec3> points;
  uint64_t state = 12345;
  auto uniform = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(state >> 11) / 9007199254740992.0;
  };
  for (int i = 0; i < 600; ++i) {  // the box and a margin around it
    Vec3 x;
    for (int a = 0; a < 3; ++a) x[a] = lo[a] - 0.1 * (hi[a] - lo[a]) + 1.2 * (hi[a] - lo[a]) * uniform();
    points.push_back(x);
  }
  for (int32_t c : among) {
    Vec3 mean{0, 0, 0};
    for (int q = 0; q < 8; ++q) mean += model_cell_corner(model, c, q) / 8.0;
    points.push_back(mean);
  }
  int held = 0;
  for (const Vec3& x : points) {
    const int expected = every_cell(x);
    held += expected >= 0;
    EXPECT_EQ(locate.cell_at(x), expected) << x.x << " " << x.y << " " << x.z;
  }
  EXPECT_GT(held, static_cast<int>(among.size()));  // the corner means, and random points inside
  EXPECT_EQ(locate.cell_at(Vec3{NAN, 0, 0}), -1);
}
