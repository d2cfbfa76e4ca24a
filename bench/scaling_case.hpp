// The case of bench_scaling: a 2240 x 2240 x 100 m reservoir of 20 layers with 10 deviated wells
// (R = 6 m, 12 sectors, 6 rings), `lateral` x `lateral` cells per layer. Also meshed by a test
// (tests/optimize/test_site_optimize.cpp), so that the benchmark's wells stay covered.
#pragma once
#include <string>
#include <vector>

#include "meshgen/case/case.hpp"

namespace hm::bench {

inline std::vector<double> lattice(double lo, double hi, int n) {
  std::vector<double> v(n + 1);
  for (int i = 0; i <= n; ++i) v[i] = lo + (hi - lo) * i / n;
  return v;
}

inline CaseSpec scaling_case(int lateral) {
  CaseSpec cs;
  cs.name = "scaling_" + std::to_string(lateral);
  cs.reservoir.x = lattice(0, 2240, lateral);
  cs.reservoir.y = lattice(0, 2240, lateral);
  cs.reservoir.z = lattice(2000, 2100, 20);
  for (int k = 0; k < 10; ++k) {
    WellSpec w;
    w.name = "W" + std::to_string(k + 1);
    const double x = 320 + 400 * (k % 5), y = 620 + 1000 * (k / 5);
    // Deviated: 60 m of horizontal offset over 60 m of depth, alternating directions.
    const double dx = k % 2 ? 40 : -40, dy = k % 3 ? 45 : -45;
    w.trajectory = {{x, y, 2020}, {x + dx, y + dy, 2080}};
    w.radius = 0.1;
    w.drainage_radius = 6;
    w.rings = 6;
    w.sectors = 12;
    cs.wells.push_back(w);
  }
  return cs;
}

}  // namespace hm::bench
