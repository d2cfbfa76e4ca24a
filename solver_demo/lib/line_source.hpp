// Exact solutions for the near-well accuracy study (docs/accuracy.md): the potential of a
// uniform line source on a polyline (a sum of finite-segment potentials), harmonic away from
// the polyline, and the radial / infinite-line special cases. For a diagonal permeability the
// field is that potential in the scaled coordinates x' = x / s, s_i = sqrt(k_i / k0),
// k0 = cbrt(kx ky kz) (det S = 1), where the permeability is the isotropic k0.
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

/// x' = S^-1 x and back (component-wise; s = frame_scale(K), meshgen/pipeline/permeability_frame.hpp).
/// The field is translation invariant, so the frame's origin does not matter here.
inline Vec3 to_scaled(Vec3 x, Vec3 s) { return {x.x / s.x, x.y / s.y, x.z / s.z}; }
inline Vec3 from_scaled(Vec3 x, Vec3 s) { return {x.x * s.x, x.y * s.y, x.z * s.z}; }
/// equivalent_radius (permeability_frame.hpp) of a wellbore of radius r_w about direction d in
/// the frame of scale s, exactly r_w when s = (1, 1, 1).
double equivalent_wellbore_radius(Vec3 s, Vec3 d, double r_w);

/// The manufactured pressure field p(x) = p_ref - coefficient * polyline_potential(x) of a uniform
/// line source on `polyline` (pressure in bar when coefficient = q' mu / (4 pi CDARCY k)).
/// Near the middle of a long segment p ~ p_ref' + (q' mu / (2 pi CDARCY k)) ln(d): the radial law.
///
/// Anisotropic (scale s != 1): p(x) = p_ref - coefficient * polyline_potential(S^-1 x, S^-1 source),
/// harmonic for div(K grad p) (K = k0 S^2); q' is then the rate per unit of scaled source length
/// (fluxes are the same in both frames: det S = 1).
struct LineSourceField {
  std::vector<Vec3> polyline;  ///< the well trajectory (axis of the wellbore), physical
  std::vector<Vec3> source;    ///< where the source lies: the trajectory, possibly shortened at its ends
  double r_w = 0.1;
  double p_ref = 0;
  double coefficient = 0;  ///< bar per unit of potential; q' = 4 pi CDARCY k0 coefficient / mu
  Vec3 scale{1, 1, 1};     ///< s = frame_scale(K): the field is a line source in x' = x / s
  std::vector<Vec3> scaled_source;  ///< source / s
  /// The frame the mesh's wellbore is a circle in: x_w = x / wellbore_scale ((1, 1, 1): the
  /// physical circle of radius r_w of a Euclidean mesh), and its radius there.
  Vec3 wellbore_scale{1, 1, 1};
  double wellbore_radius = 0.1;

  double pressure(Vec3 x) const { return p_ref - coefficient * polyline_potential(to_scaled(x, scale), scaled_source); }
  Vec3 pressure_gradient(Vec3 x) const {
    return -coefficient * to_scaled(polyline_potential_gradient(to_scaled(x, scale), scaled_source), scale);
  }
  /// The pressure the wellbore face with centroid x sees: the exact p on the mesh's wellbore
  /// (in the wellbore frame, x moved along its perpendicular from the polyline to distance
  /// wellbore_radius); at a trajectory end point (the centroid of a flat end cap) the mean of p
  /// over the cap disc.
  double wellbore_pressure(Vec3 x) const;
  /// The pressure of a real well (constant on its physical circle of radius r_w) at the
  /// trajectory point closest to x, as the line source sees it: p at the equivalent radius
  /// (a + b) / 2 of the wellbore's elliptic image in the scaled frame (equivalent_radius of
  /// permeability_frame.hpp: the circle with the same far field; for a well along z Peaceman's
  /// (1983) r_w (1/s_x + 1/s_y) / 2), perpendicular to the scaled leg; p on the circle r_w when
  /// isotropic. The wellbore pressure of a Peaceman connection.
  double equivalent_wellbore_pressure(Vec3 x) const;
  /// Mean of p over the disc of radius wellbore_radius (wellbore frame) centred at trajectory end
  /// `end` (0 first, 1 last), normal to the end leg (polar quadrature: the log singularity is integrable).
  double cap_mean_pressure(int end) const;
  double source_length() const;         ///< physical length of the source
  double scaled_source_length() const;  ///< the exact rate is q' x scaled_source_length()
  /// Distance from x to the scaled source polyline, in the scaled frame (the radial law's variable).
  double scaled_distance(Vec3 x) const;
};

/// Builds the field whose pressure is p_w at distance r_w and p_outer at distance `outer_distance`
/// from the midpoint of the longest leg (both along perpendicular_unit of that leg). The source is
/// the trajectory with `inset` removed at both ends, measured in the frame of scale `inset_frame`
/// (the frame the mesh's wellbore is a circle in: its end caps are half-balls of that radius there;
/// 0: the whole trajectory; inset = the wellbore's radius in its frame keeps the source inside the
/// wellbore and as far from the caps as the caps are from the ends, so that p is smooth up to them).
/// Anisotropic (scale != 1): the field is a line source in x' = x / scale; p = p_w at the
/// equivalent wellbore (the equivalent radius from the scaled midpoint, perpendicular to the
/// scaled leg) and p = p_outer at the physical point outer_distance from the midpoint along the
/// physical perpendicular. The wellbore frame is left Euclidean (set wellbore_scale /
/// wellbore_radius for a mesh built in another frame).
LineSourceField make_line_source_field(const std::vector<Vec3>& polyline, double r_w, double p_w, double p_outer,
                                       double outer_distance, double inset = 0, Vec3 scale = {1, 1, 1},
                                       Vec3 inset_frame = {1, 1, 1});

/// Reference points of such a field: the longest leg's midpoint and its perpendicular.
struct FieldReference {
  int leg = 0;
  Vec3 mid, normal, direction;
};
FieldReference field_reference(const std::vector<Vec3>& polyline);

}  // namespace hm
