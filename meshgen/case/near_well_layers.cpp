#include "near_well_layers.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "meshgen/case/case_limits.hpp"
#include "meshgen/case/permeability_metric.hpp"

namespace hm {

namespace {

// A height ratio within this relative amount of an integer n gives n children, not n + 1 (the
// ratio of two rounded lengths: an exact 3 may come out as 3 + 1e-16).
constexpr double kRatioRounding = 1e-12;

// The cells [first, last) of `planes` that the interval [from, to] meets.
std::pair<int, int> cells_between(const std::vector<double>& planes, double from, double to) {
  const int first = static_cast<int>(std::upper_bound(planes.begin(), planes.end(), from) - planes.begin()) - 1;
  const int last = static_cast<int>(std::lower_bound(planes.begin(), planes.end(), to) - planes.begin());
  return {std::max(first, 0), std::min(last, static_cast<int>(planes.size()) - 1)};
}

struct WellReach {
  std::pair<int, int> i, j, k;
};

WellReach well_reach(const CaseSpec& cs, const WellSpec& w) {
  const double reach = kLayerSplitReach * cs.transition.dilation * w.drainage_radius;
  Vec3 lo = w.trajectory.front(), hi = lo;
  for (Vec3 p : w.trajectory)
    for (int a = 0; a < 3; ++a) { lo[a] = std::min(lo[a], p[a] - reach); hi[a] = std::max(hi[a], p[a] + reach); }
  const ReservoirSpec& r = cs.reservoir;
  return {cells_between(r.x, lo.x, hi.x), cells_between(r.y, lo.y, hi.y), cells_between(r.z, lo.z, hi.z)};
}

std::vector<double> split_planes(const std::vector<double>& z, const std::vector<int>& children) {
  std::vector<double> out;
  for (size_t k = 0; k + 1 < z.size(); ++k)
    for (int c = 0; c < children[k]; ++c) out.push_back(c == 0 ? z[k] : z[k] + (z[k + 1] - z[k]) * c / children[k]);
  out.push_back(z.back());
  return out;
}

// Per-cell values of the split grid: each child repeats its layer's values.
std::vector<double> repeat_layers(const std::vector<double>& v, size_t layer_size, const std::vector<int>& children) {
  if (v.empty()) return v;
  std::vector<double> out;
  for (size_t k = 0; k < children.size(); ++k)
    for (int c = 0; c < children[k]; ++c)
      out.insert(out.end(), v.begin() + k * layer_size, v.begin() + (k + 1) * layer_size);
  return out;
}

}  // namespace

std::vector<int> near_well_layer_children(const CaseSpec& cs) {
  const ReservoirSpec& r = cs.reservoir;
  const int nz = static_cast<int>(r.z.size()) - 1;
  std::vector<int> children(nz, 1);
  if (r.corner_point || cs.wells.empty() || !(r.near_well_layer_aspect > 0)) return children;
  const PermeabilityFrame frame = permeability_frame(cs);
  if (frame.identity()) return children;
  const Vec3 s = frame.scale;
  std::vector<double> narrowest(nz, INFINITY);  // scaled lateral width, per layer
  for (const WellSpec& w : cs.wells) {
    const WellReach reach = well_reach(cs, w);
    double width = INFINITY;
    for (int i = reach.i.first; i < reach.i.second; ++i) width = std::min(width, (r.x[i + 1] - r.x[i]) / s.x);
    for (int j = reach.j.first; j < reach.j.second; ++j) width = std::min(width, (r.y[j + 1] - r.y[j]) / s.y);
    for (int k = reach.k.first; k < reach.k.second; ++k) narrowest[k] = std::min(narrowest[k], width);
  }
  for (int k = 0; k < nz; ++k) {
    if (!std::isfinite(narrowest[k])) continue;
    const double height = (r.z[k + 1] - r.z[k]) / s.z;
    const double n = std::ceil(height / (r.near_well_layer_aspect * narrowest[k]) * (1 - kRatioRounding));
    children[k] = static_cast<int>(std::clamp(n, 1.0, static_cast<double>(kMaxLayerChildren)));
  }
  return children;
}

void split_layers_near_wells(CaseSpec& cs) {
  const std::vector<int> children = near_well_layer_children(cs);
  if (std::all_of(children.begin(), children.end(), [](int n) { return n == 1; })) return;
  ReservoirSpec& r = cs.reservoir;
  const size_t layer_size = (r.x.size() - 1) * (r.y.size() - 1);
  const std::vector<double> z = split_planes(r.z, children);
  const double cells = static_cast<double>(layer_size) * static_cast<double>(z.size() - 1);
  if (cells > kMaxCells)
    throw InputError("reservoir.near_well_layer_aspect: splitting the layers near the wells gives " +
                     std::to_string(static_cast<long long>(cells)) + " cells > " +
                     std::to_string(static_cast<long long>(kMaxCells)) + ": give a larger aspect, or 0 (off)");
  std::ostringstream note;
  note << "reservoir: layers near the wells split for the permeability frame (scaled cells there at most "
       << r.near_well_layer_aspect << " x taller than wide; reservoir.near_well_layer_aspect):";
  for (size_t k = 0; k < children.size(); ++k)
    if (children[k] > 1) note << " k" << k + 1 << " x" << children[k];
  note << "; the mesh and the deck have " << z.size() - 1 << " layers instead of " << r.z.size() - 1;
  // Segments no taller than the thinnest split layer within each well's reach.
  for (size_t w = 0; w < cs.wells.size(); ++w) {
    WellSpec& ws = cs.wells[w];
    const WellReach reach = well_reach(cs, ws);
    double thinnest = INFINITY;
    for (int k = reach.k.first; k < reach.k.second; ++k)
      if (children[k] > 1) thinnest = std::min(thinnest, (r.z[k + 1] - r.z[k]) / children[k]);
    if (!std::isfinite(thinnest)) continue;
    double segment = ws.segment_length;
    for (size_t p = 0; p + 1 < ws.trajectory.size(); ++p) {
      const Vec3 leg = ws.trajectory[p + 1] - ws.trajectory[p];
      const double vertical = std::fabs(leg.z) / norm(leg);
      if (vertical * segment > thinnest) segment = thinnest / vertical;
    }
    if (segment < ws.segment_length) {
      note << "; wells[" << w << "].segment_length " << ws.segment_length << " -> " << segment;
      ws.segment_length = segment;
    }
  }
  r.cell_permx = repeat_layers(r.cell_permx, layer_size, children);
  r.cell_permy = repeat_layers(r.cell_permy, layer_size, children);
  r.cell_permz = repeat_layers(r.cell_permz, layer_size, children);
  r.cell_poro = repeat_layers(r.cell_poro, layer_size, children);
  r.cell_pore_volume_mult = repeat_layers(r.cell_pore_volume_mult, layer_size, children);
  r.z = z;
  cs.notes.push_back(note.str());
}

}  // namespace hm
