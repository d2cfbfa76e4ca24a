#include <gtest/gtest.h>

#include <set>

#include "meshgen/cavity/cavity.hpp"
#include "meshgen/grids/gabriel.hpp"
#include "uniform_nodes.hpp"

using namespace hm;
using hm::test::uniform_nodes;

namespace {

CaseSpec base_case(double h) {
  CaseSpec cs;
  cs.name = "t";
  cs.reservoir.x = uniform_nodes(0, 120, h);
  cs.reservoir.y = uniform_nodes(0, 120, h);
  cs.reservoir.z = uniform_nodes(1000, 1090, h);
  return cs;
}

WellSpec well(const std::string& name, std::vector<Vec3> traj) {
  WellSpec w;
  w.name = name;
  w.trajectory = std::move(traj);
  w.radius = 0.1;
  w.drainage_radius = 6;
  w.rings = 4;
  w.sectors = 12;
  w.segment_length = 4;
  return w;
}

struct Built {
  ReservoirGrid grid;
  std::vector<WellBlock> blocks;
  std::vector<Vec3> coords;
  CavitySet set;
};

Built build(const CaseSpec& cs) {
  Built b;
  b.grid = make_reservoir_grid(cs.reservoir);
  MeshBuilder builder;
  const auto res_ids = add_reservoir_nodes(b.grid, builder);
  std::vector<std::vector<int32_t>> well_ids;
  for (int w = 0; w < static_cast<int>(cs.wells.size()); ++w) {
    b.blocks.push_back(make_gabriel_well_block(cs, w));
    well_ids.push_back(add_well_block(b.blocks.back(), builder));
  }
  for (int32_t i = 0; i < builder.n_nodes(); ++i) b.coords.push_back(builder.node(i));
  b.set = build_cavities(cs, b.grid, b.blocks, res_ids, well_ids, b.coords);
  return b;
}

// Gabriel (edges and polygons) across the two sides of every cavity, recomputed from the
// extracted faces.
size_t cross_gabriel_violations(const Built& b) {
  size_t n = 0;
  for (const Cavity& cav : b.set.cavities) {
    std::set<std::array<int32_t, 2>> edges[2];
    std::set<int32_t> verts[2];
    for (const ConstrainedFace& f : cav.faces) {
      const int s = static_cast<int>(f.side);
      for (size_t i = 0; i < f.nodes.size(); ++i) {
        const int32_t a = f.nodes[i], c = f.nodes[(i + 1) % f.nodes.size()];
        verts[s].insert(a);
        edges[s].insert({std::min(a, c), std::max(a, c)});
      }
    }
    std::vector<std::vector<int32_t>> polygons[2];
    for (const ConstrainedFace& f : cav.faces) polygons[static_cast<int>(f.side)].push_back(f.nodes);
    for (int s = 0; s < 2; ++s) {
      std::vector<std::array<int32_t, 2>> e(edges[s].begin(), edges[s].end());
      std::vector<int32_t> p(verts[1 - s].begin(), verts[1 - s].end());
      n += gabriel_violations(b.coords, e, p).size();
      n += face_gabriel_violations(b.coords, polygons[s], p).size();
    }
  }
  return n;
}

}  // namespace

TEST(Cavity, VerticalWellGivesOneClosedManifoldGabrielCavity) {
  for (const EndCaps ends : {EndCaps::Flat, EndCaps::Hemisphere}) {
  SCOPED_TRACE(ends == EndCaps::Flat ? "flat ends" : "hemispherical caps");
  CaseSpec cs = base_case(5.0);
  cs.wells.push_back(well("P1", {{60, 60, 1020}, {60, 60, 1070}}));
  cs.wells.back().end_caps = ends;
  const Built b = build(cs);
  ASSERT_EQ(b.set.cavities.size(), 1u);
  const Cavity& cav = b.set.cavities[0];
  EXPECT_TRUE(check_cavity_manifold(cav, b.coords).empty());
  int quads = 0, triangles = 0, caps = 0;
  for (const ConstrainedFace& f : cav.faces) {
    if (f.nodes.size() == 4) ++quads;
    if (f.nodes.size() == 3) ++triangles;
    if (f.patch != kInteriorFace) ++caps;
  }
  if (ends == EndCaps::Flat) {
    EXPECT_EQ(caps, 2);                                           // the two wellbore end caps
    EXPECT_EQ(quads + caps, static_cast<int>(cav.faces.size()));  // everything else is a quad
  } else {
    EXPECT_EQ(caps, 0);               // the wellbore is closed inside the block
    EXPECT_EQ(triangles, 2 * 12);     // the caps' polar shell faces, one per sector
    EXPECT_EQ(quads + triangles, static_cast<int>(cav.faces.size()));
  }
  EXPECT_EQ(cross_gabriel_violations(b), 0u);
  // Every cell within dilation x drainage radius of the axis is deactivated.
  for (int c = 0; c < b.grid.n_cells(); ++c) {
    const Vec3 lo = b.grid.cell_lo(c), hi = b.grid.cell_hi(c);
    const double dx = std::max({lo.x - 60, 0.0, 60 - hi.x}), dy = std::max({lo.y - 60, 0.0, 60 - hi.y});
    const bool in_z = hi.z >= 1020 && lo.z <= 1070;
    if (in_z && std::hypot(dx, dy) < 1.5 * 6 - 1e-9) {
      EXPECT_FALSE(b.set.reservoir_active[c]) << c;
    }
  }
  }
}

TEST(Cavity, CoarseReservoirNeedsGabrielRepairFineDoesNot) {
  // Cells much larger than the well block break the Gabriel condition across the sides.
  CaseSpec coarse = base_case(15.0);
  coarse.wells.push_back(well("P1", {{52, 52, 1032}, {52, 52, 1058}}));
  coarse.transition.dilation = 1.0;
  const Built bc = build(coarse);
  EXPECT_FALSE(bc.set.notes.empty());
  EXPECT_EQ(cross_gabriel_violations(bc), 0u);
  CaseSpec fine = base_case(3.0);
  fine.wells.push_back(well("P1", {{60, 60, 1030}, {60, 60, 1060}}));
  fine.transition.dilation = 1.5;
  const Built bf = build(fine);
  for (const std::string& n : bf.set.notes) {
    EXPECT_EQ(n.find("Gabriel"), std::string::npos) << n;
  }
  EXPECT_EQ(cross_gabriel_violations(bf), 0u);
}

TEST(Cavity, CloseWellsShareOneCavityFarWellsDoNot) {
  CaseSpec close = base_case(5.0);
  close.wells.push_back(well("A", {{50, 60, 1020}, {50, 60, 1070}}));
  close.wells.push_back(well("B", {{66, 60, 1020}, {66, 60, 1070}}));
  const Built bc = build(close);
  ASSERT_EQ(bc.set.cavities.size(), 1u);
  EXPECT_EQ(bc.set.cavities[0].wells.size(), 2u);
  EXPECT_TRUE(check_cavity_manifold(bc.set.cavities[0], bc.coords).empty());
  CaseSpec far = base_case(5.0);
  far.wells.push_back(well("A", {{30, 60, 1020}, {30, 60, 1070}}));
  far.wells.push_back(well("B", {{90, 60, 1020}, {90, 60, 1070}}));
  const Built bf = build(far);
  EXPECT_EQ(bf.set.cavities.size(), 2u);
}

// A cavity reaching the reservoir top is open there (docs/transition.md, "Outer-boundary
// planes"): the plane is listed as a mirror, no constrained polygon lies in it, and the surface is
// a 2-manifold whose only open edges lie in the plane. Fail half: the same surface without the
// mirror is an open surface for the manifold check.
TEST(Cavity, CavityReachingTheReservoirBoundaryIsOpenInThatPlane) {
  CaseSpec cs = base_case(10.0);
  cs.wells.push_back(well("P1", {{60, 60, 1009}, {60, 60, 1050}}));
  const Built b = build(cs);
  ASSERT_EQ(b.set.cavities.size(), 1u);
  const Cavity& cav = b.set.cavities[0];
  ASSERT_EQ(cav.mirrors.size(), 1u);
  EXPECT_EQ(cav.mirrors[0].axis, 2);
  EXPECT_EQ(cav.mirrors[0].value, 1000.0);
  for (const ConstrainedFace& f : cav.faces) {
    bool all_in_plane = true;
    for (int32_t v : f.nodes) all_in_plane = all_in_plane && b.coords[v].z == 1000.0;
    EXPECT_FALSE(all_in_plane);
  }
  EXPECT_TRUE(check_cavity_manifold(cav, b.coords).empty());
  Cavity closed = cav;
  closed.mirrors.clear();
  EXPECT_FALSE(check_cavity_manifold(closed, b.coords).empty());
}
