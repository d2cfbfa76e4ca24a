#include "gabriel.hpp"

#include <algorithm>

#include "gabriel_predicates.hpp"

namespace hm {

namespace {

// Static, implicit k-d tree over point ids: the sub-range [lo, hi) splits at its median
// mid = (lo + hi) / 2 along axis[mid]; [lo, mid) lies below, (mid, hi) above.
struct KdTree {
  const std::vector<Vec3>* nodes = nullptr;
  std::vector<int32_t> ids;
  std::vector<int8_t> axis;

  void build(int lo, int hi) {
    if (hi - lo <= 1) return;
    Vec3 mn = (*nodes)[ids[lo]], mx = mn;
    for (int i = lo + 1; i < hi; ++i) {
      const Vec3 p = (*nodes)[ids[i]];
      for (int k = 0; k < 3; ++k) {
        mn[k] = std::min(mn[k], p[k]);
        mx[k] = std::max(mx[k], p[k]);
      }
    }
    int ax = 0;
    for (int k = 1; k < 3; ++k)
      if (mx[k] - mn[k] > mx[ax] - mn[ax]) ax = k;
    const int mid = (lo + hi) / 2;
    std::nth_element(ids.begin() + lo, ids.begin() + mid, ids.begin() + hi,
                     [&](int32_t a, int32_t b) { return (*nodes)[a][ax] < (*nodes)[b][ax]; });
    axis[mid] = static_cast<int8_t>(ax);
    build(lo, mid);
    build(mid + 1, hi);
  }

  // Calls visit(id) for every point with |p - c|^2 <= r2 (a superset filter; the caller
  // decides exactly).
  template <class Visit>
  void query(int lo, int hi, Vec3 c, double r2, Visit& visit) const {
    if (hi <= lo) return;
    const int mid = (lo + hi) / 2;
    const Vec3 p = (*nodes)[ids[mid]];
    if (norm2(p - c) <= r2) visit(ids[mid]);
    if (hi - lo == 1) return;
    const int ax = axis[mid];
    const double diff = c[ax] - p[ax];
    if (diff <= 0 || diff * diff <= r2) query(lo, mid, c, r2, visit);
    if (diff >= 0 || diff * diff <= r2) query(mid + 1, hi, c, r2, visit);
  }
};

KdTree make_tree(const std::vector<Vec3>& nodes, const std::vector<int32_t>& points) {
  KdTree tree;
  tree.nodes = &nodes;
  tree.ids = points;
  std::sort(tree.ids.begin(), tree.ids.end());
  tree.ids.erase(std::unique(tree.ids.begin(), tree.ids.end()), tree.ids.end());
  tree.axis.assign(tree.ids.size(), 0);
  tree.build(0, static_cast<int>(tree.ids.size()));
  return tree;
}

// Floating filter radius, widened by a margin far above the rounding of |p - c|^2 so that
// no point the exact predicate puts inside is missed; the predicate then decides.
double filter_radius2(Vec3 c, double r2) { return r2 * (1 + 1e-9) + 1e-12 * (norm2(c) + r2) + 1e-300; }

}  // namespace

std::vector<GabrielViolation> gabriel_violations(const std::vector<Vec3>& nodes,
                                                 const std::vector<std::array<int32_t, 2>>& edges,
                                                 const std::vector<int32_t>& points) {
  const KdTree tree = make_tree(nodes, points);
  const int n = static_cast<int>(tree.ids.size());

  std::vector<GabrielViolation> out;
  for (const auto& e : edges) {
    const int32_t a = std::min(e[0], e[1]), b = std::max(e[0], e[1]);
    const Vec3 pa = nodes[a], pb = nodes[b];
    const Vec3 c = 0.5 * (pa + pb);
    const double r2_filter = filter_radius2(c, 0.25 * norm2(pb - pa));
    auto visit = [&](int32_t p) {
      if (p == a || p == b) return;
      if (strictly_inside_diametral_sphere(pa, pb, nodes[p])) out.push_back({a, b, p});
    };
    tree.query(0, n, c, r2_filter, visit);
  }
  std::sort(out.begin(), out.end(), [](const GabrielViolation& x, const GabrielViolation& y) {
    return x.a != y.a ? x.a < y.a : (x.b != y.b ? x.b < y.b : x.p < y.p);
  });
  return out;
}

std::vector<GabrielViolation> gabriel_violations(const std::vector<Vec3>& nodes,
                                                 const std::vector<std::vector<int32_t>>& polygons) {
  std::vector<std::array<int32_t, 2>> edges;
  std::vector<int32_t> points;
  for (const auto& poly : polygons) {
    const size_t m = poly.size();
    for (size_t i = 0; i < m; ++i) {
      const int32_t a = poly[i], b = poly[(i + 1) % m];
      edges.push_back({std::min(a, b), std::max(a, b)});
      points.push_back(a);
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return gabriel_violations(nodes, edges, points);
}

std::vector<FaceGabrielViolation> face_gabriel_violations(const std::vector<Vec3>& nodes,
                                                          const std::vector<std::vector<int32_t>>& polygons,
                                                          const std::vector<int32_t>& points) {
  const KdTree tree = make_tree(nodes, points);
  const int n = static_cast<int>(tree.ids.size());
  std::vector<FaceGabrielViolation> out;
  for (size_t k = 0; k < polygons.size(); ++k) {
    const auto& poly = polygons[k];
    std::vector<int32_t> hits;
    for (size_t i = 1; i + 1 < poly.size(); ++i) {
      const Vec3 a = nodes[poly[0]], b = nodes[poly[i]], c = nodes[poly[i + 1]];
      // Circumcentre of the triangle (centre of its smallest sphere), for the filter only.
      const Vec3 ab = b - a, ac = c - a, w = cross(ab, ac);
      const double w2 = norm2(w);
      if (w2 == 0) continue;  // collinear: no circle (a degenerate polygon is caught elsewhere)
      const Vec3 centre = a + (norm2(ac) * cross(w, ab) + norm2(ab) * cross(ac, w)) / (2 * w2);
      auto visit = [&](int32_t p) {
        if (std::find(poly.begin(), poly.end(), p) != poly.end()) return;
        if (strictly_inside_diametral_sphere(a, b, c, nodes[p])) hits.push_back(p);
      };
      tree.query(0, n, centre, filter_radius2(centre, norm2(centre - a)), visit);
    }
    std::sort(hits.begin(), hits.end());
    hits.erase(std::unique(hits.begin(), hits.end()), hits.end());
    for (int32_t p : hits) out.push_back({static_cast<int32_t>(k), p});
  }
  return out;
}

}  // namespace hm
