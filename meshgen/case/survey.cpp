#include "survey.hpp"

#include <cmath>

namespace hm {

namespace {
constexpr double kDegree = 3.14159265358979323846 / 180.0;

// Minimum curvature's ratio factor RF = tan(b/2) / (b/2): the arc between two stations is
// the chord-weighted average of their directions scaled by RF. Its series below b = 1e-4 rad
// (error < 1e-17) avoids 0/0 on straight parts.
double ratio_factor(double dogleg) {
  if (dogleg < 1e-4) return 1.0 + dogleg * dogleg / 12.0;
  return std::tan(0.5 * dogleg) / (0.5 * dogleg);
}
}  // namespace

Vec3 survey_direction(double inclination_deg, double azimuth_deg) {
  const double i = inclination_deg * kDegree, a = azimuth_deg * kDegree;
  return {std::sin(i) * std::sin(a), std::sin(i) * std::cos(a), std::cos(i)};
}

double survey_dogleg(const SurveyStation& a, const SurveyStation& b) {
  const Vec3 da = survey_direction(a.inclination_deg, a.azimuth_deg);
  const Vec3 db = survey_direction(b.inclination_deg, b.azimuth_deg);
  // atan2 of |cross| and dot: accurate for small and large angles alike (acos is not near 0).
  return std::atan2(norm(cross(da, db)), dot(da, db));
}

std::vector<Vec3> minimum_curvature_positions(Vec3 head, const std::vector<SurveyStation>& stations) {
  std::vector<Vec3> out;
  out.reserve(stations.size() + 1);
  if (stations.empty()) return out;
  SurveyStation prev{0.0, stations.front().inclination_deg, stations.front().azimuth_deg};
  Vec3 p = head;
  out.push_back(p);
  for (const SurveyStation& s : stations) {
    const double dmd = s.md - prev.md;
    const Vec3 d1 = survey_direction(prev.inclination_deg, prev.azimuth_deg);
    const Vec3 d2 = survey_direction(s.inclination_deg, s.azimuth_deg);
    p = p + (0.5 * dmd * ratio_factor(survey_dogleg(prev, s))) * (d1 + d2);
    out.push_back(p);
    prev = s;
  }
  return out;
}

}  // namespace hm
