#include "minpv.hpp"

#include <cstddef>
#include <map>

namespace hm {

// Mirrors MinpvProcessor::process line by line (its own "\todo" quirks kept: the upward search
// stops before layer 0, the downward one tests the thickness of the cell above and the PV limit of
// the removed cell); changing them would remove or connect other cells than flow does.
MinpvResult opm_minpv(const MinpvInput& in) {
  MinpvResult out;
  const int nx = in.nx, ny = in.ny, nz = in.nz;
  auto idx = [&](int i, int j, int k) { return static_cast<std::size_t>(i) + static_cast<std::size_t>(nx) * (j + static_cast<std::size_t>(ny) * k); };
  const std::vector<double>&pv = in.pore_volume, &limit = in.minpv, &thickness = in.thickness;
  const std::vector<int>& actnum = in.actnum;
  const double z_tol = in.z_tolerance;
  const bool nogap = in.pinch_nogap;
  std::map<int64_t, int64_t> nnc;  // keyed by the upper cell; the first one kept (Result::add_nnc's insert)
  for (int kk = 0; kk < nz; ++kk)
    for (int jj = 0; jj < ny; ++jj)
      for (int ii = 0; ii < nx; ++ii) {
        const std::size_t c = idx(ii, jj, kk);
        if (!(pv[c] < limit[c] && actnum[c])) continue;
        out.removed.push_back(static_cast<int64_t>(c));
        int kk_iter = kk + 1;
        if (kk_iter == nz) continue;
        std::size_t c_below = idx(ii, jj, kk_iter);
        while (!actnum[c_below] && thickness[c_below] <= z_tol) {
          if (++kk_iter == nz) break;
          c_below = idx(ii, jj, kk_iter);
        }
        if (kk_iter == nz || kk == 0) continue;
        std::size_t c_above = idx(ii, jj, kk - 1);
        bool above_active = actnum[c_above] != 0, above_inactive = !actnum[c_above];
        const bool above_thin = thickness[c_above] < z_tol, above_small_pv = pv[c_above] < limit[c_above];
        if ((above_inactive && above_thin) || (above_active && above_small_pv && (!nogap || above_thin))) {
          for (int topk = kk - 2; topk > 0; --topk) {
            c_above = idx(ii, jj, topk);
            above_active = actnum[c_above] != 0, above_inactive = !actnum[c_above];
            const bool significant = pv[c_above] > limit[c_above], broad = thickness[c_above] > z_tol;
            if ((above_active && (significant || (nogap && broad))) || (above_inactive && broad)) break;
          }
        }
        bool below_active = actnum[c_below] != 0, below_inactive = !actnum[c_below];
        const bool below_thin = thickness[c_below] < z_tol, below_small_pv = pv[c_below] < limit[c];
        if ((below_inactive && below_thin) || (below_active && below_small_pv && (!nogap || below_thin))) {
          for (int botk = kk_iter + 1; botk < nz; ++botk) {
            c_below = idx(ii, jj, botk);
            below_active = actnum[c_below] != 0, below_inactive = !actnum[c_below];
            const bool significant = pv[c_below] > limit[c_below], broad = thickness[c_above] > z_tol;
            if ((below_active && (significant || (nogap && broad))) || (below_inactive && broad)) break;
          }
        }
        if (actnum[c_above] && actnum[c_below] && pv[c_above] > limit[c_above] && pv[c_below] > limit[c_below])
          nnc.emplace(static_cast<int64_t>(c_above), static_cast<int64_t>(c_below));
      }
  out.connections.assign(nnc.begin(), nnc.end());
  return out;
}

}  // namespace hm
