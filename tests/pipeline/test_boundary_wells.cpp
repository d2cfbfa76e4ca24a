// Wells that cross the reservoir's outer boundary (issue 12, item 2): the shipped cases
// vertical_through (fully penetrating, blocks ending in the top and bottom planes),
// deviated_through_top (30 degrees through the top: the block ends inside, the cavity reaches the
// top) and horizontal_through_sides (a reservoir 2 drainage radii thick: blocks lowered to 0.8 R,
// ending in the side planes, cavity reaching top and bottom) mesh and pass every FV check; the volume is the box
// minus the exact wellbore holes; the outer-boundary faces tile the box's surface (less the holes'
// sections where a block ends in a plane) and no interior face lies in a boundary plane.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "fvcheck/lib/checks.hpp"
#include "fvcheck/lib/quality.hpp"
#include "meshgen/case/meshed_trajectory.hpp"
#include "meshgen/grids/well_block.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"

namespace {

using namespace hm;

CaseSpec example(const std::string& name) { return load_case(std::string(HM_SOURCE_DIR) + "/examples/" + name + ".yaml"); }

// The box plane (axis, side) on which every node of face f lies, or -1.
int face_plane(const PolyMesh& m, const ReservoirSpec& r, int f) {
  const std::vector<double>* axes[3] = {&r.x, &r.y, &r.z};
  for (int k = 0; k < 3; ++k)
    for (int side = 0; side < 2; ++side) {
      const double v = side ? axes[k]->back() : axes[k]->front();
      bool all = true;
      for (const int32_t* n = m.face_begin(f); n != m.face_end(f) && all; ++n) all = m.nodes[*n][k] == v;
      if (all) return 2 * k + side;
    }
  return -1;
}

double regular_polygon_area(int n, double r) { return 0.5 * n * r * r * std::sin(2 * M_PI / n); }

struct Expect {
  int boundary_ends;                          // block ends lying in a boundary plane, over all wells
  std::vector<std::pair<int, double>> planes;  // box planes (axis, value) the cavities must touch
};

void check_case(const std::string& name, Expect want) {
  SCOPED_TRACE(name);
  const CaseSpec cs = example(name);
  const HybridMesh h = build_hybrid_mesh(cs);
  ASSERT_TRUE(h.build_report.ok);
  EXPECT_TRUE(check_csr_invariants(h.mesh).ok);
  for (const CheckResult& c :
       {check_convexity(h.mesh, h.geometry), check_conformity(h.mesh, h.geometry), check_closure(h.mesh, h.geometry),
        check_volume(h.mesh, h.geometry), check_orthogonality(h.mesh, h.geometry),
        check_auto_centering(h.mesh, h.geometry), check_planarity(h.mesh, h.geometry)})
    EXPECT_TRUE(c.ok()) << c.name << ": " << c.violations << " violations, worst " << c.worst;

  // Volume: the box minus the exact wellbore holes of the meshed parts.
  const ReservoirSpec& r = cs.reservoir;
  const double lx = r.x.back() - r.x.front(), ly = r.y.back() - r.y.front(), lz = r.z.back() - r.z.front();
  double expected = lx * ly * lz;
  int boundary_ends = 0;
  double hole_sections = 0;  // wellbore sections in the planes where blocks end
  for (size_t w = 0; w < cs.wells.size(); ++w) {
    const int sectors = h.blocks[w].sectors;
    expected -= exact_wellbore_hole_volume(cs, static_cast<int>(w), sectors);
    for (int e = 0; e < 2; ++e)
      if (h.blocks[w].boundary_end[e]) {
        ++boundary_ends;
        hole_sections += regular_polygon_area(sectors, cs.wells[w].radius);
      }
  }
  EXPECT_EQ(boundary_ends, want.boundary_ends);
  EXPECT_NEAR(total_volume(h.geometry), expected, 1e-9 * expected);
  std::set<std::pair<int, double>> planes;
  for (const Cavity& cav : h.cavities.cavities)
    for (const MirrorPlane& m : cav.mirrors) planes.insert({m.axis, m.value});
  for (const auto& p : want.planes) EXPECT_TRUE(planes.count(p)) << "axis " << p.first << " = " << p.second;

  // Outer-boundary faces lie in the box planes and tile them (less the holes' sections); no
  // interior face and no wellbore face lies in a plane.
  double boundary_area = 0;
  int off_plane = 0, interior_in_plane = 0, wellbore_in_plane = 0, transition_boundary = 0, well_boundary = 0;
  for (int f = 0; f < h.mesh.n_faces(); ++f) {
    const int plane = face_plane(h.mesh, r, f);
    const int32_t patch = h.mesh.face_patch[f];
    if (patch == kOuterBoundary) {
      if (plane < 0) ++off_plane;
      boundary_area += norm(h.geometry.face_area[f]);
      const int32_t region = h.mesh.cell_region[h.mesh.face_owner[f]];
      transition_boundary += region == kTransition;
      well_boundary += region == kWell;
    } else if (plane >= 0) {
      (patch == kInteriorFace ? interior_in_plane : wellbore_in_plane) += 1;
    }
  }
  EXPECT_EQ(off_plane, 0);
  EXPECT_EQ(interior_in_plane, 0);
  EXPECT_EQ(wellbore_in_plane, 0);
  EXPECT_GT(transition_boundary, 0);  // the cavities reach the boundary
  EXPECT_EQ(well_boundary, want.boundary_ends * h.blocks[0].rings * h.blocks[0].sectors);
  const double box_area = 2 * (lx * ly + ly * lz + lz * lx) - hole_sections;
  EXPECT_NEAR(boundary_area, box_area, 1e-9 * box_area);

  // Orthogonality of the interior faces of transition cells that reach a boundary plane, against
  // the other transition cells' (docs/transition.md, "Outer-boundary planes": figures).
  std::vector<char> at_plane(h.mesh.n_cells(), 0);
  for (int f = 0; f < h.mesh.n_faces(); ++f)
    if (h.mesh.face_patch[f] == kOuterBoundary && h.mesh.cell_region[h.mesh.face_owner[f]] == kTransition)
      at_plane[h.mesh.face_owner[f]] = 1;
  const std::vector<double> q_o = face_orthogonality(h.mesh, h.geometry);
  double worst[2] = {90, 90}, sum[2] = {0, 0};
  int count[2] = {0, 0};
  for (int f = 0; f < h.mesh.n_faces(); ++f) {
    const int o = h.mesh.face_owner[f], n = h.mesh.face_neighbour[f];
    if (n < 0) continue;
    if (h.mesh.cell_region[o] != kTransition && h.mesh.cell_region[n] != kTransition) continue;
    const int k = at_plane[o] || at_plane[n] ? 0 : 1;
    worst[k] = std::min(worst[k], q_o[f]);
    sum[k] += q_o[f];
    ++count[k];
  }
  std::printf("[ figures  ] %s: transition faces, cells at a boundary plane: %d faces, Q_O min %.2f mean %.3f deg; "
              "others: %d faces, min %.2f mean %.3f deg\n",
              name.c_str(), count[0], worst[0], sum[0] / std::max(1, count[0]), count[1], worst[1],
              sum[1] / std::max(1, count[1]));
  EXPECT_GT(count[0], 0);
  int wf = -1;
  for (int f = 0; f < h.mesh.n_faces(); ++f)
    if (h.mesh.face_neighbour[f] >= 0 && (wf < 0 || q_o[f] < q_o[wf])) wf = f;
  std::printf("[ figures  ] %s: worst interior face %.2f deg between regions %d and %d\n", name.c_str(), q_o[wf],
              h.mesh.cell_region[h.mesh.face_owner[wf]], h.mesh.cell_region[h.mesh.face_neighbour[wf]]);
  // Boundary faces in the planes: site to the boundary flux point (what fvcheck checks and a
  // Dirichlet condition uses, docs/fvcheck.md "Boundary faces") and, for information, to the face
  // centroid. No flux crosses them in a deck (no-flow).
  const std::vector<double> q_centroid = face_orthogonality(h.mesh, h.geometry, BoundaryPoint::Centroid);
  double worst_boundary = 90, worst_flux_point = 90;
  for (int f = 0; f < h.mesh.n_faces(); ++f)
    if (h.mesh.face_patch[f] == kOuterBoundary && h.mesh.cell_region[h.mesh.face_owner[f]] == kTransition) {
      worst_boundary = std::min(worst_boundary, q_centroid[f]);
      worst_flux_point = std::min(worst_flux_point, q_o[f]);
    }
  std::printf("[ figures  ] %s: transition cells' outer-boundary faces, site to flux point: worst %.2f deg\n",
              name.c_str(), worst_flux_point);
  EXPECT_GE(worst_flux_point, 45.0);
  std::printf("[ figures  ] %s: transition cells' outer-boundary faces, site to centroid: worst %.2f deg\n",
              name.c_str(), worst_boundary);
}

TEST(BoundaryWells, FullyPenetratingVerticalWells) { check_case("vertical_through", {4, {{2, 1000}, {2, 1060}}}); }
TEST(BoundaryWells, WellThroughTheTopAt30Degrees) { check_case("deviated_through_top", {2, {{2, 1000}}}); }
TEST(BoundaryWells, HorizontalWellsInAThinReservoir) { check_case("horizontal_through_sides", {4, {{0, 0}, {0, 72}, {2, 1000}, {2, 1010}}});
}

// The case of the issue: a vertical well from 12 m below the top to 12 m above the bottom of a 60 m
// reservoir (6 m cells, 5 m layers, R = 5 m), inside the box but its cavity reaching top and
// bottom: meshes with flat ends and with hemispherical caps.
TEST(BoundaryWells, CavityReachingTopAndBottomMeshes) {
  for (const EndCaps caps : {EndCaps::Flat, EndCaps::Hemisphere}) {
    CaseSpec cs = example("vertical_through");
    cs.wells.resize(1);
    cs.wells[0].trajectory = {{36, 36, 1012}, {36, 36, 1048}};
    cs.wells[0].end_caps = caps;
    cs.wells[0].end_caps_fallback = false;
    PipelineOptions opts;
    opts.optimize = false;
    const HybridMesh h = build_hybrid_mesh(cs, opts);
    ASSERT_TRUE(h.build_report.ok);
    EXPECT_FALSE(h.blocks[0].boundary_end[0] || h.blocks[0].boundary_end[1]);
    EXPECT_EQ(h.cavities.cavities.at(0).mirrors.size(), 2u);
    EXPECT_EQ(check_convexity(h.mesh, h.geometry).violations, 0);
    EXPECT_EQ(check_auto_centering(h.mesh, h.geometry).violations, 0);
    EXPECT_EQ(check_conformity(h.mesh, h.geometry).violations, 0);
    const double expected = 72.0 * 72.0 * 60.0 - exact_wellbore_hole_volume(cs, 0, h.blocks[0].sectors);
    EXPECT_NEAR(total_volume(h.geometry), expected, 1e-9 * expected);
  }
}

// Only the meshed part is connected: the block of a well entering through the top covers the
// trajectory from the top down, not the part above it.
TEST(BoundaryWells, BlockCoversOnlyTheMeshedPart) {
  const CaseSpec cs = example("vertical_through");
  const WellBlock b = make_gabriel_well_block(cs, 0);
  EXPECT_EQ(b.layer_center.front().z, 1000.0);
  EXPECT_EQ(b.layer_center.back().z, 1060.0);
  EXPECT_NEAR(well_block_prism_length(cs, 0, b.sectors), 60.0, 1e-12);
  // Oblique: the block ends where its end section keeps kRetractGap R from the top.
  const CaseSpec dev = example("deviated_through_top");
  const WellBlock d = make_gabriel_well_block(dev, 0);
  const double R = dev.wells[0].drainage_radius;
  double top = 1e300;
  for (const Vec3& p : d.nodes) top = std::min(top, p.z);
  EXPECT_NEAR(top - 1000.0, kRetractGap * R, 1e-9 * R);
  EXPECT_FALSE(d.boundary_end[0]);
}

}  // namespace

// A block squeezed between two opposite planes (a horizontal well in a reservoir 2 R thick) gets the
// largest drainage radius that keeps kBoundaryGap x that radius from both: half the thickness /
// (1 + kBoundaryGap) = 0.8 R, noted; a block too close to one plane only is refused (the well can
// move); a reservoir thinner than 2 x kMinFittedRadius x (1 + kBoundaryGap) R is refused.
TEST(BoundaryWells, SqueezedBlockGetsTheLargestRadiusThatFits) {
  CaseSpec cs = example("horizontal_through_sides");
  const ReservoirSpec& r = cs.reservoir;
  ASSERT_DOUBLE_EQ(r.z.back() - r.z.front(), 2 * cs.wells[0].drainage_radius);
  const MeshedTrajectory mt = meshed_trajectory(r, cs.wells[0], "wells[0]");
  EXPECT_NEAR(mt.drainage_radius, 0.5 * (r.z.back() - r.z.front()) / (1 + kBoundaryGap), 1e-9);
  const WellBlock b = make_well_block(cs, 0, cs.wells[0].sectors);
  EXPECT_DOUBLE_EQ(b.radii.back(), mt.drainage_radius);
  bool noted = false;
  for (const std::string& n : b.notes) noted = noted || n.find("drainage radius lowered from 5 to 4 m") != std::string::npos;
  EXPECT_TRUE(noted);
  // Off-centre by 1 m: near the top only would be refused; here both planes are within the gap.
  WellSpec w = cs.wells[0];
  for (Vec3& p : w.trajectory) p.z = 1004;
  EXPECT_NEAR(meshed_trajectory(r, w, "wells[0]").drainage_radius, 4 / (1 + kBoundaryGap), 1e-9);
  // A thick reservoir, the well 1 m below the top: the block is too close to one plane only.
  ReservoirSpec thick = r;
  thick.z = {1000, 1010, 1020, 1030};
  for (Vec3& p : w.trajectory) p.z = 1001;
  EXPECT_THROW(meshed_trajectory(thick, w, "wells[0]"), InputError);
  // Too thin: 4 m = 0.8 R < 2 x 0.5 x 1.25 R.
  ReservoirSpec thin = r;
  thin.z = {1000, 1004};
  for (Vec3& p : w.trajectory) p.z = 1002;
  EXPECT_THROW(meshed_trajectory(thin, w, "wells[0]"), InputError);
}
