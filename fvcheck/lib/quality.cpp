#include "quality.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace hm {

namespace {
constexpr double kDeg = 180.0 / M_PI;

double clamp_unit(double x) { return std::min(1.0, std::max(-1.0, x)); }

// Distinct undirected edges (a < b) of cell c.
void cell_edges(const PolyMesh& m, int c, std::vector<std::pair<int32_t, int32_t>>& edges) {
  edges.clear();
  for (const int32_t* fp = m.cell_begin(c); fp != m.cell_end(c); ++fp) {
    const int f = *fp, n = m.face_size(f);
    const int32_t* v = m.face_begin(f);
    for (int i = 0; i < n; ++i) {
      int32_t a = v[i], b = v[(i + 1) % n];
      if (a > b) std::swap(a, b);
      edges.emplace_back(a, b);
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
}
}  // namespace

std::vector<double> face_orthogonality(const PolyMesh& m, const MeshGeometry& geo) {
  std::vector<double> q(m.n_faces(), 0.0);
  for (int f = 0; f < m.n_faces(); ++f) {
    const double a = norm(geo.face_area[f]);
    const Vec3 p1 = m.cell_fv_center[m.face_owner[f]];
    const Vec3 p2 = m.face_neighbour[f] >= 0 ? m.cell_fv_center[m.face_neighbour[f]] : geo.face_centroid[f];
    const Vec3 d = p2 - p1;
    const double l = norm(d);
    if (!(a > 0) || !(l > 0)) continue;  // degenerate: Q_O = 0
    q[f] = std::asin(clamp_unit(std::fabs(dot(d, geo.face_area[f])) / (l * a))) * kDeg;
  }
  return q;
}

std::vector<double> face_planarity(const PolyMesh& m, const MeshGeometry& geo) {
  std::vector<double> q(m.n_faces(), 0.0);
  for (int f = 0; f < m.n_faces(); ++f) {
    const double a = norm(geo.face_area[f]);
    if (!(a > 0)) {
      q[f] = 90.0;
      continue;
    }
    const Vec3 n = geo.face_area[f] / a;
    const int k = m.face_size(f);
    const int32_t* v = m.face_begin(f);
    Vec3 g;
    for (int i = 0; i < k; ++i) g += m.nodes[v[i]];
    g = g / k;
    double worst = 0;
    for (int i = 0; i < k; ++i) {
      const Vec3 t = cross(m.nodes[v[i]] - g, m.nodes[v[(i + 1) % k]] - g);  // 2 * triangle area vector
      const double ta = norm(t);
      if (!(ta > 2e-12 * a)) continue;
      worst = std::max(worst, std::acos(clamp_unit(std::fabs(dot(n, t)) / ta)) * kDeg);
    }
    q[f] = worst;
  }
  return q;
}

std::vector<double> cell_min_of_faces(const PolyMesh& m, const std::vector<double>& fv) {
  std::vector<double> out(m.n_cells(), 0.0);
  for (int c = 0; c < m.n_cells(); ++c) {
    double v = std::numeric_limits<double>::infinity();
    for (const int32_t* f = m.cell_begin(c); f != m.cell_end(c); ++f) v = std::min(v, fv[*f]);
    out[c] = std::isfinite(v) ? v : 0.0;
  }
  return out;
}

std::vector<double> cell_max_of_faces(const PolyMesh& m, const std::vector<double>& fv) {
  std::vector<double> out(m.n_cells(), 0.0);
  for (int c = 0; c < m.n_cells(); ++c) {
    double v = 0;
    for (const int32_t* f = m.cell_begin(c); f != m.cell_end(c); ++f) v = std::max(v, fv[*f]);
    out[c] = v;
  }
  return out;
}

std::vector<double> cell_mean_edge_length(const PolyMesh& m) {
  std::vector<double> out(m.n_cells(), 0.0);
  std::vector<std::pair<int32_t, int32_t>> edges;
  for (int c = 0; c < m.n_cells(); ++c) {
    cell_edges(m, c, edges);
    double s = 0;
    for (auto [a, b] : edges) s += norm(m.nodes[b] - m.nodes[a]);
    out[c] = edges.empty() ? 0.0 : s / static_cast<double>(edges.size());
  }
  return out;
}

std::vector<double> cell_shape_quality(const PolyMesh& m, const std::vector<double>& h_ref) {
  std::vector<double> out(m.n_cells(), 0.0);
  const bool use_ref = h_ref.size() == static_cast<size_t>(m.n_cells());
  std::vector<std::pair<int32_t, int32_t>> edges;
  for (int c = 0; c < m.n_cells(); ++c) {
    cell_edges(m, c, edges);
    if (edges.empty()) continue;
    double h = use_ref ? h_ref[c] : 0.0;
    if (!(h > 0) || !std::isfinite(h)) {
      h = 0;
      for (auto [a, b] : edges) h += norm(m.nodes[b] - m.nodes[a]);
      h /= static_cast<double>(edges.size());
    }
    if (!(h > 0)) continue;  // every edge has zero length
    double q = 1.0;
    for (auto [a, b] : edges) {
      const double l = norm(m.nodes[b] - m.nodes[a]);
      q = std::min(q, l > 0 ? std::min(l / h, h / l) : 0.0);
    }
    out[c] = q;
  }
  return out;
}

Stats stats_of(const std::vector<double>& values, const std::vector<bool>& mask) {
  Stats s;
  double sum = 0;
  s.min = std::numeric_limits<double>::infinity();
  s.max = -std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < values.size(); ++i) {
    if (!mask.empty() && (i >= mask.size() || !mask[i])) continue;
    const double v = values[i];
    if (std::isnan(v)) continue;
    ++s.count;
    sum += v;
    s.min = std::min(s.min, v);
    s.max = std::max(s.max, v);
  }
  if (s.count == 0) return Stats{};
  s.mean = sum / static_cast<double>(s.count);
  return s;
}

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
                                             const std::vector<double>& q_p_cell) {
  // One pass with running sums: region codes read from a file may be arbitrary, so no
  // per-region masks of n_cells entries.
  struct Acc {
    int64_t cells = 0;
    Stats s[3];
    double sum[3] = {0, 0, 0};
  };
  std::map<int32_t, Acc> acc;
  const std::vector<double>* q[3] = {&q_s, &q_o_cell, &q_p_cell};
  for (int c = 0; c < m.n_cells(); ++c) {
    Acc& a = acc[m.cell_region[c]];
    ++a.cells;
    for (int k = 0; k < 3; ++k) {
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
    for (int k = 0; k < 3; ++k)
      if (a.s[k].count > 0) a.s[k].mean = a.sum[k] / static_cast<double>(a.s[k].count);
    RegionQuality rq;
    rq.region = r;
    rq.name = region_name(r);
    rq.cells = a.cells;
    rq.q_s = a.s[0];
    rq.q_o = a.s[1];
    rq.q_p = a.s[2];
    out.push_back(rq);
  }
  return out;
}

}  // namespace hm
