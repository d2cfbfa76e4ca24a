#include "meshgen/case/meshed_trajectory.hpp"

#include "meshgen/case/case_limits.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace hm {

namespace {

std::string num(double x) {
  std::ostringstream os;
  os << std::setprecision(6) << x;
  return os.str();
}

// Part [t0, t1] of segment a -> b inside the closed box (Liang-Barsky); empty when t0 > t1.
// enter / leave: the axis whose plane bounds t0 / t1 (-1 when the segment's own end does).
struct Clip {
  double t0 = 0, t1 = 1;
  int enter = -1, leave = -1;
  bool empty() const { return !(t0 <= t1); }
};

Clip clip_segment(Vec3 a, Vec3 b, Vec3 lo, Vec3 hi) {
  Clip c;
  const Vec3 d = b - a;
  for (int k = 0; k < 3; ++k) {
    if (d[k] == 0) {
      if (a[k] < lo[k] || a[k] > hi[k]) c.t0 = 1, c.t1 = 0;
      continue;
    }
    double ta = (lo[k] - a[k]) / d[k], tb = (hi[k] - a[k]) / d[k];
    if (ta > tb) std::swap(ta, tb);
    if (ta > c.t0) c.t0 = ta, c.enter = k;
    if (tb < c.t1) c.t1 = tb, c.leave = k;
  }
  return c;
}

// Axes on which p lies exactly on a box plane.
std::vector<int> planes_at(Vec3 p, Vec3 lo, Vec3 hi) {
  std::vector<int> axes;
  for (int k = 0; k < 3; ++k)
    if (p[k] == lo[k] || p[k] == hi[k]) axes.push_back(k);
  return axes;
}

}  // namespace

std::string boundary_plane_name(int axis, bool upper, double value) {
  static const char* names[3] = {"x", "y", "z"};
  std::string what;
  if (axis == 2) what = upper ? "the reservoir bottom" : "the reservoir top";
  else what = std::string("the reservoir side ") + names[axis] + (upper ? " max" : " min");
  return what + " (" + names[axis] + " = " + num(value) + ")";
}

MeshedTrajectory meshed_trajectory(const ReservoirSpec& r, const WellSpec& ws, const std::string& key, bool check_fit) {
  const std::string tkey = key + ".trajectory";
  const Vec3 lo{r.x.front(), r.y.front(), r.z.front()};
  const Vec3 hi{r.x.back(), r.y.back(), r.z.back()};
  const std::vector<Vec3>& traj = ws.trajectory;
  const int n_legs = static_cast<int>(traj.size()) - 1;
  if (n_legs < 1) throw InputError(tkey + ": needs at least 2 points");

  // 1. The legs' parts inside the box: one connected piece of positive length.
  std::vector<Clip> clips(n_legs);
  int first = -1, last = -1;
  for (int k = 0; k < n_legs; ++k) {
    clips[k] = clip_segment(traj[k], traj[k + 1], lo, hi);
    if (clips[k].empty() || !(clips[k].t1 > clips[k].t0)) continue;
    if (first < 0) first = k;
    last = k;
  }
  if (first < 0) throw InputError(tkey + ": no part of it lies inside the reservoir");
  for (int k = first; k <= last; ++k) {
    const bool starts = k == first || clips[k].t0 == 0, ends = k == last || clips[k].t1 == 1;
    if (!starts || !ends || clips[k].empty())
      throw InputError(tkey + ": leaves the reservoir and comes back (leg " + std::to_string(k) +
                       "); only one connected part inside can be meshed");
  }

  MeshedTrajectory out;
  auto at = [&](int k, double t) {
    if (t == 0) return traj[k];
    if (t == 1) return traj[k + 1];
    return traj[k] + t * (traj[k + 1] - traj[k]);
  };
  out.points.push_back(at(first, clips[first].t0));
  for (int k = first + 1; k <= last; ++k) out.points.push_back(traj[k]);
  out.points.push_back(at(last, clips[last].t1));

  // 2. Each end: inside, or on exactly one boundary plane (snapped onto it exactly).
  for (int e = 0; e < 2; ++e) {
    Vec3& p = e == 0 ? out.points.front() : out.points.back();
    const Clip& c = e == 0 ? clips[first] : clips[last];
    const int crossed = e == 0 ? (c.t0 > 0 ? c.enter : -1) : (c.t1 < 1 ? c.leave : -1);
    std::vector<int> axes = planes_at(p, lo, hi);
    if (crossed >= 0 && std::find(axes.begin(), axes.end(), crossed) == axes.end()) axes.push_back(crossed);
    // A crossing computed in floating point may also land within rounding of another plane.
    for (int k = 0; k < 3; ++k) {
      if (k == crossed || std::find(axes.begin(), axes.end(), k) != axes.end()) continue;
      const double tol = 1e-12 * std::max({1.0, std::abs(lo[k]), std::abs(hi[k])});
      if (std::abs(p[k] - lo[k]) <= tol || std::abs(p[k] - hi[k]) <= tol) axes.push_back(k);
    }
    if (axes.empty()) continue;
    if (axes.size() > 1)
      throw InputError(tkey + ": crosses the reservoir boundary at an edge or corner of the box (" + num(p.x) + ", " +
                       num(p.y) + ", " + num(p.z) + "); a well may cross one boundary plane at a time");
    const int k = axes[0];
    const bool upper = std::abs(p[k] - hi[k]) < std::abs(p[k] - lo[k]);
    p[k] = upper ? hi[k] : lo[k];
    out.plane_axis[e] = k;
    out.plane_value[e] = p[k];
    out.plane_upper[e] = upper;
    // Direction of the leg at this end, pointing into the box.
    const Vec3 inward = e == 0 ? out.points[1] - out.points[0] : out.points[out.points.size() - 2] - p;
    const double len = norm(inward);
    const Vec3 d = inward / len;
    if (d[k] == 0)
      throw InputError(tkey + ": runs along " + boundary_plane_name(k, upper, p[k]) +
                       "; a well must lie inside the reservoir or cross its boundary");
    bool perpendicular = true;
    for (int j = 0; j < 3; ++j) perpendicular = perpendicular && (j == k || inward[j] == 0);
    if (perpendicular) {
      out.ends[e] = WellEndKind::Boundary;
      continue;
    }
    // Oblique: the end cross-section (a disc of radius R normal to d) reaches R sqrt(1 - d_k^2)
    // along axis k; the end moves back along the leg until that disc keeps the gap.
    const double dk = std::abs(d[k]);
    const double reach = ws.drainage_radius * std::sqrt(std::max(0.0, 1.0 - dk * dk));
    const double s = (reach + kRetractGap * ws.drainage_radius) / dk;
    if (!(s < len))
      throw InputError(tkey + ": the leg that crosses " + boundary_plane_name(k, upper, p[k]) + " at " +
                       num(std::acos(dk) * 180.0 / 3.14159265358979323846) +
                       " degrees from its normal is too short to end the radial block inside (the block ends " +
                       num(s) + " m from the crossing, the leg has " + num(len) + " m inside)");
    p = p + s * d;
    out.ends[e] = WellEndKind::Retracted;
    out.retraction[e] = s;
  }

  // 3. The block keeps the gap from every plane it does not end on. Its lateral surface around
  //    a leg with direction d reaches R sqrt(1 - d_k^2) along axis k; a hemispherical cap
  //    reaches R beyond an inside end in every direction.
  const int m = static_cast<int>(out.points.size());
  // Whether the block ends at right angles in the plane (axis k, side) at leg s: it then comes no closer.
  auto ends_in = [&](int s, int k, bool upper) {
    bool ends_here = false;
    for (int e = 0; e < 2; ++e)
      ends_here = ends_here || (out.ends[e] == WellEndKind::Boundary && out.plane_axis[e] == k &&
                                out.plane_value[e] == (upper ? hi[k] : lo[k]) && (e == 0 ? s == 0 : s + 2 == m));
    return ends_here;
  };
  // A block squeezed between both planes of one axis (no translation can make it fit) gets the
  // largest drainage radius that keeps kBoundaryGap x that radius from both.
  double R = ws.drainage_radius;
  for (int s = 0; s + 1 < m; ++s) {
    const Vec3 a = out.points[s], b = out.points[s + 1], d = normalized(b - a);
    for (int k = 0; k < 3; ++k) {
      const double sk = std::sqrt(std::max(0.0, 1.0 - d[k] * d[k]));
      const double d_lo = std::min(a[k] - lo[k], b[k] - lo[k]), d_hi = std::min(hi[k] - a[k], hi[k] - b[k]);
      const bool lo_close = !ends_in(s, k, false) && d_lo - R * sk < kBoundaryGap * R;
      const bool hi_close = !ends_in(s, k, true) && d_hi - R * sk < kBoundaryGap * R;
      if (lo_close && hi_close && sk > 0) {
        // (1 - 1e-12): the gap test below then holds despite the rounding of this quotient.
        const double fit = std::min(d_lo, d_hi) / (sk + kBoundaryGap) * (1 - 1e-12);
        if (fit >= kMinFittedRadius * ws.drainage_radius && fit > ws.radius) R = std::min(R, fit);
      }
    }
  }
  out.drainage_radius = R;
  const double gap = kBoundaryGap * R;
  auto too_close = [&](const std::string& what, int k, bool upper, double distance) {
    throw InputError(tkey + ": " + what + " comes within " + num(std::max(0.0, distance)) + " m of " +
                     boundary_plane_name(k, upper, upper ? hi[k] : lo[k]) + "; it must keep " + num(gap) +
                     " m (" + num(kBoundaryGap) +
                     " x drainage_radius) from a boundary plane it does not end on, or cross the plane");
  };
  for (int s = 0; s + 1 < m; ++s) {
    const Vec3 a = out.points[s], b = out.points[s + 1], d = normalized(b - a);
    for (int k = 0; k < 3; ++k) {
      const double reach = R * std::sqrt(std::max(0.0, 1.0 - d[k] * d[k]));
      for (int side = 0; side < 2; ++side) {
        const bool upper = side == 1;
        if (ends_in(s, k, upper)) continue;
        const double da = upper ? hi[k] - a[k] : a[k] - lo[k], db = upper ? hi[k] - b[k] : b[k] - lo[k];
        const double dist = std::min(da, db) - reach;
        if (check_fit && dist < gap) too_close("the radial block around leg " + std::to_string(s), k, upper, dist);
      }
    }
  }
  const bool explicit_caps = ws.end_caps == EndCaps::Hemisphere && !ws.end_caps_fallback;
  if (check_fit && explicit_caps && out.clipped())
    throw InputError(key + ".end_caps: hemisphere caps need both ends of the trajectory inside the reservoir; "
                           "this well crosses the reservoir boundary (use flat or auto)");
  out.caps_fit = !out.clipped();
  for (int e = 0; e < 2 && out.caps_fit; ++e) {
    const Vec3 p = e == 0 ? out.points.front() : out.points.back();
    for (int k = 0; k < 3; ++k)
      for (int side = 0; side < 2; ++side) {
        const bool upper = side == 1;
        const double dist = (upper ? hi[k] - p[k] : p[k] - lo[k]) - R;
        if (dist >= gap) continue;
        if (check_fit && explicit_caps)
          too_close(std::string("the hemispherical cap at its ") + (e == 0 ? "start" : "end"), k, upper, dist);
        out.caps_fit = false;
      }
  }
  return out;
}

double bend_degrees(Vec3 d1, Vec3 d2) {
  return std::atan2(norm(cross(d1, d2)), dot(d1, d2)) * 180.0 / 3.14159265358979323846;
}

void check_bend_limit(const std::vector<Vec3>& points, const std::string& key, double limit_deg) {
  for (size_t k = 1; k + 1 < points.size(); ++k) {
    const double deg = bend_degrees(points[k] - points[k - 1], points[k + 1] - points[k]);
    if (deg > limit_deg * (1 + kBendLimitTolerance))
      throw InputError(key + ".trajectory: bend of " + num(deg) + " degrees at point " + std::to_string(k) +
                       " exceeds the " + num(limit_deg) + "-degree limit");
  }
}

WellSpec meshed_well_spec(const CaseSpec& cs, int w) {
  WellSpec ws = cs.wells.at(w);
  const MeshedTrajectory mt = meshed_trajectory(cs.reservoir, ws, "wells[" + std::to_string(w) + "]", false);
  ws.trajectory = mt.points;
  ws.drainage_radius = mt.drainage_radius;
  if (ws.end_caps == EndCaps::Hemisphere && !mt.caps_fit) {
    ws.end_caps = EndCaps::Flat;
    ws.end_caps_fallback = false;
  }
  return ws;
}

}  // namespace hm
