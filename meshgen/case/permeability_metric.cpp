#include "permeability_metric.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "meshgen/case/grdecl.hpp"
#include "meshgen/case/segment_distance.hpp"

namespace hm {

namespace {

// The active cells of a corner-point model whose centre (the mean of its corners) lies within each
// well's drainage radius of its path, the cells the near-well cells replace; where none does (cells
// wider than the reach), the radius is doubled until some do.
std::vector<int> corner_point_cells_near_paths(const CaseSpec& cs) {
  const CornerPointModel& m = *cs.reservoir.corner_point;
  std::vector<Vec3> centre(m.n_cells());
  for (size_t c = 0; c < m.n_cells(); ++c) {
    if (!m.actnum[c]) continue;
    Vec3 sum;
    for (const Vec3& p : cell_corners(m, c)) sum += p;
    centre[c] = sum / 8.0;
  }
  std::vector<int> cells;
  for (const WellSpec& w : cs.wells) {
    const size_t before = cells.size();
    Vec3 lo = w.trajectory.front(), hi = lo;
    for (const Vec3& p : w.trajectory)
      for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], p[d]), hi[d] = std::max(hi[d], p[d]);
    for (double reach = w.drainage_radius; cells.size() == before && reach < 1e3 * w.drainage_radius; reach *= 2)
      for (size_t c = 0; c < m.n_cells(); ++c) {
        const Vec3 x = centre[c];
        const bool in_box = x.x > lo.x - reach && x.x < hi.x + reach && x.y > lo.y - reach && x.y < hi.y + reach &&
                            x.z > lo.z - reach && x.z < hi.z + reach;
        if (m.actnum[c] && in_box && polyline_distance({x}, w.trajectory, reach) < reach) cells.push_back(static_cast<int>(c));
      }
  }
  return cells;
}

// The middle value (the mean of the two middle ones for an even count); v is reordered.
double median(std::vector<double>& v) {
  const size_t h = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(h), v.end());
  if (v.size() % 2 == 1) return v[h];
  const double upper = v[h];
  return 0.5 * (upper + *std::max_element(v.begin(), v.begin() + static_cast<long>(h)));
}

// The reservoir cells the wells' trajectories pass through (sampled every segment_length / 4).
std::vector<int> box_cells_on_paths(const CaseSpec& cs) {
  std::vector<int> cells;
  for (const WellSpec& w : cs.wells)
    for (size_t i = 0; i + 1 < w.trajectory.size(); ++i) {
      const Vec3 a = w.trajectory[i], b = w.trajectory[i + 1];
      const int n = std::max(1, static_cast<int>(std::ceil(4 * norm(b - a) / w.segment_length)));
      for (int s = 0; s <= n; ++s) cells.push_back(reservoir_cell_at(cs.reservoir, a + (static_cast<double>(s) / n) * (b - a)));
    }
  return cells;
}

}  // namespace

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
    // The cells near the trajectories, each once.
    std::vector<int> cells = r.corner_point ? corner_point_cells_near_paths(cs) : box_cells_on_paths(cs);
    if (cells.empty())
      for (size_t c = 0; c < r.cell_permx.size(); ++c) cells.push_back(static_cast<int>(c));
    std::sort(cells.begin(), cells.end());
    cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
    // The level: the geometric mean of kx. The anisotropy, which alone sets the frame: the median of
    // the cells' ky/kx and kz/kx, which a few tight cells (kz orders below the rest) do not drag along
    // as they drag a mean.
    double log_kx = 0;
    std::vector<double> ky_kx, kz_kx;
    for (int c : cells) {
      const Vec3 k = reservoir_permeability(r, c);
      log_kx += std::log(k.x);
      ky_kx.push_back(k.y / k.x);
      kz_kx.push_back(k.z / k.x);
    }
    const double kx = std::exp(log_kx / static_cast<double>(cells.size()));
    f.k = {kx, kx * median(ky_kx), kx * median(kz_kx)};
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
