// The regular triangulation the optimiser keeps across its rounds (PowerDiagram): moving a few
// sites in it and extracting the cells gives the diagram that build_power_cells builds from
// scratch on the same sites (same cells, same faces, same node numbering, the same power
// vertices bit for bit: the regular triangulation does not depend on its history, and a
// vertex is computed from its cell's points in site order), it moves only the sites that
// changed, a saved copy serves a call it is nearer to, and a move that hides a site is
// reported as build_power_cells reports it, after which the next call starts afresh.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "../transition/synthetic_cavity.hpp"
#include "meshgen/transition/transition_internal.hpp"

using namespace hm;
using namespace hm::transition_detail;
using namespace hm::testing;

namespace {

// The box-in-box cavity of the transition tests (a block of reservoir cells around an inner
// block), its frames and its corrected sites: a cavity with constrained polygons on both sides.
struct Sites {
  Scene sc;
  SiteSet set;
  std::vector<PolygonFrame> frames;
  const Cavity& cavity = sc.cavity;
  const std::vector<Vec3>& coords = sc.coords;
};

void make_sites_box(Sites& s) {
  const std::vector<double> x{0, 8, 14, 19, 23, 27, 32, 38, 46}, y{0, 5, 11, 16, 20, 25, 31, 36, 44},
      z{0, 4, 9, 13, 16, 20, 24, 29, 35};
  InnerBlock b;
  b.center = {23, 20, 16};
  b.half = 2.5;
  build_scene(s.sc, x, y, z, [](int i, int j, int k) { return i >= 2 && i <= 5 && j >= 2 && j <= 5 && k >= 2 && k <= 5; },
              {b});
  std::vector<std::string> notes;
  for (const ConstrainedFace& f : s.sc.cavity.faces) s.frames.push_back(fit_polygon(f.nodes, s.sc.coords));
  attach_voronoi_edges(s.sc.cavity, s.sc.coords, s.frames, notes);
  s.set = make_sites(s.sc.cavity, s.sc.coords, s.sc.grid, s.frames, notes);
}

// The same diagram: same sites per cell, same faces with the same node ids, free power
// vertices within `tol` of each other.
void expect_same(const TransitionCells& a, const TransitionCells& b, double tol) {
  ASSERT_EQ(a.cells.size(), b.cells.size());
  EXPECT_EQ(a.cell_site, b.cell_site);
  for (size_t c = 0; c < a.cells.size(); ++c) {
    ASSERT_EQ(a.cells[c].size(), b.cells[c].size()) << "cell " << c;
    for (size_t f = 0; f < a.cells[c].size(); ++f) EXPECT_EQ(a.cells[c][f].nodes, b.cells[c][f].nodes) << "cell " << c;
  }
  ASSERT_EQ(a.new_nodes.size(), b.new_nodes.size());
  EXPECT_EQ(a.new_node_sites, b.new_node_sites);
  double worst = 0;
  for (size_t v = 0; v < a.new_nodes.size(); ++v) worst = std::max(worst, norm(a.new_nodes[v] - b.new_nodes[v]));
  EXPECT_LE(worst, tol);
}

// Moves `count` polygon sites (every `stride`-th polygon with a mirror) to `factor` x their
// distance along their dual lines, each with its reflection; returns the polygons moved.
std::vector<int> move_polygon_sites(Sites& s, int count, size_t stride, double factor) {
  std::vector<int> moved;
  for (size_t q = 0; q < s.set.internal_of.size() && static_cast<int>(moved.size()) < count; q += stride) {
    const int i = s.set.internal_of[q];
    if (i < 0 || s.set.sites[i].kind != SiteKind::InternalPolygon || s.set.external_of[q] < 0 ||
        s.set.sites[s.set.external_of[q]].kind != SiteKind::ExternalMirror)
      continue;
    place_polygon_site(s.set, i, factor * s.set.sites[i].t, s.cavity, s.coords, s.frames);
    moved.push_back(static_cast<int>(q));
  }
  return moved;
}

TransitionCells from_scratch(const Sites& s) {
  TransitionCells out;
  out.base_node_id = 100;
  EXPECT_TRUE(build_power_cells(s.set, s.cavity, s.coords, s.frames, out).empty());
  return out;
}

}  // namespace

TEST(PowerDiagram, MovedSitesGiveTheDiagramBuiltFromScratch) {
  Sites s;
  make_sites_box(s);
  PowerDiagram d;
  TransitionCells first;
  first.base_node_id = 100;
  ASSERT_TRUE(d.cells(s.set, s.cavity, s.coords, s.frames, first).empty());
  EXPECT_EQ(d.moved_last(), 0);  // the first call triangulates
  expect_same(first, from_scratch(s), 0.0);
  ASSERT_GT(first.cells.size(), 20u);

  // Move three polygon sites along their dual lines (each moves its reflection too: six
  // sites), incrementally, then back.
  const std::vector<Site> before = s.set.sites;
  ASSERT_EQ(move_polygon_sites(s, 3, 7, 0.9).size(), 3u);
  TransitionCells after;
  after.base_node_id = 100;
  ASSERT_TRUE(d.cells(s.set, s.cavity, s.coords, s.frames, after).empty());
  EXPECT_EQ(d.moved_last(), 6);  // three sites and their reflections
  const TransitionCells scratch = from_scratch(s);
  expect_same(after, scratch, 0.0);
  // Something did change (the test would pass vacuously otherwise).
  double shift = 0;
  for (size_t c = 0; c < first.sites.size(); ++c) shift = std::max(shift, norm(first.sites[c] - after.sites[c]));
  EXPECT_GT(shift, 0.0);

  s.set.sites = before;
  TransitionCells back;
  back.base_node_id = 100;
  ASSERT_TRUE(d.cells(s.set, s.cavity, s.coords, s.frames, back).empty());
  EXPECT_EQ(d.moved_last(), 6);
  expect_same(back, first, 0.0);
}

// The optimiser's round: the diagram saved, a few moves applied, all but one undone. The next
// call starts from the saved copy (two sites to move instead of four) and gives the diagram
// built from scratch.
TEST(PowerDiagram, SavedCopyServesTheCallItIsNearerTo) {
  Sites s;
  make_sites_box(s);
  PowerDiagram d;
  TransitionCells out;
  out.base_node_id = 100;
  ASSERT_TRUE(d.cells(s.set, s.cavity, s.coords, s.frames, out).empty());
  d.save();
  const std::vector<Site> before = s.set.sites;
  const std::vector<int> moved = move_polygon_sites(s, 3, 5, 0.85);
  ASSERT_EQ(moved.size(), 3u);
  ASSERT_TRUE(d.cells(s.set, s.cavity, s.coords, s.frames, out).empty());
  EXPECT_EQ(d.moved_last(), 6);
  for (size_t k = 1; k < moved.size(); ++k)
    for (int site : {s.set.internal_of[moved[k]], s.set.external_of[moved[k]]}) s.set.sites[site] = before[site];
  TransitionCells kept;
  kept.base_node_id = 100;
  ASSERT_TRUE(d.cells(s.set, s.cavity, s.coords, s.frames, kept).empty());
  EXPECT_EQ(d.moved_last(), 2);  // from the copy: one site and its reflection
  expect_same(kept, from_scratch(s), 0.0);
  // Back to the sites before the moves: two sites from the triangulation the last call left.
  s.set.sites = before;
  ASSERT_TRUE(d.cells(s.set, s.cavity, s.coords, s.frames, kept).empty());
  EXPECT_EQ(d.moved_last(), 2);
  expect_same(kept, from_scratch(s), 0.0);
}

TEST(PowerDiagram, HiddenSiteIsReportedThenRecovered) {
  Sites s;
  make_sites_box(s);
  PowerDiagram d;
  TransitionCells out;
  ASSERT_TRUE(d.cells(s.set, s.cavity, s.coords, s.frames, out).empty());
  // Put an internal site onto its neighbour with a much smaller weight: it has no power cell.
  int a = -1, b = -1;
  for (int i = 0; i < static_cast<int>(s.set.sites.size()) && b < 0; ++i)
    if (s.set.sites[i].alive && s.set.sites[i].kind == SiteKind::InternalPolygon) (a < 0 ? a : b) = i;
  ASSERT_GE(b, 0);
  const Site saved = s.set.sites[b];
  s.set.sites[b].p = s.set.sites[a].p + Vec3{1e-3, 0, 0};
  s.set.sites[b].w2 = 1e-6 * s.set.sites[a].w2;
  TransitionCells hidden_out, scratch_out;
  const std::vector<int> hidden = d.cells(s.set, s.cavity, s.coords, s.frames, hidden_out);
  EXPECT_EQ(hidden, build_power_cells(s.set, s.cavity, s.coords, s.frames, scratch_out));
  ASSERT_EQ(hidden, std::vector<int>{b});
  EXPECT_TRUE(hidden_out.cells.empty());
  // Back to a valid site set: the next call starts from scratch and gives the same diagram.
  s.set.sites[b] = saved;
  TransitionCells again;
  again.base_node_id = 100;
  ASSERT_TRUE(d.cells(s.set, s.cavity, s.coords, s.frames, again).empty());
  EXPECT_EQ(d.moved_last(), 0);
  expect_same(again, from_scratch(s), 0.0);
}

// Power vertices that rounding split: coincident_pairs finds every pair within eps, and no
// other, as the quadratic search does; on a lattice whose spacing is the bucket side (1024 eps:
// every point on a bucket face, up to rounding) with copies shifted by 0.5 to 1.5 eps in all
// directions, so that pairs straddle faces, edges and corners of the buckets.
TEST(PowerDiagram, CoincidentPairsAreThoseOfTheQuadraticSearch) {
  const double eps = 1e-3;
  std::vector<Vec3> points;
  for (int i = -4; i < 5; ++i)
    for (int j = -4; j < 5; ++j)
      for (int k = -4; k < 5; ++k) points.push_back(1024 * eps * Vec3{double(i), double(j), double(k)});
  const size_t lattice = points.size();
  uint64_t state = 12345;
  auto uniform = [&] {  // deterministic, in [0, 1)
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) / 9007199254740992.0;
  };
  for (size_t p = 0; p < lattice; p += 2) {
    const Vec3 d{uniform() - 0.5, uniform() - 0.5, uniform() - 0.5};
    points.push_back(points[p] + ((0.5 + uniform()) * eps / norm(d)) * d);
  }
  std::vector<std::pair<int, int>> expected;
  for (size_t a = 0; a < points.size(); ++a)
    for (size_t b = a + 1; b < points.size(); ++b)
      if (norm(points[a] - points[b]) <= eps) expected.emplace_back(static_cast<int>(a), static_cast<int>(b));
  ASSERT_GT(expected.size(), 100u);   // the shifted copies within eps
  ASSERT_LT(expected.size(), 300u);   // and not those beyond it
  std::vector<std::pair<int, int>> found = coincident_pairs(points, eps);
  std::sort(found.begin(), found.end());
  EXPECT_EQ(found, expected);  // duplicates would show
}
