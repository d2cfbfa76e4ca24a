// Robustness: random straight deviated wells (fixed seed) in a refined reservoir. Every
// case must give a conforming mesh whose volume is the box minus the wellbore holes, or a
// clear InputError; never another failure.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

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
}  // namespace

TEST(RandomWells, EveryCaseMeshesConformingOrIsRefusedAsInput) {
  std::mt19937 rng(20261122);
  std::uniform_real_distribution<double> u(0, 1);
  int meshed = 0, refused = 0;
  for (int t = 0; t < 10; ++t) {
    CaseSpec cs;
    cs.name = "random";
    cs.reservoir.x = axis({0, 40, 70, 90}, 100, 140, 4, {150, 170, 200});
    cs.reservoir.y = axis({0, 40, 70, 90}, 100, 140, 4, {150, 170, 200});
    cs.reservoir.z = axis({980, 995}, 1005, 1055, 4, {1065, 1080});
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
    cs.wells.push_back(w);
    SCOPED_TRACE("case " + std::to_string(t));
    try {
      PipelineOptions opts;
      opts.optimize = false;
      const HybridMesh h = build_hybrid_mesh(cs, opts);
      ASSERT_TRUE(h.build_report.ok);
      const double wellbore = 0.5 * w.sectors * w.radius * w.radius * std::sin(2 * M_PI / w.sectors) * len;
      const double expected = (200.0 * 200.0 * 100.0) - wellbore;
      EXPECT_NEAR(total_volume(h.geometry), expected, 1e-9 * expected);
      ++meshed;
    } catch (const InputError& e) {
      ++refused;
      std::printf("[ refused   ] case %d: %s\n", t, e.what());
    }
  }
  std::printf("[ random    ] %d meshed, %d refused as input\n", meshed, refused);
  EXPECT_GE(meshed, 8);
}
