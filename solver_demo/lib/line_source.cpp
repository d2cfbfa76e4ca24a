#include "line_source.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "meshgen/pipeline/permeability_frame.hpp"

namespace hm {

namespace {
constexpr double kPi = 3.14159265358979323846;

// r - s for r = sqrt(s^2 + d2), without cancellation when s > 0.
double r_minus_s(double s, double d2) {
  const double r = std::sqrt(s * s + d2);
  return s > 0 ? d2 / (r + s) : r - s;
}
}  // namespace

double segment_potential(Vec3 x, Vec3 a, Vec3 b) {
  const Vec3 ab = b - a;
  const double len = norm(ab);
  const Vec3 u = ab / len;
  const Vec3 ax = x - a;
  const double s = dot(ax, u);               // axial coordinate from A
  const double d2 = std::max(0.0, norm2(ax - s * u));  // squared distance to the line
  // r_a + r_b - L = (r_a - s) + (r_b - (L - s)).
  const double gap = r_minus_s(s, d2) + r_minus_s(len - s, d2);
  if (!(gap > 0)) return std::numeric_limits<double>::infinity();
  const double ra = std::sqrt(s * s + d2), rb = std::sqrt((len - s) * (len - s) + d2);
  return std::log((ra + rb + len) / gap);
}

Vec3 segment_potential_gradient(Vec3 x, Vec3 a, Vec3 b) {
  const Vec3 ab = b - a;
  const double len = norm(ab);
  const Vec3 u = ab / len;
  const double s = dot(x - a, u);
  const double d2 = std::max(0.0, norm2(x - a - s * u));
  const double gap = r_minus_s(s, d2) + r_minus_s(len - s, d2);
  const double ra = std::sqrt(s * s + d2), rb = std::sqrt((len - s) * (len - s) + d2);
  // (r_a + r_b)^2 - L^2 = gap (r_a + r_b + L), without cancellation.
  const double factor = -2 * len / (gap * (ra + rb + len));
  return factor * ((x - a) / ra + (x - b) / rb);
}

Vec3 polyline_potential_gradient(Vec3 x, const std::vector<Vec3>& poly) {
  Vec3 g;
  for (size_t k = 0; k + 1 < poly.size(); ++k) g += segment_potential_gradient(x, poly[k], poly[k + 1]);
  return g;
}

double polyline_potential(Vec3 x, const std::vector<Vec3>& poly) {
  double phi = 0;
  for (size_t k = 0; k + 1 < poly.size(); ++k) phi += segment_potential(x, poly[k], poly[k + 1]);
  return phi;
}

PolylinePoint closest_on_polyline(Vec3 x, const std::vector<Vec3>& poly) {
  PolylinePoint best;
  best.distance = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k + 1 < poly.size(); ++k) {
    const Vec3 ab = poly[k + 1] - poly[k];
    const double t = std::clamp(dot(x - poly[k], ab) / norm2(ab), 0.0, 1.0);
    const Vec3 p = poly[k] + t * ab;
    const double d = norm(x - p);
    if (d < best.distance) best = {d, static_cast<int>(k), t, p};
  }
  return best;
}

Vec3 perpendicular_unit(Vec3 d) {
  const Vec3 u = normalized(d);
  if (std::fabs(u.z) > 0.9) return normalized(cross(u, Vec3{0, 1, 0}));  // near vertical: ~x
  return normalized(cross(u, Vec3{0, 0, 1}));
}

double equivalent_wellbore_radius(Vec3 s, Vec3 d, double r_w) {
  if (s.x == 1 && s.y == 1 && s.z == 1) return r_w;
  return equivalent_radius(s, normalized(d), r_w);
}

double LineSourceField::source_length() const {
  double len = 0;
  for (size_t k = 0; k + 1 < source.size(); ++k) len += norm(source[k + 1] - source[k]);
  return len;
}

double LineSourceField::scaled_source_length() const {
  double len = 0;
  for (size_t k = 0; k + 1 < scaled_source.size(); ++k) len += norm(scaled_source[k + 1] - scaled_source[k]);
  return len;
}

double LineSourceField::scaled_distance(Vec3 x) const {
  std::vector<Vec3> axis;
  for (Vec3 p : polyline) axis.push_back(to_scaled(p, scale));
  return closest_on_polyline(to_scaled(x, scale), axis).distance;
}

double LineSourceField::cap_mean_pressure(int end) const {
  const size_t n = polyline.size();
  const Vec3 w = wellbore_scale;
  const Vec3 e = to_scaled(end == 0 ? polyline[0] : polyline[n - 1], w);
  const Vec3 d = to_scaled(end == 0 ? polyline[1] - polyline[0] : polyline[n - 1] - polyline[n - 2], w);
  const Vec3 u = perpendicular_unit(d), v = normalized(cross(normalized(d), u));
  const double r = wellbore_radius;
  // rho = r s^2 (drho = 2 r s ds) smooths rho ln(rho) near the centre; midpoint rules in s and theta.
  const int ns = 64, nt = 32;
  double sum = 0, weight = 0;
  for (int i = 0; i < ns; ++i) {
    const double s = (i + 0.5) / ns, rho = r * s * s, wt = rho * 2 * r * s;
    for (int j = 0; j < nt; ++j) {
      const double th = 2 * kPi * (j + 0.5) / nt;
      sum += wt * pressure(from_scaled(e + rho * (std::cos(th) * u + std::sin(th) * v), w));
      weight += wt;
    }
  }
  return sum / weight;
}

double LineSourceField::wellbore_pressure(Vec3 x) const {
  const Vec3 w = wellbore_scale;
  std::vector<Vec3> axis;
  for (Vec3 p : polyline) axis.push_back(to_scaled(p, w));
  const Vec3 xw = to_scaled(x, w);
  const PolylinePoint cp = closest_on_polyline(xw, axis);
  const int last_leg = static_cast<int>(axis.size()) - 2;
  const double r = wellbore_radius;
  if (cp.distance <= 1e-9 * r) {
    if (cp.leg == 0 && cp.t == 0.0) return cap_mean_pressure(0);
    if (cp.leg == last_leg && cp.t == 1.0) return cap_mean_pressure(1);
    return pressure(from_scaled(cp.point + r * perpendicular_unit(axis[cp.leg + 1] - axis[cp.leg]), w));
  }
  return pressure(from_scaled(cp.point + (r / cp.distance) * (xw - cp.point), w));
}

double LineSourceField::equivalent_wellbore_pressure(Vec3 x) const {
  const PolylinePoint cp = closest_on_polyline(x, polyline);
  const Vec3 d = polyline[cp.leg + 1] - polyline[cp.leg];
  const Vec3 n = perpendicular_unit(to_scaled(d, scale));
  return pressure(from_scaled(to_scaled(cp.point, scale) + equivalent_wellbore_radius(scale, d, r_w) * n, scale));
}

FieldReference field_reference(const std::vector<Vec3>& poly) {
  FieldReference ref;
  double best = -1;
  for (size_t k = 0; k + 1 < poly.size(); ++k) {
    const double len = norm(poly[k + 1] - poly[k]);
    if (len > best) best = len, ref.leg = static_cast<int>(k);
  }
  ref.direction = normalized(poly[ref.leg + 1] - poly[ref.leg]);
  ref.mid = 0.5 * (poly[ref.leg] + poly[ref.leg + 1]);
  ref.normal = perpendicular_unit(ref.direction);
  return ref;
}

LineSourceField make_line_source_field(const std::vector<Vec3>& poly, double r_w, double p_w, double p_outer,
                                       double outer_distance, double inset, Vec3 scale, Vec3 inset_frame) {
  LineSourceField f;
  f.polyline = poly;
  f.source = poly;
  const size_t n = poly.size();
  // The end moved by `inset` along its leg, both measured in the inset's frame.
  auto inset_end = [&](Vec3 end, Vec3 inward) {
    return from_scaled(to_scaled(end, inset_frame) + inset * normalized(to_scaled(inward, inset_frame)), inset_frame);
  };
  f.source[0] = inset_end(poly[0], poly[1] - poly[0]);
  f.source[n - 1] = inset_end(poly[n - 1], poly[n - 2] - poly[n - 1]);
  f.r_w = r_w;
  f.scale = scale;
  for (Vec3 p : f.source) f.scaled_source.push_back(to_scaled(p, scale));
  f.wellbore_radius = r_w;
  const FieldReference ref = field_reference(poly);
  // The equivalent wellbore at the reference point (the physical circle r_w when isotropic).
  const Vec3 w = to_scaled(ref.mid, scale) + equivalent_wellbore_radius(scale, ref.direction, r_w) *
                                                 perpendicular_unit(to_scaled(ref.direction, scale));
  const double phi_w = polyline_potential(w, f.scaled_source);
  const double phi_o = polyline_potential(to_scaled(ref.mid + outer_distance * ref.normal, scale), f.scaled_source);
  // p = p_ref - c phi with p(phi_w) = p_w and p(phi_o) = p_outer.
  f.coefficient = (p_outer - p_w) / (phi_w - phi_o);
  f.p_ref = p_w + f.coefficient * phi_w;
  return f;
}

}  // namespace hm
