#include "meshgen/case/segment_distance.hpp"

#include <algorithm>
#include <cmath>

namespace hm {

// Closest points of two segments (Ericson, Real-Time Collision Detection, 5.1.9), with the
// parallel and degenerate cases resolved by clamping.
double segment_segment_distance(Vec3 p0, Vec3 p1, Vec3 q0, Vec3 q1) {
  const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = dot(d1, d1), e = dot(d2, d2), f = dot(d2, r);
  double s = 0, t = 0;
  if (a == 0 && e == 0) return norm(r);
  if (a == 0) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = dot(d1, r);
    if (e == 0) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = dot(d1, d2), denom = a * e - b * b;
      // Non-parallel: closest point of the infinite lines clamped to segment 1; parallel
      // (denom == 0 or lost to rounding): any s works, take 0.
      s = denom > 0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return norm((p0 + s * d1) - (q0 + t * d2));
}

namespace {
// Distance between the axis-aligned bounding boxes of two segments (a lower bound).
double box_gap(Vec3 p0, Vec3 p1, Vec3 q0, Vec3 q1) {
  double gap2 = 0;
  for (int k = 0; k < 3; ++k) {
    const double plo = std::min(p0[k], p1[k]), phi = std::max(p0[k], p1[k]);
    const double qlo = std::min(q0[k], q1[k]), qhi = std::max(q0[k], q1[k]);
    const double g = std::max({0.0, qlo - phi, plo - qhi});
    gap2 += g * g;
  }
  return std::sqrt(gap2);
}
}  // namespace

double polyline_distance(const std::vector<Vec3>& a, const std::vector<Vec3>& b, double cutoff) {
  double best = std::numeric_limits<double>::infinity();
  const size_t na = a.size() > 1 ? a.size() - 1 : a.size();  // a single point is a zero-length segment
  const size_t nb = b.size() > 1 ? b.size() - 1 : b.size();
  for (size_t i = 0; i < na; ++i) {
    const Vec3 p0 = a[i], p1 = a[std::min(i + 1, a.size() - 1)];
    for (size_t j = 0; j < nb; ++j) {
      const Vec3 q0 = b[j], q1 = b[std::min(j + 1, b.size() - 1)];
      const double gap = box_gap(p0, p1, q0, q1);
      if (gap >= cutoff || gap >= best) continue;
      best = std::min(best, segment_segment_distance(p0, p1, q0, q1));
    }
  }
  return best;
}

}  // namespace hm
