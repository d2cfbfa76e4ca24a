// Robustness: random straight deviated wells and random bent wells (fixed seeds) in a refined reservoir,
// every other case with hemispherical end caps. Every case must give a conforming mesh whose volume is
// the box minus the wellbore holes, or a clear InputError; never another failure.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "fvcheck/lib/checks.hpp"
#include "meshgen/grids/well_block.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"

using namespace hm;

namespace {
std::vector<double> axis(std::initializer_list<double> coarse_lo, double fine_lo, double fine_hi, double h,
                         std::initializer_list<double> coarse_hi) {
  std::vector<double> v(coarse_lo);
  for (double x = fine_lo; x <= fine_hi + 1e-9; x += h) v.push_back(x);
  v.insert(v.end(), coarse_hi);
  return v;
}

// A 200 x 200 x 100 m reservoir refined to 4 m around (100-140, 100-140, 1005-1055), one well.
CaseSpec random_case(const std::string& name, const WellSpec& well) {
  CaseSpec cs;
  cs.name = name;
  cs.reservoir.x = axis({0, 40, 70, 90}, 100, 140, 4, {150, 170, 200});
  cs.reservoir.y = axis({0, 40, 70, 90}, 100, 140, 4, {150, 170, 200});
  cs.reservoir.z = axis({980, 995}, 1005, 1055, 4, {1065, 1080});
  cs.wells.push_back(well);
  return cs;
}

// The box minus the wellbore hole: the inner polygon's area times the block's prism length
// (the trajectory length for a straight well; wedges included at bends), plus the two polyhedral
// half-balls of radius r_w with hemispherical end caps.
double box_minus_hole(const CaseSpec& cs, const HybridMesh& h) {
  const int sectors = h.blocks.at(0).sectors;
  const double r_w = cs.wells[0].radius;
  const double caps =
      cs.wells[0].end_caps == EndCaps::Hemisphere ? 2 * hemisphere_cap_volume(r_w, sectors) : 0.0;
  return 200.0 * 200.0 * 100.0 -
         0.5 * sectors * r_w * r_w * std::sin(2 * M_PI / sectors) * well_block_prism_length(cs, 0, sectors) - caps;
}
// Every other case with hemispherical end caps, strictly (they must mesh: no fallback to flat ends).
void alternate_end_caps(WellSpec& w, int t) {
  w.end_caps = t % 2 ? EndCaps::Hemisphere : EndCaps::Flat;
  w.end_caps_fallback = false;
}

// Meshes the case (no optimisation). Returns true when it meshes, after checking the total volume
// against the box minus the exact hole (and, with fv_checks, convexity, auto-centering and
// conformity); false when it is refused as input.
bool meshes_or_is_refused(const CaseSpec& cs, int t, bool fv_checks) {
  try {
    PipelineOptions opts;
    opts.optimize = false;
    const HybridMesh h = build_hybrid_mesh(cs, opts);
    EXPECT_TRUE(h.build_report.ok);
    const double expected = box_minus_hole(cs, h);
    EXPECT_NEAR(total_volume(h.geometry), expected, 1e-9 * expected);
    if (fv_checks) {
      EXPECT_EQ(check_convexity(h.mesh, h.geometry).violations, 0);
      EXPECT_EQ(check_auto_centering(h.mesh, h.geometry).violations, 0);
      EXPECT_EQ(check_conformity(h.mesh, h.geometry).violations, 0);
    }
    return true;
  } catch (const InputError& e) {
    std::printf("[ refused   ] case %d: %s\n", t, e.what());
    return false;
  }
}
}  // namespace

TEST(RandomWells, EveryCaseMeshesConformingOrIsRefusedAsInput) {
  std::mt19937 rng(20261122);
  std::uniform_real_distribution<double> u(0, 1);
  int meshed = 0, refused = 0;
  for (int t = 0; t < 10; ++t) {
    const double inc = u(rng) * M_PI / 2, az = u(rng) * 2 * M_PI, len = 10 + 10 * u(rng);
    const Vec3 a{112 + 16 * u(rng), 112 + 16 * u(rng), 1015 + 8 * u(rng)};
    const Vec3 b = a + len * Vec3{std::sin(inc) * std::cos(az), std::sin(inc) * std::sin(az), std::cos(inc)};
    WellSpec w;
    w.name = "W";
    w.trajectory = {a, b};
    w.radius = 0.1;
    w.drainage_radius = 3 + 2 * u(rng);
    w.rings = 5;
    w.sectors = 12;
    w.segment_length = 4;
    alternate_end_caps(w, t);
    SCOPED_TRACE("case " + std::to_string(t) + (t % 2 ? ", caps" : ", flat"));
    if (meshes_or_is_refused(random_case("random", w), t, false))
      ++meshed;
    else
      ++refused;
  }
  std::printf("[ random    ] %d meshed, %d refused as input\n", meshed, refused);
  EXPECT_GE(meshed, 8);
}

// Narrow wedges at a bend (a short segment_length: no wedge longer than a segment outside the
// bend): the fan of the inner-side wedge polygons' sites converges on the bend's focal line,
// which free sites must own. Every site whose sphere covers the focal line is lowered off it,
// reservoir polygons' included (docs/transition.md, "Bends: the focal line"): before, the
// reservoir polygons' spheres covered the whole line, no free site was placed, and this 57-degree
// bend failed the self-check (conformity) from 5 wedges on (segment_length 1.5 m and less).
TEST(RandomWells, NarrowBendWedgesMeshAtEverySegmentLength) {
  for (const double segment : {3.0, 1.5, 1.0, 0.5}) {
    WellSpec w;
    w.name = "B";
    w.trajectory = {{121.27380110904662, 123.98985691436629, 1015.768043692008},
                    {121.27380110904662, 123.98985691436629, 1029.768043692008},
                    {121.41446089713006, 135.78741950047069, 1037.304470687008}};
    w.radius = 0.1;
    w.drainage_radius = 3;
    w.rings = 4;
    w.sectors = 12;
    w.segment_length = segment;
    w.end_caps = EndCaps::Flat;
    SCOPED_TRACE("segment_length " + std::to_string(segment));
    EXPECT_TRUE(meshes_or_is_refused(random_case("narrow_wedges", w), 0, true));
  }
}

// Random bent wells (two legs, bends of 10-110 degrees in random planes): the bend wedges must
// give a conforming mesh, convex transition cells with their sites inside (fvcheck), and a
// volume equal to the box minus the wellbore hole, whose exact volume is the inner polygon's
// area times the block's prism length (wedges included).
TEST(RandomWells, BentWellsMeshConvexAndExactOrAreRefusedAsInput) {
  std::mt19937 rng(20261123);
  std::uniform_real_distribution<double> u(0, 1);
  int meshed = 0, refused = 0;
  for (int t = 0; t < 12; ++t) {
    const double bend = (10 + 100 * u(rng)) * M_PI / 180, turn = 2 * M_PI * u(rng);
    const Vec3 a{120 + 4 * u(rng), 120 + 4 * u(rng), 1012 + 4 * u(rng)};
    const Vec3 b = a + Vec3{0, 0, 14};
    // Second leg: turned by `bend` from the vertical, azimuth `turn`.
    const Vec3 d2{std::sin(bend) * std::cos(turn), std::sin(bend) * std::sin(turn), std::cos(bend)};
    WellSpec w;
    w.name = "B";
    w.trajectory = {a, b, b + 14.0 * d2};
    w.radius = 0.1;
    w.drainage_radius = 3;
    w.rings = 4;
    w.sectors = 12;
    w.segment_length = 3;
    alternate_end_caps(w, t);
    SCOPED_TRACE("case " + std::to_string(t) + ", bend " + std::to_string(bend * 180 / M_PI) + " deg" +
                 (t % 2 ? ", caps" : ", flat"));
    if (meshes_or_is_refused(random_case("random_bent", w), t, true))
      ++meshed;
    else
      ++refused;
  }
  std::printf("[ random    ] bent: %d meshed, %d refused as input\n", meshed, refused);
  EXPECT_GE(meshed, 10);
}
