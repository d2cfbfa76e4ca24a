// Well paths from deviation surveys (measured depth, inclination, azimuth) by the
// minimum-curvature method, the industry standard (SPE-84246, "Wellbore survey calculation").
#pragma once
#include <vector>

#include "meshgen/core/vec3.hpp"

namespace hm {

/// One survey station. Inclination from the vertical (0 = straight down), azimuth clockwise
/// from grid north (+y) toward east (+x), both in degrees; md in metres along the hole.
struct SurveyStation {
  double md = 0, inclination_deg = 0, azimuth_deg = 0;
};

/// Positions of the stations in the case frame (x east, y north, z depth positive down) for a
/// wellhead `head` at md = 0. Between two stations the hole is the circular arc tangent to both
/// station directions (minimum curvature), so the positions are exact for a path made of arcs.
/// Requires md strictly increasing from > 0 (the head is the implicit station md 0 with the
/// first station's direction) and doglegs < 180 degrees (validated by the case reader).
std::vector<Vec3> minimum_curvature_positions(Vec3 head, const std::vector<SurveyStation>& stations);

/// Unit direction of a station (x east, y north, z down).
Vec3 survey_direction(double inclination_deg, double azimuth_deg);

/// Dogleg angle (radians) between two station directions.
double survey_dogleg(const SurveyStation& a, const SurveyStation& b);

}  // namespace hm
