#include "corner_point_refine.hpp"

#include <algorithm>
#include <numeric>
#include <cmath>
#include <limits>
#include <set>
#include <utility>

namespace hm {

namespace {

// Pillar (i, j) of the model as two points (top, bottom) of COORD.
const double* pillar(const CornerPointModel& m, int i, int j) { return &m.coord[6 * (size_t(i) + size_t(m.nx + 1) * j)]; }

// Bilinear weights of the 4 corners (00, 10, 01, 11) at (s, t). At s, t in {0, 1} the weights
// are exactly 0 and 1, so interpolated values there are the corner values bit for bit.
std::array<double, 4> bilinear_weights(double s, double t) {
  return {(1 - s) * (1 - t), s * (1 - t), (1 - s) * t, s * t};
}

// The point of the pillar quad of column (i, j) at parameters (s, t) and depth z, in plan.
Vec3 column_point(const CornerPointModel& m, int i, int j, double s, double t, double z) {
  const int nx1 = m.nx + 1;
  const auto w = bilinear_weights(s, t);
  const int p[4] = {i + nx1 * j, i + 1 + nx1 * j, i + nx1 * (j + 1), i + 1 + nx1 * (j + 1)};
  Vec3 out{0, 0, z};
  for (int a = 0; a < 4; ++a) {
    const Vec3 q = pillar_point(m, p[a], z);
    out.x += w[a] * q.x;
    out.y += w[a] * q.y;
  }
  return out;
}

// (s, t) in [0, 1]^2 of plan point x in column (i, j) at depth x.z, by Newton on the bilinear
// map; false when x is not in the column's quad.
bool locate_in_column(const CornerPointModel& m, int i, int j, Vec3 x, double& s, double& t) {
  const Vec3 a = column_point(m, i, j, 0, 0, x.z), b = column_point(m, i, j, 1, 0, x.z);
  const Vec3 c = column_point(m, i, j, 0, 1, x.z), d = column_point(m, i, j, 1, 1, x.z);
  const double lo_x = std::min({a.x, b.x, c.x, d.x}), hi_x = std::max({a.x, b.x, c.x, d.x});
  const double lo_y = std::min({a.y, b.y, c.y, d.y}), hi_y = std::max({a.y, b.y, c.y, d.y});
  if (x.x < lo_x || x.x > hi_x || x.y < lo_y || x.y > hi_y) return false;
  s = t = 0.5;
  for (int it = 0; it < 30; ++it) {
    const auto w = bilinear_weights(s, t);
    const double px = w[0] * a.x + w[1] * b.x + w[2] * c.x + w[3] * d.x - x.x;
    const double py = w[0] * a.y + w[1] * b.y + w[2] * c.y + w[3] * d.y - x.y;
    const double xs = (1 - t) * (b.x - a.x) + t * (d.x - c.x), ys = (1 - t) * (b.y - a.y) + t * (d.y - c.y);
    const double xt = (1 - s) * (c.x - a.x) + s * (d.x - b.x), yt = (1 - s) * (c.y - a.y) + s * (d.y - b.y);
    const double det = xs * yt - xt * ys;
    if (!(std::abs(det) > 0)) return false;
    s -= (px * yt - py * xt) / det;
    t -= (xs * py - ys * px) / det;
  }
  // A column is chosen to size slices, not to place nodes: a point on a shared edge may go to
  // either column.
  constexpr double kEdge = 1e-9;
  return s >= -kEdge && s <= 1 + kEdge && t >= -kEdge && t <= 1 + kEdge;
}

double plan_distance(Vec3 a, Vec3 b) { return std::hypot(a.x - b.x, a.y - b.y); }

// Points along the path at most `step` apart (the vertices included).
std::vector<Vec3> sample_path(const std::vector<Vec3>& path, double step) {
  std::vector<Vec3> out;
  for (size_t k = 0; k + 1 < path.size(); ++k) {
    const int n = std::max(1, static_cast<int>(std::ceil(norm(path[k + 1] - path[k]) / step)));
    for (int a = 0; a < n; ++a) out.push_back(path[k] + (path[k + 1] - path[k]) * (double(a) / n));
  }
  if (!path.empty()) out.push_back(path.back());
  return out;
}

// Thickness (in depth) at (s, t) of the layer of column (i, j) that holds depth z (of the layer as read, when
// layers are split at fault steps); 0 if none does.
double layer_thickness(const CornerPointModel& m, int i, int j, double s, double t, double z) {
  const auto w = bilinear_weights(s, t);
  for (int k = 0; k < m.nz; ++k) {
    double top = 0, bottom = 0;
    for (int a = 0; a < 4; ++a) {
      top += w[a] * m.zcorn[zcorn_index(m, i, j, k, a)];
      bottom += w[a] * m.zcorn[zcorn_index(m, i, j, k, 4 | a)];
    }
    if (top <= z && z <= bottom) {
      // Layers split at fault steps: a child counts as at least kStepChildSizing of its parent's
      // thickness (docs/corner-point.md, "Fault steps": sized by the thinner child, thin layers gave
      // several times the cells; sized by the parent, a sheared model and two wells failed).
      if (!m.parent_layer.empty()) {
        int k0 = k, k1 = k;
        while (k0 > 0 && m.parent_layer[k0 - 1] == m.parent_layer[k]) --k0;
        while (k1 + 1 < m.nz && m.parent_layer[k1 + 1] == m.parent_layer[k]) ++k1;
        double parent_top = 0, parent_bottom = 0;
        for (int a = 0; a < 4; ++a) {
          parent_top += w[a] * m.zcorn[zcorn_index(m, i, j, k0, a)];
          parent_bottom += w[a] * m.zcorn[zcorn_index(m, i, j, k1, 4 | a)];
        }
        return std::max(bottom - top, kStepChildSizing * (parent_bottom - parent_top));
      }
      return bottom - top;
    }
  }
  return 0;
}

// Whether layer k is one of several children of a layer split at fault steps.
bool is_step_child(const CornerPointModel& m, int k) {
  if (m.parent_layer.empty()) return false;
  return (k > 0 && m.parent_layer[k - 1] == m.parent_layer[k]) ||
         (k + 1 < m.nz && m.parent_layer[k + 1] == m.parent_layer[k]);
}

// Largest lean from the vertical (radians) of the 4 pillars of column (i, j).
double column_lean(const CornerPointModel& m, int i, int j) {
  double lean = 0;
  for (int dj = 0; dj < 2; ++dj)
    for (int di = 0; di < 2; ++di) {
      const double* p = pillar(m, i + di, j + dj);
      const double dz = std::abs(p[5] - p[2]);
      if (dz > 0) lean = std::max(lean, std::atan(std::hypot(p[3] - p[0], p[4] - p[1]) / dz));
    }
  return lean;
}

// The widest cells whose top and bottom faces near depth z (within `reach`) keep the next layer's
// corners out of their triangles' diametral spheres on the leaning pillars of column (i, j); infinity
// where the pillars are vertical (kLeanSphereMargin).
double lean_limited_size(const CornerPointModel& m, int i, int j, double s, double t, double z, double reach) {
  const double sin_2lean = std::sin(2 * std::min(column_lean(m, i, j), std::atan(1.0)));
  if (!(sin_2lean > 0)) return std::numeric_limits<double>::infinity();
  const auto w = bilinear_weights(s, t);
  double thinnest = std::numeric_limits<double>::infinity();
  for (int k = 0; k < m.nz; ++k) {
    if (!is_step_child(m, k)) continue;
    double top = 0, bottom = 0;
    for (int a = 0; a < 4; ++a) {
      top += w[a] * m.zcorn[zcorn_index(m, i, j, k, a)];
      bottom += w[a] * m.zcorn[zcorn_index(m, i, j, k, 4 | a)];
    }
    if (bottom > top && bottom >= z - reach && top <= z + reach) thinnest = std::min(thinnest, bottom - top);
  }
  return std::sqrt(2.0) * thinnest / (kLeanSphereMargin * sin_2lean);
}

// What one path point asks of one slice: children of `size` within `reach` of it, growing beyond.
// Its distance from parameter s across the slice is d + |s - s_ref| width (s_ref: the point's own
// parameter when the slice holds it, d = 0; else the slice's end nearer to it, d its distance).
struct SliceRequest {
  double width, d, s_ref, size, reach;
  bool graded;
  // The target child width at s, as a parameter across the slice.
  double target(double s) const {
    const double dist = d + std::abs(s - s_ref) * width;
    return (size + kRefinementGrowth * std::max(0.0, dist - reach)) / width;
  }
};

// Resolution of the equidistribution: the smallest target is a few hundredths of a wide slice.
constexpr int kSliceSamples = 512;

// Children's bounds across one slice: sizes following the smallest target of `asks`, by
// equidistribution of the integral of 1 / target; {0, 1} when nothing asks. If an ask that is not
// graded splits the slice, equal children, as many as the largest ask needs where it is nearest.
std::vector<double> slice_bounds(const std::vector<SliceRequest>& asks) {
  if (asks.empty()) return {0.0, 1.0};
  auto equal_children = [](const SliceRequest& q) { return static_cast<int>(std::lround(1.0 / q.target(q.s_ref))); };
  if (std::any_of(asks.begin(), asks.end(), [&](const SliceRequest& q) { return !q.graded && equal_children(q) > 1; })) {
    int n = 1;
    for (const SliceRequest& q : asks) n = std::max(n, equal_children(q));
    std::vector<double> bounds;
    for (int a = 0; a < n; ++a) bounds.push_back(double(a) / n);
    bounds.push_back(1.0);
    return bounds;
  }
  std::vector<double> cumulative(kSliceSamples + 1, 0.0);
  for (int a = 0; a < kSliceSamples; ++a) {
    const double s = (a + 0.5) / kSliceSamples;
    double target = std::numeric_limits<double>::infinity();
    for (const SliceRequest& q : asks) target = std::min(target, q.target(s));
    cumulative[a + 1] = cumulative[a] + 1.0 / (target * kSliceSamples);
  }
  const int n = std::max(1, static_cast<int>(std::lround(cumulative.back())));
  std::vector<double> bounds{0.0};
  for (int k = 1, a = 0; k < n; ++k) {
    const double level = cumulative.back() * k / n;
    while (cumulative[a + 1] < level) ++a;
    bounds.push_back((a + (level - cumulative[a]) / (cumulative[a + 1] - cumulative[a])) / kSliceSamples);
  }
  bounds.push_back(1.0);
  return bounds;
}

}  // namespace

bool ColumnSplits::refines() const {
  return std::any_of(i.begin(), i.end(), [](int n) { return n > 1; }) ||
         std::any_of(j.begin(), j.end(), [](int n) { return n > 1; });
}

double ColumnSplits::cells(int nz) const {
  const double ni = std::accumulate(i.begin(), i.end(), 0.0), nj = std::accumulate(j.begin(), j.end(), 0.0);
  return ni * nj * nz;
}

namespace {

// The model cell (ip, jp) holding x in plan and its parameters (s, t) there; false outside the columns.
bool locate_point(const CornerPointModel& m, Vec3 x, int& ip, int& jp, double& s, double& t) {
  for (int j = 0; j < m.ny; ++j)
    for (int i = 0; i < m.nx; ++i)
      if (locate_in_column(m, i, j, x, s, t)) return ip = i, jp = j, true;
  return false;
}

// Calls visit(slice index, along i?, request) for what each point of the path asks of each slice
// across it wider than `wider_than` target sizes (every slice of its row along i, of its column along j).
template <class Visit>
void for_each_ask(const CornerPointModel& m, const RefinementRequest& r, double wider_than, Visit visit) {
  for (const Vec3& x : sample_path(r.path, 0.5 * r.cell_size)) {
    int ip = -1, jp = -1;
    double s = 0, t = 0;
    if (!locate_point(m, x, ip, jp, s, t)) continue;
    double size = r.cell_size;
    if (const double h = layer_thickness(m, ip, jp, s, t, x.z); r.limit_by_layer && h > 0)
      size = std::min(size, kCellsPerLayerThickness * h);
    if (r.limit_by_lean) size = std::min(size, lean_limited_size(m, ip, jp, s, t, x.z, r.reach));
    auto ask = [&](int slice, bool along_i, int holder, double at, Vec3 lo, Vec3 hi) {
      const double width = plan_distance(lo, hi);
      if (!(width > wider_than * size)) return;
      if (slice == holder)
        visit(slice, along_i, SliceRequest{width, 0.0, at, size, r.reach, r.graded});
      else if (slice > holder)
        visit(slice, along_i, SliceRequest{width, plan_distance(x, lo), 0.0, size, r.reach, r.graded});
      else
        visit(slice, along_i, SliceRequest{width, plan_distance(x, hi), 1.0, size, r.reach, r.graded});
    };
    for (int i = 0; i < m.nx; ++i)
      ask(i, true, ip, s, column_point(m, i, jp, 0, t, x.z), column_point(m, i, jp, 1, t, x.z));
    for (int j = 0; j < m.ny; ++j)
      ask(j, false, jp, t, column_point(m, ip, j, s, 0, x.z), column_point(m, ip, j, s, 1, x.z));
  }
}

}  // namespace

ColumnSplits near_well_splits(const CornerPointModel& m, const std::vector<RefinementRequest>& wells) {
  using Asks = std::vector<std::vector<SliceRequest>>;
  std::vector<Asks> ask_i(wells.size(), Asks(m.nx)), ask_j(wells.size(), Asks(m.ny));
  auto ask_of = [&](size_t w) {
    return [&, w](int slice, bool along_i, const SliceRequest& q) { (along_i ? ask_i : ask_j)[w][slice].push_back(q); };
  };
  for (size_t w = 0; w < wells.size(); ++w)
    if (wells[w].cell_size > 0) for_each_ask(m, wells[w], kRefineWiderThan, ask_of(w));
  // A well whose reach (or the slices next to it) the children of another well cross asks for every
  // slice there wider than its size: cells many times longer than wide beside its cavity give walls
  // that no Gabriel repair clears. Its new children may cross a third well's reach, and so on: passes
  // until no well is newly crossed (at most one per well, as a crossed well asks for no more).
  auto split_by_others = [&](const std::vector<Asks>& asks, size_t w, size_t slice) {
    std::vector<SliceRequest> others;
    for (size_t o = 0; o < wells.size(); ++o)
      if (o != w) others.insert(others.end(), asks[o][slice].begin(), asks[o][slice].end());
    return slice_bounds(others).size() > 2;
  };
  std::vector<std::set<std::pair<bool, int>>> near(wells.size());  // slices within reach, and the next ones
  for (size_t w = 0; w < wells.size() && wells.size() > 1; ++w)
    if (wells[w].cell_size > 0)
      for_each_ask(m, wells[w], 0.0, [&](int slice, bool along_i, const SliceRequest& q) {
        if (q.d < wells[w].reach)
          for (int next : {slice - 1, slice, slice + 1})
            if (next >= 0 && next < (along_i ? m.nx : m.ny)) near[w].insert({along_i, next});
      });
  std::vector<char> crossed(wells.size(), 0);
  for (bool more = wells.size() > 1; more;) {
    std::vector<size_t> newly;
    for (size_t w = 0; w < wells.size(); ++w) {
      if (crossed[w] || !(wells[w].cell_size > 0)) continue;
      for (const auto& [along_i, slice] : near[w])
        if (split_by_others(along_i ? ask_i : ask_j, w, slice)) {
          newly.push_back(w);
          break;
        }
    }
    for (size_t w : newly) {
      crossed[w] = 1;
      ask_i[w].assign(m.nx, {}), ask_j[w].assign(m.ny, {});
      for_each_ask(m, wells[w], kRefineBesideChildrenWiderThan, ask_of(w));
    }
    more = !newly.empty();
  }
  Asks all_i(m.nx), all_j(m.ny);
  for (size_t w = 0; w < wells.size(); ++w) {
    for (int i = 0; i < m.nx; ++i) all_i[i].insert(all_i[i].end(), ask_i[w][i].begin(), ask_i[w][i].end());
    for (int j = 0; j < m.ny; ++j) all_j[j].insert(all_j[j].end(), ask_j[w][j].begin(), ask_j[w][j].end());
  }
  ColumnSplits out;
  for (const auto& asks : all_i) out.i_bounds.push_back(slice_bounds(asks));
  for (const auto& asks : all_j) out.j_bounds.push_back(slice_bounds(asks));
  for (const auto& b : out.i_bounds) out.i.push_back(static_cast<int>(b.size()) - 1);
  for (const auto& b : out.j_bounds) out.j.push_back(static_cast<int>(b.size()) - 1);
  return out;
}

CornerPointModel refined_model(const CornerPointModel& m, const ColumnSplits& splits) {
  // Per refined pillar line / slice: the model slice it lies in and its parametric position.
  struct Slot {
    int parent;
    int child, of;
    double s0, s1;  // the child's ends, as parameters across its parent
  };
  auto slots = [](const std::vector<int>& n, const std::vector<std::vector<double>>& bounds) {
    std::vector<Slot> v;
    for (int p = 0; p < static_cast<int>(n.size()); ++p)
      for (int a = 0; a < n[p]; ++a) {
        const bool given = !bounds.empty();
        v.push_back({p, a, n[p], given ? bounds[p][a] : double(a) / n[p], given ? bounds[p][a + 1] : double(a + 1) / n[p]});
      }
    return v;
  };
  const std::vector<Slot> si = slots(splits.i, splits.i_bounds), sj = slots(splits.j, splits.j_bounds);
  CornerPointModel r;
  r.nx = static_cast<int>(si.size());
  r.ny = static_cast<int>(sj.size());
  r.nz = m.nz;
  r.parent_nx = m.parent_cell.empty() ? m.nx : m.parent_nx;
  r.parent_ny = m.parent_cell.empty() ? m.ny : m.parent_ny;
  r.parent_layer = m.parent_layer;
  r.parent_nz = m.parent_nz;
  r.pinch = m.pinch;
  r.region_mult = m.region_mult;
  r.multregt_records = m.multregt_records;
  r.region_arrays = m.region_arrays;
  r.has_mapaxes = m.has_mapaxes;
  r.map_origin = m.map_origin;
  r.map_unit_x = m.map_unit_x;
  r.map_unit_y = m.map_unit_y;
  // Keyed by the cells of the model as read (cell_as_read), so they hold for the children as they are.
  r.nnc = m.nnc;
  r.edit_nnc = m.edit_nnc;
  r.deck_editnnc = m.deck_editnnc;
  r.minpv_connections = m.minpv_connections;
  r.minpv_removed = m.minpv_removed;

  // Pillars: pillar line I lies in model slice si[I].parent at its child's start (the last line at s = 1).
  auto line = [](const std::vector<Slot>& sl, int I, int& parent, double& s) {
    if (I < static_cast<int>(sl.size())) {
      parent = sl[I].parent, s = sl[I].s0;
    } else {
      parent = sl.back().parent, s = 1.0;
    }
  };
  r.coord.resize(6 * size_t(r.nx + 1) * (r.ny + 1));
  for (int J = 0; J <= r.ny; ++J)
    for (int I = 0; I <= r.nx; ++I) {
      int i, j;
      double s, t;
      line(si, I, i, s);
      line(sj, J, j, t);
      const auto w = bilinear_weights(s, t);
      const double* p[4] = {pillar(m, i, j), pillar(m, i + 1, j), pillar(m, i, j + 1), pillar(m, i + 1, j + 1)};
      double* out = &r.coord[6 * (size_t(I) + size_t(r.nx + 1) * J)];
      for (int a = 0; a < 6; ++a) out[a] = w[0] * p[0][a] + w[1] * p[1][a] + w[2] * p[2][a] + w[3] * p[3][a];
    }

  resize_cell_arrays(r, m);
  for (int k = 0; k < r.nz; ++k)
    for (int J = 0; J < r.ny; ++J)
      for (int I = 0; I < r.nx; ++I) {
        const size_t c = I + size_t(r.nx) * (J + size_t(r.ny) * k);
        const int i = si[I].parent, j = sj[J].parent;
        const int pc = i + m.nx * (j + m.ny * k);
        inherit_cell(r, c, m, pc);
        for (int q = 0; q < 8; ++q) {
          const double s = q & 1 ? si[I].s1 : si[I].s0;
          const double t = (q >> 1) & 1 ? sj[J].s1 : sj[J].s0;
          const int side = q & 4;
          const auto w = bilinear_weights(s, t);
          double z = 0;
          for (int a = 0; a < 4; ++a) z += w[a] * m.zcorn[zcorn_index(m, i, j, k, side | a)];
          r.zcorn[zcorn_index(r, I, J, k, q)] = z;
        }
        // +x, -x, +y, -y act on the parent's faces; z on every child.
        const bool at[6] = {si[I].child == si[I].of - 1, si[I].child == 0, sj[J].child == sj[J].of - 1,
                            sj[J].child == 0, true, true};
        for (int d = 0; d < 6; ++d)
          if (!m.trans_mult[d].empty()) r.trans_mult[d][c] = at[d] ? m.trans_mult[d][pc] : 1.0;
      }
  // A new pillar on a model column edge gets its depths from the parents on either side, each
  // interpolating its own corners: where a fault's throw passes through zero between two model
  // pillars (a scissor fault) the two sides' depths are the same number and may differ by a rounding.
  merge_rounded_depths(r);
  return r;
}

}  // namespace hm
