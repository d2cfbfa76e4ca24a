// Structured radial well block (paper sections 2 and 5.1); layout in well_block.hpp.
//
// Geometry. Leg k of the trajectory polyline carries a right-handed frame (u_k, v_k, d_k);
// leg k's frame is leg k-1's turned by the minimal rotation taking d_{k-1} to d_k (about
// d_{k-1} x d_k): the rotation-minimising (parallel transport) frame, which does not twist.
// Every cross-section (layer) is perpendicular to the meshed axis; a node is
// P + r (cos phi u + sin phi v). On straight parts every cell is a right prism over an
// annular sector: faces planar and co-circular, and with the FV centre on the cell's
// mid-angle radial line the ring and angular faces are orthogonal to the centre-to-centre
// segments. A bend is meshed as mirror wedges on a fillet arc (below): the meshed axis cuts
// the corner, by a distance each bend's note states.
//
// End caps. Both extremities are closed. The end annulus quads of the first and last layers
// are faces of the end cells (outer-surface faces, later claimed by transition cells). The
// ring-0 polygon of each end layer (`sectors` nodes, planar and co-circular) caps the
// wellbore hole: it is no face of a block cell but an outer-surface polygon with
// surface_cell = -1 and surface_patch = wellbore_patch(well); it becomes a wellbore boundary
// face of the transition cell that claims it.
#include "well_block.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "gabriel.hpp"
#include "meshgen/case/case_limits.hpp"
#include "meshgen/case/meshed_trajectory.hpp"
#include "meshgen/case/segment_distance.hpp"

namespace hm {

namespace {

constexpr double kPi = 3.14159265358979323846;

std::string num(double x) {
  std::ostringstream os;
  os << std::setprecision(6) << x;
  return os.str();
}

std::string well_key(int w) { return "wells[" + std::to_string(w) + "]"; }

std::string well_label(const CaseSpec& cs, int w) { return well_key(w) + " (" + cs.wells[w].name + ")"; }

// The minimal rotation taking unit d1 to unit d2 (about d1 x d2), applied to x.
// Rodrigues with the unnormalised axis k = d1 x d2: sin = |k|, cos = c, (1 - c) / sin^2 = 1 / (1 + c).
// Requires d1 . d2 > -1 (bends above kMaxBlockBendDegrees are rejected before).
Vec3 rotate_minimal(Vec3 x, Vec3 d1, Vec3 d2) {
  const Vec3 k = cross(d1, d2);
  const double c = dot(d1, d2);
  return c * x + cross(k, x) + (dot(k, x) / (1.0 + c)) * k;
}


struct Leg {
  Vec3 a, b;       // trajectory points at its ends
  Vec3 d, u, v;    // right-handed frame, d along the leg
  double length = 0;
  double bend_start = -1, bend_end = -1;  // bend angles (degrees) at its ends, -1 at a trajectory end
};

void validate_well(const WellSpec& ws, int w, int sectors) {
  const std::string key = well_key(w);
  if (ws.trajectory.size() < 2) throw InputError(key + ".trajectory: needs at least 2 points");
  for (size_t k = 0; k + 1 < ws.trajectory.size(); ++k)
    if (ws.trajectory[k] == ws.trajectory[k + 1])
      throw InputError(key + ".trajectory: points " + std::to_string(k) + " and " + std::to_string(k + 1) +
                       " coincide");
  if (!(ws.radius > 0)) throw InputError(key + ".radius: must be > 0");
  if (!(ws.drainage_radius > ws.radius)) throw InputError(key + ".drainage_radius: must be > radius");
  if (ws.rings < 1) throw InputError(key + ".rings: must be >= 1");
  if (sectors < 3) throw InputError(key + ".sectors: must be >= 3");
  if (!(ws.segment_length > 0)) throw InputError(key + ".segment_length: must be > 0");
}

// Legs with their directions, bend angles and transported frames.
std::vector<Leg> make_legs(const WellSpec& ws, int w) {
  const std::vector<Vec3>& traj = ws.trajectory;
  const int n_legs = static_cast<int>(traj.size()) - 1;
  // The block's own limit; case validation refuses bends above kMaxBendDegrees (what the transition holds).
  check_bend_limit(traj, well_key(w), kMaxBlockBendDegrees);
  std::vector<Leg> legs(n_legs);
  for (int k = 0; k < n_legs; ++k) {
    Leg& g = legs[k];
    g.a = traj[k];
    g.b = traj[k + 1];
    g.length = norm(g.b - g.a);
    g.d = (g.b - g.a) / g.length;
  }
  for (int k = 1; k < n_legs; ++k) {
    const double deg = bend_degrees(legs[k - 1].d, legs[k].d);
    legs[k - 1].bend_end = deg;
    legs[k].bend_start = deg;
  }
  // Initial frame: the x axis (y if the first leg is nearly along x) projected off d_0.
  const Vec3 d0 = legs[0].d;
  const Vec3 ref = std::abs(d0.x) > 0.9 ? Vec3{0, 1, 0} : Vec3{1, 0, 0};
  legs[0].u = normalized(ref - dot(ref, d0) * d0);
  legs[0].v = cross(d0, legs[0].u);
  for (int k = 1; k < n_legs; ++k) {
    const Vec3 d = legs[k].d;
    const Vec3 u = rotate_minimal(legs[k - 1].u, legs[k - 1].d, d);
    // Re-orthonormalise so that rounding does not accumulate along many legs.
    legs[k].u = normalized(u - dot(u, d) * d);
    legs[k].v = cross(d, legs[k].u);
  }
  return legs;
}


std::string bend_phrase(const Leg& g) {
  if (g.bend_start >= 0 && g.bend_end >= 0) return "its bends of " + num(g.bend_start) + " and " + num(g.bend_end) + " degrees";
  return "its bend of " + num(std::max(g.bend_start, g.bend_end)) + " degrees";
}


// ---- Bends as mirror wedges.
// A bend of angle beta at trajectory point B (legs d1 -> d2) is meshed on a fillet arc of
// radius rho tangent to both legs: the axis leaves leg 1 at T1 = B - t d1 and joins leg 2 at
// T2 = B + t d2 (t = rho tan(beta / 2)), through k wedges. Wedge j lies between the
// perpendicular cross-sections at stations X_j and X_{j+1} (normals d^(j), d^(j+1): d1 turned
// by j beta / k), which are mirror images of each other through the plane with normal
// d^(j) + d^(j+1) (X_{j+1} = X_j + delta (d^(j) + d^(j+1)), delta = rho tan(beta / (2 k))), and
// so are their nodes, since the minimal rotation and that reflection agree on vectors normal
// to d^(j). Every face of a wedge (ring and angular faces: a node pair and its mirror image;
// axial faces: in a cross-section) is then a planar isosceles trapezoid or a cross-section
// polygon: planar and co-circular, as the transition mesh needs (paper 5.4, 5.7).
// rho > R (drainage radius) keeps the inner side of every wedge open.
struct BendPlan {
  int point = -1;       // trajectory point index
  double angle = 0;     // beta (radians)
  Vec3 axis;            // unit rotation axis, d1 x d2 / |d1 x d2|
  double radius = 0;    // rho
  double tangent = 0;   // t
  int wedges = 0;       // k
  double lean = 0;      // largest lean of its joint and outer faces (bend_lean), radians
};

// rho >= 1.3 R: the wedges' inner sides stay open and the transition's free sites fit on the
// bend's focal line (docs/transition.md, "Bends": fillets of 1.1-1.25 R failed the self-check
// at 60-119.9 degrees, 1.3-2 R passed).
constexpr double kMinFilletFactor = 1.3;
constexpr double kPreferredFilletFactor = 1.5;  // rho = 1.5 R when the legs allow it
constexpr double kMaxWedgeAngle = kPi / 6;    // 30 degrees per wedge keeps the outer surface Gabriel

// x turned by `angle` about the unit axis n (Rodrigues).
Vec3 rotate_about(Vec3 x, Vec3 n, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return c * x + s * cross(n, x) + ((1.0 - c) * dot(n, x)) * n;
}

// Fillet radius and wedge count of every bend; throws when a leg cannot hold the wedges at
// its ends even with the smallest fillet.
std::vector<BendPlan> plan_bends(const WellSpec& ws, int w, const std::vector<Leg>& legs) {
  const int n_legs = static_cast<int>(legs.size());
  std::vector<BendPlan> plans;
  std::vector<double> t_min(n_legs + 1, 0.0);  // per trajectory point: the smallest tangent length
  for (int k = 1; k < n_legs; ++k) {
    const Vec3 d1 = legs[k - 1].d, d2 = legs[k].d;
    BendPlan p;
    p.point = k;
    p.angle = std::atan2(norm(cross(d1, d2)), dot(d1, d2));
    if (p.angle == 0) continue;  // collinear points: a plain cross-section
    p.axis = normalized(cross(d1, d2));
    t_min[k] = kMinFilletFactor * ws.drainage_radius * std::tan(0.5 * p.angle);
    plans.push_back(p);
  }
  for (int k = 0; k < n_legs; ++k) {
    const double need = t_min[k] + t_min[k + 1];
    if (!(need < legs[k].length)) {
      throw InputError(well_key(w) + ".trajectory: leg " + std::to_string(k) + " too short for " + bend_phrase(legs[k]) +
                       " (needs > " + num(need) + " m with drainage radius " + num(ws.drainage_radius) + ")");
    }
  }
  for (BendPlan& p : plans) {
    const int k = p.point;
    // Each bend may use its smallest tangent plus half of what its legs leave free (all of
    // it on a leg whose other end is a trajectory end), less a straight part of half a
    // segment (or all that is free, if less) that every leg keeps: a capped fillet never
    // leaves a sliver of straight leg.
    auto room = [&](int leg, int other_point) {
      const double free = legs[leg].length - t_min[k] - t_min[other_point];
      const double usable = free - std::min(free, 0.5 * ws.segment_length);
      const bool shared = other_point > 0 && other_point < n_legs && t_min[other_point] > 0;
      return t_min[k] + (shared ? 0.5 : 1.0) * usable;
    };
    const double cap = std::min(room(k - 1, k - 1), room(k, k + 1));
    const double half_tan = std::tan(0.5 * p.angle);
    // Preferred: 1.5 R, and an arc at least one segment long (gentle bends).
    const double preferred = std::max(kPreferredFilletFactor * ws.drainage_radius, ws.segment_length / p.angle);
    p.radius = std::max(kMinFilletFactor * ws.drainage_radius, std::min(preferred, cap / half_tan));
    p.tangent = p.radius * half_tan;
    const int by_angle = static_cast<int>(std::ceil(p.angle / kMaxWedgeAngle));
    // No wedge longer than a segment on the outside of the bend (arc radius rho + R): longer
    // wedges there cost accuracy (docs/accuracy.md: 2 wedges on the bent case, 0.95 % of the
    // drawdown next to the bend; 4 wedges, 0.38 %).
    const int by_length =
        static_cast<int>(std::ceil((p.radius + ws.drainage_radius) * p.angle / ws.segment_length - 1e-9));
    p.wedges = std::max({1, by_angle, by_length});
  }
  return plans;
}

// A perpendicular cross-section of the block: axis point, unit normal, in-plane frame.
struct Station {
  Vec3 p, d, u, v;
  int bend_point = -1;  // trajectory point of the bend whose wedges it bounds, -1 on straight parts
};

// The smallest length of an end segment at a flat end that the transition can face: the end
// annulus quad of the outer ring carries a transition site on the normal through its
// circumcentre, (r_in + r_out) / (2 cos(pi / n)) from the axis, while the ring cell's FV centre
// lies half the segment deep at sqrt(r_in r_out): the segment between them is at
// atan((L / 2 + t) / offset) to the quad (t > 0, the site's height). With a large ring ratio
// and short segments that is below fvcheck's 45 degrees whatever t the cavity allows
// (docs/robustness.md, session 8: R 95-130 m, 10 m segments, ratio 3.3: 31 degrees). The end
// segment is made long enough for kFlatEndAngle at t = 0; inner rings have smaller offsets
// (the same ratio, smaller radii).
constexpr double kFlatEndAngle = 50.0 * kPi / 180.0;

double flat_end_min_segment(const std::vector<double>& radii, int sectors) {
  const double r_in = radii[radii.size() - 2], r_out = radii.back();
  const double offset = (r_in + r_out) / (2.0 * std::cos(kPi / sectors)) - std::sqrt(r_in * r_out);
  return 2.0 * offset * std::tan(kFlatEndAngle);
}

// The trajectory the block follows: meshed_well_spec's, less the trajectory point next to a flat
// end (one facing the transition) whose leg is too short to hold the end's minimum segment
// beside the bend there (leg - the bend's smallest tangent < flat_end_min_segment): that end
// segment came out shorter, its ring cells' FV centres too close to the end face, and the end faces'
// orthogonality fell below fvcheck's 45 degrees (a survey well clipped 1.3 m before a station:
// 24 degrees, docs/corner-point.md, "Horizontal wells from surveys"). Without the point the leg
// runs straight to the next one, off the trajectory by at most the short leg times the bend's
// sine. The rule takes the requested sectors, so that the block and its exact volumes agree.
WellSpec block_well_spec(const CaseSpec& cs, int w) {
  WellSpec ws = meshed_well_spec(cs, w);
  if (ws.end_caps != EndCaps::Flat) return ws;
  const MeshedTrajectory mt = meshed_trajectory(cs.reservoir, cs.wells[w], well_key(w), false);
  const double end_min = flat_end_min_segment(ring_radii(ws), std::max(3, ws.sectors));
  std::vector<Vec3>& p = ws.trajectory;
  auto too_short = [&](Vec3 end, Vec3 at, Vec3 next) {
    const double angle = bend_degrees(at - end, next - at) * kPi / 180;
    return angle > 0 && norm(at - end) - kMinFilletFactor * ws.drainage_radius * std::tan(0.5 * angle) < end_min;
  };
  const bool with_md = ws.trajectory_md.size() == p.size();
  auto drop = [&](size_t i) {
    p.erase(p.begin() + static_cast<std::ptrdiff_t>(i));
    if (with_md) ws.trajectory_md.erase(ws.trajectory_md.begin() + static_cast<std::ptrdiff_t>(i));
  };
  if (mt.ends[0] != WellEndKind::Boundary)
    while (p.size() > 2 && too_short(p[0], p[1], p[2])) drop(1);
  if (mt.ends[1] != WellEndKind::Boundary)
    while (p.size() > 2 && too_short(p[p.size() - 1], p[p.size() - 2], p[p.size() - 3])) drop(p.size() - 2);
  return ws;
}

// Positions (distances from the start, increasing, the last = length) of the stations that
// split a straight part of `length` into segments of about `seg`, the first at least
// first_min long and the last at least last_min (0: no minimum). Where the minima leave less
// than half a segment between them, the part is split only at the end segments' boundary,
// or not at all.
std::vector<double> straight_stations(double length, double seg, double first_min, double last_min) {
  if (!(length > 0)) return {};
  const int n = std::max(1L, std::lround(length / seg));
  const double uniform = length / n;
  std::vector<double> out;
  if (first_min <= uniform && last_min <= uniform) {
    for (int j = 1; j <= n; ++j) out.push_back(j == n ? length : length * j / n);
    return out;
  }
  // An end with a minimum the middle segments would not reach gets its own end segment.
  double a = first_min > uniform ? first_min : 0.0, b = last_min > uniform ? last_min : 0.0;
  const double middle = (length - a - b) / std::max(1L, std::lround((length - a - b) / seg));
  if (first_min > middle) a = first_min;
  if (last_min > middle) b = last_min;
  const double rest = length - a - b;
  if (rest < 0.5 * seg) {
    // One segment if the minima overlap, or if only one end has one; else the two end segments.
    if (a > 0 && b > 0 && rest >= 0) out.push_back(a + rest * a / (a + b));
    out.push_back(length);
    return out;
  }
  const int mid = std::max(1L, std::lround(rest / seg));
  if (a > 0) out.push_back(a);
  for (int j = 1; j <= mid; ++j) out.push_back(j == mid && b == 0 ? length : a + rest * j / mid);
  if (b > 0) out.push_back(length);
  return out;
}

// Stations along the trajectory: straight parts of each leg split into segments of about
// segment_length, bends replaced by their wedges; with hemispherical caps, the stations of
// hemisphere_end_grading (case.hpp) at both trajectory ends; at a flat end facing the
// transition, a first (last) segment at least end_min[0] (end_min[1]) long.
std::vector<Station> make_stations(const WellSpec& ws, const std::vector<Leg>& legs,
                                   const std::vector<BendPlan>& plans, std::array<double, 2> end_min) {
  const int n_legs = static_cast<int>(legs.size());
  std::vector<const BendPlan*> plan_at(n_legs + 1, nullptr);
  for (const BendPlan& p : plans) plan_at[p.point] = &p;
  std::vector<Station> st;
  for (int k = 0; k < n_legs; ++k) {
    const Leg& g = legs[k];
    const double t0 = plan_at[k] ? plan_at[k]->tangent : 0.0;
    const double t1 = plan_at[k + 1] ? plan_at[k + 1]->tangent : 0.0;
    Vec3 s0 = g.a + t0 * g.d, s1 = g.b - t1 * g.d;
    if (k == 0) st.push_back({s0, g.d, g.u, g.v, -1});
    // (a bend's last station, already pushed, is s0 of this leg)
    // Graded stations at the trajectory's ends, as many as leave half a segment between them.
    std::vector<double> lo = k == 0 ? hemisphere_end_grading(ws) : std::vector<double>{};
    std::vector<double> hi = k + 1 == n_legs ? hemisphere_end_grading(ws) : std::vector<double>{};
    const double full = g.length - t0 - t1;
    while (!(lo.empty() && hi.empty()) &&
           (lo.empty() ? 0.0 : lo.back()) + (hi.empty() ? 0.0 : hi.back()) > full - 0.5 * ws.segment_length)
      (lo.size() >= hi.size() ? lo : hi).pop_back();
    for (double d : lo) st.push_back({s0 + d * g.d, g.d, g.u, g.v, -1});
    if (!lo.empty()) s0 = s0 + lo.back() * g.d;
    if (!hi.empty()) s1 = s1 - hi.back() * g.d;
    const double straight = g.length - t0 - t1 - (lo.empty() ? 0.0 : lo.back()) - (hi.empty() ? 0.0 : hi.back());
    const double first_min = k == 0 && lo.empty() ? end_min[0] : 0.0;
    const double last_min = k + 1 == n_legs && hi.empty() ? end_min[1] : 0.0;
    const std::vector<double> at = straight_stations(straight, ws.segment_length, first_min, last_min);
    for (size_t j = 0; j < at.size(); ++j)
      st.push_back({j + 1 == at.size() ? s1 : s0 + (at[j] / straight) * (s1 - s0), g.d, g.u, g.v, -1});
    for (int j = static_cast<int>(hi.size()) - 2; j >= -1; --j)  // hi.back() was s1
      st.push_back({j < 0 ? g.b : g.b - hi[j] * g.d, g.d, g.u, g.v, -1});
    if (k + 1 == n_legs) break;
    const Leg& h = legs[k + 1];
    const BendPlan* p = plan_at[k + 1];
    if (!p) continue;  // collinear: the leg's last station is the next leg's first
    st.back().bend_point = p->point;
    const double delta = p->radius * std::tan(0.5 * p->angle / p->wedges);
    for (int j = 1; j <= p->wedges; ++j) {
      const Station& prev = st.back();
      Station s;
      if (j == p->wedges) {
        s = {h.a + p->tangent * h.d, h.d, h.u, h.v, p->point};
      } else {
        const double a = p->angle * j / p->wedges;
        s.d = rotate_about(g.d, p->axis, a);
        s.u = rotate_about(g.u, p->axis, a);
        s.v = cross(s.d, s.u);
        s.p = prev.p + delta * (prev.d + s.d);
        s.bend_point = p->point;
      }
      st.push_back(s);
    }
  }
  return st;
}

// ---- Wedge counts for orthogonality at bends.
// Faces between two wedges are mirror planes (orthogonal); two faces of a bend are not
// (docs/anisotropy.md, "Bend wedges"): the cross-section where a straight cell meets the first
// (last) wedge, whose wedge centre lies nearer the arc's axis than the straight cell's, and a
// wedge's outer ring face, whose transition site lies on the normal through the face's
// circumcentre, off the wedge centre's normal line. Both leans fall as the wedge angle squared.

// The radius of ring i's FV centres: the geometric mean of its radii (the log form's).
double ring_centre_radius(const std::vector<double>& radii, int i) { return std::sqrt(radii[i] * radii[i + 1]); }

// FV centre of the radial cell (ring, sector) between stations a and b: the midpoint of the point
// at r_center on the mid-angle radial line of both cross-sections.
Vec3 radial_centre(const Station& a, const Station& b, double r_center, double phi_mid) {
  const double c = std::cos(phi_mid), s = std::sin(phi_mid);
  return 0.5 * (a.p + r_center * (c * a.u + s * a.v) + b.p + r_center * (c * b.u + s * b.v));
}

double angle_between(Vec3 a, Vec3 b) { return std::atan2(norm(cross(a, b)), std::abs(dot(a, b))); }

// Circumcentre of the triangle p0 p1 p2 (of a planar co-circular polygon through them).
Vec3 circumcentre(Vec3 p0, Vec3 p1, Vec3 p2) {
  const Vec3 a = p1 - p0, b = p2 - p0, n = cross(a, b);
  return p0 + cross(dot(a, a) * b - dot(b, b) * a, n) / (2.0 * dot(n, n));
}

// The largest lean (radians) at the bend whose stations carry bend_point == point: across the
// cross-sections joining the wedges to the straight cells, and between a wedge's outer ring
// cell and a transition site on its outer face's circumcentre normal, taken in the face's plane
// (site height 0: the bound for any height the transition gives it).
double bend_lean(const std::vector<Station>& st, int point, const std::vector<double>& radii, int sectors) {
  int first = -1, last = -1;
  for (int l = 0; l < static_cast<int>(st.size()); ++l)
    if (st[l].bend_point == point) {
      if (first < 0) first = l;
      last = l;
    }
  const int rings = static_cast<int>(radii.size()) - 1;
  const double sector_angle = 2.0 * kPi / sectors;
  double lean = 0;
  for (int i = 0; i < rings; ++i) {
    const double r_center = ring_centre_radius(radii, i);
    for (int s = 0; s < sectors; ++s) {
      const double phi = (s + 0.5) * sector_angle;
      for (int joint : {first, last}) {
        const int before = joint - 1, after = joint + 1;
        if (before < 0 || after >= static_cast<int>(st.size())) continue;
        const Vec3 d = radial_centre(st[joint], st[after], r_center, phi) - radial_centre(st[before], st[joint], r_center, phi);
        lean = std::max(lean, angle_between(d, st[joint].d));
      }
      if (i + 1 < rings) continue;
      const double r = radii[rings], p0 = s * sector_angle, p1 = p0 + sector_angle;
      for (int l = first; l < last; ++l) {
        const Station &a = st[l], &b = st[l + 1];
        auto at = [&](const Station& x, double q) { return x.p + r * (std::cos(q) * x.u + std::sin(q) * x.v); };
        const Vec3 n0 = at(a, p0), n1 = at(a, p1), n2 = at(b, p1);
        const Vec3 normal = normalized(cross(n1 - n0, n2 - n0));
        const Vec3 to_centre = radial_centre(a, b, r_center, phi) - circumcentre(n0, n1, n2);
        lean = std::max(lean, angle_between(to_centre, normal));
      }
    }
  }
  return lean;
}

// Leans above this raise the bend's wedge count (issue 15: 1 degree on every radial and
// transition face). The outer faces' lean is bounded at site height 0; the transition's sites
// sit higher, so fvcheck measures less. A tighter bound gives more, narrower wedges, which the
// transition holds less well (docs/anisotropy.md, "Session 34: wedges by their lean").
constexpr double kMaxBendLean = 1.0 * kPi / 180.0;
// More wedges than this per bend are not made: the lean stays above kMaxBendLean (a short
// straight cell beside a sharp bend) and the note says so.
constexpr int kMaxBendWedges = 24;

// The stations of make_stations with each bend's wedge count raised (plans updated) until
// its lean is at most kMaxBendLean or it has kMaxBendWedges wedges.
std::vector<Station> stations_with_orthogonal_bends(const WellSpec& ws, const std::vector<Leg>& legs,
                                                    std::vector<BendPlan>& plans, std::array<double, 2> end_min,
                                                    const std::vector<double>& radii, int sectors) {
  for (;;) {
    std::vector<Station> st = make_stations(ws, legs, plans, end_min);
    bool raised = false;
    for (BendPlan& p : plans) {
      p.lean = bend_lean(st, p.point, radii, sectors);
      if (p.lean > kMaxBendLean && p.wedges < kMaxBendWedges) {
        ++p.wedges;
        raised = true;
      }
    }
    if (!raised) return st;
  }
}

// The block's axis: its bends (wedge counts raised for orthogonality) and its stations, as
// make_well_block builds them with `sectors` sectors.
struct BlockAxis {
  std::vector<BendPlan> plans;
  std::vector<Station> stations;
};

BlockAxis block_axis(const CaseSpec& cs, int w, const WellSpec& ws, const std::vector<Leg>& legs,
                     const std::vector<double>& radii, int sectors) {
  const MeshedTrajectory mt = meshed_trajectory(cs.reservoir, cs.wells[w], well_key(w), false);
  std::array<double, 2> end_min{0.0, 0.0};
  for (int e = 0; e < 2; ++e)
    if (ws.end_caps == EndCaps::Flat && mt.ends[e] != WellEndKind::Boundary) end_min[e] = flat_end_min_segment(radii, sectors);
  BlockAxis axis;
  axis.plans = plan_bends(ws, w, legs);
  axis.stations = stations_with_orthogonal_bends(ws, legs, axis.plans, end_min, radii, sectors);
  return axis;
}

// Signed volume of a closed cell given as its 6 outward faces (fan around each face's node
// mean, as in compute_geometry).
double hexahedron_volume(const std::vector<Vec3>& x, const std::vector<CellFace>& faces) {
  Vec3 x0;
  std::array<Vec3, 6> mean{};
  for (size_t f = 0; f < faces.size(); ++f) {
    for (int32_t v : faces[f].nodes) mean[f] += x[v];
    mean[f] = mean[f] / static_cast<double>(faces[f].nodes.size());
    x0 += mean[f];
  }
  x0 = x0 / static_cast<double>(faces.size());
  double vol = 0;
  for (size_t f = 0; f < faces.size(); ++f) {
    const std::vector<int32_t>& nv = faces[f].nodes;
    for (size_t i = 0; i < nv.size(); ++i) {
      const Vec3 a = x[nv[i]], b = x[nv[(i + 1) % nv.size()]];
      vol += dot(mean[f] - x0, cross(a - x0, b - x0)) / 6.0;
    }
  }
  return vol;
}

// Where the Gabriel condition fails on a block's outer surface. On a straight leg the
// outer surface is made of rectangles: no vertex is inside an edge's diametral sphere
// (distance^2 = chord^2 + h^2 / 4 > h^2 / 4). Violations come from
// - the end faces: the angular edge of ring i contains the ring i-1 vertices at its two
//   angles iff r_{i-1} / r_i > cos(2 pi / sectors) (paper 5.1, "extremities"; with 3 sectors
//   the outer chords' spheres also reach end-face vertices); more sectors fix it;
// - the bends: the wedge quads are isosceles trapezoids; with wedges of at most 30 degrees
//   on a 1.5 R fillet their circumcentres lie inside them (no violation measured for bends
//   of 30-120 degrees with 6-24 sectors); a violation there is reported, not repaired.
struct GabrielDiagnosis {
  int total = 0, end_face = 0, bend = 0, other = 0;
  int cap = 0;               // violations involving a hemispherical cap's vertex (more sectors do not help)
  int bend_point = -1;       // trajectory point of the first bend with violations
  double bend_degrees = 0;
};

GabrielDiagnosis diagnose_gabriel(const WellBlock& block, const std::vector<Vec3>& trajectory) {
  GabrielDiagnosis diag;
  const std::vector<GabrielViolation> violations = gabriel_violations(block.nodes, block.surface_faces);
  diag.total = static_cast<int>(violations.size());
  if (violations.empty()) return diag;
  const std::vector<int32_t>& layer_point = block.layer_bend;
  const int per_layer = (block.rings + 1) * block.sectors;
  const int last = block.layers - 1;
  // Hemispherical caps' nodes come after the layers'. A cap's shells are Gabriel for every sector
  // count (tests/grids); a violation there means the cap reaches another part of the block.
  const int32_t layer_nodes = block.layers * per_layer;
  for (const GabrielViolation& v : violations) {
    if (v.a >= layer_nodes || v.b >= layer_nodes || v.p >= layer_nodes) {
      ++diag.cap;
      continue;
    }
    const int la = v.a / per_layer, lb = v.b / per_layer, lp = v.p / per_layer;
    int point = -1;
    for (int l : {la, lb, lp})
      if (layer_point[l] >= 0) point = layer_point[l];
    if (point < 0) {
      // Near an end: the offending vertex or the edge lies on an end face (with 3 sectors
      // the outer chords' spheres also reach into the end faces).
      const bool end = lp == 0 || lp == last || (la == lb && (la == 0 || la == last));
      ++(end ? diag.end_face : diag.other);
      continue;
    }
    ++diag.bend;
    if (diag.bend_point < 0 || point < diag.bend_point) diag.bend_point = point;
  }
  if (diag.bend_point > 0) {
    const Vec3 d1 = normalized(trajectory[diag.bend_point] - trajectory[diag.bend_point - 1]);
    const Vec3 d2 = normalized(trajectory[diag.bend_point + 1] - trajectory[diag.bend_point]);
    diag.bend_degrees = bend_degrees(d1, d2);
  }
  return diag;
}

// Smallest sector count whose end faces are Gabriel for the ring ratio q = r_{i+1} / r_i.
int min_end_face_sectors(double ratio) {
  int n = 4;
  while (std::cos(2.0 * kPi / n) < 1.0 / ratio) ++n;
  return n;
}

// Smallest sector count whose ring cells hold their FV centre (at sqrt(r_in r_out), inside the
// outer chord at r_out cos(pi / n) iff cos(pi / n) > 1 / sqrt(q)).
int min_centred_sectors(double ratio) {
  int n = 3;
  while (!(std::cos(kPi / n) > 1.0 / std::sqrt(ratio))) ++n;
  return n;
}

// Radial cells whose FV centre is not strictly on the inner side of every face plane. With flat
// ends the end faces' Gabriel rule (cos(2 pi / n) >= 1 / q) raises the sectors beyond
// min_centred_sectors; hemispherical caps have no end faces, so it is checked directly.
int count_off_centre_cells(const WellBlock& b) {
  int off = 0;
  for (size_t c = 0; c < b.cell_faces.size(); ++c) {
    const Vec3 x = b.cell_attrs[c].fv_center;
    for (const CellFace& f : b.cell_faces[c]) {
      Vec3 area, mean;
      const size_t k = f.nodes.size();
      for (size_t i = 0; i < k; ++i) {
        area += cross(b.nodes[f.nodes[i]], b.nodes[f.nodes[(i + 1) % k]]);
        mean += b.nodes[f.nodes[i]];
      }
      if (!(dot(area, x - mean / static_cast<double>(k)) < 0)) {
        ++off;
        break;
      }
    }
  }
  return off;
}

double regular_polygon_area(int n, double r) { return 0.5 * n * r * r * std::sin(2.0 * kPi / n); }

// ---- Hemispherical end caps (paper 5.1: "segments of a sphere ... on each extremity").
// The cap at an end point E (outward axis a, the end cross-section's frame u, v) continues
// the rings as spherical shells: node (ring i, latitude j, sector s) is
// E + r_i (cos alpha_j (cos phi_s u + sin phi_s v) + sin alpha_j a), alpha_0 = 0 (the end
// cross-section's own nodes), alpha_B = pi/2 (one pole node per ring). Every face is planar
// and co-circular: shell and cone faces are isosceles trapezoids (a node pair and its mirror
// image through the sector's mid-meridian plane), meridian faces lie in a plane through the
// axis with two nodes on each of two circles about E, polar shell faces are isosceles triangles.
// The FV centre of cell (i, j, s) is E + sqrt(r_i r_{i+1}) (cos beta_j m_s + sin beta_j a) on
// the mid-meridian m_s, with beta_j the direction of the circumcentre of the band's shell
// faces, so the shell faces are orthogonal to the centre-to-centre segments; the interior
// band limits alpha_1..alpha_{B-1} are chosen so that each cone face is orthogonal too:
// its plane contains the ray at latitude atan(tan(alpha) / cos(h)) (h = half the sector
// angle), which must bisect the two centre latitudes beta_{j-1} and beta_j.
struct CapLatitudes {
  std::vector<double> alpha;  // B + 1 band limits
  std::vector<double> beta;   // B FV-centre latitudes
};

CapLatitudes cap_latitudes(int bands, double sector_angle) {
  const double ch = std::cos(0.5 * sector_angle);
  CapLatitudes c;
  c.alpha.resize(bands + 1);
  c.beta.resize(bands);
  for (int j = 0; j <= bands; ++j) c.alpha[j] = 0.5 * kPi * j / bands;
  auto circumcentre_latitude = [&](double a0, double a1) {
    return std::atan2(ch * (std::cos(a0) - std::cos(a1)), std::sin(a1) - std::sin(a0));
  };
  // Fixed point (a contraction, slower with more bands: 178 steps for 4 bands, 1855 for 13,
  // measured; the bound leaves room for ~100 sectors).
  for (int it = 0; it < 100000; ++it) {
    for (int j = 0; j < bands; ++j) c.beta[j] = circumcentre_latitude(c.alpha[j], c.alpha[j + 1]);
    double change = 0;
    for (int j = 1; j < bands; ++j) {
      const double next = std::atan(ch * std::tan(0.5 * (c.beta[j - 1] + c.beta[j])));
      change = std::max(change, std::abs(next - c.alpha[j]));
      c.alpha[j] = next;
    }
    if (change < 1e-15) break;
  }
  c.alpha[bands] = 0.5 * kPi;
  for (int j = 0; j < bands; ++j) c.beta[j] = circumcentre_latitude(c.alpha[j], c.alpha[j + 1]);
  return c;
}

// Distance from the cap centre E of the FV centres of a ring whose cylinder cells have theirs at
// `cylinder_r_center` from the axis.
double cap_centre_distance(double cylinder_r_center, const CapLatitudes& lat) {
  return cylinder_r_center / std::cos(lat.beta[0]);
}

// Orients a closed convex cell's faces outward (normal away from the mean of its nodes).
void orient_outward(const std::vector<Vec3>& x, std::vector<CellFace>& faces) {
  Vec3 inside;
  int n = 0;
  for (const CellFace& f : faces)
    for (int32_t v : f.nodes) inside += x[v], ++n;
  inside = inside / static_cast<double>(n);
  for (CellFace& f : faces) {
    Vec3 normal, mean;
    const size_t k = f.nodes.size();
    for (size_t i = 0; i < k; ++i) {
      normal += cross(x[f.nodes[i]], x[f.nodes[(i + 1) % k]]);
      mean += x[f.nodes[i]];
    }
    if (dot(normal, mean / static_cast<double>(k) - inside) < 0) std::reverse(f.nodes.begin(), f.nodes.end());
  }
}

}  // namespace

WellBlock make_well_block(const CaseSpec& cs, int w, int sectors) {
  if (w < 0 || w >= static_cast<int>(cs.wells.size())) throw std::out_of_range("make_well_block: no well " + std::to_string(w));
  validate_well(cs.wells[w], w, sectors);
  // Only the part of the trajectory inside the reservoir is meshed (meshed_trajectory.hpp).
  const MeshedTrajectory mt = meshed_trajectory(cs.reservoir, cs.wells[w], well_key(w), false);
  const WellSpec ws = block_well_spec(cs, w);

  WellBlock block;
  block.well = w;
  block.trajectory = ws.trajectory;
  for (int e = 0; e < 2; ++e) {
    block.boundary_end[e] = mt.ends[e] == WellEndKind::Boundary;
    block.boundary_axis[e] = block.boundary_end[e] ? mt.plane_axis[e] : -1;
    block.boundary_value[e] = mt.plane_value[e];
    if (mt.ends[e] != WellEndKind::Inside)
      block.notes.push_back(well_label(cs, w) + ": the trajectory crosses " +
                            boundary_plane_name(mt.plane_axis[e], mt.plane_upper[e], mt.plane_value[e]) +
                            (mt.ends[e] == WellEndKind::Boundary
                                 ? ": the radial block ends in that plane (its end faces are outer-boundary faces)"
                                 : ": the radial block ends " + num(mt.retraction[e]) +
                                       " m inside (flat end), the transition mesh fills the rest up to the plane"));
  }
  if (mt.drainage_radius < cs.wells[w].drainage_radius)
    block.notes.push_back(well_label(cs, w) + ": drainage radius lowered from " + num(cs.wells[w].drainage_radius) +
                          " to " + num(mt.drainage_radius) + " m: the radial block lies between two opposite boundary "
                          "planes and keeps " + num(kBoundaryGap) + " x drainage_radius from both");
  if (cs.wells[w].end_caps == EndCaps::Hemisphere && ws.end_caps == EndCaps::Flat)
    block.notes.push_back(well_label(cs, w) + ": closed with flat ends (end_caps: auto): hemispherical caps do not fit "
                                              "between the trajectory's ends and the reservoir boundary");
  block.rings = ws.rings;
  block.sectors = sectors;
  block.sectors_requested = ws.sectors;
  block.radii = ring_radii(ws);

  std::vector<double> cos_s(sectors), sin_s(sectors);
  for (int s = 0; s < sectors; ++s) {
    const double phi = 2.0 * kPi * s / sectors;
    cos_s[s] = std::cos(phi);
    sin_s[s] = std::sin(phi);
  }

  const std::vector<Leg> legs = make_legs(ws, w);
  const BlockAxis axis = block_axis(cs, w, ws, legs, block.radii, sectors);
  const std::vector<BendPlan>& plans = axis.plans;
  const std::vector<Station>& stations = axis.stations;
  const int n_layers = static_cast<int>(stations.size());
  block.layers = n_layers;
  for (const Station& st : stations) {
    block.layer_center.push_back(st.p);
    block.layer_bend.push_back(st.bend_point);
  }
  for (const BendPlan& p : plans) {
    const Vec3 d1 = legs[p.point - 1].d, d2 = legs[p.point].d;
    const Vec3 inward = normalized(d2 - dot(d1, d2) * d1);  // from the first leg toward the arc's centre
    block.bend_axes.push_back({ws.trajectory[p.point] - p.tangent * d1 + p.radius * inward, p.axis, p.radius});
  }
  for (const BendPlan& p : plans)
    block.notes.push_back(well_label(cs, w) + ": bend of " + num(p.angle * 180 / kPi) + " degrees at trajectory point " +
                          std::to_string(p.point) + " meshed as " + std::to_string(p.wedges) +
                          " mirror wedge(s) on an arc of radius " + num(p.radius) + " m: the wellbore axis leaves the"
                          " trajectory " + num(p.tangent) + " m before the point and passes " +
                          num(polyline_distance({ws.trajectory[p.point]}, block.layer_center)) + " m from it" +
                          (p.lean > kMaxBendLean ? "; its faces lean up to " + num(p.lean * 180 / kPi) +
                                                       " degrees off orthogonal (" + std::to_string(kMaxBendWedges) +
                                                       " wedges at most; a longer leg beside it gives less)"
                                                 : ""));

  // Nodes: local id = (layer * (rings + 1) + ring) * sectors + sector.
  const int rings = ws.rings;
  const int per_layer = (rings + 1) * sectors;
  block.nodes.reserve(static_cast<size_t>(n_layers) * per_layer);
  for (const Station& st : stations)
    for (int i = 0; i <= rings; ++i)
      for (int s = 0; s < sectors; ++s) block.nodes.push_back(st.p + block.radii[i] * (cos_s[s] * st.u + sin_s[s] * st.v));
  auto node = [&](int l, int i, int s) { return static_cast<int32_t>((l * (rings + 1) + i) * sectors + s % sectors); };

  // Attributes shared by every radial cell, cylinder and caps.
  const double sector_angle = 2.0 * kPi / sectors;
  auto radial_cell = [&](int ring, int sector, int segment) {
    CellAttributes at;
    at.region = kWell;
    at.perm = cs.reservoir.permeability;
    at.porosity = cs.reservoir.porosity;
    RadialCellInfo& rad = at.radial;
    rad.well = w;
    rad.ring = ring;
    rad.sector = sector;
    rad.segment = segment;
    rad.r_in = block.radii[ring];
    rad.r_out = block.radii[ring + 1];
    rad.r_center = ring_centre_radius(block.radii, ring);
    rad.angle = sector_angle;
    return at;
  };

  // Cells: id = (segment * rings + ring) * sectors + sector.
  const int32_t wellbore = wellbore_patch(w);
  const int n_segments = n_layers - 1;
  block.cell_faces.reserve(static_cast<size_t>(n_segments) * rings * sectors);
  block.cell_attrs.reserve(static_cast<size_t>(n_segments) * rings * sectors);
  for (int l = 0; l < n_segments; ++l) {
    const Station &s0 = stations[l], &s1 = stations[l + 1];
    const double length = norm(s1.p - s0.p);
    for (int i = 0; i < rings; ++i)
      for (int s = 0; s < sectors; ++s) {
        const int32_t a = node(l, i, s), b = node(l, i, s + 1), c = node(l, i + 1, s + 1), d = node(l, i + 1, s);
        const int32_t a2 = node(l + 1, i, s), b2 = node(l + 1, i, s + 1), c2 = node(l + 1, i + 1, s + 1),
                      d2 = node(l + 1, i + 1, s);
        // Outward: (u, v, d) is right handed and sectors turn from u toward v.
        std::vector<CellFace> faces(6);
        faces[0] = {{a, a2, b2, b}, i == 0 ? wellbore : kInteriorFace};  // inner ring face (wellbore at ring 0)
        faces[1] = {{d, c, c2, d2}, kInteriorFace};                     // outer ring face
        faces[2] = {{a, d, d2, a2}, kInteriorFace};                     // angular face at sector s
        faces[3] = {{b, b2, c2, c}, kInteriorFace};                     // angular face at sector s + 1
        // axial faces on layers l and l + 1; an end lying in a boundary plane is outer boundary
        faces[4] = {{a, b, c, d}, l == 0 && block.boundary_end[0] ? kOuterBoundary : kInteriorFace};
        faces[5] = {{a2, d2, c2, b2}, l + 1 == n_segments && block.boundary_end[1] ? kOuterBoundary : kInteriorFace};
        const double vol = hexahedron_volume(block.nodes, faces);
        if (!(vol > 0))
          throw InputError(well_key(w) + ".trajectory: radial cell (ring " + std::to_string(i) + ", sector " +
                           std::to_string(s) + ", segment " + std::to_string(l) + ") is inverted (volume " + num(vol) +
                           " m3)");
        CellAttributes at = radial_cell(i, s, l);
        const RadialCellInfo& rad = at.radial;
        at.radial.length = length;
        // Ring and angular faces exactly orthogonal on straight parts; on the mirror plane in a wedge.
        at.fv_center = radial_centre(s0, s1, rad.r_center, (s + 0.5) * sector_angle);
        block.cell_faces.push_back(std::move(faces));
        block.cell_attrs.push_back(at);
      }
  }
  auto cell = [&](int l, int i, int s) { return static_cast<int32_t>((l * rings + i) * sectors + s); };

  // Hemispherical caps (cap_latitudes): cells appended after the cylinder's, nodes after its
  // nodes; the end cross-section's nodes are the caps' latitude-0 nodes. cap_outer collects
  // the outermost ring's shell faces (cell id, face index): the caps' part of the outer surface.
  std::vector<std::pair<int32_t, int>> cap_outer;
  auto add_cap = [&](bool at_start) {
    const int bands = hemisphere_cap_bands(sectors);
    const CapLatitudes lat = cap_latitudes(bands, sector_angle);
    const int layer = at_start ? 0 : n_layers - 1;
    const Station& st = stations[layer];
    const Vec3 e = st.p, a = at_start ? -1.0 * st.d : st.d;
    const int32_t base = static_cast<int32_t>(block.nodes.size());
    // Nodes: latitudes 1..B-1 ((j - 1) * (rings + 1) + i) * sectors + s, then one pole per ring.
    for (int j = 1; j < bands; ++j)
      for (int i = 0; i <= rings; ++i)
        for (int s = 0; s < sectors; ++s)
          block.nodes.push_back(e + block.radii[i] * (std::cos(lat.alpha[j]) * (cos_s[s] * st.u + sin_s[s] * st.v) +
                                                      std::sin(lat.alpha[j]) * a));
    const int32_t pole_base = static_cast<int32_t>(block.nodes.size());
    for (int i = 0; i <= rings; ++i) block.nodes.push_back(e + block.radii[i] * a);
    auto cap_node = [&](int i, int j, int s) -> int32_t {
      if (j == 0) return node(layer, i, s);
      if (j == bands) return pole_base + i;
      return base + static_cast<int32_t>(((j - 1) * (rings + 1) + i) * sectors + s % sectors);
    };
    for (int j = 0; j < bands; ++j)
      for (int i = 0; i < rings; ++i)
        for (int s = 0; s < sectors; ++s) {
          const int32_t A = cap_node(i, j, s), B = cap_node(i, j, s + 1), C = cap_node(i + 1, j, s + 1),
                        D = cap_node(i + 1, j, s);
          const int32_t A2 = cap_node(i, j + 1, s), B2 = cap_node(i, j + 1, s + 1), C2 = cap_node(i + 1, j + 1, s + 1),
                        D2 = cap_node(i + 1, j + 1, s);
          const bool polar = j + 1 == bands;  // A2 == B2 and C2 == D2: the pole nodes
          std::vector<CellFace> faces;
          faces.push_back({polar ? std::vector<int32_t>{A, B, B2} : std::vector<int32_t>{A, B, B2, A2},
                           i == 0 ? wellbore : kInteriorFace});  // inner shell (wellbore at ring 0)
          faces.push_back({polar ? std::vector<int32_t>{D, C, C2} : std::vector<int32_t>{D, C, C2, D2},
                           kInteriorFace});                                       // outer shell
          faces.push_back({{A, D, D2, A2}, kInteriorFace});                       // meridian at sector s
          faces.push_back({{B, C, C2, B2}, kInteriorFace});                       // meridian at sector s + 1
          faces.push_back({{A, B, C, D}, kInteriorFace});                         // cone at alpha_j (end plane: j = 0)
          if (!polar) faces.push_back({{A2, B2, C2, D2}, kInteriorFace});         // cone at alpha_{j+1}
          orient_outward(block.nodes, faces);
          const double vol = hexahedron_volume(block.nodes, faces);
          if (!(vol > 0))
            throw InputError(well_key(w) + ".end_caps: cap cell (ring " + std::to_string(i) + ", band " +
                             std::to_string(j) + ", sector " + std::to_string(s) + ") is degenerate (volume " +
                             num(vol) + " m3)");
          CellAttributes at = radial_cell(i, s, at_start ? -1 : n_segments);
          RadialCellInfo& rad = at.radial;
          rad.band = j;
          rad.cap_center = e;
          // Every centre of ring i at one distance from E keeps the shell, cone and meridian faces
          // orthogonal; r_center / cos(beta_0) puts band 0's centre straight above the cylinder's
          // (at r_center from the axis), so the end plane is orthogonal too.
          rad.r_center = cap_centre_distance(rad.r_center, lat);
          const double phi_mid = (s + 0.5) * sector_angle;
          const Vec3 m = std::cos(phi_mid) * st.u + std::sin(phi_mid) * st.v;
          at.fv_center = e + rad.r_center * (std::cos(lat.beta[j]) * m + std::sin(lat.beta[j]) * a);
          if (i + 1 == rings) cap_outer.push_back({static_cast<int32_t>(block.cell_faces.size()), 1});
          block.cell_faces.push_back(std::move(faces));
          block.cell_attrs.push_back(at);
        }
  };
  const bool hemispheres = ws.end_caps == EndCaps::Hemisphere;
  block.hemisphere_caps = hemispheres;
  if (hemispheres) {
    add_cap(true);
    add_cap(false);
  }

  // Outer surface, normals out of the block.
  auto add_surface = [&](std::vector<int32_t> poly, int32_t c, int32_t patch) {
    block.surface_faces.push_back(std::move(poly));
    block.surface_cell.push_back(c);
    block.surface_patch.push_back(patch);
  };
  for (int l = 0; l < n_segments; ++l)
    for (int s = 0; s < sectors; ++s)
      add_surface(block.cell_faces[cell(l, rings - 1, s)][1].nodes, cell(l, rings - 1, s), kInteriorFace);
  if (hemispheres) {
    for (const auto& [c, k] : cap_outer) add_surface(block.cell_faces[c][k].nodes, c, kInteriorFace);
    return block;
  }
  // Flat ends: the end annulus and the cap polygon over the wellbore, except at an end lying in
  // a boundary plane (no flow there, nothing for the transition to claim).
  for (int i = 0; i < rings; ++i)
    for (int s = 0; s < sectors; ++s) {
      if (!block.boundary_end[0]) add_surface(block.cell_faces[cell(0, i, s)][4].nodes, cell(0, i, s), kInteriorFace);
      if (!block.boundary_end[1])
        add_surface(block.cell_faces[cell(n_segments - 1, i, s)][5].nodes, cell(n_segments - 1, i, s), kInteriorFace);
    }
  std::vector<int32_t> start_cap, end_cap;
  for (int s = 0; s < sectors; ++s) {
    start_cap.push_back(node(0, 0, sectors - 1 - s));
    end_cap.push_back(node(n_layers - 1, 0, s));
  }
  if (!block.boundary_end[0]) add_surface(std::move(start_cap), -1, wellbore);
  if (!block.boundary_end[1]) add_surface(std::move(end_cap), -1, wellbore);
  return block;
}

int count_gabriel_violations(const WellBlock& block) {
  return static_cast<int>(gabriel_violations(block.nodes, block.surface_faces).size());
}

WellBlock make_gabriel_well_block(const CaseSpec& cs, int w) {
  if (w < 0 || w >= static_cast<int>(cs.wells.size()))
    throw std::out_of_range("make_gabriel_well_block: no well " + std::to_string(w));
  const WellSpec ws = block_well_spec(cs, w);
  const int requested = ws.sectors;
  int sectors = requested;
  WellBlock block;
  // Raising sectors only helps the end faces and the cells' centring (see diagnose_gabriel):
  // stop as soon as a violation elsewhere appears.
  bool for_gabriel = false, for_centres = false;
  for (;;) {
    block = make_well_block(cs, w, sectors);
    const GabrielDiagnosis diag = diagnose_gabriel(block, ws.trajectory);
    const int off_centre = count_off_centre_cells(block);
    if (diag.total == 0 && off_centre == 0) break;
    const std::string label = well_label(cs, w);
    if (diag.cap > 0)
      throw InputError(label + ": the outer surface of the radial block is not Gabriel next to a hemispherical end cap (" +
                       std::to_string(diag.cap) + " violations: the cap, which reaches drainage_radius beyond the end "
                       "point, comes close to another part of the block); use a smaller drainage_radius or "
                       "end_caps: flat");
    if (diag.bend > 0)
      throw InputError(label + ": the outer surface of the radial block is not Gabriel next to the bend of " +
                       num(diag.bend_degrees) + " degrees at trajectory point " + std::to_string(diag.bend_point) +
                       " with " + std::to_string(sectors) + " sectors (" + std::to_string(diag.bend) +
                       " surface vertices inside diametral spheres of edges of the bend's wedges; a longer"
                       " segment_length or a gentler bend gives wider wedges" +
                       (sectors > requested ? "; the end faces needed " + std::to_string(sectors) + " sectors" : "") +
                       ")");
    if (diag.other > 0)
      throw InputError(label + ": the outer surface of the radial block is not Gabriel with " +
                       std::to_string(sectors) + " sectors (" + std::to_string(diag.other) + " violations)");
    for_gabriel = for_gabriel || diag.end_face > 0;
    for_centres = for_centres || off_centre > 0;
    const int next = sectors % 2 == 0 ? sectors + 2 : sectors + 1;
    if (next > 4 * requested) {
      const double ratio = block.radii[1] / block.radii[0];
      if (diag.end_face > 0)
        throw InputError(label + ": the end faces of the radial block are not Gabriel even with " +
                         std::to_string(sectors) + " sectors (4x the " + std::to_string(requested) + " requested, " +
                         std::to_string(diag.end_face) + " violations): the ring radius ratio " + num(ratio) +
                         " needs cos(2 pi / sectors) >= 1 / " + num(ratio) + ", i.e. at least " +
                         std::to_string(min_end_face_sectors(ratio)) + " sectors; use fewer rings");
      throw InputError(label + ": " + std::to_string(off_centre) + " radial cells do not contain their FV centre even with " +
                       std::to_string(sectors) + " sectors (4x the " + std::to_string(requested) +
                       " requested): the ring radius ratio " + num(ratio) + " needs cos(pi / sectors) > 1 / sqrt(" +
                       num(ratio) + "), i.e. at least " + std::to_string(min_centred_sectors(ratio)) +
                       " sectors; use fewer rings");
    }
    sectors = next;
  }
  block.sectors_requested = requested;
  if (sectors != requested)
    block.notes.push_back(well_label(cs, w) + ": sectors raised from " + std::to_string(requested) + " to " +
                          std::to_string(sectors) +
                          (for_gabriel ? " for the Gabriel condition" : " so that every radial cell holds its FV centre") +
                          (for_gabriel && for_centres ? " and the cells' centring" : ""));
  // A radial cell replaces the reservoir rock around its FV centre: it takes the rock of the
  // model cell that holds that centre.
  for (CellAttributes& at : block.cell_attrs) assign_reservoir_rock(cs.reservoir, reservoir_cell_at(cs.reservoir, at.fv_center), at);
  return block;
}

std::vector<Vec3> meshed_axis(const WellBlock& block) {
  std::vector<Vec3> axis;
  for (int l = 0; l < block.layers; ++l)
    if (l == 0 || l + 1 == block.layers || block.layer_bend[l] >= 0) axis.push_back(block.layer_center[l]);
  return axis;
}

std::vector<int32_t> add_well_block_nodes(const WellBlock& block, MeshBuilder& builder) {
  std::vector<int32_t> ids(block.nodes.size());
  for (size_t i = 0; i < block.nodes.size(); ++i) ids[i] = builder.add_node(block.nodes[i]);
  return ids;
}

void add_well_block_cells(const WellBlock& block, const std::vector<int32_t>& ids, MeshBuilder& builder) {
  for (size_t c = 0; c < block.cell_faces.size(); ++c) {
    std::vector<CellFace> faces = block.cell_faces[c];
    for (CellFace& f : faces)
      for (int32_t& v : f.nodes) v = ids[v];
    builder.add_cell(faces, block.cell_attrs[c]);
  }
}

std::vector<int32_t> add_well_block(const WellBlock& block, MeshBuilder& builder) {
  std::vector<int32_t> ids = add_well_block_nodes(block, builder);
  add_well_block_cells(block, ids, builder);
  return ids;
}

double well_block_prism_length(const CaseSpec& cs, int w, int sectors) {
  const WellSpec ws = block_well_spec(cs, w);
  const std::vector<Leg> legs = make_legs(ws, w);
  double length = 0;
  for (const Leg& g : legs) length += g.length;
  // A wedge of angle a and half length delta is the prism along its mirror normal over the
  // cross-section projected on the mirror plane (area A cos(a/2)), of height 2 |h| with h
  // affine over it and equal to delta cos(a/2) at the centre: volume A x 2 delta cos^2(a/2).
  // The k wedges of a bend replace the 2 t of straight legs around the bend point.
  for (const BendPlan& p : block_axis(cs, w, ws, legs, ring_radii(ws), sectors).plans) {
    const double a = p.angle / p.wedges, delta = p.radius * std::tan(0.5 * a), c = std::cos(0.5 * a);
    length += p.wedges * 2.0 * delta * c * c - 2.0 * p.tangent;
  }
  return length;
}

double hemisphere_cap_volume(double radius, int sectors) {
  // The cap's polyhedral half-ball is the union of the pyramids from its centre E over its
  // shell faces (E lies in the plane of its remaining face, the end cross-section).
  const int bands = hemisphere_cap_bands(sectors);
  const double angle = 2.0 * kPi / sectors;
  const CapLatitudes lat = cap_latitudes(bands, angle);
  auto at = [&](double alpha, double phi) {
    return radius * Vec3{std::cos(alpha) * std::cos(phi), std::cos(alpha) * std::sin(phi), std::sin(alpha)};
  };
  double volume = 0;
  for (int j = 0; j < bands; ++j) {
    const Vec3 a = at(lat.alpha[j], 0), b = at(lat.alpha[j], angle), c = at(lat.alpha[j + 1], angle),
               d = at(lat.alpha[j + 1], 0);
    // Tetrahedra E-a-b-c and E-a-c-d (the second vanishes at the pole, where c = d).
    volume += (std::abs(dot(a, cross(b, c))) + std::abs(dot(a, cross(c, d)))) / 6.0;
  }
  return sectors * volume;
}

double exact_well_block_volume(const CaseSpec& cs, int w, int sectors) {
  const WellSpec ws = block_well_spec(cs, w);
  const double annulus = regular_polygon_area(sectors, ws.drainage_radius) - regular_polygon_area(sectors, ws.radius);
  const double caps = ws.end_caps == EndCaps::Hemisphere
                          ? 2.0 * (hemisphere_cap_volume(ws.drainage_radius, sectors) -
                                   hemisphere_cap_volume(ws.radius, sectors))
                          : 0.0;
  return annulus * well_block_prism_length(cs, w, sectors) + caps;
}

double exact_wellbore_hole_volume(const CaseSpec& cs, int w, int sectors) {
  const WellSpec ws = block_well_spec(cs, w);
  const double caps = ws.end_caps == EndCaps::Hemisphere ? 2.0 * hemisphere_cap_volume(ws.radius, sectors) : 0.0;
  return regular_polygon_area(sectors, ws.radius) * well_block_prism_length(cs, w, sectors) + caps;
}

}  // namespace hm
