#include "permeability_metric.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace hm {

Vec3 frame_scale(Vec3 k) {
  if (k.x == k.y && k.y == k.z) return {1, 1, 1};
  const double k0 = std::cbrt(k.x * k.y * k.z);
  return {std::sqrt(k.x / k0), std::sqrt(k.y / k0), std::sqrt(k.z / k0)};
}

PermeabilityFrame permeability_frame(const CaseSpec& cs) {
  PermeabilityFrame f;
  const ReservoirSpec& r = cs.reservoir;
  f.origin = {r.x.front(), r.y.front(), r.z.front()};
  f.k = r.permeability;
  if (cs.metric != MeshMetric::Permeability) return f;
  if (!r.cell_permx.empty()) {
    // Geometric mean over the cells the trajectories pass through (each sample once per cell).
    std::vector<int> cells;
    for (const WellSpec& w : cs.wells)
      for (size_t i = 0; i + 1 < w.trajectory.size(); ++i) {
        const Vec3 a = w.trajectory[i], b = w.trajectory[i + 1];
        const int n = std::max(1, static_cast<int>(std::ceil(4 * norm(b - a) / w.segment_length)));
        for (int s = 0; s <= n; ++s) cells.push_back(reservoir_cell_at(r, a + (static_cast<double>(s) / n) * (b - a)));
      }
    if (cells.empty())
      for (size_t c = 0; c < r.cell_permx.size(); ++c) cells.push_back(static_cast<int>(c));
    std::sort(cells.begin(), cells.end());
    cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
    Vec3 log_sum;
    for (int c : cells) {
      const Vec3 k = reservoir_permeability(r, c);
      log_sum += Vec3{std::log(k.x), std::log(k.y), std::log(k.z)};
    }
    const double n = static_cast<double>(cells.size());
    f.k = {std::exp(log_sum.x / n), std::exp(log_sum.y / n), std::exp(log_sum.z / n)};
  }
  f.scale = frame_scale(f.k);
  return f;
}

Vec3 to_scaled(const PermeabilityFrame& f, Vec3 x) {
  return {f.origin.x + (x.x - f.origin.x) / f.scale.x, f.origin.y + (x.y - f.origin.y) / f.scale.y,
          f.origin.z + (x.z - f.origin.z) / f.scale.z};
}

Vec3 to_physical(const PermeabilityFrame& f, Vec3 x) {
  return {f.origin.x + (x.x - f.origin.x) * f.scale.x, f.origin.y + (x.y - f.origin.y) * f.scale.y,
          f.origin.z + (x.z - f.origin.z) * f.scale.z};
}

}  // namespace hm
