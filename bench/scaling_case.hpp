// The cases of bench_scaling: a 2240 x 2240 x 100 m reservoir of 20 layers with 10 deviated wells
// (R = 6 m, 12 sectors, 6 rings), `lateral` x `lateral` cells per layer; and the same wells in
// reservoirs of 10 m cells and growing extent (the cost of a well against the reservoir's size). Also meshed by a test
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

// The deviated well k of the case (its head at `head_x`, `head_y`; 60 m of horizontal offset over 60 m
// of depth, alternating directions).
inline WellSpec scaling_well(int k, double head_x, double head_y) {
  WellSpec w;
  w.name = "W" + std::to_string(k + 1);
  const double dx = k % 2 ? 40 : -40, dy = k % 3 ? 45 : -45;
  w.trajectory = {{head_x, head_y, 2020}, {head_x + dx, head_y + dy, 2080}};
  w.radius = 0.1;
  w.drainage_radius = 6;
  w.rings = 6;
  w.sectors = 12;
  return w;
}

inline CaseSpec scaling_case(int lateral) {
  CaseSpec cs;
  cs.name = "scaling_" + std::to_string(lateral);
  cs.reservoir.x = lattice(0, 2240, lateral);
  cs.reservoir.y = lattice(0, 2240, lateral);
  cs.reservoir.z = lattice(2000, 2100, 20);
  for (int k = 0; k < 10; ++k) cs.wells.push_back(scaling_well(k, 320 + 400 * (k % 5), 620 + 1000 * (k / 5)));
  return cs;
}

// The cost of a well against the reservoir's size: cells of 10 x 10 x 5 m in `lateral` x `lateral` x 20
// (lateral >= 66, even), and `wells` (0-10) of the same ten wells, 140 m apart in a 2 x 5 cluster about
// the middle of the reservoir. The middle is a grid node for every even lateral, so the wells cross the
// same cells (shifted) at every size, and their cavities are the same.
inline CaseSpec fixed_cell_case(int lateral, int wells) {
  CaseSpec cs;
  cs.name = "fixed_cell_" + std::to_string(lateral) + "_" + std::to_string(wells);
  const double extent = 10.0 * lateral, middle = 10.0 * (lateral / 2);
  cs.reservoir.x = lattice(0, extent, lateral);
  cs.reservoir.y = lattice(0, extent, lateral);
  cs.reservoir.z = lattice(2000, 2100, 20);
  for (int k = 0; k < wells; ++k)
    cs.wells.push_back(scaling_well(k, middle - 280 + 140 * (k % 5), middle - 70 + 140 * (k / 5)));
  return cs;
}

}  // namespace hm::bench
