// Transition mesh of one cavity (issue #3): synthetic cavities built in the test,
// assembled with the reservoir cells and the inner blocks through one MeshBuilder.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <set>

#include "meshgen/transition/transition_internal.hpp"
#include "synthetic_cavity.hpp"

namespace hm::testing {
namespace {

const std::vector<double> kX{0, 8, 14, 19, 23, 27, 32, 38, 46};
const std::vector<double> kY{0, 5, 11, 16, 20, 25, 31, 36, 44};
const std::vector<double> kZ{0, 4, 9, 13, 16, 20, 24, 29, 35};

bool central(int i, int j, int k) { return i >= 2 && i <= 5 && j >= 2 && j <= 5 && k >= 2 && k <= 5; }

void print(const char* name, const Scene& sc, const Metrics& mt) {
  const TransitionReport& r = sc.transition.report;
  std::printf("[%s] cells %d faces %d vertices %d (new %d, identified %d) | sites in %d (boxes %d) out %d | "
              "corrections %d (iters %d) split %d empty-fix %d hidden %d snapped %d removed-faces %d merged-cells %d coincident %d | "
              "orth min 90-%.1e mean 90-%.1e (n %d) res-min 90-%.1e | planarity %.2e convexity %.2e site-margin %.3e closure %.2e | shift id %.1e snap %.1e\n",
              name, mt.transition_cells, mt.transition_faces, mt.transition_nodes, r.free_vertices,
              r.identified_vertices, r.internal_sites, r.box_sites, r.external_sites, r.site_corrections,
              r.correction_iterations, r.split_boxes, r.emptiness_fixes, r.hidden_sites, r.snapped_vertices,
              r.removed_faces, r.merged_cells, r.coincident_vertices, 90 - mt.min_orth, 90 - mt.mean_orth, mt.n_orth, 90 - mt.min_orth_res,
              mt.max_planarity, mt.max_convexity, mt.min_site_margin, mt.max_closure,
              r.max_identification_shift, r.max_snap_shift);
  for (const std::string& n : r.notes) std::printf("   note: %s\n", n.c_str());
  for (const std::string& p : sc.report.problems) std::printf("   builder: %s\n", p.c_str());
}

// The properties every cavity must satisfy.
void expect_valid(const Scene& sc, const Metrics& mt, double planarity_tol) {
  EXPECT_TRUE(sc.report.ok);
  EXPECT_EQ(sc.report.unmatched_faces, 0);
  EXPECT_EQ(sc.report.misoriented_faces, 0);
  EXPECT_EQ(sc.report.overused_faces, 0);
  EXPECT_EQ(sc.report.degenerate_faces, 0);
  EXPECT_TRUE(mt.csr_ok);
  EXPECT_EQ(mt.bad_boundary_faces, 0);
  EXPECT_EQ(mt.polygons_not_once, 0);
  EXPECT_EQ(sc.transition.report.missing_polygons, 0);
  EXPECT_EQ(sc.transition.report.unmatched_external_faces, 0);
  EXPECT_LT(mt.max_closure, 1e-9);
  EXPECT_NEAR(mt.volume, sc.box_volume, 1e-9 * sc.box_volume);
  EXPECT_EQ(mt.negative_volumes, 0);
  EXPECT_LT(mt.max_planarity, planarity_tol);
  EXPECT_LT(mt.max_convexity, planarity_tol);
  EXPECT_GT(mt.min_site_margin, 0.0);
}

TEST(Transition, BoxInBox) {
  Scene sc;
  InnerBlock b;
  b.center = {23, 20, 16};
  b.half = 2.5;
  build_scene(sc, kX, kY, kZ, central, {b});
  const Metrics mt = measure(sc);
  print("box-in-box", sc, mt);
  expect_valid(sc, mt, 1e-9);
  EXPECT_NEAR(mt.min_orth, 90.0, 1e-9);
  EXPECT_NEAR(mt.min_orth_res, 90.0, 1e-9);
}

// Same cavity with spacings that binary floating point cannot represent (x 1.7, like real
// grids): co-sphericity is no longer exact, so power vertices near a lattice node split
// and are identified combinatorially / snapped; the mesh must still be exact in topology.
TEST(Transition, BoxInBoxNonBinarySpacing) {
  auto scaled = [](std::vector<double> v, double f, double o) {
    for (double& x : v) x = o + f * x;
    return v;
  };
  Scene sc;
  InnerBlock b;
  b.center = {1000.1 + 1.7 * 23, -50.3 + 1.3 * 20, 2000.7 + 1.1 * 16};
  b.half = 2.5;
  build_scene(sc, scaled(kX, 1.7, 1000.1), scaled(kY, 1.3, -50.3), scaled(kZ, 1.1, 2000.7), central, {b});
  const Metrics mt = measure(sc);
  print("box-in-box x1.7", sc, mt);
  expect_valid(sc, mt, 1e-9);
  EXPECT_GT(mt.min_orth, 89.999);
}

// (b) the inner block rotated by 30 degrees about an oblique axis: non-axis-aligned quads.
TEST(Transition, RotatedBlock) {
  Scene sc;
  InnerBlock b;
  b.center = {23, 20, 16};
  b.half = 2.5;
  b.axis = {1, 2, 3};
  b.angle = M_PI / 6;
  build_scene(sc, kX, kY, kZ, central, {b});
  const Metrics mt = measure(sc);
  print("rotated", sc, mt);
  expect_valid(sc, mt, 1e-9);
  EXPECT_GT(mt.min_orth, 89.999);
}

// (c) an L-shaped deactivated region: concave edges on the reservoir side.
TEST(Transition, LShapedCavity) {
  Scene sc;
  InnerBlock b;
  b.center = {18.5, 15.5, 16};
  b.half = 1;
  b.axis = {0, 1, 1};
  b.angle = 0.2;
  build_scene(sc, kX, kY, kZ, [](int i, int j, int k) { return central(i, j, k) && !(i >= 4 && j >= 4); }, {b});
  const Metrics mt = measure(sc);
  print("L-shape", sc, mt);
  expect_valid(sc, mt, 1e-9);
  EXPECT_GT(mt.min_orth, 89.999);
}

// (d) two inner blocks in one cavity.
TEST(Transition, TwoBlocksOneCavity) {
  Scene sc;
  InnerBlock b1, b2;
  b1.center = {16.5, 20, 16};
  b1.half = 2;
  b2.center = {29.5, 20.5, 16.5};
  b2.half = 2;
  b2.axis = {0, 1, 1};
  b2.angle = 0.35;
  build_scene(sc, kX, kY, kZ, [](int i, int j, int k) { return i >= 1 && i <= 6 && j >= 2 && j <= 5 && k >= 2 && k <= 5; },
              {b1, b2});
  const Metrics mt = measure(sc);
  print("two blocks", sc, mt);
  expect_valid(sc, mt, 1e-9);
  EXPECT_GT(mt.min_orth, 89.999);
}

// Paper 5.3 cross-check: the internal Voronoi vertex found from the attached tetrahedra is
// the brute-force one, t* = min over cavity vertices X on the inner side of
// (|X-O|^2 - rho^2) / (2 n.(X-O)); same for the external vertex of the well polygons
// (max over the outer side).
TEST(Transition, PolygonDualsMatchBruteForce) {
  Scene sc;
  InnerBlock b;
  b.center = {23, 20, 16};
  b.half = 2.5;
  b.axis = {1, 2, 3};
  b.angle = M_PI / 6;
  build_scene(sc, kX, kY, kZ, central, {b});
  const std::vector<PolygonDual> duals = polygon_duals(sc.cavity, sc.coords);
  ASSERT_EQ(duals.size(), sc.cavity.faces.size());
  int checked_out = 0;
  for (size_t q = 0; q < duals.size(); ++q) {
    const PolygonDual& d = duals[q];
    double t_in = 1e300, t_out = -1e300;
    for (int32_t v : sc.cavity.vertices) {
      const Vec3 x = sc.coords[v] - d.center;
      const double h = dot(d.normal, x);
      const double r = (norm2(x) - d.radius * d.radius) / (2 * h);
      if (h > 1e-9 * d.radius) t_in = std::min(t_in, r);
      if (h < -1e-9 * d.radius) t_out = std::max(t_out, r);
    }
    EXPECT_GT(d.inner_tets, 0) << "polygon " << q;
    EXPECT_NEAR(d.t_in, t_in, 1e-9 * d.radius) << "polygon " << q;
    EXPECT_GT(d.t_in, 0) << "polygon " << q;
    if (sc.cavity.faces[q].side == FaceSide::Well) {
      EXPECT_NEAR(d.t_out, t_out, 1e-9 * d.radius) << "polygon " << q;
      ++checked_out;
    }
  }
  EXPECT_EQ(checked_out, 24);
  EXPECT_TRUE(non_admissible_polygons(sc.cavity, sc.coords).empty());
}

// The output does not depend on memory addresses: two runs give identical cells and nodes.
TEST(Transition, Deterministic) {
  InnerBlock b;
  b.center = {23, 20, 16};
  b.half = 2.5;
  b.axis = {1, 2, 3};
  b.angle = M_PI / 6;
  Scene s1, s2;
  build_scene(s1, kX, kY, kZ, central, {b});
  build_scene(s2, kX, kY, kZ, central, {b});
  ASSERT_EQ(s1.transition.cells.size(), s2.transition.cells.size());
  ASSERT_EQ(s1.transition.new_nodes.size(), s2.transition.new_nodes.size());
  for (size_t i = 0; i < s1.transition.new_nodes.size(); ++i)
    EXPECT_TRUE(s1.transition.new_nodes[i] == s2.transition.new_nodes[i]);
  for (size_t c = 0; c < s1.transition.cells.size(); ++c) {
    ASSERT_EQ(s1.transition.cells[c].size(), s2.transition.cells[c].size());
    for (size_t f = 0; f < s1.transition.cells[c].size(); ++f)
      EXPECT_EQ(s1.transition.cells[c][f].nodes, s2.transition.cells[c][f].nodes);
  }
}

// Pass/fail pair for admissibility: the L-shaped cavity with a block too close to a
// reservoir face (a block vertex inside the face's diametral sphere) is refused with a
// clear message and the reservoir cells to deactivate; once they are deactivated the
// enlarged cavity is built and valid.
TEST(Transition, NonAdmissibleCavityIsRefusedThenEnlarged) {
  InnerBlock b;
  b.center = {18.5, 15.5, 16};
  b.half = 2;
  std::set<int> extra;
  auto inactive = [&](int i, int j, int k) {
    const int c = i + 8 * (j + 8 * k);
    return (central(i, j, k) && !(i >= 4 && j >= 4)) || extra.count(c) > 0;
  };
  int refusals = 0;
  for (int attempt = 0; attempt < 4; ++attempt) {
    Scene sc;
    try {
      build_scene(sc, kX, kY, kZ, inactive, {b});
    } catch (const TransitionError& e) {
      ++refusals;
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind("transition: ", 0), 0u) << msg;
      EXPECT_NE(msg.find("constrained polygons are not Delaunay admissible"), std::string::npos) << msg;
      EXPECT_NE(msg.find("the cavity must be enlarged"), std::string::npos) << msg;
      EXPECT_FALSE(non_admissible_polygons(sc.cavity, sc.coords).empty());
      ASSERT_FALSE(e.polygons.empty());
      ASSERT_FALSE(e.cells_to_deactivate.empty());
      for (int32_t c : e.cells_to_deactivate) {
        EXPECT_TRUE(sc.active[c]) << c;
        EXPECT_TRUE(extra.insert(c).second) << c;
      }
      continue;
    }
    const Metrics mt = measure(sc);
    print("L-shape enlarged", sc, mt);
    expect_valid(sc, mt, 1e-9);
    break;
  }
  EXPECT_GE(refusals, 1);
  EXPECT_LE(refusals, 2);
}

// One internal site per polygon of `cav` (no external sites), polygon q's at height t[q].
transition_detail::SiteSet polygon_sites(const Cavity& cav, const std::vector<transition_detail::PolygonFrame>& frames,
                                         const std::vector<double>& t) {
  using namespace transition_detail;
  SiteSet set;
  set.internal_of.assign(cav.faces.size(), -1);
  set.external_of.assign(cav.faces.size(), -1);
  for (size_t q = 0; q < cav.faces.size(); ++q) {
    Site s;
    s.kind = SiteKind::InternalPolygon;
    s.polygon = static_cast<int>(q);
    s.polygons = {static_cast<int>(q)};
    s.vertices = cav.faces[q].nodes;
    std::sort(s.vertices.begin(), s.vertices.end());
    s.t = t[q];
    s.p = frames[q].center + t[q] * frames[q].normal;
    s.w2 = frames[q].radius * frames[q].radius + t[q] * t[q];
    set.internal_of[q] = static_cast<int>(q);
    set.sites.push_back(s);
  }
  return set;
}

// Pass/fail pair for the site correction (5.5.3): a large site whose radical plane with a
// small neighbour does not separate them is moved toward its polygon until condition (6)
// holds; with one iteration allowed the same set fails with the documented message.
TEST(Transition, SiteCorrection) {
  using namespace transition_detail;
  std::vector<Vec3> coords;
  Cavity cav;
  auto square = [&](Vec3 c, double r) {
    ConstrainedFace f;
    for (int k = 0; k < 4; ++k) {
      const double a = M_PI / 4 + k * M_PI / 2;
      f.nodes.push_back(static_cast<int32_t>(coords.size()));
      coords.push_back(c + Vec3{r * std::cos(a), r * std::sin(a), 0});
    }
    f.side = FaceSide::Well;
    cav.faces.push_back(f);
  };
  square({0, 0, 0}, 1.0);
  square({2, 0, 2}, 0.1);
  for (int32_t v = 0; v < 8; ++v) cav.vertices.push_back(v);
  std::vector<PolygonFrame> frames;
  for (const ConstrainedFace& f : cav.faces) frames.push_back(fit_polygon(f.nodes, coords));
  EXPECT_NEAR(frames[0].radius, 1.0, 1e-15);
  EXPECT_NEAR(frames[1].center.x, 2.0, 1e-15);
  auto make = [&]() { return polygon_sites(cav, frames, {3.0, 0.1}); };
  ReservoirGrid grid;
  SiteSet bad = make();
  int iterations = 0;
  try {
    correct_sites(bad, cav, coords, grid, frames, 1, &iterations);
    FAIL() << "expected no convergence in one iteration";
  } catch (const TransitionError& e) {
    EXPECT_STREQ(e.what(), "transition: site correction did not converge after 1 iterations (1 pairs left: 1 well > well)");
    EXPECT_EQ(e.polygons, (std::vector<int32_t>{0, 1}));  // both sites of the pair
    EXPECT_TRUE(e.cells_to_deactivate.empty());           // well polygons, no reservoir behind
  }
  SiteSet good = make();
  const int corrections = correct_sites(good, cav, coords, grid, frames, 100, &iterations);
  EXPECT_GE(corrections, 1);
  EXPECT_GE(iterations, 2);
  const Site &a = good.sites[0], &s = good.sites[1];
  EXPECT_LE(std::abs(a.w2 - s.w2), norm2(a.p - s.p));  // condition (6)
  EXPECT_LT(a.t, 3.0);                                   // the larger site moved
  EXPECT_EQ(s.t, 0.1);                                   // the smaller did not
}

// A correction that cannot converge stops where its state repeats (the iterations are deterministic
// in it, so they would cycle until the cap) and says so. Two coplanar well triangles whose quad is
// not Delaunay: the far vertex of one lies inside the other's circumcircle, so no sphere through that
// triangle is empty and no height of the two sites satisfies both the emptiness and condition (6).
TEST(Transition, SiteCorrectionStopsAtACycle) {
  using namespace transition_detail;
  const std::vector<Vec3> coords = {{0, 0, 0}, {2, 0, 0}, {1, 1.2, 0}, {1, -0.3, 0}};
  Cavity cav;
  for (const std::vector<int32_t>& nodes : {std::vector<int32_t>{0, 1, 2}, std::vector<int32_t>{0, 3, 1}}) {
    ConstrainedFace f;
    f.nodes = nodes;
    f.side = FaceSide::Well;
    cav.faces.push_back(f);
  }
  cav.vertices = {0, 1, 2, 3};
  std::vector<PolygonFrame> frames;
  for (const ConstrainedFace& f : cav.faces) frames.push_back(fit_polygon(f.nodes, coords));
  ASSERT_GT(frames[0].normal.z, 0);  // both open toward +z
  ASSERT_GT(frames[1].normal.z, 0);
  SiteSet set = polygon_sites(cav, frames, {0.5, 0.5});
  ReservoirGrid grid;
  int iterations = 0;
  constexpr int kCap = 400;
  try {
    correct_sites(set, cav, coords, grid, frames, kCap, &iterations);
    FAIL() << "a quad that is not Delaunay cannot be corrected";
  } catch (const TransitionError& e) {
    EXPECT_NE(std::string(e.what()).find("repeats an earlier one: a cycle"), std::string::npos) << e.what();
    EXPECT_EQ(e.polygons, (std::vector<int32_t>{0, 1}));
  }
  EXPECT_LT(iterations, kCap);
}

// Hidden sites are detected, never dropped silently: a site sitting on another one with a
// smaller weight has no power cell; build_power_cells names it and emits nothing, and the
// same set without it gives one cell per internal site.
TEST(Transition, HiddenSiteIsReported) {
  using namespace transition_detail;
  Scene sc;
  InnerBlock b;
  b.center = {23, 20, 16};
  b.half = 2.5;
  build_scene(sc, kX, kY, kZ, central, {b});
  std::vector<std::string> notes;
  std::vector<PolygonFrame> frames;
  for (const ConstrainedFace& f : sc.cavity.faces) frames.push_back(fit_polygon(f.nodes, sc.coords));
  attach_voronoi_edges(sc.cavity, sc.coords, frames, notes);
  SiteSet set = make_sites(sc.cavity, sc.coords, sc.grid, frames, notes);
  int internal = 0;
  for (const Site& s : set.sites) internal += s.alive && s.internal();
  TransitionCells ok;
  EXPECT_TRUE(build_power_cells(set, sc.cavity, sc.coords, frames, ok).empty());
  EXPECT_EQ(static_cast<int>(ok.cells.size()), internal);
  EXPECT_EQ(ok.report.missing_polygons, 0);
  Site ghost = set.sites[set.internal_of[0]];
  ghost.w2 *= 0.5;
  set.sites.push_back(ghost);
  TransitionCells out;
  const std::vector<int> hidden = build_power_cells(set, sc.cavity, sc.coords, frames, out);
  ASSERT_EQ(hidden.size(), 1u);
  EXPECT_EQ(hidden[0], static_cast<int>(set.sites.size()) - 1);
  EXPECT_TRUE(out.cells.empty());
}

// A broken cavity (one reservoir polygon dropped, so the surface is open) is not silently
// accepted: the power faces that should have been that polygon match no constrained
// polygon, are reported, and the builder finds the faces left without a partner.
TEST(Transition, OpenCavityIsReported) {
  Scene sc;
  InnerBlock b;
  b.center = {23, 20, 16};
  b.half = 2.5;
  build_scene_with(sc, kX, kY, kZ, central, {b}, [](Cavity& c) {
    for (size_t q = 0; q < c.faces.size(); ++q)
      if (c.faces[q].side == FaceSide::Reservoir) {
        c.faces.erase(c.faces.begin() + static_cast<long>(q));
        return;
      }
  });
  EXPECT_GT(sc.transition.report.unmatched_external_faces, 0);
  EXPECT_FALSE(sc.report.ok);
  EXPECT_GT(sc.report.unmatched_faces, 0);
}

// The wall check of a corner-point cavity (model_wall_orthogonality_refusal): one tetrahedral cell
// whose base is an obtuse model triangle (its circumcentre outside it). A site over the triangle
// passes; a site low over the circumcentre's side fails at its boundary flux point (on edge AB) and
// names the polygon and the model cell behind it. An outer-surface or well polygon is not a wall.
TEST(Transition, ModelWallFaceBelowOrthogonalityIsRefusedWithTheCellBehind) {
  const std::vector<Vec3> coords{{0, 0, 0}, {10, 0, 0}, {5, 1, 0}, {5, 0.5, 5}};
  Cavity cav;
  ConstrainedFace wall;
  wall.nodes = {0, 1, 2};  // normal +z: into the cavity
  wall.side = FaceSide::Reservoir;
  wall.outside_cell = 7;
  wall.inside_cell = 3;
  cav.faces.push_back(wall);
  TransitionCells t;
  t.base_node_id = 4;
  t.cells.push_back({{{0, 2, 1}}, {{0, 1, 3}}, {{1, 2, 3}}, {{2, 0, 3}}});  // outward
  t.cell_polygons = {{0}};
  t.cell_site = {0};
  t.weights = {0};
  t.h_ref = {5};

  t.sites = {{5, 0.5, 1}};  // foot inside the triangle: Q_O 90
  EXPECT_FALSE(model_wall_orthogonality_refusal(t, cav, coords, 45).has_value());

  t.sites = {{5, -3, 0.5}};  // foot outside: to (5, 0, 0), asin(0.5 / |(0, 3, -0.5)|) = 9.5 degrees
  const auto r = model_wall_orthogonality_refusal(t, cav, coords, 45);
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->polygons, std::vector<int32_t>{0});
  EXPECT_EQ(r->cells_to_deactivate, std::vector<int32_t>{7});
  EXPECT_NE(r->reason.find("worst 9.46"), std::string::npos) << r->reason;
  EXPECT_FALSE(model_wall_orthogonality_refusal(t, cav, coords, 9).has_value());  // above the threshold

  cav.faces[0].outside_cell = -1;  // the model's outer surface: no cell to move away
  EXPECT_FALSE(model_wall_orthogonality_refusal(t, cav, coords, 45).has_value());
  cav.faces[0].outside_cell = 7;
  cav.faces[0].side = FaceSide::Well;
  EXPECT_FALSE(model_wall_orthogonality_refusal(t, cav, coords, 45).has_value());
}

}  // namespace
}  // namespace hm::testing

namespace hm::testing {

// The optimiser's acceptance of one site move (docs/optimization.md, "Rounds"). A move that mends a
// shape failure the raw diagram had is kept although Q_S falls: before session 25 such moves were
// refused for the missing Q_S gain, the round's other moves kept, and the raw diagram's failing cells
// reached the self-check (corner-point sweep seed 16: 3 cells not convex, exit 1; it meshes now).
TEST(SiteOptimizer, MoveIsKeptForWhatItDoesToTheCellsAroundIt) {
  using transition_detail::MoveEffect;
  using transition_detail::move_is_kept;
  using Kind = transition_detail::MoveKind;
  MoveEffect mends;
  mends.q_s_before = 2.0, mends.q_s_after = 1.9;
  mends.failing_before = 2, mends.failing_after = 0;
  for (Kind k : {Kind::ShortEdge, Kind::SkewStep, Kind::Repair, Kind::SliverRemoval}) EXPECT_TRUE(move_is_kept(mends, k));
  MoveEffect breaks = mends;  // a newly failing cell refuses any move
  breaks.newly_failing = true;
  for (Kind k : {Kind::ShortEdge, Kind::SkewStep, Kind::Repair, Kind::SliverRemoval}) EXPECT_FALSE(move_is_kept(breaks, k));
  MoveEffect gain;  // a short-edge move: Q_S up, no skewed face added
  gain.q_s_before = 1.0, gain.q_s_after = 1.2;
  EXPECT_TRUE(move_is_kept(gain, Kind::ShortEdge));
  EXPECT_FALSE(move_is_kept(gain, Kind::Repair));  // a repair is kept for mending alone
  gain.skewed_after = 1;
  EXPECT_FALSE(move_is_kept(gain, Kind::ShortEdge));
  // A sliver removal needs that nothing fails and no face around it newly exceeds checkMesh's
  // skewness limit (accuracy_bent: a removal made a face of skewness 21, session 30).
  EXPECT_FALSE(move_is_kept(gain, Kind::SliverRemoval));
  gain.skewed_before = 1;
  EXPECT_TRUE(move_is_kept(gain, Kind::SliverRemoval));
  gain.q_s_after = 0.5;  // whatever it does to Q_S
  EXPECT_TRUE(move_is_kept(gain, Kind::SliverRemoval));
  MoveEffect step;  // a step against skewness: fewer skewed faces, or as many with a lower worst
  step.skewed_before = 2, step.skewed_after = 2, step.worst_skew_before = 5.0, step.worst_skew_after = 4.5;
  EXPECT_TRUE(move_is_kept(step, Kind::SkewStep));
  step.worst_skew_after = 5.5;
  EXPECT_FALSE(move_is_kept(step, Kind::SkewStep));
}

}  // namespace hm::testing
