#include "corner_point_path.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "meshgen/core/geometry.hpp"
#include "segment_distance.hpp"

namespace hm {

namespace {

constexpr double kPi = 3.14159265358979323846;

// The 6 faces of a cell as corner quads, all oriented alike (corner bit 0 +i, bit 1 +j, bit 2 +k).
constexpr int kFaces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};

std::string metres(double x) {
  std::ostringstream os;
  os << std::setprecision(4) << x << " m";
  return os.str();
}

// A polyline parametrised by its length.
class Polyline {
 public:
  explicit Polyline(const std::vector<Vec3>& p) : p_(p), arc_(p.size(), 0.0) {
    for (size_t i = 1; i < p.size(); ++i) arc_[i] = arc_[i - 1] + norm(p[i] - p[i - 1]);
  }
  double length() const { return arc_.back(); }
  const std::vector<double>& arc() const { return arc_; }
  // The leg holding length s (the last leg for s at or beyond the end).
  size_t leg(double s) const {
    const size_t k = static_cast<size_t>(std::upper_bound(arc_.begin(), arc_.end(), s) - arc_.begin());
    return std::min(k == 0 ? 0 : k - 1, p_.size() - 2);
  }
  Vec3 at(double s) const {
    const size_t k = leg(s);
    const double t = (s - arc_[k]) / (arc_[k + 1] - arc_[k]);
    return p_[k] + t * (p_[k + 1] - p_[k]);
  }
  Vec3 direction(double s) const {
    const size_t k = leg(s);
    return normalized(p_[k + 1] - p_[k]);
  }
  double interpolate(const std::vector<double>& v, double s) const {
    const size_t k = leg(s);
    const double t = (s - arc_[k]) / (arc_[k + 1] - arc_[k]);
    return v[k] + t * (v[k + 1] - v[k]);
  }

 private:
  const std::vector<Vec3>& p_;
  std::vector<double> arc_;
};

}  // namespace

CornerPointInterior::CornerPointInterior(const CornerPointModel& m, Vec3 lo, Vec3 hi) {
  for (size_t c = 0; c < m.n_cells(); ++c) {
    if (!m.actnum[c]) continue;
    const std::array<Vec3, 8> corners = cell_corners(m, c);
    Cell cell{corners[0], corners[0], corners};
    for (const Vec3& p : corners)
      for (int k = 0; k < 3; ++k) cell.lo[k] = std::min(cell.lo[k], p[k]), cell.hi[k] = std::max(cell.hi[k], p[k]);
    bool meets = true;
    for (int k = 0; k < 3; ++k) meets = meets && cell.lo[k] <= hi[k] && cell.hi[k] >= lo[k];
    if (meets && cell.hi.z > cell.lo.z) cells_.push_back(cell);
  }
  const double scale = std::max({1.0, hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  nudge_ = kFaceNudge * scale * normalized(Vec3{0.5772156649, 0.3183098862, -1.0});
  if (cells_.empty()) return;
  // Buckets of the cells' median extent per axis (thin layers: flat buckets), at most about 4 per cell.
  origin_ = cells_[0].lo;
  Vec3 top = cells_[0].hi;
  for (const Cell& c : cells_)
    for (int k = 0; k < 3; ++k) origin_[k] = std::min(origin_[k], c.lo[k]), top[k] = std::max(top[k], c.hi[k]);
  for (int k = 0; k < 3; ++k) {
    std::vector<double> extent;
    for (const Cell& c : cells_) extent.push_back(c.hi[k] - c.lo[k]);
    std::nth_element(extent.begin(), extent.begin() + extent.size() / 2, extent.end());
    bucket_size_[k] = std::max(extent[extent.size() / 2], 1e-9 * std::max(1.0, top[k] - origin_[k]));
  }
  const double limit = 4.0 * static_cast<double>(cells_.size()) + 64;
  for (;;) {
    double count = 1;
    for (int k = 0; k < 3; ++k) count *= std::floor((top[k] - origin_[k]) / bucket_size_[k]) + 1;
    if (count <= limit) break;
    bucket_size_ = 2.0 * bucket_size_;
  }
  for (int k = 0; k < 3; ++k) buckets_[k] = static_cast<int>(std::floor((top[k] - origin_[k]) / bucket_size_[k])) + 1;
  const size_t n_buckets = size_t(buckets_[0]) * buckets_[1] * buckets_[2];
  bucket_begin_.assign(n_buckets + 1, 0);
  auto for_each_bucket = [&](const Cell& c, auto visit) {
    const std::array<int, 3> a = bucket_index(c.lo), b = bucket_index(c.hi);
    for (int z = a[2]; z <= b[2]; ++z)
      for (int y = a[1]; y <= b[1]; ++y)
        for (int x = a[0]; x <= b[0]; ++x) visit(x + buckets_[0] * (y + size_t(buckets_[1]) * z));
  };
  for (const Cell& c : cells_) for_each_bucket(c, [&](size_t b) { ++bucket_begin_[b + 1]; });
  for (size_t b = 0; b < n_buckets; ++b) bucket_begin_[b + 1] += bucket_begin_[b];
  bucket_cells_.resize(bucket_begin_.back());
  std::vector<int32_t> fill(bucket_begin_.begin(), bucket_begin_.end() - 1);
  for (size_t c = 0; c < cells_.size(); ++c)
    for_each_bucket(cells_[c], [&](size_t b) { bucket_cells_[fill[b]++] = static_cast<int32_t>(c); });
}

std::array<int, 3> CornerPointInterior::bucket_index(Vec3 p) const {
  std::array<int, 3> i{};
  for (int k = 0; k < 3; ++k)
    i[k] = static_cast<int>(std::clamp(std::floor((p[k] - origin_[k]) / bucket_size_[k]), -1.0, double(buckets_[k])));
  return i;
}

bool CornerPointInterior::contains(Vec3 q) const {
  // A point on a face (a path's end given on a layer boundary) is moved off it, up and sideways by
  // kFaceNudge of the region's extent in a direction no face has (symbolic perturbation): on a face
  // between two cells it is then inside one of them, on the model's top outside it.
  const Vec3 p = q + nudge_;
  if (cells_.empty()) return false;
  const std::array<int, 3> at = bucket_index(p);
  for (int k = 0; k < 3; ++k)
    if (at[k] < 0 || at[k] >= buckets_[k]) return false;  // beyond every cell's box
  const size_t bucket = at[0] + buckets_[0] * (at[1] + size_t(buckets_[1]) * at[2]);
  for (int32_t i = bucket_begin_[bucket]; i < bucket_begin_[bucket + 1]; ++i) {
    const Cell& c = cells_[bucket_cells_[i]];
    bool in_box = true;
    for (int k = 0; k < 3; ++k) in_box = in_box && p[k] >= c.lo[k] && p[k] <= c.hi[k];
    if (!in_box) continue;
    double w = 0;
    for (const auto& f : kFaces) {
      const Vec3 a = c.corners[f[0]] - p, b = c.corners[f[1]] - p, q = c.corners[f[2]] - p, d = c.corners[f[3]] - p;
      w += triangle_solid_angle(a, b, q) + triangle_solid_angle(a, q, d);
    }
    if (std::abs(w) > 2.0 * kPi) return true;  // winding number 1 (4 pi), not 0
  }
  return false;
}

double surface_gap(const CornerPointModel& m, Vec3 at, const WellSpec& ws) {
  const double R = ws.drainage_radius, reach = R + kSurfaceGap * R;
  // The block's outer end-face polygon: from the last ring's inner radius to R over one sector.
  const double r_in = ring_radii(ws)[ws.rings - 1], arc = 2 * kPi / std::max(3, ws.sectors);
  const Vec3 outer_far{R * std::cos(arc), R * std::sin(arc), 0}, inner_near{r_in, 0, 0};
  auto active = [&](int i, int j, int k) {
    return i >= 0 && j >= 0 && k >= 0 && i < m.nx && j < m.ny && k < m.nz && m.actnum[i + m.nx * (j + m.ny * k)];
  };
  // kFaces in the order -i, +i, -j, +j, -k, +k: the logical neighbour across each.
  constexpr int kStep[6][3] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
  double longest = 0;
  for (int c = 0; c < static_cast<int>(m.n_cells()); ++c) {
    if (!m.actnum[c]) continue;
    const int i = c % m.nx, j = c / m.nx % m.ny, k = c / (m.nx * m.ny);
    for (int f = 0; f < 6; ++f) {
      if (active(i + kStep[f][0], j + kStep[f][1], k + kStep[f][2])) continue;
      std::array<Vec3, 4> q;
      bool near = false;
      for (int v = 0; v < 4; ++v) q[v] = corner(m, size_t(c), kFaces[f][v]), near = near || norm(q[v] - at) <= reach;
      if (!near) continue;
      for (int v = 0; v < 4; ++v) longest = std::max(longest, norm(q[(v + 1) % 4] - q[v]));
      longest = std::max({longest, norm(q[2] - q[0]), norm(q[3] - q[1])});
    }
  }
  longest = std::max(longest, norm(outer_far - inner_near));
  return std::clamp(kSurfaceGapMargin * 0.5 * longest, kSurfaceGapMin * R, kSurfaceGap * R);
}

double surface_clearance(const CornerPointModel& m, const WellSpec& ws) {
  const double R = ws.drainage_radius, reach = 2 * R;
  const std::vector<Vec3>& path = ws.trajectory;
  Vec3 lo = path.front(), hi = lo;
  for (const Vec3& p : path)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k] - reach), hi[k] = std::max(hi[k], p[k] + reach);
  auto index = [&](int i, int j, int k) { return i + m.nx * (j + m.ny * k); };
  auto inside = [&](int i, int j, int k) { return i >= 0 && j >= 0 && k >= 0 && i < m.nx && j < m.ny && k < m.nz; };
  auto thick = [&](int c) {
    for (int q = 0; q < 4; ++q)
      if (corner_depth(m, c, q) != corner_depth(m, c, q + 4)) return true;
    return false;
  };
  auto meshed = [&](int i, int j, int k) { return inside(i, j, k) && m.actnum[index(i, j, k)] && thick(index(i, j, k)); };
  // Across a top or bottom face, layers of zero thickness are stepped over: the cell beyond touches it.
  auto meshed_across = [&](int i, int j, int k, int f) {
    static constexpr int kStep[6][3] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
    i += kStep[f][0], j += kStep[f][1], k += kStep[f][2];
    if (f >= 4)
      while (inside(i, j, k) && m.actnum[index(i, j, k)] && !thick(index(i, j, k))) k += kStep[f][2];
    return meshed(i, j, k);
  };
  // Nodes beyond the end planes face the block's ends, whose faces clip_path_to_model sizes.
  const size_t n = path.size();
  auto beyond_ends = [&](Vec3 q) {
    return dot(q - path[0], path[1] - path[0]) < 0 || dot(q - path[n - 1], path[n - 1] - path[n - 2]) > 0;
  };
  // A column whose plan box (its pillars are straight, from its top cell's top to its bottom cell's
  // bottom) lies farther than the reach from the path in plan holds no node near it.
  std::vector<Vec3> plan_path;
  for (const Vec3& p : path) plan_path.push_back({p.x, p.y, 0});
  auto column_near = [&](int i, int j) {
    const std::array<Vec3, 8> top = cell_corners(m, size_t(index(i, j, 0)));
    const std::array<Vec3, 8> bottom = cell_corners(m, size_t(index(i, j, m.nz - 1)));
    Vec3 a{top[0].x, top[0].y, 0}, b = a;
    for (int q = 0; q < 8; ++q)
      for (const Vec3& p : {top[q], bottom[q]})
        a = {std::min(a.x, p.x), std::min(a.y, p.y), 0}, b = {std::max(b.x, p.x), std::max(b.y, p.y), 0};
    return polyline_distance({0.5 * (a + b)}, plan_path, reach + 0.5 * norm(b - a)) <= reach + 0.5 * norm(b - a);
  };
  std::vector<char> column(size_t(m.nx) * m.ny);
  for (int j = 0; j < m.ny; ++j)
    for (int i = 0; i < m.nx; ++i) column[i + size_t(m.nx) * j] = column_near(i, j);
  double nearest = INFINITY;
  for (int c = 0; c < static_cast<int>(m.n_cells()); ++c) {
    if (!m.actnum[c] || !column[c % (m.nx * m.ny)]) continue;
    const std::array<Vec3, 8> corners = cell_corners(m, size_t(c));
    bool near = true;
    for (int k = 0; k < 3 && near; ++k) {
      double a = corners[0][k], b = a;
      for (const Vec3& p : corners) a = std::min(a, p[k]), b = std::max(b, p[k]);
      near = b >= lo[k] && a <= hi[k];
    }
    if (!near || !thick(c)) continue;
    const int i = c % m.nx, j = c / m.nx % m.ny, k = c / (m.nx * m.ny);
    for (int f = 0; f < 6; ++f) {
      if (meshed_across(i, j, k, f)) continue;
      for (int v = 0; v < 4; ++v) {
        const Vec3 q = corners[kFaces[f][v]];
        if (!beyond_ends(q)) nearest = std::min(nearest, polyline_distance({q}, path, reach) - R);
      }
    }
  }
  return nearest;
}

OuterFaceFit fit_outer_faces(const WellSpec& ws, double clearance) {
  const double allowed = clearance / kSurfaceGapMargin, R = ws.drainage_radius;
  auto chord = [R](int n) { return 2 * R * std::sin(kPi / n); };
  OuterFaceFit fit{ws.sectors, ws.segment_length, true};
  if (!(clearance > 0)) return fit.fits = false, fit;  // the surface reaches into the block: no face fits
  // A face's circumcentre lies R cos(pi / sectors) from the axis: its sphere reaches no node farther.
  const double sphere = 0.5 * std::hypot(chord(fit.sectors), fit.segment_length);
  if (R * std::cos(kPi / fit.sectors) + sphere <= R + clearance) return fit;
  while (chord(fit.sectors) > std::sqrt(2.0) * allowed && fit.sectors < 4 * ws.sectors)
    fit.sectors += fit.sectors % 2 == 0 ? 2 : 1;
  const double length2 = 4 * allowed * allowed - chord(fit.sectors) * chord(fit.sectors);
  fit.fits = length2 > 0;
  if (fit.fits) fit.segment_length = std::min(ws.segment_length, std::sqrt(length2));
  return fit;
}

ClippedPath clip_path_to_model(const CornerPointModel& m, const WellSpec& ws, const std::string& key,
                               SurfaceGapRule rule) {
  const std::string tkey = key + ".trajectory";
  const Polyline path(ws.trajectory);
  const std::vector<double> md = well_measured_depths(ws);
  const double R = ws.drainage_radius, gap = kSurfaceGap * R, L = path.length();
  Vec3 lo = ws.trajectory.front(), hi = lo;
  for (const Vec3& p : ws.trajectory)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  const double reach = R + 2.0 * gap;
  const CornerPointInterior interior(m, lo - Vec3{reach, reach, reach}, hi + Vec3{reach, reach, reach});

  // 1. Samples every R / 8 along the path: one connected run inside the model.
  const int n = static_cast<int>(std::ceil(L / (R / 8.0))) + 1;
  auto s_of = [&](int k) { return k == n - 1 ? L : L * k / (n - 1); };
  std::vector<char> inside(n);
  for (int k = 0; k < n; ++k) inside[k] = interior.contains(path.at(s_of(k)));
  const auto first_it = std::find(inside.begin(), inside.end(), 1);
  if (first_it == inside.end())
    throw InputError(tkey + ": no part of it lies inside the corner-point model's active cells");
  const int first = static_cast<int>(first_it - inside.begin());
  const int last = n - 1 - static_cast<int>(std::find(inside.rbegin(), inside.rend(), 1) - inside.rbegin());
  for (int k = first; k <= last; ++k)
    if (!inside[k])
      throw InputError(tkey + ": leaves the corner-point model's active cells and comes back (at measured depth " +
                       metres(path.interpolate(md, s_of(k))) + "); only one connected part inside can be meshed");
  ClippedPath out;

  // 2. The crossings (bisection between the samples on either side), then each crossing end moved
  //    inward until the block's end cross-section and the gap beyond it are inside.
  auto crossing = [&](double s_out, double s_in) {
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (s_out + s_in);
      (interior.contains(path.at(mid)) ? s_in : s_out) = mid;
    }
    return s_in;
  };
  // The end cross-section (its centre and 16 points of its rim) with the gap around it in 26
  // directions (the cube's faces, edges and corners) inside the model.
  std::vector<Vec3> around;
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j)
      for (int k = -1; k <= 1; ++k)
        if (i || j || k) around.push_back(normalized(Vec3{double(i), double(j), double(k)}));
  auto end_clear = [&](double s, double g) {
    const Vec3 p = path.at(s), d = path.direction(s);
    const Vec3 helper = std::abs(d.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    const Vec3 u = normalized(cross(d, helper)), v = cross(d, u);
    for (int k = -1; k < 16; ++k) {
      const Vec3 q = k < 0 ? p : p + R * (std::cos(2 * kPi * k / 16) * u + std::sin(2 * kPi * k / 16) * v);
      for (const Vec3& e : around)
        if (!interior.contains(q + g * e)) return false;
    }
    return true;
  };
  double a = first > 0 ? crossing(s_of(first - 1), s_of(first)) : 0.0;
  double b = last < n - 1 ? crossing(s_of(last + 1), s_of(last)) : L;
  const double step = R / 16.0;
  const double a0 = a, b0 = b;
  auto gap_at = [&](double s) {
    return rule == SurfaceGapRule::SurfaceFaces ? surface_gap(m, path.at(s), ws)
           : rule == SurfaceGapRule::Least      ? kSurfaceGapMin * R
                                                : gap;
  };
  // An end inside the model keeps the same gap as a crossing end: a path that ends near the model's
  // surface is moved back as one that crosses it.
  out.gap[0] = gap_at(a);
  if (first > 0 || !end_clear(a, out.gap[0]))
    while (a < b && !end_clear(a, out.gap[0])) a += step;
  else
    out.gap[0] = 0;
  out.gap[1] = gap_at(b);
  if (last < n - 1 || !end_clear(b, out.gap[1]))
    while (b > a && !end_clear(b, out.gap[1])) b -= step;
  else
    out.gap[1] = 0;
  out.crosses = {first > 0, last < n - 1};
  if (a == 0 && b == L) {
    out.points = ws.trajectory;
    out.md = md;
    return out;
  }
  if (!(b - a > std::min(ws.segment_length, R)))
    throw InputError(tkey + ": only " + metres(std::max(0.0, b - a)) + " of its " + metres(b0 - a0) +
                     " inside the corner-point model's active cells keep " + metres(std::max(out.gap[0], out.gap[1])) +
                     " (" + std::to_string(std::max(out.gap[0], out.gap[1]) / R).substr(0, 4) +
                     " x drainage_radius) from the model's surface with the whole end cross-section of the radial "
                     "block; a well must run farther into the model, or take a smaller drainage_radius "
                     "(docs/corner-point.md)");

  out.points.push_back(path.at(a));
  out.md.push_back(path.interpolate(md, a));
  for (size_t i = 0; i < ws.trajectory.size(); ++i)
    if (path.arc()[i] > a && path.arc()[i] < b) out.points.push_back(ws.trajectory[i]), out.md.push_back(md[i]);
  out.points.push_back(path.at(b));
  out.md.push_back(path.interpolate(md, b));
  out.cut = {a, L - b};
  return out;
}

}  // namespace hm
