// Exact solutions for the near-well accuracy study (docs/accuracy.md): the potential of a
// uniform line source on a polyline (a sum of finite-segment potentials), harmonic away from
// the polyline, and the radial / infinite-line special cases.
#pragma once
#include <vector>

#include "meshgen/core/vec3.hpp"

namespace hm {

/// ln((r_a + r_b + L) / (r_a + r_b - L)) for the segment A-B, evaluated without the
/// cancellation of r_a + r_b - L near the segment. +inf on the segment.
double segment_potential(Vec3 x, Vec3 a, Vec3 b);

/// Gradient of segment_potential: -2L / ((r_a + r_b)^2 - L^2) (grad r_a + grad r_b).
Vec3 segment_potential_gradient(Vec3 x, Vec3 a, Vec3 b);

/// Sum of segment_potential over the legs of the polyline.
double polyline_potential(Vec3 x, const std::vector<Vec3>& polyline);

Vec3 polyline_potential_gradient(Vec3 x, const std::vector<Vec3>& polyline);

struct PolylinePoint {
  double distance = 0;  ///< |x - point|
  int leg = 0;          ///< leg index of the closest point
  double t = 0;         ///< parameter on that leg in [0, 1]
  Vec3 point;           ///< the closest point
};
/// Closest point of the polyline to x (first leg wins ties).
PolylinePoint closest_on_polyline(Vec3 x, const std::vector<Vec3>& polyline);

/// A unit vector perpendicular to d: horizontal (d x z) unless d is nearly vertical, then x-like.
Vec3 perpendicular_unit(Vec3 d);

/// The manufactured pressure field p(x) = p_ref - coefficient * polyline_potential(x) of a uniform
/// line source on `polyline` (pressure in bar when coefficient = q' mu / (4 pi CDARCY k)).
/// Near the middle of a long segment p ~ p_ref' + (q' mu / (2 pi CDARCY k)) ln(d): the radial law.
struct LineSourceField {
  std::vector<Vec3> polyline;  ///< the well trajectory (axis of the wellbore)
  std::vector<Vec3> source;    ///< where the source lies: the trajectory, possibly shortened at its ends
  double r_w = 0.1;
  double p_ref = 0;
  double coefficient = 0;  ///< bar per unit of potential; q' = 4 pi CDARCY k coefficient / mu

  double pressure(Vec3 x) const { return p_ref - coefficient * polyline_potential(x, source); }
  Vec3 pressure_gradient(Vec3 x) const { return -coefficient * polyline_potential_gradient(x, source); }
  /// The pressure the wellbore face with centroid x sees: the exact p on the wellbore circle
  /// (x moved along its perpendicular from the polyline to distance r_w); at a trajectory end
  /// point (the centroid of an end cap) the mean of p over the cap disc of radius r_w.
  double wellbore_pressure(Vec3 x) const;
  /// Mean of p over the disc of radius r_w centred at trajectory end `end` (0 first, 1 last),
  /// normal to the end leg (quadrature in polar coordinates: the log singularity is integrable).
  double cap_mean_pressure(int end) const;
  double source_length() const;  ///< the exact rate is q' x source_length()
};

/// Builds the field whose pressure is p_w at distance r_w and p_outer at distance `outer_distance`
/// from the midpoint of the longest leg (both along perpendicular_unit of that leg). The source is
/// the trajectory with `inset` (m) removed at both ends (0: the whole trajectory; inset = r_w keeps
/// the source strictly inside the wellbore, so that p is smooth up to the end caps).
LineSourceField make_line_source_field(const std::vector<Vec3>& polyline, double r_w, double p_w, double p_outer,
                                       double outer_distance, double inset = 0);

/// Reference points of such a field: the longest leg's midpoint and its perpendicular.
struct FieldReference {
  int leg = 0;
  Vec3 mid, normal, direction;
};
FieldReference field_reference(const std::vector<Vec3>& polyline);

}  // namespace hm
