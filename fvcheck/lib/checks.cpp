#include "checks.hpp"

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <limits>
#include <mutex>
#include <numeric>

#include "meshgen/core/parallel.hpp"
#include "quality.hpp"

namespace hm {

namespace {

constexpr size_t kWorstIds = 10;

// Ids of the (up to) k entries with the worst values, worst first; NaN counts as worst.
// Only entries accepted by `keep` are considered. Ties go to the smaller id, so the order is
// total: each chunk's k worst are found in parallel, and the k worst of their union are the
// k worst of all.
template <class Keep>
std::vector<int32_t> worst_ids_of(const std::vector<double>& v, bool higher_is_worse, Keep keep) {
  auto key = [&](int32_t i) {
    const double x = v[i];
    if (std::isnan(x)) return higher_is_worse ? std::numeric_limits<double>::infinity()
                                              : -std::numeric_limits<double>::infinity();
    return x;
  };
  auto worse = [&](int32_t a, int32_t b) {
    const double ka = key(a), kb = key(b);
    if (ka != kb) return higher_is_worse ? ka > kb : ka < kb;
    return a < b;
  };
  auto k_worst = [&](std::vector<int32_t>& idx) {
    const size_t k = std::min(kWorstIds, idx.size());
    std::partial_sort(idx.begin(), idx.begin() + k, idx.end(), worse);
    idx.resize(k);
  };
  std::vector<int32_t> candidates;
  std::mutex candidates_mutex;
  parallel_ranges(static_cast<int64_t>(v.size()), [&](int64_t b, int64_t e) {
    std::vector<int32_t> idx;
    for (int64_t i = b; i < e; ++i)
      if (keep(static_cast<size_t>(i))) idx.push_back(static_cast<int32_t>(i));
    k_worst(idx);
    std::lock_guard<std::mutex> lock(candidates_mutex);
    candidates.insert(candidates.end(), idx.begin(), idx.end());
  }, 1 << 16);
  k_worst(candidates);
  return candidates;
}
std::vector<int32_t> worst_ids_of(const std::vector<double>& v, bool higher_is_worse) {
  return worst_ids_of(v, higher_is_worse, [](size_t) { return true; });
}

// Sets r.worst (the largest value, or the smallest when lower is worse; `empty` when there
// are none) and the ids of the worst values.
void rank_worst(CheckResult& r, bool higher_is_worse, double empty = 0.0) {
  if (r.values.empty()) r.worst = empty;
  else r.worst = higher_is_worse ? *std::max_element(r.values.begin(), r.values.end())
                                 : *std::min_element(r.values.begin(), r.values.end());
  r.worst_ids = worst_ids_of(r.values, higher_is_worse);
}

void push_example(std::vector<int32_t>& ids, int32_t id) {
  if (ids.size() < kWorstIds && std::find(ids.begin(), ids.end(), id) == ids.end()) ids.push_back(id);
}

double coord_floor(double max_abs_coord) { return 64.0 * DBL_EPSILON * max_abs_coord; }

// Bounding box and largest |coordinate| of the points added (repeats change nothing).
struct ScaleBox {
  Vec3 lo{DBL_MAX, DBL_MAX, DBL_MAX}, hi{-DBL_MAX, -DBL_MAX, -DBL_MAX};
  double amax = 0;
  bool empty = true;
  void add(Vec3 p) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
      amax = std::max(amax, std::fabs(p[k]));
    }
    empty = false;
  }
  // Bounding-box diagonal and absolute tolerance.
  void finish(double rel_tol, double* length, double* tol) const {
    *length = empty ? 0.0 : norm(hi - lo);
    *tol = std::max(rel_tol * *length, coord_floor(amax));
  }
};

// Bounding-box diagonal and absolute tolerance of a node set.
void scale_of(const std::vector<Vec3>& nodes, const int32_t* b, const int32_t* e, double rel_tol, double* length,
              double* tol) {
  ScaleBox box;
  for (const int32_t* v = b; v != e; ++v) box.add(nodes[*v]);
  box.finish(rel_tol, length, tol);
}

// Closest distance from p to triangle (a, b, c) (Ericson, Real-Time Collision Detection 5.1.5).
double point_triangle_distance(Vec3 p, Vec3 a, Vec3 b, Vec3 c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return norm(p - a);
  const Vec3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return norm(p - b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return norm(p - (a + (d1 / (d1 - d3)) * ab));
  const Vec3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return norm(p - c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return norm(p - (a + (d2 / (d2 - d6)) * ac));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return norm(p - (b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b)));
  const double denom = va + vb + vc;
  if (!(std::fabs(denom) > 0)) {  // degenerate triangle: distance to its edges
    auto seg = [](Vec3 q, Vec3 s0, Vec3 s1) {
      const Vec3 d = s1 - s0;
      const double l2 = norm2(d);
      const double t = l2 > 0 ? std::min(1.0, std::max(0.0, dot(q - s0, d) / l2)) : 0.0;
      return norm(q - (s0 + t * d));
    };
    return std::min(seg(p, a, b), std::min(seg(p, b, c), seg(p, c, a)));
  }
  const double v = vb / denom, w = vc / denom;
  return norm(p - (a + v * ab + w * ac));
}

// Uniform grid of a subset of nodes, for box queries (hanging-node search): buckets of side
// `cell` (the median face extent, so that a face's box meets a few buckets), nodes sorted by
// (bucket, id). A bucket's range is found in a dense table of bucket starts when the grid has
// at most a few buckets per node (a reservoir's lattice), else through an open-addressing hash
// of its index. A k-d tree split at medians visits both sides of every tie, and a reservoir
// lattice is all ties.
class NodeGrid {
 public:
  NodeGrid(const std::vector<Vec3>& pts, const std::vector<int32_t>& ids, double cell) : pts_(pts) {
    lo_ = {DBL_MAX, DBL_MAX, DBL_MAX};
    Vec3 hi{-DBL_MAX, -DBL_MAX, -DBL_MAX};
    for (int32_t v : ids)
      for (int a = 0; a < 3; ++a) lo_[a] = std::min(lo_[a], pts[v][a]), hi[a] = std::max(hi[a], pts[v][a]);
    if (ids.empty()) return;
    const double extent = std::max({hi.x - lo_.x, hi.y - lo_.y, hi.z - lo_.z});
    cell_ = std::isfinite(cell) && cell > 0 ? cell : 1.0;
    if (extent / cell_ > kMaxDim - 1) cell_ = extent / (kMaxDim - 1);
    if (!(cell_ > 0)) cell_ = 1.0;
    for (int a = 0; a < 3; ++a) dim_[a] = std::min<int64_t>(kMaxDim, static_cast<int64_t>((hi[a] - lo_[a]) / cell_) + 1);
    const double buckets = static_cast<double>(dim_[0]) * static_cast<double>(dim_[1]) * static_cast<double>(dim_[2]);
    if (buckets <= 4.0 * static_cast<double>(ids.size()) + 4096) {
      // Counting sort by bucket; ids ascending within a bucket (ids is ascending).
      dense_start_.assign(static_cast<size_t>(buckets) + 1, 0);
      for (int32_t v : ids) ++dense_start_[key_of(pts[v]) + 1];
      for (size_t b = 0; b + 1 < dense_start_.size(); ++b) {
        occupied_ += dense_start_[b + 1] > 0;
        dense_start_[b + 1] += dense_start_[b];
      }
      ids_.resize(ids.size());
      std::vector<uint32_t> fill(dense_start_.begin(), dense_start_.end() - 1);
      for (int32_t v : ids) ids_[fill[key_of(pts[v])]++] = v;
      return;
    }
    std::vector<std::pair<uint64_t, int32_t>> keyed;
    keyed.reserve(ids.size());
    for (int32_t v : ids) keyed.emplace_back(key_of(pts[v]), v);
    std::sort(keyed.begin(), keyed.end());
    ids_.resize(keyed.size());
    for (size_t i = 0; i < keyed.size(); ++i) ids_[i] = keyed[i].second;
    for (size_t i = 0; i < keyed.size(); ++i)
      if (i == 0 || keyed[i].first != keyed[i - 1].first) keys_.push_back(keyed[i].first), begin_.push_back(i);
    begin_.push_back(keyed.size());
    occupied_ = keys_.size();
    size_t size = 16;
    while (size < 2 * keys_.size()) size *= 2;
    table_.assign(size, -1);
    for (size_t b = 0; b < keys_.size(); ++b) {
      size_t h = slot(keys_[b]);
      while (table_[h] >= 0) h = (h + 1) & (table_.size() - 1);
      table_[h] = static_cast<int64_t>(b);
    }
  }
  // Visits every node inside the box [lo, hi], bucket by bucket (z, y, x order), by id within one.
  template <class Visit>
  void query(Vec3 lo, Vec3 hi, Visit visit) const {
    if (ids_.empty()) return;
    int64_t i0[3], i1[3];
    for (int a = 0; a < 3; ++a) i0[a] = index(lo[a], a), i1[a] = index(hi[a], a);
    auto visit_inside = [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) {
        const Vec3 p = pts_[ids_[i]];
        if (p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z) visit(ids_[i]);
      }
    };
    const double buckets = static_cast<double>(i1[0] - i0[0] + 1) * (i1[1] - i0[1] + 1) * (i1[2] - i0[2] + 1);
    if (buckets > static_cast<double>(occupied_)) {  // a box larger than the occupied grid: scan it all
      visit_inside(0, ids_.size());
      return;
    }
    for (int64_t z = i0[2]; z <= i1[2]; ++z)
      for (int64_t y = i0[1]; y <= i1[1]; ++y) {
        const int64_t row = (z * dim_[1] + y) * dim_[0];
        if (!dense_start_.empty()) {  // the row's buckets x0..x1 are contiguous
          visit_inside(dense_start_[row + i0[0]], dense_start_[row + i1[0] + 1]);
          continue;
        }
        for (int64_t x = i0[0]; x <= i1[0]; ++x) {
          const int64_t b = find(static_cast<uint64_t>(row + x));
          if (b >= 0) visit_inside(begin_[b], begin_[b + 1]);
        }
      }
  }

 private:
  static constexpr int64_t kMaxDim = int64_t(1) << 20;
  int64_t index(double x, int a) const {
    const double t = std::floor((x - lo_[a]) / cell_);
    if (!(t > 0)) return 0;  // also NaN
    return std::min<int64_t>(dim_[a] - 1, static_cast<int64_t>(std::min(t, static_cast<double>(kMaxDim))));
  }
  uint64_t key_of(Vec3 p) const {
    return static_cast<uint64_t>((index(p.z, 2) * dim_[1] + index(p.y, 1)) * dim_[0] + index(p.x, 0));
  }
  size_t slot(uint64_t key) const { return static_cast<size_t>((key * 0x9E3779B97F4A7C15ull) >> 17) & (table_.size() - 1); }
  int64_t find(uint64_t key) const {
    for (size_t h = slot(key);; h = (h + 1) & (table_.size() - 1)) {
      const int64_t b = table_[h];
      if (b < 0 || keys_[b] == key) return b;
    }
  }
  const std::vector<Vec3>& pts_;
  Vec3 lo_;
  double cell_ = 1.0;
  int64_t dim_[3] = {1, 1, 1};
  size_t occupied_ = 0;                // buckets holding a node
  std::vector<int32_t> ids_;           // sorted by (bucket, id)
  std::vector<uint32_t> dense_start_;  // dense grid: bucket b is ids_[dense_start_[b] .. dense_start_[b + 1])
  std::vector<uint64_t> keys_;         // hashed grid: occupied buckets, ascending
  std::vector<size_t> begin_;          // hashed grid: bucket k is ids_[begin_[k] .. begin_[k + 1])
  std::vector<int64_t> table_;         // hashed grid: hash slot -> bucket, -1 empty
};

double cross2(double ax, double ay, double bx, double by) { return ax * by - ay * bx; }

// Distance between 2D segments (p0,p1) and (q0,q1); 0 if they cross.
double segment_distance_2d(const double* p0, const double* p1, const double* q0, const double* q1) {
  auto orient = [](const double* a, const double* b, const double* c) {
    return cross2(b[0] - a[0], b[1] - a[1], c[0] - a[0], c[1] - a[1]);
  };
  const double o1 = orient(p0, p1, q0), o2 = orient(p0, p1, q1), o3 = orient(q0, q1, p0), o4 = orient(q0, q1, p1);
  if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0))) return 0.0;
  auto pseg = [](const double* x, const double* a, const double* b) {
    const double dx = b[0] - a[0], dy = b[1] - a[1];
    const double l2 = dx * dx + dy * dy;
    double t = l2 > 0 ? ((x[0] - a[0]) * dx + (x[1] - a[1]) * dy) / l2 : 0.0;
    t = std::min(1.0, std::max(0.0, t));
    const double ex = a[0] + t * dx - x[0], ey = a[1] + t * dy - x[1];
    return std::sqrt(ex * ex + ey * ey);
  };
  return std::min(std::min(pseg(p0, q0, q1), pseg(p1, q0, q1)), std::min(pseg(q0, p0, p1), pseg(q1, p0, p1)));
}

}  // namespace

CellScales compute_cell_scales(const PolyMesh& m, double rel_tol) {
  CellScales s;
  s.length.assign(m.n_cells(), 0.0);
  s.tol.assign(m.n_cells(), 0.0);
  parallel_ranges(m.n_cells(), [&](int64_t b, int64_t e) {
    for (int c = static_cast<int>(b); c < e; ++c) {
      // Over every face's nodes: a node shared by faces counts once in a box anyway.
      ScaleBox box;
      for (const int32_t* f = m.cell_begin(c); f != m.cell_end(c); ++f)
        for (const int32_t* v = m.face_begin(*f); v != m.face_end(*f); ++v) box.add(m.nodes[*v]);
      box.finish(rel_tol, &s.length[c], &s.tol[c]);
    }
  });
  return s;
}

void cell_node_ids_into(const PolyMesh& m, int c, std::vector<int32_t>* ids) {
  ids->clear();
  for (const int32_t* f = m.cell_begin(c); f != m.cell_end(c); ++f) ids->insert(ids->end(), m.face_begin(*f), m.face_end(*f));
  std::sort(ids->begin(), ids->end());
  ids->erase(std::unique(ids->begin(), ids->end()), ids->end());
}

std::vector<int32_t> cell_node_ids(const PolyMesh& m, int c) {
  std::vector<int32_t> ids;
  cell_node_ids_into(m, c, &ids);
  return ids;
}

namespace {

// Whether |cross| <= tol * hypot(cx, cy), deciding on the bounds max(|cx|, |cy|) <= hypot <=
// |cx| + |cy| (with a margin far above rounding) when they settle it: hypot is slow.
bool on_chord_line(double abs_cross, double tol, double cx, double cy) {
  const double ax = std::fabs(cx), ay = std::fabs(cy);
  const double scale = tol * (ax + ay);
  if (std::isfinite(scale) && scale > 1e-290 && std::isfinite(abs_cross)) {  // else (rare) as hypot has it
    if (abs_cross > tol * (ax + ay) * (1 + 1e-6)) return false;
    if (abs_cross < tol * std::max(ax, ay) * (1 - 1e-6)) return true;
  }
  return abs_cross <= tol * std::hypot(cx, cy);
}

// face_polygon_defect of a face whose area vector and centroid (polygon_area_centroid) are known.
int polygon_defect(const std::vector<Vec3>& nodes, const int32_t* begin, const int32_t* end, double rel_tol,
                   Vec3 area, Vec3 centroid) {
  const int k = static_cast<int>(end - begin);
  if (k < 3) return 3;
  double diam = 0, tol = 0;
  scale_of(nodes, begin, end, rel_tol, &diam, &tol);
  const double an = norm(area);
  if (!(diam > 0) || !(an > tol * tol)) return 3;  // no usable normal
  const Vec3 n = area / an;
  // In-plane basis: the coordinate axis least aligned with n gives a stable u.
  const Vec3 axis = std::fabs(n.x) <= std::fabs(n.y) && std::fabs(n.x) <= std::fabs(n.z)
                        ? Vec3{1, 0, 0}
                        : (std::fabs(n.y) <= std::fabs(n.z) ? Vec3{0, 1, 0} : Vec3{0, 0, 1});
  const Vec3 u = normalized(cross(n, axis)), w = cross(n, u);
  // Projected corners: on the stack for the usual faces (no allocation per face).
  std::array<double, 64> small;
  std::vector<double> large;
  if (2 * k > static_cast<int>(small.size())) large.resize(2 * k);
  double* q = 2 * k > static_cast<int>(small.size()) ? large.data() : small.data();
  for (int i = 0; i < k; ++i) {
    const Vec3 d = nodes[begin[i]] - centroid;
    q[2 * i] = dot(d, u);
    q[2 * i + 1] = dot(d, w);
  }
  auto P = [&](int i) { return &q[2 * (((i % k) + k) % k)]; };
  // Non-adjacent edges must keep apart. Two edges whose boxes are 2 tol apart on an axis are
  // farther than tol (far beyond rounding: tol >= 1e-9 of the face's extent).
  auto apart = [&](const double* a0, const double* a1, const double* b0, const double* b1) {
    for (int x = 0; x < 2; ++x)
      if (std::min(b0[x], b1[x]) - std::max(a0[x], a1[x]) > 2 * tol ||
          std::min(a0[x], a1[x]) - std::max(b0[x], b1[x]) > 2 * tol)
        return true;
    return false;
  };
  for (int i = 0; i < k; ++i)
    for (int j = i + 2; j < k; ++j) {
      if (i == 0 && j == k - 1) continue;
      if (apart(P(i), P(i + 1), P(j), P(j + 1))) continue;
      if (segment_distance_2d(P(i), P(i + 1), P(j), P(j + 1)) <= tol) return 2;
    }
  // Turns: (u, w, n) is right-handed and the cycle is counter-clockwise seen from n, so a
  // convex vertex turns left. A vertex is reflex if it lies beyond tol on the wrong side of
  // the chord joining its neighbours; a straight-back spike is an intersection.
  int defect = 0;
  for (int i = 0; i < k; ++i) {
    const double* a = P(i - 1);
    const double* b = P(i);
    const double* c = P(i + 1);
    const double e1x = b[0] - a[0], e1y = b[1] - a[1], e2x = c[0] - b[0], e2y = c[1] - b[1];
    const double cr = cross2(e1x, e1y, e2x, e2y);
    if (on_chord_line(std::fabs(cr), tol, c[0] - a[0], c[1] - a[1])) {
      if (e1x * e2x + e1y * e2y < 0) return 2;  // folds back on itself
      continue;                                 // straight: a node on an edge line is allowed
    }
    if (cr < 0) defect = 1;
  }
  return defect;
}

}  // namespace

int face_polygon_defect(const std::vector<Vec3>& nodes, const int32_t* begin, const int32_t* end, double rel_tol) {
  if (end - begin < 3) return 3;
  Vec3 area, centroid;
  polygon_area_centroid(nodes, begin, end, &area, &centroid);
  return polygon_defect(nodes, begin, end, rel_tol, area, centroid);
}

CheckResult check_convexity(const PolyMesh& m, const MeshGeometry& geo, const CheckOptions& opt) {
  CheckResult r;
  r.name = "convexity";
  r.values.assign(m.n_cells(), 0.0);
  std::vector<int> defect(m.n_faces());
  parallel_ranges(m.n_faces(), [&](int64_t b, int64_t e) {
    for (int f = static_cast<int>(b); f < e; ++f)
      defect[f] = polygon_defect(m.nodes, m.face_begin(f), m.face_end(f), opt.rel_tol, geo.face_area[f],
                                 geo.face_centroid[f]);
  });
  int64_t reflex = 0, non_simple = 0, degenerate = 0;
  std::vector<int32_t> ex_reflex, ex_non_simple, ex_degenerate, ex_outside;
  for (int f = 0; f < m.n_faces(); ++f) {
    if (defect[f] == 1) ++reflex, push_example(ex_reflex, f);
    if (defect[f] == 2) ++non_simple, push_example(ex_non_simple, f);
    if (defect[f] == 3) ++degenerate, push_example(ex_degenerate, f);
  }
  // Per cell (in parallel): its value and 1 = a node outside a face plane, 2 = a bad face.
  std::vector<char> flags(m.n_cells(), 0);
  parallel_ranges(m.n_cells(), [&](int64_t cb, int64_t ce) {
    std::vector<int32_t> ids;
    for (int c = static_cast<int>(cb); c < ce; ++c) {
      cell_node_ids_into(m, c, &ids);
      double L = 0, tol = 0;
      scale_of(m.nodes, ids.data(), ids.data() + ids.size(), opt.rel_tol, &L, &tol);
      double worst = -std::numeric_limits<double>::infinity();
      bool bad_face = false;
      const bool few = ids.size() <= 64;  // the face's nodes as bits of their place in ids
      for (const int32_t* fp = m.cell_begin(c); fp != m.cell_end(c); ++fp) {
        const int f = *fp;
        if (defect[f] != 0) bad_face = true;
        const Vec3 a = m.face_sign(f, c) * geo.face_area[f];
        const double an = norm(a);
        if (!(an > 0)) continue;  // degenerate face: already flagged
        const Vec3 n = a / an;
        uint64_t on_face = 0;
        if (few)
          for (const int32_t* v = m.face_begin(f); v != m.face_end(f); ++v)
            on_face |= uint64_t(1) << (std::lower_bound(ids.begin(), ids.end(), *v) - ids.begin());
        for (size_t i = 0; i < ids.size(); ++i) {
          const int32_t v = ids[i];
          if (few ? (on_face >> i) & 1 : std::find(m.face_begin(f), m.face_end(f), v) != m.face_end(f)) continue;
          worst = std::max(worst, dot(m.nodes[v] - geo.face_centroid[f], n));
        }
      }
      const bool outside = worst > tol;
      double value = L > 0 && std::isfinite(worst) ? worst / L : (std::isfinite(worst) ? 0.0 : -1.0);
      if (std::isnan(worst)) value = 1.0;
      if (bad_face) value = std::max(value, 1.0);
      r.values[c] = value;
      flags[c] = static_cast<char>((outside ? 1 : 0) | (bad_face ? 2 : 0));
    }
  });
  int64_t outside_cells = 0;
  r.failing.assign(m.n_cells(), 0);
  for (int c = 0; c < m.n_cells(); ++c) {
    if (flags[c] & 1) ++outside_cells, push_example(ex_outside, c);
    if (flags[c]) ++r.violations, r.failing[c] = 1;
  }
  rank_worst(r, true);
  r.counts = {{"cells_with_node_outside_face_plane", outside_cells},
              {"faces_with_reflex_vertex", reflex},
              {"self_intersecting_faces", non_simple},
              {"degenerate_faces", degenerate}};
  r.id_lists = {{"cells_with_node_outside_face_plane", ex_outside},
                {"faces_with_reflex_vertex", ex_reflex},
                {"self_intersecting_faces", ex_non_simple},
                {"degenerate_faces", ex_degenerate}};
  r.measures = {{"rel_tol", opt.rel_tol}};
  return r;
}

CheckResult check_conformity(const PolyMesh& m, const MeshGeometry& geo, const CheckOptions& opt,
                             const BuildReport* build) {
  CheckResult r;
  r.name = "conformity";
  const int nf = m.n_faces(), nc = m.n_cells();
  r.values.assign(nc, 0.0);
  auto mark_face = [&](int f) {
    r.values[m.face_owner[f]] += 1;
    if (m.face_neighbour[f] >= 0) r.values[m.face_neighbour[f]] += 1;
  };

  // (a) Faces declared interior that found no second cell.
  int64_t unmatched = 0;
  std::vector<int32_t> ex_unmatched;
  for (int f = 0; f < nf; ++f)
    if (m.face_patch[f] == kUnmatchedFace) ++unmatched, push_example(ex_unmatched, f), mark_face(f);

  // (b) Two face records over the same node set: a face used by more than two cells. Faces
  // are grouped by their smallest node (a counting sort, by face id within a node), and a face
  // is compared with the earlier faces of its group only.
  std::vector<int32_t> sorted_nodes(m.face_nodes.size());
  parallel_ranges(nf, [&](int64_t b, int64_t e) {
    for (int f = static_cast<int>(b); f < e; ++f) {
      std::copy(m.face_begin(f), m.face_end(f), sorted_nodes.begin() + m.face_node_ptr[f]);
      std::sort(sorted_nodes.begin() + m.face_node_ptr[f], sorted_nodes.begin() + m.face_node_ptr[f + 1]);
    }
  });
  auto key_begin = [&](int32_t f) { return sorted_nodes.begin() + m.face_node_ptr[f]; };
  auto key_end = [&](int32_t f) { return sorted_nodes.begin() + m.face_node_ptr[f + 1]; };
  auto key_less = [&](int32_t a, int32_t b) {
    return std::lexicographical_compare(key_begin(a), key_end(a), key_begin(b), key_end(b));
  };
  std::vector<int32_t> group_ptr(m.n_nodes() + 1, 0), group(nf);
  for (int f = 0; f < nf; ++f) ++group_ptr[*key_begin(f) + 1];
  for (int v = 0; v < m.n_nodes(); ++v) group_ptr[v + 1] += group_ptr[v];
  {
    std::vector<int32_t> fill(group_ptr.begin(), group_ptr.end() - 1);
    for (int f = 0; f < nf; ++f) group[fill[*key_begin(f)]++] = f;
  }
  std::vector<int32_t> first_same(nf, -1);  // the smallest face id over the same node set, if earlier
  parallel_ranges(nf, [&](int64_t b, int64_t e) {
    for (int f = static_cast<int>(b); f < e; ++f) {
      const int32_t v = *key_begin(f);
      for (int32_t i = group_ptr[v]; i < group_ptr[v + 1] && group[i] < f; ++i)
        if (std::equal(key_begin(f), key_end(f), key_begin(group[i]), key_end(group[i]))) {
          first_same[f] = group[i];
          break;
        }
    }
  });
  group_ptr = {};
  group = {};
  // Each set of equal faces (ids ascending), the sets in the order of their sorted node lists;
  // a set of n faces counts n - 1 duplicates.
  std::vector<std::vector<int32_t>> same_sets;
  {
    std::vector<int32_t> set_of(nf, -1);
    for (int f = 0; f < nf; ++f) {
      const int32_t root = first_same[f];
      if (root < 0) continue;
      if (set_of[root] < 0) set_of[root] = static_cast<int32_t>(same_sets.size()), same_sets.push_back({root});
      same_sets[set_of[root]].push_back(f);
    }
  }
  first_same = {};
  std::sort(same_sets.begin(), same_sets.end(),
            [&](const std::vector<int32_t>& a, const std::vector<int32_t>& b) { return key_less(a[0], b[0]); });
  int64_t duplicates = 0;
  std::vector<int32_t> ex_dup;
  for (const std::vector<int32_t>& set : same_sets)
    for (size_t i = 1; i < set.size(); ++i) {
      ++duplicates;
      push_example(ex_dup, set[i]);
      mark_face(set[i]);
      mark_face(set[i - 1]);
    }
  sorted_nodes = {};

  // (c) Each cell's surface: every edge used by exactly two of its faces, once per direction.
  int64_t open_cells = 0, misoriented_cells = 0;
  std::vector<int32_t> ex_open, ex_misoriented;
  // A directed edge packed as (lo << 33) | (hi << 1) | (traversed lo -> hi): sorting the keys
  // sorts by (lo, hi, direction). Node ids are below 2^31.
  auto edge_key = [](int32_t a, int32_t b) {
    return a < b ? (uint64_t(a) << 33) | (uint64_t(b) << 1) | 1u : (uint64_t(b) << 33) | (uint64_t(a) << 1);
  };
  std::vector<char> surface(nc, 0);  // 1: open, 2: misoriented
  parallel_ranges(nc, [&](int64_t cb, int64_t ce) {
    std::vector<uint64_t> edges;
    for (int c = static_cast<int>(cb); c < ce; ++c) {
      edges.clear();
      for (const int32_t* fp = m.cell_begin(c); fp != m.cell_end(c); ++fp) {
        const int f = *fp, k = m.face_size(f);
        const int32_t* v = m.face_begin(f);
        const bool own = m.face_sign(f, c) > 0;
        for (int i = 0; i < k; ++i) {
          const int32_t a = v[i], b = v[i + 1 == k ? 0 : i + 1];
          edges.push_back(own ? edge_key(a, b) : edge_key(b, a));
        }
      }
      std::sort(edges.begin(), edges.end());
      bool open = false, misoriented = false;
      for (size_t i = 0; i < edges.size();) {
        size_t j = i;
        while (j < edges.size() && (edges[j] >> 1) == (edges[i] >> 1)) ++j;
        if (j - i != 2) open = true;
        else if ((edges[i] & 1) == (edges[i + 1] & 1)) misoriented = true;
        i = j;
      }
      surface[c] = static_cast<char>((open ? 1 : 0) | (misoriented ? 2 : 0));
    }
  });
  for (int c = 0; c < nc; ++c) {
    if (surface[c] & 1) ++open_cells, push_example(ex_open, c), r.values[c] += 1;
    if (surface[c] & 2) ++misoriented_cells, push_example(ex_misoriented, c), r.values[c] += 1;
  }

  // (d) Hanging nodes: a node (referenced by some face) lying on a face's fan triangles within
  // tol_F while not one of its vertices. This also catches duplicated nodes. Candidates: the
  // nodes in the face's bounding box padded by tol_F (NodeGrid).
  std::vector<char> used(m.n_nodes(), 0);
  for (int32_t v : m.face_nodes) used[v] = 1;
  std::vector<int32_t> used_ids;
  for (int v = 0; v < m.n_nodes(); ++v)
    if (used[v]) used_ids.push_back(v);
  // Bucket side: the median extent (bounding-box diagonal) of the faces.
  std::vector<double> extent(nf, 0.0);
  parallel_ranges(nf, [&](int64_t b, int64_t e) {
    for (int f = static_cast<int>(b); f < e; ++f) {
      double tol = 0;
      scale_of(m.nodes, m.face_begin(f), m.face_end(f), opt.rel_tol, &extent[f], &tol);
    }
  });
  double median_extent = 0;
  if (nf > 0) {
    std::nth_element(extent.begin(), extent.begin() + nf / 2, extent.end());
    median_extent = extent[nf / 2];
  }
  extent = {};
  const NodeGrid tree(m.nodes, used_ids, median_extent);
  used_ids = {};
  std::vector<char> hanging(m.n_nodes(), 0);
  int64_t hanging_pairs = 0;
  std::vector<int32_t> ex_hanging;
  // Face by face in parallel: the (face, node) pairs found, per chunk in face order; then
  // recorded in face order as a serial scan would.
  struct Chunk {
    int64_t begin;
    std::vector<std::pair<int32_t, int32_t>> hits;
  };
  std::vector<Chunk> chunks;
  std::mutex chunks_mutex;
  parallel_ranges(nf, [&](int64_t fb, int64_t fe) {
    Chunk chunk{fb, {}};
    for (int f = static_cast<int>(fb); f < fe; ++f) {
      const int k = m.face_size(f);
      const int32_t* v = m.face_begin(f);
      ScaleBox box;
      Vec3 g;
      for (int i = 0; i < k; ++i) {
        const Vec3 p = m.nodes[v[i]];
        g += p;
        box.add(p);
      }
      g = g / k;
      double diam = 0, tol = 0;
      box.finish(opt.rel_tol, &diam, &tol);
      const Vec3 pad{tol, tol, tol};
      tree.query(box.lo - pad, box.hi + pad, [&](int32_t p) {
        if (std::find(v, v + k, p) != v + k) return;
        double d = DBL_MAX;
        for (int i = 0; i < k && d > tol; ++i)
          d = std::min(d, point_triangle_distance(m.nodes[p], g, m.nodes[v[i]], m.nodes[v[(i + 1) % k]]));
        if (d <= tol) chunk.hits.emplace_back(f, p);
      });
    }
    if (chunk.hits.empty()) return;
    std::lock_guard<std::mutex> lock(chunks_mutex);
    chunks.push_back(std::move(chunk));
  });
  std::sort(chunks.begin(), chunks.end(), [](const Chunk& a, const Chunk& b) { return a.begin < b.begin; });
  for (const Chunk& chunk : chunks)
    for (const auto& [f, p] : chunk.hits) {
      ++hanging_pairs;
      hanging[p] = 1;
      push_example(ex_hanging, p);
      mark_face(f);
    }
  const int64_t hanging_nodes = std::count(hanging.begin(), hanging.end(), 1);
  (void)geo;

  int64_t b_over = 0, b_misor = 0, b_degen = 0;
  if (build) b_over = build->overused_faces, b_misor = build->misoriented_faces, b_degen = build->degenerate_faces;
  r.violations = unmatched + duplicates + open_cells + misoriented_cells + hanging_nodes + b_over + b_misor + b_degen;
  r.worst = r.values.empty() ? 0.0 : *std::max_element(r.values.begin(), r.values.end());
  r.worst_ids = worst_ids_of(r.values, true, [&](size_t c) { return r.values[c] > 0; });
  r.counts = {{"unmatched_faces", unmatched},
              {"duplicate_faces", duplicates},
              {"open_cells", open_cells},
              {"misoriented_cells", misoriented_cells},
              {"hanging_nodes", hanging_nodes},
              {"hanging_node_face_pairs", hanging_pairs},
              {"builder_overused_faces", b_over},
              {"builder_misoriented_faces", b_misor},
              {"builder_degenerate_faces", b_degen}};
  r.id_lists = {{"unmatched_faces", ex_unmatched},
                {"duplicate_faces", ex_dup},
                {"open_cells", ex_open},
                {"misoriented_cells", ex_misoriented},
                {"hanging_nodes", ex_hanging}};
  r.measures = {{"rel_tol", opt.rel_tol}};
  return r;
}

CheckResult check_closure(const PolyMesh& m, const MeshGeometry& geo, const CheckOptions& opt) {
  CheckResult r;
  r.name = "closure";
  r.values.assign(m.n_cells(), 0.0);
  parallel_ranges(m.n_cells(), [&](int64_t b, int64_t e) {
    for (int c = static_cast<int>(b); c < e; ++c) {
      double total = 0;
      for (const int32_t* f = m.cell_begin(c); f != m.cell_end(c); ++f) total += norm(geo.face_area[*f]);
      const double s = norm(cell_area_sum(m, geo, c));
      const double ratio = total > 0 ? s / total : 1.0;
      r.values[c] = std::isnan(ratio) ? 1.0 : ratio;
    }
  });
  r.failing.assign(m.n_cells(), 0);
  for (int c = 0; c < m.n_cells(); ++c)
    if (!(r.values[c] <= opt.closure_tol)) ++r.violations, r.failing[c] = 1;
  rank_worst(r, true);
  r.measures = {{"tolerance", opt.closure_tol}};
  return r;
}

CheckResult check_volume(const PolyMesh& m, const MeshGeometry& geo, const CheckOptions& opt) {
  return check_volume(m, geo, opt, compute_cell_scales(m, opt.rel_tol));
}

CheckResult check_volume(const PolyMesh& m, const MeshGeometry& geo, const CheckOptions& opt, const CellScales& sc) {
  CheckResult r;
  r.name = "volume";
  r.values.assign(m.n_cells(), 0.0);
  r.failing.assign(m.n_cells(), 0);
  double min_vol = std::numeric_limits<double>::infinity(), total = 0;
  for (int c = 0; c < m.n_cells(); ++c) {
    const double L = sc.length[c], v = geo.cell_volume[c];
    r.values[c] = L > 0 ? v / (L * L * L) : 0.0;
    if (std::isnan(r.values[c])) r.values[c] = -1.0;
    if (!(r.values[c] > opt.volume_rel_tol)) ++r.violations, r.failing[c] = 1;
    min_vol = std::min(min_vol, v);
    total += v;
  }
  rank_worst(r, false);
  r.measures = {{"min_volume", std::isfinite(min_vol) ? min_vol : 0.0},
                {"total_volume", total},
                {"rel_tol", opt.volume_rel_tol}};
  return r;
}

CheckResult check_orthogonality(const PolyMesh& m, const MeshGeometry& geo, const CheckOptions& opt) {
  CheckResult r;
  r.name = "orthogonality";
  r.id_kind = IdKind::Face;
  const bool k_metric = !(m.metric_scale == Vec3{1, 1, 1});
  if (k_metric) {
    r.values = face_frame_nonorthogonality(m, geo);
    for (double& v : r.values) v = 90.0 - v;
  } else {
    r.values = face_orthogonality(m, geo);
  }
  std::vector<char> cell_bad(m.n_cells(), 0);
  r.failing.assign(m.n_faces(), 0);
  for (int f = 0; f < m.n_faces(); ++f)
    if (!(r.values[f] >= opt.min_orthogonality_deg)) {
      ++r.violations, r.failing[f] = 1;
      cell_bad[m.face_owner[f]] = 1;
      if (m.face_neighbour[f] >= 0) cell_bad[m.face_neighbour[f]] = 1;
    }
  rank_worst(r, false, 90.0);
  r.counts = {{"cells_with_violations", std::count(cell_bad.begin(), cell_bad.end(), 1)}};
  r.measures = {{"min_deg", r.worst}, {"threshold_deg", opt.min_orthogonality_deg}, {"k_metric", k_metric ? 1.0 : 0.0}};
  // For information (docs/fvcheck.md, "Boundary faces"): boundary faces measured from the FV
  // centre to the face centroid, the paper's literal eq. 8, which is not the pair the flux uses.
  if (!k_metric) {
    double worst = 90.0;
    int64_t below = 0;
    for (int f = 0; f < m.n_faces(); ++f) {
      if (m.face_neighbour[f] >= 0) continue;
      const double at_centroid = face_orthogonality_of(m, geo, f, geo.face_centroid[f]);
      worst = std::min(worst, at_centroid);
      below += !(at_centroid >= opt.min_orthogonality_deg);
    }
    r.measures.push_back({"boundary_centroid_min_deg", worst});
    r.counts.push_back({"boundary_faces_below_threshold_at_centroid", below});
  }
  return r;
}

CheckResult check_auto_centering(const PolyMesh& m, const MeshGeometry& geo, const CheckOptions& opt) {
  return check_auto_centering(m, geo, opt, compute_cell_scales(m, opt.rel_tol));
}

CheckResult check_auto_centering(const PolyMesh& m, const MeshGeometry& geo, const CheckOptions& opt,
                                 const CellScales& sc) {
  CheckResult r;
  r.name = "auto_centering";
  r.values.assign(m.n_cells(), 0.0);
  r.failing.assign(m.n_cells(), 0);
  parallel_ranges(m.n_cells(), [&](int64_t b, int64_t e) {
    for (int c = static_cast<int>(b); c < e; ++c) {
      const Vec3 x = m.cell_fv_center[c];
      double worst = -std::numeric_limits<double>::infinity();
      for (const int32_t* fp = m.cell_begin(c); fp != m.cell_end(c); ++fp) {
        const Vec3 a = m.face_sign(*fp, c) * geo.face_area[*fp];
        const double an = norm(a);
        if (!(an > 0)) continue;
        worst = std::max(worst, dot(x - geo.face_centroid[*fp], a / an));
      }
      const double L = sc.length[c];
      double value = L > 0 ? worst / L : 1.0;
      if (std::isnan(value) || !std::isfinite(worst)) value = 1.0;  // no usable face or a NaN centre
      r.values[c] = value;
      r.failing[c] = !(worst < -sc.tol[c]) || !std::isfinite(worst);
    }
  });
  r.violations = std::count(r.failing.begin(), r.failing.end(), 1);
  rank_worst(r, true);
  r.measures = {{"rel_tol", opt.rel_tol}};
  return r;
}

CheckResult check_planarity(const PolyMesh& m, const MeshGeometry& geo, const CheckOptions& opt) {
  CheckResult r;
  r.name = "planarity";
  r.id_kind = IdKind::Face;
  r.values = face_planarity(m, geo);
  std::vector<char> cell_bad(m.n_cells(), 0);
  r.failing.assign(m.n_faces(), 0);
  for (int f = 0; f < m.n_faces(); ++f)
    if (!(r.values[f] <= opt.max_planarity_deg)) {
      ++r.violations, r.failing[f] = 1;
      cell_bad[m.face_owner[f]] = 1;
      if (m.face_neighbour[f] >= 0) cell_bad[m.face_neighbour[f]] = 1;
    }
  rank_worst(r, true);
  r.counts = {{"cells_with_violations", std::count(cell_bad.begin(), cell_bad.end(), 1)}};
  r.measures = {{"max_deg", r.worst}, {"threshold_deg", opt.max_planarity_deg}};
  return r;
}


std::vector<CheckResult> check_shapes(const PolyMesh& mesh, const MeshGeometry& geo, const CheckOptions& opt,
                                      const CellScales* scales, int64_t* exempt_cells) {
  std::vector<char> ours(mesh.n_cells(), 1);
  if (mesh.reservoir_cells_are_model)
    for (int c = 0; c < mesh.n_cells(); ++c) ours[c] = mesh.cell_region[c] != kReservoir;
  const int64_t exempt = std::count(ours.begin(), ours.end(), 0);
  if (exempt_cells) *exempt_cells = exempt;
  auto run = [&](const PolyMesh& m, const MeshGeometry& g, const CellScales& sc) {
    return std::vector<CheckResult>{check_convexity(m, g, opt), check_orthogonality(m, g, opt),
                                    check_auto_centering(m, g, opt, sc), check_planarity(m, g, opt)};
  };
  if (exempt == 0) return run(mesh, geo, scales ? *scales : compute_cell_scales(mesh, opt.rel_tol));
  if (exempt == mesh.n_cells()) {  // only the model's cells: nothing of ours to judge
    std::vector<CheckResult> out(4);
    const char* names[] = {"convexity", "orthogonality", "auto_centering", "planarity"};
    for (int i = 0; i < 4; ++i) out[i].name = names[i];
    return out;
  }
  std::vector<int32_t> cell_of;
  const PolyMesh sub = cells_as_mesh(mesh, ours, &cell_of);
  const MeshGeometry sub_geo = compute_geometry(sub);
  std::vector<CheckResult> out = run(sub, sub_geo, compute_cell_scales(sub, opt.rel_tol));
  for (CheckResult& r : out) {  // ids of the kept cells' mesh -> cells of the whole mesh
    for (int32_t& id : r.worst_ids) id = cell_of[r.id_kind == IdKind::Face ? sub.face_owner[id] : id];
    r.id_kind = IdKind::Cell;
    r.values.clear();
    r.failing.clear();
  }
  return out;
}

}  // namespace hm
