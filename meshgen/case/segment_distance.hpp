// Distances between line segments and polylines (well-to-well spacing checks).
#pragma once
#include <limits>
#include <vector>

#include "meshgen/core/vec3.hpp"

namespace hm {

/// Minimum Euclidean distance between the closed segments [p0, p1] and [q0, q1].
/// Degenerate segments (p0 == p1) are handled as points.
double segment_segment_distance(Vec3 p0, Vec3 p1, Vec3 q0, Vec3 q1);

/// Minimum distance between two polylines (>= 1 point each). Segment pairs whose bounding
/// boxes are at least `cutoff` apart are skipped, so the result is exact when it is below
/// `cutoff` and otherwise only guaranteed to be >= cutoff (possibly +inf).
double polyline_distance(const std::vector<Vec3>& a, const std::vector<Vec3>& b,
                         double cutoff = std::numeric_limits<double>::infinity());

}  // namespace hm
