#include "quality.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace hm {

std::vector<int64_t> histogram(const std::vector<double>& values, const std::vector<bool>& mask, double lo,
                               double hi, int nbins) {
  std::vector<int64_t> h(std::max(nbins, 1), 0);
  const int nb = static_cast<int>(h.size());
  for (size_t i = 0; i < values.size(); ++i) {
    if (!mask.empty() && (i >= mask.size() || !mask[i])) continue;
    const double v = values[i];
    if (std::isnan(v)) continue;
    double t = hi > lo ? (v - lo) / (hi - lo) * nb : 0.0;
    int b = t <= 0 ? 0 : (t >= nb ? nb - 1 : static_cast<int>(t));
    ++h[b];
  }
  return h;
}

std::string region_name(int32_t region) {
  switch (region) {
    case kReservoir: return "reservoir";
    case kTransition: return "transition";
    case kWell: return "well";
    default: return "region_" + std::to_string(region);
  }
}

std::vector<RegionQuality> quality_by_region(const PolyMesh& m, const std::vector<double>& q_s,
                                             const std::vector<double>& q_o_cell,
                                             const std::vector<double>& q_p_cell,
                                             const std::vector<double>& k_angle_cell,
                                             const std::vector<double>& k_angle_interior_cell) {
  // One pass with running sums: region codes read from a file may be arbitrary, so no
  // per-region masks of n_cells entries.
  struct Acc {
    int64_t cells = 0;
    Stats s[5];
    double sum[5] = {0, 0, 0, 0, 0};
  };
  std::map<int32_t, Acc> acc;
  const std::vector<double>* q[5] = {&q_s, &q_o_cell, &q_p_cell, &k_angle_cell, &k_angle_interior_cell};
  for (int c = 0; c < m.n_cells(); ++c) {
    Acc& a = acc[m.cell_region[c]];
    ++a.cells;
    for (int k = 0; k < 5; ++k) {
      if (static_cast<size_t>(c) >= q[k]->size()) continue;
      const double v = (*q[k])[c];
      if (std::isnan(v)) continue;
      Stats& s = a.s[k];
      s.min = s.count == 0 ? v : std::min(s.min, v);
      s.max = s.count == 0 ? v : std::max(s.max, v);
      ++s.count;
      a.sum[k] += v;
    }
  }
  std::vector<RegionQuality> out;
  for (auto& [r, a] : acc) {
    for (int k = 0; k < 5; ++k)
      if (a.s[k].count > 0) a.s[k].mean = a.sum[k] / static_cast<double>(a.s[k].count);
    RegionQuality rq;
    rq.region = r;
    rq.name = region_name(r);
    rq.cells = a.cells;
    rq.q_s = a.s[0];
    rq.q_o = a.s[1];
    rq.q_p = a.s[2];
    rq.k_angle = a.s[3];
    rq.k_angle_interior = a.s[4];
    out.push_back(rq);
  }
  return out;
}

}  // namespace hm
