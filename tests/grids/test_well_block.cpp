// Radial well block: closure, exact volumes, orthogonality, rotation-minimising frame,
// Gabriel condition (pass/fail pairs) and input errors, with flat ends and with
// hemispherical end caps (cap cells, their faces, graded end layers, the end_caps key).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "fvcheck/lib/checks.hpp"
#include "meshgen/core/geometry.hpp"
#include "meshgen/core/mesh_builder.hpp"
#include "meshgen/grids/gabriel.hpp"
#include "meshgen/grids/gabriel_predicates.hpp"
#include "meshgen/grids/well_block.hpp"

using namespace hm;

namespace {

constexpr double kPi = 3.14159265358979323846;

struct WellParams {
  std::vector<Vec3> trajectory;
  int sectors = 12;
  int rings = 6;
  double radius = 0.1;
  double drainage_radius = 8.0;
  double segment_length = 4.0;
  EndCaps end_caps = EndCaps::Hemisphere;  // the case default
};

CaseSpec make_case(const WellParams& p) {
  CaseSpec cs;
  cs.name = "well_block_test";
  cs.reservoir.x = {-200, 200};
  cs.reservoir.y = {-200, 200};
  cs.reservoir.z = {-200, 200};
  cs.reservoir.permeability = {120, 80, 15};
  cs.reservoir.porosity = 0.23;
  WellSpec w;
  w.name = "P1";
  w.trajectory = p.trajectory;
  w.radius = p.radius;
  w.drainage_radius = p.drainage_radius;
  w.rings = p.rings;
  w.sectors = p.sectors;
  w.segment_length = p.segment_length;
  w.end_caps = p.end_caps;
  cs.wells.push_back(w);
  return cs;
}

// A vertical leg of length l1 from the origin, then a leg of length l2 turned by `bend`
// degrees in the x-z plane.
std::vector<Vec3> bent(double bend_deg, double l1 = 40, double l2 = 40) {
  const double t = bend_deg * kPi / 180;
  return {{0, 0, 0}, {0, 0, l1}, {l2 * std::sin(t), 0, l1 + l2 * std::cos(t)}};
}

std::vector<Vec3> straight(Vec3 direction, double length = 40) {
  return {{10, -5, 3}, Vec3{10, -5, 3} + length * normalized(direction)};
}

const char* caps_name(EndCaps caps) { return caps == EndCaps::Flat ? "flat" : "hemisphere"; }

std::string first_problem(const std::vector<std::string>& v) { return v.empty() ? "" : v[0]; }

// The builder's key of a face cycle (rotation/orientation independent) plus its orientation.
std::pair<std::vector<int32_t>, bool> face_key(const std::vector<int32_t>& cycle) {
  bool reversed = false;
  std::vector<int32_t> key = canonical_cycle(cycle, &reversed);
  return {key, reversed};
}

struct BuiltBlock {
  WellBlock block;
  std::vector<int32_t> ids;
  PolyMesh mesh;
  BuildReport report;
  MeshGeometry geo;
};

BuiltBlock build(const CaseSpec& cs, int sectors) {
  BuiltBlock b;
  b.block = make_well_block(cs, 0, sectors);
  MeshBuilder builder;
  b.ids = add_well_block(b.block, builder);
  b.mesh = builder.finish(&b.report);
  b.geo = compute_geometry(b.mesh);
  return b;
}

// Reference rotation (axis-angle, normalised axis) taking unit d1 to unit d2.
Vec3 rotate_axis_angle(Vec3 x, Vec3 d1, Vec3 d2) {
  const Vec3 k = cross(d1, d2);
  if (norm(k) == 0) return x;
  const Vec3 axis = normalized(k);
  const double angle = std::acos(std::max(-1.0, std::min(1.0, dot(d1, d2))));
  return std::cos(angle) * x + std::sin(angle) * cross(axis, x) + (1 - std::cos(angle)) * dot(axis, x) * axis;
}

int brute_force_violations(const WellBlock& b, int* surely_inside) {
  std::set<std::pair<int32_t, int32_t>> edges;
  std::set<int32_t> verts;
  for (const auto& poly : b.surface_faces)
    for (size_t i = 0; i < poly.size(); ++i) {
      const int32_t a = poly[i], c = poly[(i + 1) % poly.size()];
      edges.insert({std::min(a, c), std::max(a, c)});
      verts.insert(a);
    }
  int maybe = 0;
  *surely_inside = 0;
  for (const auto& e : edges) {
    const Vec3 a = b.nodes[e.first], c = b.nodes[e.second];
    const Vec3 m = 0.5 * (a + c);
    const double r2 = 0.25 * norm2(c - a);
    for (int32_t p : verts) {
      if (p == e.first || p == e.second) continue;
      const double d2 = norm2(b.nodes[p] - m);
      if (d2 < r2 * (1 - 1e-9)) ++*surely_inside;
      if (d2 < r2 * (1 + 1e-9)) ++maybe;
    }
  }
  return maybe;
}

}  // namespace

// ---------------------------------------------------------------- closure and volumes

struct ShapeCase {
  const char* name;
  std::vector<Vec3> trajectory;
};

// Closure, exact volume and a closed outward outer surface are properties of every block:
// each trajectory runs with flat ends and with hemispherical caps.
class WellBlockShapes : public ::testing::TestWithParam<std::tuple<ShapeCase, EndCaps>> {
 protected:
  WellParams params() const {
    WellParams p;
    p.trajectory = std::get<0>(GetParam()).trajectory;
    p.end_caps = std::get<1>(GetParam());
    return p;
  }
  std::string label() const {
    return std::string(std::get<0>(GetParam()).name) + " " + caps_name(std::get<1>(GetParam()));
  }
};

TEST_P(WellBlockShapes, CellsClosedNotInvertedAndVolumeExact) {
  const WellParams p = params();
  const CaseSpec cs = make_case(p);
  const BuiltBlock b = build(cs, p.sectors);
  const WellBlock& blk = b.block;
  const bool hemispheres = p.end_caps == EndCaps::Hemisphere;
  ASSERT_EQ(blk.hemisphere_caps, hemispheres);
  const int bands = hemispheres ? hemisphere_cap_bands(p.sectors) : 0;
  ASSERT_EQ(blk.cell_faces.size(), static_cast<size_t>((blk.layers - 1 + 2 * bands) * blk.rings * blk.sectors));

  // The block alone: everything matches except the outer-surface faces, which are declared
  // interior (the transition mesh claims them).
  EXPECT_EQ(b.report.overused_faces, 0) << first_problem(b.report.problems);
  EXPECT_EQ(b.report.misoriented_faces, 0) << first_problem(b.report.problems);
  EXPECT_EQ(b.report.degenerate_faces, 0) << first_problem(b.report.problems);
  EXPECT_EQ(b.report.removed_unused_nodes, 0);
  EXPECT_TRUE(check_csr_invariants(b.mesh).ok);
  std::set<std::vector<int32_t>> unmatched, expected;
  int wellbore = 0;
  for (int f = 0; f < b.mesh.n_faces(); ++f) {
    if (b.mesh.face_patch[f] == kUnmatchedFace)
      unmatched.insert(face_key({b.mesh.face_begin(f), b.mesh.face_end(f)}).first);
    if (b.mesh.face_patch[f] == wellbore_patch(0)) ++wellbore;
  }
  for (size_t k = 0; k < blk.surface_faces.size(); ++k) {
    if (blk.surface_cell[k] < 0) continue;  // flat ends' wellbore polygons are no cell faces
    std::vector<int32_t> g;
    for (int32_t v : blk.surface_faces[k]) g.push_back(b.ids[v]);
    expected.insert(face_key(g).first);
  }
  EXPECT_EQ(unmatched, expected);
  EXPECT_EQ(b.report.unmatched_faces, static_cast<int>(expected.size()));
  // Ring-0 faces of the cylinder, plus the inner shell faces of both caps.
  EXPECT_EQ(wellbore, (blk.layers - 1 + 2 * bands) * blk.sectors);

  double total = 0;
  for (int c = 0; c < b.mesh.n_cells(); ++c) {
    double area_scale = 0;
    for (const int32_t* f = b.mesh.cell_begin(c); f != b.mesh.cell_end(c); ++f) area_scale += norm(b.geo.face_area[*f]);
    EXPECT_LE(norm(cell_area_sum(b.mesh, b.geo, c)), 1e-12 * area_scale) << "cell " << c;
    EXPECT_GT(b.geo.cell_volume[c], 0) << "cell " << c;
    total += b.geo.cell_volume[c];
  }
  const double exact = exact_well_block_volume(cs, 0, p.sectors);
  EXPECT_NEAR(total / exact, 1.0, 1e-12) << label() << ": " << total << " vs " << exact;
  RecordProperty("volume_relative_error", std::to_string(std::abs(total / exact - 1)));
  std::printf("[ volume    ] %-23s cells %5d  relative error %.2e\n", label().c_str(), b.mesh.n_cells(),
              std::abs(total / exact - 1));
}

TEST_P(WellBlockShapes, OuterSurfaceClosedAndOutward) {
  const WellParams p = params();
  const CaseSpec cs = make_case(p);
  const WellBlock blk = make_well_block(cs, 0, p.sectors);
  const bool hemispheres = p.end_caps == EndCaps::Hemisphere;
  ASSERT_EQ(blk.surface_faces.size(), blk.surface_cell.size());
  ASSERT_EQ(blk.surface_faces.size(), blk.surface_patch.size());
  // Every surface edge in exactly two polygons, with opposite directions.
  std::map<std::pair<int32_t, int32_t>, int> directed;
  for (const auto& poly : blk.surface_faces)
    for (size_t i = 0; i < poly.size(); ++i) ++directed[{poly[i], poly[(i + 1) % poly.size()]}];
  for (const auto& [edge, uses] : directed) {
    EXPECT_EQ(uses, 1) << edge.first << "->" << edge.second;
    auto back = directed.find({edge.second, edge.first});
    EXPECT_TRUE(back != directed.end() && back->second == 1) << edge.first << "->" << edge.second;
  }
  // Outward: the surface encloses the solid outer-polygon tube (block + capped wellbore),
  // whose volume is area(outer polygon) x L* (divergence theorem; L* = the trajectory length
  // on straight wells, less what the wedges cut at the bends), plus with hemispherical caps
  // the two polyhedral half-balls of radius R.
  double enclosed = 0;
  int wellbore_polygons = 0;
  for (size_t k = 0; k < blk.surface_faces.size(); ++k) {
    Vec3 area, centroid;
    const auto& poly = blk.surface_faces[k];
    polygon_area_centroid(blk.nodes, poly.data(), poly.data() + poly.size(), &area, &centroid);
    enclosed += dot(centroid, area) / 3.0;
    if (blk.surface_cell[k] < 0) {
      ++wellbore_polygons;
      EXPECT_EQ(blk.surface_patch[k], wellbore_patch(0));
      EXPECT_EQ(static_cast<int>(poly.size()), blk.sectors);
    } else {
      EXPECT_EQ(blk.surface_patch[k], kInteriorFace);
    }
  }
  // Flat: the side, both end annuli and the two wellbore polygons; hemispheres: the side and
  // the caps' outer shells only.
  const int side = (blk.layers - 1) * blk.sectors;
  if (hemispheres) {
    EXPECT_EQ(wellbore_polygons, 0);
    EXPECT_EQ(blk.surface_faces.size(), static_cast<size_t>(side + 2 * hemisphere_cap_bands(blk.sectors) * blk.sectors));
  } else {
    EXPECT_EQ(wellbore_polygons, 2);
    EXPECT_EQ(blk.surface_faces.size(), static_cast<size_t>(side + 2 * blk.rings * blk.sectors + 2));
  }
  const double length = well_block_prism_length(cs, 0, p.sectors);
  const double outer_area = 0.5 * p.sectors * p.drainage_radius * p.drainage_radius * std::sin(2 * kPi / p.sectors);
  const double caps = hemispheres ? 2 * hemisphere_cap_volume(p.drainage_radius, p.sectors) : 0.0;
  EXPECT_NEAR(enclosed / (outer_area * length + caps), 1.0, 1e-12) << label();
  // The same figure as the block plus its hole.
  EXPECT_NEAR(enclosed / (exact_well_block_volume(cs, 0, p.sectors) + exact_wellbore_hole_volume(cs, 0, p.sectors)), 1.0,
              1e-12)
      << label();
}

INSTANTIATE_TEST_SUITE_P(
    Trajectories, WellBlockShapes,
    ::testing::Combine(
        ::testing::Values(ShapeCase{"vertical", straight({0, 0, 1})}, ShapeCase{"deviated45", straight({1, 1, std::sqrt(2.0)})},
                          ShapeCase{"horizontal", straight({1, 0, 0})}, ShapeCase{"bend30", bent(30)},
                          ShapeCase{"bend60", bent(60)}, ShapeCase{"bend90", bent(90)},
                          ShapeCase{"twobends3d", {{0, 0, 0}, {0, 0, 30}, {20, 5, 50}, {25, 35, 60}}}),
        ::testing::Values(EndCaps::Flat, EndCaps::Hemisphere)),
    [](const ::testing::TestParamInfo<std::tuple<ShapeCase, EndCaps>>& info) {
      return std::string(std::get<0>(info.param).name) + "_" + caps_name(std::get<1>(info.param));
    });

// ---------------------------------------------------------------- cell data

TEST(WellBlock, CellAttributesAndNodeRadii) {
  WellParams p;
  p.trajectory = straight({0, 1, 1}, 20);
  p.segment_length = 5;
  p.end_caps = EndCaps::Flat;  // the node and cell index layout of a flat block (no graded end layers)
  const CaseSpec cs = make_case(p);
  const WellBlock blk = make_well_block(cs, 0, 8);
  ASSERT_EQ(blk.layers, 5);
  ASSERT_EQ(blk.radii.size(), 7u);
  EXPECT_EQ(blk.radii.front(), 0.1);
  EXPECT_EQ(blk.radii.back(), 8.0);
  for (int i = 0; i + 1 < 7; ++i) EXPECT_NEAR(blk.radii[i + 1] / blk.radii[i], std::pow(80.0, 1.0 / 6), 1e-12);
  EXPECT_EQ(blk.nodes.size(), static_cast<size_t>(5 * 7 * 8));
  const Vec3 d = normalized(p.trajectory[1] - p.trajectory[0]);
  for (int l = 0; l < blk.layers; ++l) {
    EXPECT_NEAR(norm(blk.layer_center[l] - (p.trajectory[0] + 5.0 * l * d)), 0, 1e-12);
    for (int i = 0; i <= 6; ++i)
      for (int s = 0; s < 8; ++s) {
        const Vec3 e = blk.nodes[(l * 7 + i) * 8 + s] - blk.layer_center[l];
        EXPECT_NEAR(dot(e, d), 0, 1e-12);              // perpendicular cross-sections
        EXPECT_NEAR(norm(e), blk.radii[i], 1e-12 * 8);  // nodes on the circle
      }
  }
  for (size_t c = 0; c < blk.cell_attrs.size(); ++c) {
    const CellAttributes& at = blk.cell_attrs[c];
    const RadialCellInfo& r = at.radial;
    EXPECT_EQ(at.region, kWell);
    EXPECT_EQ(at.ijk, (std::array<int32_t, 3>{-1, -1, -1}));
    EXPECT_EQ(at.perm, (Vec3{120, 80, 15}));
    EXPECT_EQ(at.porosity, 0.23);
    EXPECT_EQ(r.well, 0);
    EXPECT_EQ(static_cast<size_t>((r.segment * 6 + r.ring) * 8 + r.sector), c);
    EXPECT_EQ(r.r_in, blk.radii[r.ring]);
    EXPECT_EQ(r.r_out, blk.radii[r.ring + 1]);
    EXPECT_DOUBLE_EQ(r.r_center, std::sqrt(r.r_in * r.r_out));
    EXPECT_DOUBLE_EQ(r.angle, 2 * kPi / 8);
    EXPECT_NEAR(r.length, 5.0, 1e-12);
    // FV centre at radius r_center from the axis, at the mid angle of its sector.
    const Vec3 axis_mid = 0.5 * (blk.layer_center[r.segment] + blk.layer_center[r.segment + 1]);
    const Vec3 off = at.fv_center - axis_mid;
    EXPECT_NEAR(norm(off), r.r_center, 1e-12 * 8);
    EXPECT_NEAR(dot(off, d), 0, 1e-12);
    const Vec3 n0 = blk.nodes[(r.segment * 7) * 8 + r.sector] - blk.layer_center[r.segment];
    const Vec3 n1 = blk.nodes[(r.segment * 7) * 8 + (r.sector + 1) % 8] - blk.layer_center[r.segment];
    EXPECT_NEAR(norm(cross(off, normalized(n0) + normalized(n1))), 0, 1e-12 * 8);
    EXPECT_GT(dot(off, n0 + n1), 0);
  }
}

// ---------------------------------------------------------------- orthogonality

namespace {
// Largest angle (rad) between the centre-to-centre segment and the shared face's normal over
// the interior faces whose two cells satisfy `pick`.
template <class Pick>
double max_orthogonality_angle(const BuiltBlock& b, Pick pick, int* n_faces) {
  double worst = 0;
  *n_faces = 0;
  for (int f = 0; f < b.mesh.n_faces(); ++f) {
    const int c1 = b.mesh.face_owner[f], c2 = b.mesh.face_neighbour[f];
    if (c2 < 0 || !pick(b.mesh.cell_radial[c1], b.mesh.cell_radial[c2])) continue;
    ++*n_faces;
    const Vec3 link = b.mesh.cell_fv_center[c2] - b.mesh.cell_fv_center[c1];
    const Vec3 n = b.geo.face_area[f];
    worst = std::max(worst, std::atan2(norm(cross(link, n)), dot(link, n)));
  }
  return worst;
}
}  // namespace

// The cylinder's cells (band -1); the caps' faces are checked in EndCaps.* below.
bool cylinder_pair(const RadialCellInfo& a, const RadialCellInfo& c) { return a.band < 0 && c.band < 0; }

TEST(WellBlock, FvCentresOnRadialLinesMakeRingFacesOrthogonal) {
  for (EndCaps caps : {EndCaps::Flat, EndCaps::Hemisphere})
    for (const auto& traj : {straight({0, 0, 1}), straight({1, -2, 2})}) {
      WellParams p;
      p.trajectory = traj;
      p.end_caps = caps;
      const BuiltBlock b = build(make_case(p), p.sectors);
      int n = 0;
      const double ring = max_orthogonality_angle(
          b,
          [](const RadialCellInfo& a, const RadialCellInfo& c) {
            return cylinder_pair(a, c) && a.sector == c.sector && a.segment == c.segment;
          },
          &n);
      EXPECT_EQ(n, (b.block.layers - 1) * (p.rings - 1) * p.sectors) << caps_name(caps);
      EXPECT_LT(ring, 1e-9) << caps_name(caps);
      const double angular = max_orthogonality_angle(
          b,
          [](const RadialCellInfo& a, const RadialCellInfo& c) {
            return cylinder_pair(a, c) && a.ring == c.ring && a.segment == c.segment;
          },
          &n);
      EXPECT_EQ(n, (b.block.layers - 1) * p.rings * p.sectors) << caps_name(caps);
      EXPECT_LT(angular, 1e-9) << caps_name(caps);
      std::printf("[ orthog.   ] %-10s worst ring-face angle %.2e rad, angular-face angle %.2e rad\n", caps_name(caps),
                  ring, angular);
    }
  // Pass/fail: the same check on centres moved off their radial lines (a ring-dependent
  // shift across the vertical axis) fails.
  WellParams p;
  p.trajectory = straight({0, 0, 1});
  BuiltBlock b = build(make_case(p), p.sectors);
  for (int c = 0; c < b.mesh.n_cells(); ++c) b.mesh.cell_fv_center[c] += Vec3{0.01 * b.mesh.cell_radial[c].ring, 0, 0};
  int n = 0;
  EXPECT_GT(max_orthogonality_angle(
                b, [](const RadialCellInfo& a, const RadialCellInfo& c) { return a.sector == c.sector && a.segment == c.segment; },
                &n),
            1e-6);
}

// Largest planarity and co-circularity misfits of a polygon: distances of its 4th, 5th, ...
// nodes from the plane of the first three and from the circle through them (0 for a triangle).
void face_misfit(const std::vector<Vec3>& x, const std::vector<int32_t>& q, double* circle, double* plane) {
  const Vec3 a = x[q[0]], b = x[q[1]], c = x[q[2]];
  const Vec3 ab = b - a, ac = c - a, n = cross(ab, ac);
  // Circumcentre of a, b, c.
  const Vec3 o = a + (dot(ac, ac) * cross(n, ab) + dot(ab, ab) * cross(ac, n)) / (2.0 * dot(n, n));
  const Vec3 nu = normalized(n);
  *plane = *circle = 0;
  for (size_t k = 3; k < q.size(); ++k) {
    const Vec3 d = x[q[k]];
    *plane = std::max(*plane, std::abs(dot(d - a, nu)));
    *circle = std::max(*circle, std::abs(norm((d - o) - dot(d - o, nu) * nu) - norm(a - o)));
  }
}

// Bends are mirror wedges: every quad of the block, wedges included, is planar and
// co-circular (what the transition mesh needs to stay convex), the centres stay inside
// their cells, and the ring faces stay orthogonal to the centre-to-centre segments.
TEST(WellBlock, BendWedgesHavePlanarCocircularFacesAndCentredCells) {
  for (EndCaps caps : {EndCaps::Flat, EndCaps::Hemisphere}) {
    for (double bend : {10.0, 30.0, 60.0, 90.0, 120.0}) {
      WellParams p;
      p.trajectory = bent(bend, 60, 60);
      p.end_caps = caps;
      const BuiltBlock b = build(make_case(p), p.sectors);
      double circle = 0, plane = 0;
      int wedge_faces = 0;
      for (size_t c = 0; c < b.block.cell_faces.size(); ++c) {
        const RadialCellInfo& r = b.block.cell_attrs[c].radial;
        const int l = r.segment;  // -1 or layers - 1 in a cap
        const bool wedge = r.band < 0 && b.block.layer_bend[l] >= 0 && b.block.layer_bend[l + 1] >= 0;
        for (const CellFace& f : b.block.cell_faces[c]) {
          double cm = 0, pm = 0;
          face_misfit(b.block.nodes, f.nodes, &cm, &pm);
          circle = std::max(circle, cm);
          plane = std::max(plane, pm);
          wedge_faces += wedge;
        }
      }
      EXPECT_GT(wedge_faces, 0) << "bend " << bend << " " << caps_name(caps);
      EXPECT_LT(circle, 1e-12 * 60) << "bend " << bend << " " << caps_name(caps);
      EXPECT_LT(plane, 1e-12 * 60) << "bend " << bend << " " << caps_name(caps);
      const MeshGeometry geo = compute_geometry(b.mesh);
      EXPECT_EQ(check_auto_centering(b.mesh, geo).violations, 0) << "bend " << bend << " " << caps_name(caps);
      EXPECT_EQ(check_convexity(b.mesh, geo).violations, 0) << "bend " << bend << " " << caps_name(caps);
      int n = 0;
      const double ring = max_orthogonality_angle(
          b,
          [](const RadialCellInfo& a, const RadialCellInfo& c) {
            return cylinder_pair(a, c) && a.sector == c.sector && a.segment == c.segment;
          },
          &n);
      std::printf("[ bend      ] %3g deg %-10s: misfit circle %.1e plane %.1e, worst ring-face angle %.4f rad\n", bend,
                  caps_name(caps), circle, plane, ring);
      EXPECT_LT(ring, 0.02) << "bend " << bend << " " << caps_name(caps);  // measured: at most 0.013 rad (0.75 deg)
    }
  }
  // Fail case: shifting one wedge cross-section along its normal breaks the mirror symmetry,
  // and with it the co-circularity of the wedge quads.
  WellParams p;
  p.trajectory = bent(50);
  WellBlock blk = make_well_block(make_case(p), 0, p.sectors);
  int inner = -1;
  for (int l = 1; l + 1 < blk.layers; ++l)
    if (blk.layer_bend[l - 1] >= 0 && blk.layer_bend[l] >= 0 && blk.layer_bend[l + 1] >= 0) inner = l;
  ASSERT_GE(inner, 0);
  const Vec3 normal = normalized(blk.layer_center[inner + 1] - blk.layer_center[inner - 1]);
  const int per_layer = (p.rings + 1) * p.sectors;
  for (int v = 0; v < per_layer; ++v) blk.nodes[inner * per_layer + v] += 0.2 * normal;
  double worst = 0;
  for (const auto& faces : blk.cell_faces)
    for (const CellFace& f : faces) {
      double cm = 0, pm = 0;
      face_misfit(blk.nodes, f.nodes, &cm, &pm);
      worst = std::max(worst, cm);
    }
  EXPECT_GT(worst, 1e-3);
}

// ---------------------------------------------------------------- rotation-minimising frame

TEST(WellBlock, BendLayersAreSharedAndTheFrameDoesNotTwist) {
  WellParams p;
  p.trajectory = {{0, 0, 0}, {0, 0, 30}, {20, 5, 50}, {25, 35, 60}, {60, 40, 62}};
  p.sectors = 10;
  const CaseSpec cs = make_case(p);
  const BuiltBlock b = build(cs, p.sectors);
  const WellBlock& blk = b.block;
  const int per_layer = (p.rings + 1) * p.sectors;
  // No duplicate nodes: every local node is distinct in space (bend nodes are shared ids).
  std::vector<Vec3> sorted = blk.nodes;
  std::sort(sorted.begin(), sorted.end(), [](Vec3 a, Vec3 c) { return a.x < c.x; });
  double closest = 1e300;
  for (size_t i = 0; i < sorted.size(); ++i)
    for (size_t j = i + 1; j < sorted.size() && sorted[j].x - sorted[i].x < 1e-3; ++j)
      closest = std::min(closest, norm(sorted[j] - sorted[i]));
  EXPECT_GT(closest, 1e-3);
  // The builder matched the axial faces on both sides of every bend layer (checked through
  // the unmatched count: only outer-surface faces remain unmatched).
  int outer = 0;
  for (int32_t c : blk.surface_cell) outer += c >= 0;
  EXPECT_EQ(b.report.unmatched_faces, outer);
  EXPECT_EQ(b.report.misoriented_faces + b.report.overused_faces + b.report.degenerate_faces, 0);

  // Each bend is a run of wedge layers; the meshed axis stays on the trajectory's legs
  // outside the wedges and cuts each corner by less than the fillet allows.
  std::set<int32_t> bends;
  for (int l = 0; l < blk.layers; ++l) {
    if (blk.layer_bend[l] >= 0) {
      bends.insert(blk.layer_bend[l]);
      continue;
    }
    double on_leg = 1e300;  // distance of a straight-part layer centre from the legs
    for (size_t k = 0; k + 1 < p.trajectory.size(); ++k) {
      const Vec3 a = p.trajectory[k], ab = p.trajectory[k + 1] - a;
      const double s = std::clamp(dot(blk.layer_center[l] - a, ab) / dot(ab, ab), 0.0, 1.0);
      on_leg = std::min(on_leg, norm(blk.layer_center[l] - (a + s * ab)));
    }
    EXPECT_LT(on_leg, 1e-12 * 100) << "layer " << l;
  }
  EXPECT_EQ(bends, (std::set<int32_t>{1, 2, 3}));
  ASSERT_EQ(blk.notes.size(), 3u);

  // The last polygon is the first one turned by the product of the minimal bend rotations.
  const int last = blk.layers - 1;
  for (int v = 0; v < per_layer; ++v) {
    Vec3 e = blk.nodes[v] - blk.layer_center[0];
    for (size_t k = 1; k + 1 < p.trajectory.size(); ++k)
      e = rotate_axis_angle(e, normalized(p.trajectory[k] - p.trajectory[k - 1]),
                            normalized(p.trajectory[k + 1] - p.trajectory[k]));
    const Vec3 got = blk.nodes[last * per_layer + v] - blk.layer_center[last];
    EXPECT_NEAR(norm(got - e), 0, 1e-12 * 60) << "node " << v;
  }
}

TEST(WellBlock, PlanarBendKeepsTheBinormalComponent) {
  // Pass/fail pair for "no twist": in the x-z plane the binormal is y; the minimal rotation
  // keeps every node's y offset, a twisted frame (here: sectors shifted by one) does not.
  WellParams p;
  p.trajectory = {{0, 0, 0}, {0, 0, 30}, {25, 0, 45}, {60, 0, 40}};
  const WellBlock blk = make_well_block(make_case(p), 0, p.sectors);
  const int per_layer = (p.rings + 1) * p.sectors, last = blk.layers - 1;
  double worst = 0, shifted = 0;
  for (int i = 0; i <= p.rings; ++i)
    for (int s = 0; s < p.sectors; ++s) {
      const double y0 = blk.nodes[i * p.sectors + s].y - blk.layer_center[0].y;
      const double y1 = blk.nodes[last * per_layer + i * p.sectors + s].y - blk.layer_center[last].y;
      const double y1_shift =
          blk.nodes[last * per_layer + i * p.sectors + (s + 1) % p.sectors].y - blk.layer_center[last].y;
      worst = std::max(worst, std::abs(y1 - y0));
      shifted = std::max(shifted, std::abs(y1_shift - y0));
    }
  EXPECT_LT(worst, 1e-12 * 8);
  EXPECT_GT(shifted, 1.0);
}

// Every face at a bend leans at most 1 degree off orthogonal (issue 15), in particular the cross-sections
// where the straight cells meet the first and last wedges (the centre-to-centre segment against
// the face normal), and each wedge's outer ring face toward the transition, whose site lies on
// the normal through the face's circumcentre (the cell's FV centre against that normal, i.e. the
// site at height 0: the bound for any height). Bends of 10-120 degrees, 8-24 sectors, both ends.
TEST(WellBlock, BendFacesLeanAtMostOneDegree) {
  const double one_degree = kPi / 180;
  for (EndCaps caps : {EndCaps::Flat, EndCaps::Hemisphere})
    for (double bend : {10.0, 30.0, 60.0, 90.0, 120.0})
      for (int sectors : {8, 12, 24}) {
        WellParams p;
        p.trajectory = bent(bend, 60, 60);
        p.end_caps = caps;
        BuiltBlock b = build(make_case(p), sectors);
        const std::string label = "bend " + std::to_string(bend) + " " + caps_name(caps) + " " + std::to_string(sectors);
        ASSERT_EQ(b.block.notes.size(), 1u) << label;
        EXPECT_EQ(b.block.notes[0].find("lean up to"), std::string::npos) << b.block.notes[0];
        auto along_axis = [](const RadialCellInfo& a, const RadialCellInfo& c) {
          return cylinder_pair(a, c) && a.ring == c.ring && a.sector == c.sector && a.segment != c.segment;
        };
        int n = 0;
        const double axial = max_orthogonality_angle(b, along_axis, &n);
        const double cylinder = max_orthogonality_angle(b, cylinder_pair, &n);  // ring and angular faces too
        double outer = 0;
        for (size_t i = 0; i < b.block.surface_faces.size(); ++i) {
          const int32_t c = b.block.surface_cell[i];
          const std::vector<int32_t>& f = b.block.surface_faces[i];
          // the side only: the outer ring face (index 1) of a cylinder cell, not a flat end's annulus
          if (c < 0 || b.block.cell_attrs[c].radial.band >= 0 || f != b.block.cell_faces[c][1].nodes) continue;
          const Vec3 p0 = b.block.nodes[f[0]], p1 = b.block.nodes[f[1]], p2 = b.block.nodes[f[2]];
          const Vec3 e1 = p1 - p0, e2 = p2 - p0, nrm = cross(e1, e2);
          const Vec3 centre = p0 + cross(dot(e1, e1) * e2 - dot(e2, e2) * e1, nrm) / (2 * dot(nrm, nrm));
          const Vec3 to_cell = b.block.cell_attrs[c].fv_center - centre;
          outer = std::max(outer, std::atan2(norm(cross(to_cell, nrm)), std::abs(dot(to_cell, nrm))));
        }
        std::printf("[ bend lean ] %3g deg %-10s %2d sectors: worst axial face %.3f deg, any face between two cylinder "
                    "cells %.3f deg, outer face %.3f deg\n",
                    bend, caps_name(caps), sectors, axial / one_degree, cylinder / one_degree, outer / one_degree);
        EXPECT_LE(cylinder, one_degree) << label;
        EXPECT_LE(outer, one_degree) << label;
        if (bend != 60.0 || sectors != 12) continue;
        // Fail half: the first wedge's centres moved 1.5 degrees across the joint are seen.
        for (int c = 0; c < b.mesh.n_cells(); ++c) {
          const RadialCellInfo& r = b.mesh.cell_radial[c];
          const int l = r.segment;
          if (r.band >= 0 || b.block.layer_bend[l] < 0 || l == 0 || b.block.layer_bend[l - 1] >= 0) continue;
          const Vec3 d = normalized(b.block.layer_center[l + 1] - b.block.layer_center[l]);
          const Vec3 across = normalized(cross(d, Vec3{0.3, 0.5, 0.8}));
          const double half_length = 0.5 * norm(b.block.layer_center[l + 1] - b.block.layer_center[l]);
          b.mesh.cell_fv_center[c] = b.mesh.cell_fv_center[c] + std::tan(1.5 * one_degree) * half_length * across;
        }
        EXPECT_GT(max_orthogonality_angle(b, along_axis, &n), one_degree) << label;
      }
}

// Where even kMaxBendWedges wedges leave a bend's faces leaning more than 1 degree (a short straight
// cell between two sharp bends), the block is still made and the bend's note says how far off it is.
TEST(WellBlock, BendThatCannotBeMadeOrthogonalSaysSo) {
  WellParams p;
  p.trajectory = {{0, 0, 0}, {0, 0, 40}, {21, 0, 40}, {21, 0, 0}};  // two 90-degree bends, a 21 m leg between
  p.end_caps = EndCaps::Flat;
  const WellBlock b = make_well_block(make_case(p), 0, 12);
  ASSERT_EQ(b.notes.size(), 2u);
  for (const std::string& note : b.notes) {
    std::printf("[ bend note ] %s\n", note.c_str());
    EXPECT_NE(note.find("meshed as 24 mirror wedge(s)"), std::string::npos) << note;
    EXPECT_NE(note.find("; its faces lean up to "), std::string::npos) << note;
  }
}

// ---------------------------------------------------------------- segments near bends

TEST(WellBlock, BendNotesStateTheWedgesAndTheAxisOffset) {
  WellParams p;
  p.trajectory = bent(90, 100, 100);
  p.end_caps = EndCaps::Flat;  // uniform layers on the legs (graded end layers: below)
  const WellBlock blk = make_well_block(make_case(p), 0, 12);
  // rho = 1.5 R = 12 m, t = rho tan 45 = 12 m. Wedges: no more than 30 degrees each (3), no
  // wedge longer than a segment on the outside of the bend, on the arc of radius rho + R = 20 m
  // (20 m x pi/2 / 4 m = 7.85: 8), and as many as keep the faces at the bend within 1 degree of
  // orthogonal (bend_lean: 15 wedges of 6 degrees; WellBlock.BendFacesLeanAtMostOneDegree). With
  // an odd count the axis point nearest to the corner is the middle chord's midpoint, at
  // rho cos 3 deg from the arc centre: rho / cos 45 - rho cos 3 deg = 4.98701 m.
  ASSERT_EQ(blk.notes.size(), 1u);
  EXPECT_EQ(blk.notes[0],
            "wells[0] (P1): bend of 90 degrees at trajectory point 1 meshed as 15 mirror wedge(s) on an arc of radius "
            "12 m: the wellbore axis leaves the trajectory 12 m before the point and passes 4.98701 m from it");
  // 88 m straight on each leg: 22 segments each, plus the 15 wedges.
  EXPECT_EQ(blk.layers, 22 + 15 + 22 + 1);
  // The wedges' outer axial edges (ring R, on the arc of radius about rho + R) are at most a
  // segment long (7 wedges would have made them longer: 2 (rho + R) sin(pi / 28) > 4 m).
  const int per_layer = (p.rings + 1) * 12;
  double longest_outer = 0;
  for (int l = 0; l + 1 < blk.layers; ++l) {
    if (blk.layer_bend[l] < 0 || blk.layer_bend[l + 1] < 0) continue;
    for (int s = 0; s < 12; ++s)
      longest_outer = std::max(longest_outer, norm(blk.nodes[(l + 1) * per_layer + p.rings * 12 + s] -
                                                   blk.nodes[l * per_layer + p.rings * 12 + s]));
  }
  EXPECT_LE(longest_outer, p.segment_length);
  EXPECT_GT(2 * 20.0 * std::sin(kPi / 28), p.segment_length);
  std::printf("[ wedges    ] 90 deg bend: longest outer wedge edge %.4f m (segment %.1f m)\n", longest_outer,
              p.segment_length);
  // The same distance from the block itself: the corner to the meshed axis polyline.
  const std::vector<Vec3> axis = meshed_axis(blk);
  double to_axis = 1e300;
  for (size_t k = 0; k + 1 < axis.size(); ++k) {
    const Vec3 a = axis[k], ab = axis[k + 1] - a, x = p.trajectory[1];
    const double s = std::clamp(dot(x - a, ab) / dot(ab, ab), 0.0, 1.0);
    to_axis = std::min(to_axis, norm(x - (a + s * ab)));
  }
  EXPECT_NEAR(to_axis, 12.0 * std::sqrt(2.0) - 12.0 * std::cos(kPi / 60), 1e-9);
  // The block's volume follows the closed form of the wedges, with either end.
  for (EndCaps caps : {EndCaps::Flat, EndCaps::Hemisphere}) {
    p.end_caps = caps;
    BuiltBlock b = build(make_case(p), 12);
    double total = 0;
    for (double v : b.geo.cell_volume) total += v;
    EXPECT_NEAR(total / exact_well_block_volume(make_case(p), 0, 12), 1.0, 1e-12) << caps_name(caps);
    // The caps change the ends, not the bend.
    EXPECT_EQ(b.block.notes, blk.notes) << caps_name(caps);
    // Hemispheres grade the first and last layers (r_k - r_w for the 5 rings below 4 m, the
    // last at 3.754 m): 100 - 12 - 3.754 = 84.2 m straight on each leg gives 21 segments
    // plus the 5 graded layers.
    EXPECT_EQ(b.block.layers, caps == EndCaps::Flat ? 22 + 15 + 22 + 1 : (5 + 21) + 15 + (21 + 5) + 1) << caps_name(caps);
  }
  // A gentle bend takes an arc of one segment (rho = 4 m / 5 deg = 45.8 m); on its outside
  // (rho + R) x 5 deg = 4.70 m is longer than a segment: 2 wedges. The axis then passes
  // through the bisector station, rho / cos 2.5 - rho = 0.0436679 m from the corner.
  p.trajectory = bent(5, 100, 100);
  p.end_caps = EndCaps::Flat;  // its end lies 0.4 m inside the test box: a cap would not fit (flat + a note)
  const WellBlock gentle = make_well_block(make_case(p), 0, 12);
  ASSERT_EQ(gentle.notes.size(), 1u);
  EXPECT_NE(gentle.notes[0].find("meshed as 2 mirror wedge(s) on an arc of radius 45.8366 m"), std::string::npos)
      << gentle.notes[0];
  EXPECT_NE(gentle.notes[0].find("passes 0.0436679 m from it"), std::string::npos) << gentle.notes[0];
  // Straight wells keep the requested split and say nothing; hemispheres add the 5 graded
  // layers at each end and split the remaining 92.5 m into 23 segments.
  p.trajectory = straight({0, 0, 1}, 100);
  p.end_caps = EndCaps::Flat;
  const WellBlock plain = make_well_block(make_case(p), 0, 12);
  EXPECT_EQ(plain.layers, 26);
  EXPECT_TRUE(plain.notes.empty());
  p.end_caps = EndCaps::Hemisphere;
  const WellBlock capped = make_well_block(make_case(p), 0, 12);
  EXPECT_EQ(capped.layers, 1 + 5 + 23 + 5);
  EXPECT_TRUE(capped.notes.empty());
}

// ---------------------------------------------------------------- Gabriel

TEST(Gabriel, ExactPredicateOnTheSphereIsNotInside) {
  const Vec3 a{0, 0, 0}, b{10, 0, 0};
  EXPECT_FALSE(strictly_inside_diametral_sphere(a, b, {5, 3, 4}));  // |p - m| = 5 = radius
  EXPECT_TRUE(strictly_inside_diametral_sphere(a, b, {5, 3, 3.999999999}));
  EXPECT_FALSE(strictly_inside_diametral_sphere(a, b, {5, 3, 4.000000001}));
  EXPECT_FALSE(strictly_inside_diametral_sphere(a, b, a));  // an endpoint is on the sphere
  EXPECT_TRUE(strictly_inside_diametral_sphere(a, b, {0.5, 0.1, -0.2}));
}

TEST(Gabriel, KdTreeSearchAgreesWithBruteForce) {
  // Points on a jittered lattice and random-ish edges: the k-d tree finds every pair.
  std::vector<Vec3> nodes;
  unsigned state = 12345;
  auto rnd = [&]() { state = state * 1103515245u + 12345u; return ((state >> 8) & 0xffff) / 65536.0; };
  for (int i = 0; i < 400; ++i) nodes.push_back({10 * rnd(), 10 * rnd(), 3 * rnd()});
  std::vector<std::array<int32_t, 2>> edges;
  for (int i = 0; i < 300; ++i) {
    const int32_t a = static_cast<int32_t>(rnd() * 400), c = static_cast<int32_t>(rnd() * 400);
    if (a != c) edges.push_back({std::min(a, c), std::max(a, c)});
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  std::vector<int32_t> points(400);
  for (int i = 0; i < 400; ++i) points[i] = i;
  const auto found = gabriel_violations(nodes, edges, points);
  size_t expected = 0;
  for (const auto& e : edges)
    for (int32_t p : points)
      if (p != e[0] && p != e[1] && norm2(nodes[p] - 0.5 * (nodes[e[0]] + nodes[e[1]])) < 0.25 * norm2(nodes[e[1]] - nodes[e[0]]))
        ++expected;
  EXPECT_GT(expected, 100u);
  EXPECT_EQ(found.size(), expected);
}

TEST(Gabriel, EndFacesFailWithTooFewSectorsAndPassWithEnough) {
  // Ring ratio q = 80^(1/6) = 2.075: the angular edge of ring i contains the ring i-1 vertices
  // at its two angles iff 1/q = 0.482 > cos(2 pi / sectors). 5 sectors: cos 72 deg = 0.309, fails;
  // 6 sectors: cos 60 deg = 0.5, passes. Flat ends: the end annuli are on the outer surface
  // (hemispherical caps hide them; their outer shells are checked in EndCaps.* below).
  WellParams p;
  p.trajectory = straight({0, 0, 1}, 40);
  p.end_caps = EndCaps::Flat;
  const CaseSpec cs = make_case(p);
  for (int sectors : {4, 5, 6, 12}) {
    const WellBlock blk = make_well_block(cs, 0, sectors);
    const int count = count_gabriel_violations(blk);
    // Closed form (sectors >= 4): per end, per ring i and inner ring j < i with
    // r_j / r_i > cos(2 pi / n), 2 vertices per angular edge.
    int formula = 0;
    for (int i = 1; i <= p.rings; ++i)
      for (int j = 0; j < i; ++j)
        if (blk.radii[j] / blk.radii[i] > std::cos(2 * kPi / sectors)) formula += 2 * 2 * sectors;
    int surely = 0;
    const int maybe = brute_force_violations(blk, &surely);
    EXPECT_EQ(count, formula) << sectors << " sectors";
    EXPECT_LE(surely, count);
    EXPECT_LE(count, maybe);
    std::printf("[ gabriel   ] straight, %2d sectors: %d violations (closed form %d)\n", sectors, count, formula);
  }
  EXPECT_EQ(count_gabriel_violations(make_well_block(cs, 0, 5)), 120);
  EXPECT_EQ(count_gabriel_violations(make_well_block(cs, 0, 6)), 0);
}

TEST(Gabriel, LongSegmentsOnStraightLegsStayGabriel) {
  // The outer surface of a straight leg is made of rectangles: an axial edge of length h has
  // every other vertex at distance^2 >= chord^2 + h^2 / 4 from its midpoint, so even 50 m
  // segments against 8 m chords are Gabriel (flat ends: 6 sectors keep the end annuli
  // Gabriel, and the layers are the uniform 50 m ones).
  WellParams p;
  p.trajectory = straight({1, 0, 1}, 200);
  p.segment_length = 50;
  p.end_caps = EndCaps::Flat;
  const CaseSpec cs = make_case(p);
  const WellBlock blk = make_well_block(cs, 0, 6);
  EXPECT_EQ(blk.layers, 5);
  EXPECT_EQ(count_gabriel_violations(blk), 0);
  int surely = 0;
  EXPECT_EQ(brute_force_violations(blk, &surely), 0);
}

TEST(Gabriel, BendWedgesAreGabrielUpTo120DegreesWithManySectors) {
  // Wedges of at most 30 degrees on a fillet of 1.5 R: the wedge trapezoids keep their
  // circumcentre inside, so no surface vertex enters an edge's diametral sphere (the
  // bisector-plane mitre of the first version failed from 50 degrees with 12 sectors).
  for (EndCaps caps : {EndCaps::Flat, EndCaps::Hemisphere})
    for (double bend : {30.0, 60.0, 90.0, 120.0})
      for (int sectors : {6, 12, 24}) {
        WellParams p;
        p.trajectory = bent(bend, 60, 60);
        p.end_caps = caps;
        const WellBlock blk = make_well_block(make_case(p), 0, sectors);
        EXPECT_EQ(count_gabriel_violations(blk), 0) << bend << " deg, " << sectors << " sectors, " << caps_name(caps);
        int surely = 0;
        EXPECT_EQ(brute_force_violations(blk, &surely), 0)
            << bend << " deg, " << sectors << " sectors, " << caps_name(caps);
      }
}

TEST(Gabriel, MakeGabrielRaisesSectorsAndSaysSo) {
  // Flat ends: their annuli are what more sectors repair.
  WellParams p;
  p.trajectory = straight({0, 0, 1}, 40);
  p.end_caps = EndCaps::Flat;
  p.sectors = 4;
  const WellBlock raised = make_gabriel_well_block(make_case(p), 0);
  EXPECT_EQ(raised.sectors, 6);
  EXPECT_EQ(raised.sectors_requested, 4);
  EXPECT_EQ(count_gabriel_violations(raised), 0);
  ASSERT_EQ(raised.notes.size(), 1u);
  EXPECT_EQ(raised.notes[0], "wells[0] (P1): sectors raised from 4 to 6 for the Gabriel condition");

  // 20 rings: ratio 80^(1/20) = 1.245 needs cos(2 pi / n) >= 0.803, i.e. n >= 10.
  p.sectors = 8;
  p.rings = 20;
  const WellBlock fine = make_gabriel_well_block(make_case(p), 0);
  EXPECT_EQ(fine.sectors, 10);
  ASSERT_EQ(fine.notes.size(), 1u);
  EXPECT_EQ(fine.notes[0], "wells[0] (P1): sectors raised from 8 to 10 for the Gabriel condition");

  // Already Gabriel: untouched.
  p.sectors = 12;
  p.rings = 6;
  const WellBlock same = make_gabriel_well_block(make_case(p), 0);
  EXPECT_EQ(same.sectors, 12);
  EXPECT_TRUE(same.notes.empty());
}

TEST(Gabriel, MakeGabrielGivesUpWithTheReason) {
  WellParams p;
  p.trajectory = straight({0, 0, 1}, 40);
  p.end_caps = EndCaps::Flat;  // the end annuli's reason
  p.sectors = 3;
  p.rings = 60;  // ratio 1.076 needs 17 sectors, 4 x 3 = 12 allowed
  try {
    make_gabriel_well_block(make_case(p), 0);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "wells[0] (P1): the end faces of the radial block are not Gabriel even with 12 sectors (4x the 3 "
              "requested, 2880 violations): the ring radius ratio 1.07577 needs cos(2 pi / sectors) >= 1 / 1.07577, "
              "i.e. at least 17 sectors; use fewer rings");
  }
  // The figure in the message is right: 17 sectors pass, 16 do not.
  EXPECT_EQ(count_gabriel_violations(make_well_block(make_case(p), 0, 17)), 0);
  EXPECT_GT(count_gabriel_violations(make_well_block(make_case(p), 0, 16)), 0);
}

// ---------------------------------------------------------------- bad input

TEST(WellBlockInput, LegTooShortForItsBend) {
  WellParams p;
  p.trajectory = {{0, 0, 0}, {0, 0, 5}, {10, 0, 5}};  // 5 m then a 90-degree bend, drainage radius 8
  try {
    make_well_block(make_case(p), 0, 12);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "wells[0].trajectory: leg 0 too short for its bend of 90 degrees (needs > 10.4 m with drainage radius 8)");
  }
  // Pass/fail: 10.5 m is enough (and the second leg holds 1.3 R tan 45 = 10.4 m).
  p.trajectory = {{0, 0, 0}, {0, 0, 10.5}, {11, 0, 10.5}};
  EXPECT_NO_THROW(make_well_block(make_case(p), 0, 12));
  // The middle leg of a U holds both fillets: at least 1.3 R tan 45 = 10.4 m each.
  p.trajectory = {{0, 0, 0}, {0, 0, 20}, {20, 0, 20}, {20, 0, 0}};
  try {
    make_well_block(make_case(p), 0, 12);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "wells[0].trajectory: leg 1 too short for its bends of 90 and 90 degrees (needs > 20.8 m with drainage "
              "radius 8)");
  }
}

TEST(WellBlockInput, BendAbove120DegreesAndDegenerateSpecs) {
  WellParams p;
  p.trajectory = bent(150, 60, 60);
  try {
    make_well_block(make_case(p), 0, 12);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "wells[0].trajectory: bend of 150 degrees at point 1 exceeds the 120-degree limit");
  }
  p.trajectory = bent(119, 60, 60);
  EXPECT_NO_THROW(make_well_block(make_case(p), 0, 12));
  p.trajectory = {{0, 0, 0}, {0, 0, 0}, {0, 0, 10}};
  EXPECT_THROW(make_well_block(make_case(p), 0, 12), InputError);
  p.trajectory = straight({0, 0, 1});
  EXPECT_THROW(make_well_block(make_case(p), 0, 2), InputError);
  p.drainage_radius = 0.05;
  EXPECT_THROW(make_well_block(make_case(p), 0, 12), InputError);
}

// ---------------------------------------------------------------- hemispherical end caps

namespace {

struct CapTrajectory {
  const char* name;
  std::vector<Vec3> trajectory;
};

// (trajectory, sectors, rings)
using CapParam = std::tuple<CapTrajectory, int, int>;

bool is_cap(const RadialCellInfo& r) { return r.band >= 0; }

// Worst angle (rad) between the centre-to-centre segment and the shared face's normal, per
// kind of face next to a cap cell: shell (ring to ring), cone (band to band), meridian
// (sector to sector), end plane (cylinder to band 0). `odd` counts faces between two cells
// that differ in more than one index (there should be none).
struct CapFaceAngles {
  double shell = 0, cone = 0, meridian = 0, end_plane = 0;
  int n_shell = 0, n_cone = 0, n_meridian = 0, n_end_plane = 0, odd = 0;
};

CapFaceAngles cap_face_angles(const PolyMesh& mesh, const MeshGeometry& geo) {
  CapFaceAngles out;
  for (int f = 0; f < mesh.n_faces(); ++f) {
    const int c1 = mesh.face_owner[f], c2 = mesh.face_neighbour[f];
    if (c2 < 0) continue;
    const RadialCellInfo &a = mesh.cell_radial[c1], &c = mesh.cell_radial[c2];
    if (!is_cap(a) && !is_cap(c)) continue;
    const Vec3 link = mesh.cell_fv_center[c2] - mesh.cell_fv_center[c1];
    const double angle = std::atan2(norm(cross(link, geo.face_area[f])), dot(link, geo.face_area[f]));
    const int differ = (a.ring != c.ring) + (a.sector != c.sector) + (a.band != c.band);
    if (is_cap(a) != is_cap(c)) {
      // Band 0 of a cap and the end cell of the cylinder (segment 0 before the start cap at
      // segment -1, the last segment before the end cap at segment `segments`).
      const RadialCellInfo &capped = is_cap(a) ? a : c, &cylinder = is_cap(a) ? c : a;
      if (capped.band != 0 || a.ring != c.ring || a.sector != c.sector || std::abs(capped.segment - cylinder.segment) != 1)
        ++out.odd;
      out.end_plane = std::max(out.end_plane, angle);
      ++out.n_end_plane;
    } else if (differ != 1 || a.segment != c.segment) {
      ++out.odd;
    } else if (a.ring != c.ring) {
      out.shell = std::max(out.shell, angle);
      ++out.n_shell;
    } else if (a.band != c.band) {
      out.cone = std::max(out.cone, angle);
      ++out.n_cone;
    } else {
      out.meridian = std::max(out.meridian, angle);
      ++out.n_meridian;
    }
  }
  return out;
}

// Sum of a block cell's outward face area vectors, and the sum of their norms (scale).
Vec3 block_cell_area_sum(const WellBlock& blk, size_t c, double* scale) {
  Vec3 sum;
  *scale = 0;
  for (const CellFace& f : blk.cell_faces[c]) {
    Vec3 area, centroid;
    polygon_area_centroid(blk.nodes, f.nodes.data(), f.nodes.data() + f.nodes.size(), &area, &centroid);
    sum += area;
    *scale += norm(area);
  }
  return sum;
}

// Largest signed distance of `x` beyond the planes of a block cell's faces (outward
// normals): negative iff x is strictly inside a convex cell.
double beyond_faces(const WellBlock& blk, size_t c, Vec3 x) {
  double worst = -1e300;
  for (const CellFace& f : blk.cell_faces[c]) {
    Vec3 area, centroid;
    polygon_area_centroid(blk.nodes, f.nodes.data(), f.nodes.data() + f.nodes.size(), &area, &centroid);
    worst = std::max(worst, dot(x - centroid, normalized(area)));
  }
  return worst;
}

// Directed surface edges without exactly one reverse partner, or used more than once
// (0 for a closed, consistently oriented surface).
int open_surface_edges(const std::vector<std::vector<int32_t>>& polygons) {
  std::map<std::pair<int32_t, int32_t>, int> directed;
  for (const auto& poly : polygons)
    for (size_t i = 0; i < poly.size(); ++i) ++directed[{poly[i], poly[(i + 1) % poly.size()]}];
  int bad = 0;
  for (const auto& [edge, uses] : directed) {
    auto back = directed.find({edge.second, edge.first});
    bad += uses != 1 || back == directed.end() || back->second != 1;
  }
  return bad;
}

}  // namespace

class HemisphereCaps : public ::testing::TestWithParam<CapParam> {
 protected:
  WellParams params() const {
    WellParams p;
    p.trajectory = std::get<0>(GetParam()).trajectory;
    p.sectors = std::get<1>(GetParam());
    p.rings = std::get<2>(GetParam());
    p.end_caps = EndCaps::Hemisphere;
    return p;
  }
  std::string label() const {
    return std::string(std::get<0>(GetParam()).name) + ", " + std::to_string(std::get<1>(GetParam())) + " sectors, " +
           std::to_string(std::get<2>(GetParam())) + " rings";
  }
};

// Every cap cell: closed, positive, its nodes on the spheres of radius r_in and r_out about
// its end point, its faces planar and co-circular; the cells after the cylinder's, start
// cap first, bands x rings x sectors each.
TEST_P(HemisphereCaps, CellsClosedPositivePlanarCocircularOnSphericalShells) {
  const WellParams p = params();
  const BuiltBlock b = build(make_case(p), p.sectors);
  const WellBlock& blk = b.block;
  const int bands = hemisphere_cap_bands(p.sectors);
  const size_t cylinder = static_cast<size_t>((blk.layers - 1) * p.rings * p.sectors);
  const size_t per_cap = static_cast<size_t>(bands * p.rings * p.sectors);
  ASSERT_EQ(blk.cell_faces.size(), cylinder + 2 * per_cap);
  ASSERT_EQ(b.mesh.n_cells(), static_cast<int>(blk.cell_faces.size()));
  EXPECT_EQ(b.report.overused_faces + b.report.misoriented_faces + b.report.degenerate_faces, 0)
      << first_problem(b.report.problems);
  double worst_circle = 0, worst_plane = 0, worst_closure = 0;
  int faces = 0, triangles = 0;
  for (size_t c = cylinder; c < blk.cell_faces.size(); ++c) {
    const RadialCellInfo& r = blk.cell_attrs[c].radial;
    const bool start = c < cylinder + per_cap;
    ASSERT_GE(r.band, 0) << "cell " << c;
    EXPECT_LT(r.band, bands);
    EXPECT_EQ(r.segment, start ? -1 : blk.layers - 1);
    EXPECT_EQ(r.cap_center, start ? p.trajectory.front() : p.trajectory.back());
    EXPECT_EQ(b.mesh.cell_radial[c].band, r.band);
    // Closed: the outward area vectors of its faces sum to zero.
    double scale = 0;
    const double closure = norm(block_cell_area_sum(blk, c, &scale)) / scale;
    worst_closure = std::max(worst_closure, closure);
    EXPECT_LT(closure, 1e-12) << label() << ", cell " << c;
    EXPECT_GT(b.geo.cell_volume[c], 0) << label() << ", cell " << c;
    // A polar cell (last band) has 5 faces: its outer cone degenerates to the pole nodes.
    EXPECT_EQ(blk.cell_faces[c].size(), r.band + 1 == bands ? 5u : 6u);
    for (const CellFace& f : blk.cell_faces[c]) {
      ++faces;
      triangles += f.nodes.size() == 3;
      double diameter = 0;
      for (int32_t v : f.nodes) {
        const double d = norm(blk.nodes[v] - r.cap_center);
        const double scale_d = 1e-12 * (norm(r.cap_center) + r.r_out);
        EXPECT_TRUE(std::abs(d - r.r_in) < scale_d || std::abs(d - r.r_out) < scale_d)
            << label() << ", cell " << c << ": node " << v << " at " << d << " from its end point";
        for (int32_t w : f.nodes) diameter = std::max(diameter, norm(blk.nodes[w] - blk.nodes[v]));
      }
      double circle = 0, plane = 0;
      face_misfit(blk.nodes, f.nodes, &circle, &plane);
      worst_circle = std::max(worst_circle, circle / diameter);
      worst_plane = std::max(worst_plane, plane / diameter);
    }
  }
  // Polar shell faces (inner and outer) are the only triangles.
  EXPECT_EQ(triangles, 2 * 2 * p.rings * p.sectors);
  EXPECT_LT(worst_circle, 1e-12) << label();
  EXPECT_LT(worst_plane, 1e-12) << label();
  std::printf("[ cap cells ] %-32s %5d faces: misfit / diameter circle %.1e plane %.1e, closure %.1e\n",
              label().c_str(), faces, worst_circle, worst_plane, worst_closure);
}

// Shell, cone and meridian faces are orthogonal to the centre-to-centre segments, and so is
// the end plane between the cylinder and band 0: the cap's centres lie at r_center /
// cos(beta_0) from the end point, band 0's straight above the cylinder's.
TEST_P(HemisphereCaps, ShellConeMeridianAndEndPlaneFacesOrthogonal) {
  const WellParams p = params();
  const BuiltBlock b = build(make_case(p), p.sectors);
  const int bands = hemisphere_cap_bands(p.sectors);
  const CapFaceAngles a = cap_face_angles(b.mesh, b.geo);
  EXPECT_EQ(a.odd, 0);
  EXPECT_EQ(a.n_shell, 2 * bands * (p.rings - 1) * p.sectors);
  EXPECT_EQ(a.n_cone, 2 * (bands - 1) * p.rings * p.sectors);
  EXPECT_EQ(a.n_meridian, 2 * bands * p.rings * p.sectors);
  EXPECT_EQ(a.n_end_plane, 2 * p.rings * p.sectors);
  EXPECT_LT(a.shell, 1e-9) << label();
  EXPECT_LT(a.cone, 1e-9) << label();
  EXPECT_LT(a.meridian, 1e-9) << label();
  EXPECT_LT(a.end_plane, 1e-9) << label();
  std::printf("[ cap orth. ] %-32s shell %.1e cone %.1e meridian %.1e end plane %.1e rad\n", label().c_str(),
              a.shell, a.cone, a.meridian, a.end_plane);
}

// Every FV centre (cap and cylinder) strictly on the inner side of each of its cell's faces.
TEST_P(HemisphereCaps, FvCentresStrictlyInsideTheirCells) {
  const WellParams p = params();
  const WellBlock blk = make_well_block(make_case(p), 0, p.sectors);
  double worst = -1e300;  // largest (face plane distance / r_out): negative inside
  for (size_t c = 0; c < blk.cell_faces.size(); ++c) {
    const double beyond = beyond_faces(blk, c, blk.cell_attrs[c].fv_center);
    EXPECT_LT(beyond, 0) << label() << ", cell " << c << " band " << blk.cell_attrs[c].radial.band;
    worst = std::max(worst, beyond / blk.cell_attrs[c].radial.r_out);
  }
  std::printf("[ cap fv    ] %-32s closest FV centre to a face: %.2e r_out inside\n", label().c_str(), -worst);
}

// The outer surface (cylinder side + caps' outer shells): closed, each polygon facing away
// from its cell's centre, enclosing block + wellbore hole, and Gabriel.
TEST_P(HemisphereCaps, OuterSurfaceClosedOutwardAndGabriel) {
  const WellParams p = params();
  const CaseSpec cs = make_case(p);
  const WellBlock blk = make_well_block(cs, 0, p.sectors);
  const int bands = hemisphere_cap_bands(p.sectors);
  ASSERT_EQ(blk.surface_faces.size(), static_cast<size_t>((blk.layers - 1 + 2 * bands) * p.sectors));
  EXPECT_EQ(open_surface_edges(blk.surface_faces), 0) << label();
  double enclosed = 0;
  for (size_t k = 0; k < blk.surface_faces.size(); ++k) {
    const std::vector<int32_t>& poly = blk.surface_faces[k];
    ASSERT_GE(blk.surface_cell[k], 0);
    EXPECT_EQ(blk.surface_patch[k], kInteriorFace);
    const CellAttributes& at = blk.cell_attrs[blk.surface_cell[k]];
    EXPECT_EQ(at.radial.ring, p.rings - 1);
    Vec3 area, centroid;
    polygon_area_centroid(blk.nodes, poly.data(), poly.data() + poly.size(), &area, &centroid);
    EXPECT_GT(dot(centroid - at.fv_center, area), 0) << label() << ", surface polygon " << k;
    enclosed += dot(centroid, area) / 3.0;
  }
  const double solid = exact_well_block_volume(cs, 0, p.sectors) + exact_wellbore_hole_volume(cs, 0, p.sectors);
  EXPECT_NEAR(enclosed / solid, 1.0, 1e-12) << label();
  const int violations = count_gabriel_violations(blk);
  int surely = 0;
  const int maybe = brute_force_violations(blk, &surely);
  EXPECT_EQ(violations, 0) << label();
  EXPECT_LE(surely, violations) << label();
  std::printf("[ cap gabr. ] %-32s %d violations (brute force: %d sure, %d within 1e-9)\n", label().c_str(), violations,
              surely, maybe);
  // Fail case: without one cap polygon the surface is open along its edges.
  std::vector<std::vector<int32_t>> holed = blk.surface_faces;
  holed.pop_back();
  EXPECT_GT(open_surface_edges(holed), 0);
}

// The block's volume is the closed form, and each cap holds the polyhedral half-ball at R
// less the one at r_w.
TEST_P(HemisphereCaps, VolumeExact) {
  const WellParams p = params();
  const CaseSpec cs = make_case(p);
  const BuiltBlock b = build(cs, p.sectors);
  double total = 0, start_cap = 0, end_cap = 0;
  for (int c = 0; c < b.mesh.n_cells(); ++c) {
    total += b.geo.cell_volume[c];
    const RadialCellInfo& r = b.mesh.cell_radial[c];
    if (r.band >= 0) (r.segment < 0 ? start_cap : end_cap) += b.geo.cell_volume[c];
  }
  const double exact = exact_well_block_volume(cs, 0, p.sectors);
  const double cap = hemisphere_cap_volume(p.drainage_radius, p.sectors) - hemisphere_cap_volume(p.radius, p.sectors);
  EXPECT_NEAR(total / exact, 1.0, 1e-12) << label();
  EXPECT_NEAR(start_cap / cap, 1.0, 1e-12) << label();
  EXPECT_NEAR(end_cap / cap, 1.0, 1e-12) << label();
  std::printf("[ cap vol.  ] %-32s block %.2e, caps %.2e %.2e relative error\n", label().c_str(),
              std::abs(total / exact - 1), std::abs(start_cap / cap - 1), std::abs(end_cap / cap - 1));
}

INSTANTIATE_TEST_SUITE_P(
    Trajectories, HemisphereCaps,
    ::testing::Combine(::testing::Values(CapTrajectory{"vertical", straight({0, 0, 1})},
                                         CapTrajectory{"deviated", straight({1, 1, std::sqrt(2.0)})},
                                         CapTrajectory{"horizontal", straight({1, 0, 0})},
                                         CapTrajectory{"bend60", bent(60)}),
                       ::testing::Values(6, 12, 24), ::testing::Values(4, 5, 6)),
    [](const ::testing::TestParamInfo<CapParam>& info) {
      return std::string(std::get<0>(info.param).name) + "_" + std::to_string(std::get<1>(info.param)) + "sectors_" +
             std::to_string(std::get<2>(info.param)) + "rings";
    });

// The checks above fail on broken caps: a reversed face (closure), a node off its sphere
// (planarity, co-circularity), centres off their latitude (orthogonality), a centre beyond
// its outer shell (inside).
TEST(HemisphereCapChecks, FailOnBrokenCaps) {
  WellParams p;
  p.trajectory = straight({0, 0, 1});
  const BuiltBlock b = build(make_case(p), p.sectors);
  const WellBlock& blk = b.block;
  const size_t first_cap = static_cast<size_t>((blk.layers - 1) * p.rings * p.sectors);
  // A polar cell of the start cap (band bands-1, ring 2, sector 0).
  const int bands = hemisphere_cap_bands(p.sectors);
  const size_t polar = first_cap + static_cast<size_t>(((bands - 1) * p.rings + 2) * p.sectors);
  ASSERT_EQ(blk.cell_attrs[polar].radial.band, bands - 1);
  ASSERT_EQ(blk.cell_attrs[polar].radial.ring, 2);

  double scale = 0;
  const double closed = norm(block_cell_area_sum(blk, polar, &scale)) / scale;
  EXPECT_LT(closed, 1e-12);
  WellBlock reversed = blk;
  std::reverse(reversed.cell_faces[polar][0].nodes.begin(), reversed.cell_faces[polar][0].nodes.end());
  const double open = norm(block_cell_area_sum(reversed, polar, &scale)) / scale;
  EXPECT_GT(open, 1e-3);

  // The first latitude-1 node of the start cap (right after the layers' nodes), pushed 1 % off
  // its sphere: the faces around it are no longer planar and co-circular.
  WellBlock bumped = blk;
  const size_t node = static_cast<size_t>(blk.layers * (p.rings + 1) * p.sectors);
  const Vec3 e = blk.cell_attrs[first_cap].radial.cap_center;
  ASSERT_NEAR(norm(blk.nodes[node] - e), p.radius, 1e-12 * 100);
  bumped.nodes[node] = e + 1.01 * (blk.nodes[node] - e);
  double worst_circle = 0, worst_plane = 0;
  for (size_t c = first_cap; c < blk.cell_faces.size(); ++c)
    for (const CellFace& f : bumped.cell_faces[c]) {
      double circle = 0, plane = 0;
      face_misfit(bumped.nodes, f.nodes, &circle, &plane);
      worst_circle = std::max(worst_circle, circle);
      worst_plane = std::max(worst_plane, plane);
    }
  EXPECT_GT(worst_circle, 1e-6);
  EXPECT_GT(worst_plane, 1e-6);

  // Centres at their cells' node means instead of sqrt(r_in r_out) at latitude beta_j.
  BuiltBlock moved = b;
  for (int c = 0; c < moved.mesh.n_cells(); ++c) {
    if (moved.mesh.cell_radial[c].band < 0) continue;
    Vec3 mean;
    int n = 0;
    for (const CellFace& f : blk.cell_faces[c])
      for (int32_t v : f.nodes) mean += blk.nodes[v], ++n;
    moved.mesh.cell_fv_center[c] = mean / static_cast<double>(n);
  }
  const CapFaceAngles a = cap_face_angles(moved.mesh, moved.geo);
  EXPECT_GT(a.shell, 1e-4);
  EXPECT_GT(a.cone, 1e-4);
  EXPECT_LT(a.meridian, 1e-9);  // the node mean stays on the mid-meridian plane: still orthogonal

  // Centres at sqrt(r_in r_out) from the end point (without 1 / cos(beta_0)): shells, cones and
  // meridians stay orthogonal, the end plane leans by about beta_0 / 2.
  BuiltBlock inner = b;
  for (int c = 0; c < inner.mesh.n_cells(); ++c) {
    const RadialCellInfo& r = inner.mesh.cell_radial[c];
    if (r.band < 0) continue;
    const Vec3 x = inner.mesh.cell_fv_center[c];
    inner.mesh.cell_fv_center[c] = r.cap_center + std::sqrt(r.r_in * r.r_out) * normalized(x - r.cap_center);
  }
  const CapFaceAngles ai = cap_face_angles(inner.mesh, inner.geo);
  EXPECT_LT(ai.shell, 1e-9);
  EXPECT_LT(ai.cone, 1e-9);
  EXPECT_GT(ai.end_plane, 1.0 * kPi / 180);

  // A centre just beyond the cell's outer shell.
  const Vec3 fv = blk.cell_attrs[polar].fv_center;
  EXPECT_LT(beyond_faces(blk, polar, fv), 0);
  const Vec3 out = e + (1.001 * blk.cell_attrs[polar].radial.r_out) * normalized(fv - e);
  EXPECT_GT(beyond_faces(blk, polar, out), 0);
}

// The polyhedral half-ball: exact pyramids with one band (3 and 4 sectors), scaling as r^3,
// and below the half-ball 2/3 pi r^3, approaching it monotonically as the sectors grow.
TEST(HemisphereCapVolume, PyramidsThenApproachesTheHalfBallFromBelow) {
  const double r = 1.7;
  const double ball = 2.0 / 3.0 * kPi * r * r * r;
  // 3 and 4 sectors (2 bands): the convex hull of nodes on the sphere that include the end
  // polygon's and the pole: more than the pyramid over the end polygon with apex at the pole
  // (sqrt(3)/4 r^3 and 2/3 r^3), less than the half-ball.
  EXPECT_GT(hemisphere_cap_volume(r, 4), 2.0 * r * r * r / 3.0);
  EXPECT_GT(hemisphere_cap_volume(r, 3), std::sqrt(3.0) / 4.0 * r * r * r);
  EXPECT_LT(hemisphere_cap_volume(r, 4), ball);
  double previous = 0;
  for (int sectors : {6, 12, 24, 48}) {
    const double v = hemisphere_cap_volume(r, sectors);
    EXPECT_GT(v, previous) << sectors << " sectors";
    EXPECT_LT(v, ball) << sectors << " sectors";
    EXPECT_NEAR(hemisphere_cap_volume(2 * r, sectors), 8 * v, 1e-13 * v) << sectors << " sectors";
    std::printf("[ cap vol.  ] %2d sectors (%2d bands): polyhedral / ball half = %.6f\n", sectors,
                hemisphere_cap_bands(sectors), v / ball);
    previous = v;
  }
  EXPECT_GT(previous / ball, 0.98);
}

// ---------------------------------------------------------------- end_caps in the case file

namespace {
std::string case_with_end_caps(const std::string& line) {
  return R"(name: caps
reservoir: {x: [0, 100], y: [0, 100], z: [0, 60]}
wells:
  - name: P1
    trajectory: [[50, 50, 15], [50, 50, 45]]
    radius: 0.1
    drainage_radius: 8.0
    bhp: 150
)" + line;
}
}  // namespace

TEST(EndCapsKey, FlatAndHemisphereParseOtherValuesFail) {
  // The default is auto: hemispherical caps, flat ends where they cannot be meshed.
  for (const char* line : {"", "    end_caps: auto\n"}) {
    const WellSpec w = parse_case(case_with_end_caps(line)).wells.at(0);
    EXPECT_EQ(w.end_caps, EndCaps::Hemisphere);
    EXPECT_TRUE(w.end_caps_fallback);
  }
  const WellSpec strict = parse_case(case_with_end_caps("    end_caps: hemisphere\n")).wells.at(0);
  EXPECT_EQ(strict.end_caps, EndCaps::Hemisphere);
  EXPECT_FALSE(strict.end_caps_fallback);
  const WellSpec flat = parse_case(case_with_end_caps("    end_caps: flat\n")).wells.at(0);
  EXPECT_EQ(flat.end_caps, EndCaps::Flat);
  EXPECT_FALSE(flat.end_caps_fallback);
  for (const auto& [value, shown] : std::vector<std::pair<std::string, std::string>>{
           {"round", "'round'"}, {"[flat]", "a list"}, {"Flat", "'Flat'"}}) {
    try {
      parse_case(case_with_end_caps("    end_caps: " + value + "\n"));
      ADD_FAILURE() << "expected InputError for " << value;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), "wells[0].end_caps: expected auto, hemisphere or flat, got " + shown);
    }
  }
}

// ---------------------------------------------------------------- graded end layers

// With hemispherical caps the layers next to each end are as thin as the rings: distances
// r_k - r_w from the end for every ring radius r_k with r_k - r_w below segment_length,
// then uniform segments; with flat ends every layer is a segment.
TEST(WellBlock, HemisphereEndLayersAreGradedLikeTheRings) {
  WellParams p;
  p.trajectory = {{0, 0, 0}, {0, 0, 40}};
  const CaseSpec capped = make_case(p);
  const WellBlock blk = make_well_block(capped, 0, p.sectors);
  // r_k = 0.1 x 80^(k/6): r_k - r_w = 0.1075, 0.3309, 0.7944, 1.7566, 3.7545 (< 4) and 7.9 (> 4;
  // its layer, r_6 - r_5 = 4.15 m, would also be thicker than a segment).
  std::vector<double> graded;
  for (int k = 1; k <= p.rings; ++k) {
    const double d = p.radius * std::pow(p.drainage_radius / p.radius, k / 6.0) - p.radius;
    if (d < p.segment_length) graded.push_back(d);
  }
  ASSERT_EQ(graded.size(), 5u);
  // Then 40 - 2 x 3.7545 = 32.49 m in round(32.49 / 4) = 8 uniform segments.
  const int uniform = 8;
  ASSERT_EQ(blk.layers, 1 + 5 + uniform + 5);
  std::vector<double> from_start, from_end;
  for (int l = 0; l < blk.layers; ++l) {
    from_start.push_back(blk.layer_center[l].z);
    from_end.push_back(40 - blk.layer_center[blk.layers - 1 - l].z);
    EXPECT_NEAR(blk.layer_center[l].x, 0, 1e-15);
    EXPECT_NEAR(blk.layer_center[l].y, 0, 1e-15);
  }
  for (const std::vector<double>* d : {&from_start, &from_end}) {
    EXPECT_NEAR((*d)[0], 0, 1e-12);
    for (size_t k = 0; k < graded.size(); ++k) EXPECT_NEAR((*d)[k + 1], graded[k], 1e-12) << "layer " << k + 1;
    const double step = (40 - 2 * graded.back()) / uniform;
    for (int j = 1; j <= uniform; ++j) EXPECT_NEAR((*d)[graded.size() + j], graded.back() + j * step, 1e-12);
  }
  // Symmetric: the same distances from both ends.
  for (int l = 0; l < blk.layers; ++l) EXPECT_NEAR(from_start[l], from_end[l], 1e-12) << "layer " << l;
  // The segment lengths in the cells agree (the first cylinder cell is r_1 - r_w long).
  EXPECT_NEAR(blk.cell_attrs[0].radial.length, graded[0], 1e-12);

  // Flat ends: 10 uniform segments of 4 m.
  p.end_caps = EndCaps::Flat;
  const WellBlock flat = make_well_block(make_case(p), 0, p.sectors);
  ASSERT_EQ(flat.layers, 11);
  for (int l = 0; l < flat.layers; ++l) EXPECT_NEAR(flat.layer_center[l].z, 4.0 * l, 1e-12) << "layer " << l;
}
