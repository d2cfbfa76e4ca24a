#include "corner_point_fault_steps.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <limits>

#include "segment_distance.hpp"

namespace hm {

bool FaultStepSplit::splits() const {
  return std::any_of(children.begin(), children.end(), [](int n) { return n > 1; });
}

namespace {

// The up-to-4 columns around pillar (I, J), as slots a (bit 0: the column's i is I, bit 1: its j is J),
// and the corner of that column on the pillar.
struct PillarColumns {
  const CornerPointModel& m;
  bool present(int I, int J, int a) const {
    const int ci = column_i(I, a), cj = column_j(J, a);
    return ci >= 0 && cj >= 0 && ci < m.nx && cj < m.ny;
  }
  static int column_i(int I, int a) { return I - 1 + (a & 1); }
  static int column_j(int J, int a) { return J - 1 + (a >> 1); }
  static int corner(int a) { return (a & 1 ? 0 : 1) | (a & 2 ? 0 : 2); }
  double top(int I, int J, int a, int k) const {
    return m.zcorn[zcorn_index(m, column_i(I, a), column_j(J, a), k, corner(a))];
  }
  double bottom(int I, int J, int a, int k) const {
    return m.zcorn[zcorn_index(m, column_i(I, a), column_j(J, a), k, 4 | corner(a))];
  }
  bool active(int I, int J, int a, int k) const {
    return m.actnum[column_i(I, a) + size_t(m.nx) * (column_j(J, a) + size_t(m.ny) * k)] != 0;
  }
};

// The depths of the active cells' tops and bottoms of column slot a on pillar (I, J), sorted.
std::vector<double> column_boundaries(const PillarColumns& pc, int I, int J, int a) {
  std::vector<double> out;
  for (int k = 0; k < pc.m.nz; ++k)
    if (pc.active(I, J, a, k)) out.push_back(pc.top(I, J, a, k)), out.push_back(pc.bottom(I, J, a, k));
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

// Whether a boundary of column slot a lies strictly inside an active cell of slot b at pillar (I, J)
// (`fraction` of that cell's thickness from its ends).
bool cuts_a_cell_of(const PillarColumns& pc, int I, int J, const std::vector<double>& boundaries_a, int b,
                    double fraction) {
  for (int k = 0; k < pc.m.nz; ++k) {
    if (!pc.active(I, J, b, k)) continue;
    const double top = pc.top(I, J, b, k), bottom = pc.bottom(I, J, b, k), margin = fraction * (bottom - top);
    const auto it = std::upper_bound(boundaries_a.begin(), boundaries_a.end(), top + margin);
    if (it != boundaries_a.end() && *it < bottom - margin) return true;
  }
  return false;
}

// The column slots at a pillar whose layers are offset against each other both ways (a fault's two
// sides): offset[a][b], a boundary of each beyond `fraction` of a cell's thickness inside a cell of the
// other. A column with a boundary inside another's cell but not the other way round (a layer pinching
// out or ending, cells MINPV removed and their neighbours extended over them) is no fault step.
std::array<std::array<bool, 4>, 4> offset_columns(const PillarColumns& pc, int I, int J,
                                                  const std::array<std::vector<double>, 4>& boundaries,
                                                  double fraction = kMinStepFraction) {
  std::array<std::array<bool, 4>, 4> cut{}, out{};
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b)
      cut[a][b] = a != b && pc.present(I, J, a) && pc.present(I, J, b) && cuts_a_cell_of(pc, I, J, boundaries[a], b, fraction);
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b) out[a][b] = cut[a][b] && cut[b][a];
  return out;
}

// Boundaries of the columns offset against column slot a (offset[a]) strictly inside (top, bottom),
// kMinStepFraction of the thickness away from either end and from each other (the upper one kept), at
// most `limit`.
std::vector<double> steps_inside(const std::array<std::vector<double>, 4>& boundaries, const std::array<bool, 4>& offset,
                                 double top, double bottom, size_t limit) {
  const double margin = kMinStepFraction * (bottom - top);
  std::vector<double> d;
  for (int b = 0; b < 4; ++b) {
    if (!offset[b]) continue;
    const auto& v = boundaries[b];
    for (auto it = std::upper_bound(v.begin(), v.end(), top + margin); it != v.end() && *it < bottom - margin; ++it)
      d.push_back(*it);
  }
  std::sort(d.begin(), d.end());
  std::vector<double> out;
  for (double z : d)
    if (out.empty() || z - out.back() >= margin) out.push_back(z);
  if (out.size() > limit) out.resize(limit);
  return out;
}

// Distance from p to a well's path.
double path_distance(Vec3 p, const FaultStepRequest& w) {
  double d = std::numeric_limits<double>::infinity();
  for (size_t s = 0; s + 1 < w.path.size(); ++s) d = std::min(d, segment_segment_distance(p, p, w.path[s], w.path[s + 1]));
  return d;
}

// Whether a cell's bounding sphere (about the mean of its corners) comes within a well's reach.
bool cell_within_reach(const std::array<Vec3, 8>& corners, const FaultStepRequest& w) {
  Vec3 centre{0, 0, 0};
  for (const Vec3& q : corners) centre += q / 8.0;
  double radius = 0;
  for (const Vec3& q : corners) radius = std::max(radius, norm(q - centre));
  return path_distance(centre, w) <= w.reach + radius;
}

// Per cell: whether it comes within reach of a well that asked.
std::vector<char> cells_near(const CornerPointModel& m, const std::vector<FaultStepRequest>& wells,
                             const std::vector<char>& asked) {
  std::vector<char> near(m.n_cells(), 0);
  for (size_t c = 0; c < m.n_cells(); ++c) {
    const std::array<Vec3, 8> corners = cell_corners(m, c);
    for (size_t w = 0; w < wells.size() && !near[c]; ++w) near[c] = asked[w] && cell_within_reach(corners, wells[w]);
  }
  return near;
}

// The wells that did not ask but have a split cell within reach: the edge of the split cells would
// run through their cavity (a whole cell beside split ones has the children's nodes in the middle
// of its face's edge, the wall no triangulation keeps every site in its cell).
std::vector<size_t> wells_reaching_split_cells(const CornerPointModel& m, const std::vector<FaultStepRequest>& wells,
                                               const std::vector<char>& asked, const std::vector<char>& near) {
  std::vector<size_t> out;
  for (size_t w = 0; w < wells.size(); ++w) {
    if (asked[w]) continue;
    for (size_t c = 0; c < m.n_cells(); ++c)
      if (near[c] && cell_within_reach(cell_corners(m, c), wells[w])) {
        out.push_back(w);
        break;
      }
  }
  return out;
}

// Split depths of one layer at one pillar side: n - 1 increasing depths strictly inside the layer.
// Exact ones are the other side's ZCORN values; the rest pad the widest gaps at their middles.
std::vector<double> padded(std::vector<double> exact, double top, double bottom, size_t n_minus_1) {
  while (exact.size() < n_minus_1) {
    std::vector<double> b{top};
    b.insert(b.end(), exact.begin(), exact.end());
    b.push_back(bottom);
    size_t widest = 0;
    for (size_t g = 1; g + 1 < b.size(); ++g)
      if (b[g + 1] - b[g] > b[widest + 1] - b[widest]) widest = g;
    exact.insert(exact.begin() + static_cast<long>(widest), 0.5 * (b[widest] + b[widest + 1]));
  }
  return exact;
}

}  // namespace

namespace {

// The boundaries of column slot a's active cells of non-zero thickness on pillar (I, J), each with the
// thinner of the cells it separates, sorted by depth.
std::vector<std::pair<double, double>> boundaries_with_thickness(const PillarColumns& pc, int I, int J, int a) {
  std::vector<std::pair<double, double>> out;
  for (int k = 0; k < pc.m.nz; ++k) {
    if (!pc.active(I, J, a, k)) continue;
    const double top = pc.top(I, J, a, k), bottom = pc.bottom(I, J, a, k);
    if (!(bottom > top)) continue;
    out.push_back({top, bottom - top}), out.push_back({bottom, bottom - top});
  }
  std::sort(out.begin(), out.end());
  std::vector<std::pair<double, double>> merged;
  for (const auto& b : out)
    if (!merged.empty() && merged.back().first == b.first) merged.back().second = std::min(merged.back().second, b.second);
    else merged.push_back(b);
  return merged;
}

}  // namespace

SnappedSteps snap_thin_fault_steps(CornerPointModel& m, const std::vector<FaultStepRequest>& wells) {
  SnappedSteps out;
  const PillarColumns pc{m};
  for (int J = 0; J <= m.ny; ++J)
    for (int I = 0; I <= m.nx; ++I) {
      std::array<std::vector<double>, 4> boundaries;
      for (int a = 0; a < 4; ++a) boundaries[a] = pc.present(I, J, a) ? column_boundaries(pc, I, J, a) : std::vector<double>{};
      const auto offset = offset_columns(pc, I, J, boundaries, 0.0);  // thin steps too
      const int p = I + (m.nx + 1) * J;
      for (int a = 0; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b) {
          if (!offset[a][b]) continue;
          const auto fixed = boundaries_with_thickness(pc, I, J, a);
          for (const auto& [e, thick_b] : boundaries_with_thickness(pc, I, J, b))
            for (const auto& [d, thick_a] : fixed) {
              const double step = std::fabs(d - e);
              if (step == 0 || step >= kMinStepFraction * std::min(thick_a, thick_b)) continue;
              const Vec3 corner = pillar_point(m, p, e);
              if (std::none_of(wells.begin(), wells.end(),
                               [&](const FaultStepRequest& w) { return path_distance(corner, w) <= w.reach; }))
                continue;
              // Every column offset against slot a reads e at this pillar: all of them move to d.
              for (int s = 0; s < 4; ++s) {
                if (!offset[a][s] || !pc.present(I, J, s)) continue;
                const int ci = PillarColumns::column_i(I, s), cj = PillarColumns::column_j(J, s);
                for (int k = 0; k < m.nz; ++k)
                  for (int q : {PillarColumns::corner(s), 4 | PillarColumns::corner(s)}) {
                    double& z = m.zcorn[zcorn_index(m, ci, cj, k, q)];
                    if (z == e) z = d, ++out.corners;
                  }
              }
              out.largest = std::max(out.largest, step);
              break;
            }
        }
    }
  if (out.corners > 0) m.opm_volume.clear();
  return out;
}

FaultStepSplit fault_step_children(const CornerPointModel& m, const std::vector<FaultStepRequest>& wells) {
  FaultStepSplit out;
  out.children.assign(m.nz, 1);
  std::vector<char> asked(wells.size(), 0);
  const PillarColumns pc{m};
  FaultPillar fp;
  for (int J = 0; J <= m.ny; ++J)
    for (int I = 0; I <= m.nx; ++I) {
      const auto& boundaries = fp.boundaries;
      for (int a = 0; a < 4; ++a) fp.boundaries[a] = pc.present(I, J, a) ? column_boundaries(pc, I, J, a) : std::vector<double>{};
      const auto& offset = fp.offset = offset_columns(pc, I, J, boundaries);
      if (std::none_of(offset.begin(), offset.end(), [](const auto& row) { return row[0] || row[1] || row[2] || row[3]; }))
        continue;
      const int p = fp.pillar = I + (m.nx + 1) * J;
      out.fault_pillars.push_back(fp);
      for (int k = 0; k < m.nz; ++k)
        for (int a = 0; a < 4; ++a) {
          if (!pc.present(I, J, a) || !pc.active(I, J, a, k)) continue;
          const double top = pc.top(I, J, a, k), bottom = pc.bottom(I, J, a, k);
          if (!(bottom > top)) continue;
          const size_t n = steps_inside(boundaries, offset[a], top, bottom, kMaxStepChildren - 1).size();
          if (n == 0) continue;
          const Vec3 corner = pillar_point(m, p, 0.5 * (top + bottom));
          bool reached = false;
          for (size_t w = 0; w < wells.size(); ++w)
            if (path_distance(corner, wells[w]) <= wells[w].reach) asked[w] = 1, reached = true;
          if (!reached) continue;
          ++out.steps;
          out.children[k] = std::max(out.children[k], 1 + static_cast<int>(n));
        }
    }
  if (!out.splits()) return out;
  // A well beside the split cells of another asks too, and so on until none is newly reached.
  out.near = cells_near(m, wells, asked);
  for (std::vector<size_t> more; !(more = wells_reaching_split_cells(m, wells, asked, out.near)).empty();) {
    for (size_t w : more) asked[w] = 1;
    out.near = cells_near(m, wells, asked);
  }
  return out;
}

namespace {

// A ratio of lengths within this relative amount of an integer n gives n parts, not n + 1.
constexpr double kPartsRounding = 1e-12;

// The permeability frame's children depths inside (top, bottom) at one pillar side: the boundaries of
// the sides offset against it (fp may be null: no fault at the pillar) and the equal parts, no thicker
// than t, of each interval between them. A function of the interval alone, so that the two sides of a
// fault, which share the interval, get the same depths bit for bit.
std::vector<double> frame_depths(const FaultPillar* fp, int a, double top, double bottom, double t) {
  std::vector<double> cuts{top};
  if (fp && bottom > top)
    for (double z : steps_inside(fp->boundaries, fp->offset[a], top, bottom, std::numeric_limits<size_t>::max()))
      cuts.push_back(z);
  cuts.push_back(bottom);
  std::vector<double> out;
  for (size_t g = 0; g + 1 < cuts.size(); ++g) {
    if (g > 0) out.push_back(cuts[g]);
    const double length = cuts[g + 1] - cuts[g];
    const int parts = std::max(1, static_cast<int>(std::ceil(length / t * (1 - kPartsRounding))));
    for (int c = 1; c < parts; ++c) out.push_back(cuts[g] + length * c / parts);
  }
  return out;
}

// The pillars whose columns are offset against each other (FaultPillar), by increasing pillar.
std::vector<FaultPillar> fault_pillars_of(const CornerPointModel& m) {
  const PillarColumns pc{m};
  std::vector<FaultPillar> out;
  FaultPillar fp;
  for (int J = 0; J <= m.ny; ++J)
    for (int I = 0; I <= m.nx; ++I) {
      for (int a = 0; a < 4; ++a) fp.boundaries[a] = pc.present(I, J, a) ? column_boundaries(pc, I, J, a) : std::vector<double>{};
      fp.offset = offset_columns(pc, I, J, fp.boundaries);
      if (std::none_of(fp.offset.begin(), fp.offset.end(), [](const auto& row) { return row[0] || row[1] || row[2] || row[3]; }))
        continue;
      fp.pillar = I + (m.nx + 1) * J;
      out.push_back(fp);
    }
  return out;
}

// The narrowest plan width of the near active cells of non-zero thickness, scaled: each cell's edges
// along i and along j (top and bottom), divided by the frame's lateral scales.
double narrowest_scaled_width(const CornerPointModel& m, const std::vector<char>& near, Vec3 scale) {
  double width = std::numeric_limits<double>::infinity();
  for (size_t c = 0; c < m.n_cells(); ++c) {
    if (!near[c] || !m.actnum[c]) continue;
    const std::array<Vec3, 8> q = cell_corners(m, c);
    for (auto [u, v] : {std::pair{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3}, {4, 6}, {5, 7}}) {
      const Vec3 e = q[v] - q[u];
      const double plan = std::hypot(e.x / scale.x, e.y / scale.y);
      if (plan > 0) width = std::min(width, plan);
    }
  }
  return width;
}

}  // namespace

FaultStepSplit frame_layer_children(const CornerPointModel& m, const std::vector<FaultStepRequest>& wells, Vec3 scale,
                                    double aspect) {
  FaultStepSplit out;
  out.children.assign(m.nz, 1);
  if (wells.empty() || !(aspect > 0)) return out;
  out.near = cells_near(m, wells, std::vector<char>(wells.size(), 1));
  const double width = narrowest_scaled_width(m, out.near, scale);
  if (!std::isfinite(width)) return out;
  out.fault_pillars = fault_pillars_of(m);
  const int np = (m.nx + 1) * (m.ny + 1);
  std::vector<const FaultPillar*> fault_pillar(np, nullptr);
  for (const FaultPillar& fp : out.fault_pillars) fault_pillar[fp.pillar] = &fp;
  const PillarColumns pc{m};
  auto children_with = [&](double t) {
    std::vector<int> children(m.nz, 1);
    for (int k = 0; k < m.nz; ++k)
      for (int J = 0; J <= m.ny; ++J)
        for (int I = 0; I <= m.nx; ++I)
          for (int a = 0; a < 4; ++a) {
            if (!pc.present(I, J, a)) continue;
            const size_t c = PillarColumns::column_i(I, a) + size_t(m.nx) * (PillarColumns::column_j(J, a) + size_t(m.ny) * k);
            if (!out.near[c] || !m.actnum[c]) continue;
            const auto depths = frame_depths(fault_pillar[I + (m.nx + 1) * J], a, pc.top(I, J, a, k), pc.bottom(I, J, a, k), t);
            children[k] = std::max(children[k], 1 + static_cast<int>(depths.size()));
          }
    return children;
  };
  double t = aspect * width * scale.z, thickest = 0;
  for (size_t c = 0; c < m.n_cells(); ++c)
    if (out.near[c] && m.actnum[c]) {
      const std::array<Vec3, 8> q = cell_corners(m, c);
      for (int a = 0; a < 4; ++a) thickest = std::max(thickest, q[4 | a].z - q[a].z);
    }
  if (thickest <= t) return out;
  std::vector<int> children = children_with(t);
  while (*std::max_element(children.begin(), children.end()) > kMaxFrameChildren) children = children_with(t *= 1.25);
  out.children = std::move(children);
  out.child_thickness = t;
  return out;
}

CornerPointModel layers_split_at_fault_steps(const CornerPointModel& m, const FaultStepSplit& split) {
  const PillarColumns pc{m};
  const int np = (m.nx + 1) * (m.ny + 1);
  // Per split layer: per pillar and column slot, the child boundaries inside the layer (n - 1 depths).
  std::vector<std::vector<std::vector<double>>> inner(m.nz);
  std::vector<const FaultPillar*> fault_pillar(np, nullptr);
  for (const FaultPillar& fp : split.fault_pillars) fault_pillar[fp.pillar] = &fp;
  for (int k = 0; k < m.nz; ++k) {
    const int n = split.children[k];
    if (n <= 1) continue;
    auto& depth = inner[k];
    depth.assign(size_t(np) * 4, {});
    // Sides: the columns at a pillar whose layer k has the same top and bottom, and that are all near
    // a well or all not, share their depths.
    auto near_cell = [&](int I, int J, int a) {
      return split.near[PillarColumns::column_i(I, a) + size_t(m.nx) * (PillarColumns::column_j(J, a) + size_t(m.ny) * k)] != 0;
    };
    std::vector<int> side(size_t(np) * 4, -1);
    std::deque<int> queue;  // pillar * 4 + representative slot, breadth first from the steps
    for (int J = 0; J <= m.ny; ++J)
      for (int I = 0; I <= m.nx; ++I) {
        const int p = I + (m.nx + 1) * J;
        for (int a = 0; a < 4; ++a) {
          if (!pc.present(I, J, a)) continue;
          int rep = a;
          for (int b = 0; b < a; ++b)
            if (pc.present(I, J, b) && pc.top(I, J, b, k) == pc.top(I, J, a, k) &&
                pc.bottom(I, J, b, k) == pc.bottom(I, J, a, k) && near_cell(I, J, b) == near_cell(I, J, a)) {
              rep = side[size_t(p) * 4 + b];
              break;
            }
          side[size_t(p) * 4 + a] = rep;
          if (rep != a) continue;
          const double top = pc.top(I, J, a, k), bottom = pc.bottom(I, J, a, k);
          if (!near_cell(I, J, a)) {  // whole in the first child, the others of zero thickness at its bottom
            depth[size_t(p) * 4 + a].assign(size_t(n - 1), bottom);
            continue;
          }
          if (split.child_thickness > 0) {  // the frame's split: every near side by its own intervals
            auto& d = depth[size_t(p) * 4 + a] = frame_depths(fault_pillar[p], a, top, bottom, split.child_thickness);
            d.resize(size_t(n - 1), bottom);
            continue;
          }
          if (!(bottom > top) || !fault_pillar[p]) continue;
          std::vector<double> exact =
              steps_inside(fault_pillar[p]->boundaries, fault_pillar[p]->offset[a], top, bottom, size_t(n - 1));
          if (exact.empty()) continue;
          depth[size_t(p) * 4 + a] = padded(std::move(exact), top, bottom, size_t(n - 1));
          queue.push_back(p * 4 + a);
        }
      }
    // Breadth first: a side without steps takes the fractions of the side it is reached from across
    // one of its columns, so that every column sharing the pillar there gets the same depths.
    auto fractions_of = [&](int node) {
      const int p = node / 4, a = node % 4, I = p % (m.nx + 1), J = p / (m.nx + 1);
      const double top = pc.top(I, J, a, k), bottom = pc.bottom(I, J, a, k);
      std::vector<double> f;
      for (double z : depth[size_t(node)]) f.push_back(bottom > top ? (z - top) / (bottom - top) : 0.5);
      return f;
    };
    auto assign = [&](int node, const std::vector<double>& f) {
      const int p = node / 4, a = node % 4, I = p % (m.nx + 1), J = p / (m.nx + 1);
      const double top = pc.top(I, J, a, k), bottom = pc.bottom(I, J, a, k);
      auto& d = depth[size_t(node)];
      for (double x : f) d.push_back(top + x * (bottom - top));
    };
    while (!queue.empty()) {
      const int node = queue.front();
      queue.pop_front();
      const std::vector<double> f = fractions_of(node);
      const int p = node / 4, I = p % (m.nx + 1), J = p / (m.nx + 1);
      for (int a = 0; a < 4; ++a) {
        if (!pc.present(I, J, a) || side[size_t(p) * 4 + a] != node % 4) continue;
        const int ci = PillarColumns::column_i(I, a), cj = PillarColumns::column_j(J, a);
        for (int q = 0; q < 4; ++q) {
          const int I2 = ci + (q & 1), J2 = cj + (q >> 1), p2 = I2 + (m.nx + 1) * J2;
          const int a2 = (ci - I2 + 1) | ((cj - J2 + 1) << 1);
          const int rep = side[size_t(p2) * 4 + a2], node2 = p2 * 4 + rep;
          if (!depth[size_t(node2)].empty()) continue;
          assign(node2, f);
          queue.push_back(node2);
        }
      }
    }
    std::vector<double> equal;
    for (int c = 1; c < n; ++c) equal.push_back(double(c) / n);
    for (int node = 0; node < np * 4; ++node)
      if (side[size_t(node)] == node % 4 && depth[size_t(node)].empty()) assign(node, equal);
    // Every slot reads its side's depths.
    for (int node = 0; node < np * 4; ++node)
      if (side[size_t(node)] >= 0 && side[size_t(node)] != node % 4)
        depth[size_t(node)] = depth[size_t(node / 4 * 4 + side[size_t(node)])];
  }

  CornerPointModel r = m;
  std::vector<int> first_child(m.nz + 1, 0);
  for (int k = 0; k < m.nz; ++k) first_child[k + 1] = first_child[k] + split.children[k];
  r.nz = first_child[m.nz];
  if (m.parent_cell.empty()) r.parent_nx = m.nx, r.parent_ny = m.ny;
  r.parent_nz = m.parent_layer.empty() ? m.nz : m.parent_nz;
  r.parent_layer.resize(r.nz);
  for (int k = 0; k < m.nz; ++k)
    for (int c = first_child[k]; c < first_child[k + 1]; ++c) r.parent_layer[c] = m.parent_layer.empty() ? k : m.parent_layer[k];
  resize_cell_arrays(r, m);
  r.opm_volume.clear();
  for (int k = 0; k < m.nz; ++k) {
    const int nk = split.children[k];
    for (int j = 0; j < m.ny; ++j)
      for (int i = 0; i < m.nx; ++i) {
        const size_t pcell = i + size_t(m.nx) * (j + size_t(m.ny) * k);
        for (int child = 0; child < nk; ++child) {
          const int kc = first_child[k] + child;
          const size_t c = i + size_t(r.nx) * (j + size_t(r.ny) * kc);
          for (int q = 0; q < 8; ++q) {
            const int corner = q & 3, I = i + (q & 1), J = j + ((q >> 1) & 1), p = I + (m.nx + 1) * J;
            const int level = child + (q >> 2);  // 0: the parent's top ... nk: its bottom
            const double top = m.zcorn[zcorn_index(m, i, j, k, corner)], bottom = m.zcorn[zcorn_index(m, i, j, k, 4 | corner)];
            const double z = level == 0    ? top
                             : level == nk ? bottom
                                           : inner[k][size_t(p) * 4 + ((i - I + 1) | ((j - J + 1) << 1))][size_t(level - 1)];
            r.zcorn[zcorn_index(r, i, j, kc, q)] = z;
          }
          inherit_cell(r, c, m, pcell);
          // x and y multipliers on every child's faces; MULTZ where the child ends at the parent's
          // bottom, MULTZ- where it starts at its top.
          bool at_top = true, at_bottom = true;
          for (int q = 0; q < 4; ++q) {
            at_top = at_top && r.zcorn[zcorn_index(r, i, j, kc, q)] == m.zcorn[zcorn_index(m, i, j, k, q)];
            at_bottom = at_bottom && r.zcorn[zcorn_index(r, i, j, kc, 4 | q)] == m.zcorn[zcorn_index(m, i, j, k, 4 | q)];
          }
          const bool at[6] = {true, true, true, true, at_bottom, child == 0 && at_top};
          for (int d = 0; d < 6; ++d)
            if (!m.trans_mult[d].empty()) r.trans_mult[d][c] = at[d] ? m.trans_mult[d][pcell] : 1.0;
        }
      }
  }
  return r;
}

}  // namespace hm
