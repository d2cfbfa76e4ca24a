// Sites of the transition mesh (paper 5.4-5.5): placement, empty-sphere repair and the
// auto-centering correction. CGAL-free.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "transition_internal.hpp"

namespace hm::transition_detail {

namespace {

// Relative slack of the empty-sphere test: a vertex counts as inside a sphere only when
// its power is below -kEmptySlack * w^2. Own vertices are excluded, so this only absorbs
// the rounding of vertices that are co-spherical by construction (lattice nodes).
constexpr double kEmptySlack = 1e-10;
constexpr double kShrink = 0.7;  // alpha of 5.5.3 (paper: 0.7 <= alpha < 1)
// A polygon site never comes closer to its polygon than this fraction of the circumradius:
// at t = 0 it would coincide with its reflection (same weighted point, one of them hidden).
constexpr double kMinT = 1e-3;
// Below kMinT rho a site moves only to the distance one violating pair asks for
// (deep_t_satisfying), never closer than this fraction of the circumradius.
constexpr double kMinDeepT = 1e-8;
// Height of an end-face polygon's site above its polygon, in lengths of the block's end
// segment: the mirror image of the ring cell's FV centre, which lies half a segment behind the
// face (docs/transition.md "Tip sites").
constexpr double kEndFaceHeight = 0.5;
// Relative slack of the wall-column rule (align_wall_columns): a site placed at a height is read
// back through its position, rounded; only a height above this is lowered again.
constexpr double kColumnSlack = 1e-12;

double shrunk(double t, double alpha, double radius) { return std::max(alpha * t, std::min(t, kMinT * radius)); }

struct Box {
  Vec3 center;
  double w2 = 0;
};

Box reservoir_box(const ReservoirGrid& grid, int cell) {
  const auto ijk = grid.cell_ijk(cell);
  const Vec3 lo{grid.x[ijk[0]], grid.y[ijk[1]], grid.z[ijk[2]]};
  const Vec3 hi{grid.x[ijk[0] + 1], grid.y[ijk[1] + 1], grid.z[ijk[2] + 1]};
  Box b;
  b.center = 0.5 * (lo + hi);
  const Vec3 h = 0.5 * (hi - lo);
  b.w2 = dot(h, h);
  return b;
}

std::vector<int32_t> vertices_of(const Cavity& cavity, const std::vector<int>& polygons) {
  std::vector<int32_t> v;
  for (int q : polygons) v.insert(v.end(), cavity.faces[q].nodes.begin(), cavity.faces[q].nodes.end());
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  return v;
}

double mean_w2(Vec3 p, const std::vector<int32_t>& nodes, const std::vector<Vec3>& coords) {
  double s = 0;
  for (int32_t v : nodes) s += norm2(coords[v] - p);
  return s / static_cast<double>(nodes.size());
}

// Re-derives the mirror of polygon q from its internal site (5.4.2).
void update_mirror(SiteSet& set, int q, const std::vector<PolygonFrame>& frames) {
  const int e = set.external_of[q];
  if (e < 0 || set.sites[e].kind != SiteKind::ExternalMirror) return;
  const Site& in = set.sites[set.internal_of[q]];
  set.sites[e].p = 2.0 * frames[q].center - in.p;
  set.sites[e].w2 = in.w2;
  set.sites[e].unchecked = true;
}

}  // namespace

// Places the internal polygon site s at O + t n with the weight of its constrained vertices.
void place_polygon_site(SiteSet& set, int s, double t, const Cavity& cavity, const std::vector<Vec3>& coords,
                        const std::vector<PolygonFrame>& frames) {
  Site& site = set.sites[s];
  const int q = site.polygon;
  site.t = t;
  site.unchecked = true;
  site.p = frames[q].center + t * frames[q].normal;
  site.w2 = mean_w2(site.p, cavity.faces[q].nodes, coords);
  update_mirror(set, q, frames);
}

namespace {

// Paper 5.4.1 (n = 1): midpoint of [O V]. When the external site is a mirror, its sphere
// must stay empty too, which bounds t by the external Voronoi vertex: t <= -t_out.
double initial_t(const SiteSet& set, int q, const std::vector<PolygonFrame>& frames) {
  const PolygonFrame& f = frames[q];
  double reach = f.t_in;
  const int e = set.external_of[q];
  if (e >= 0 && set.sites[e].kind == SiteKind::ExternalMirror) reach = std::min(reach, -f.t_out);
  if (!(reach > 0) || !std::isfinite(reach)) reach = f.radius;  // not Delaunay: fall back on rho
  return 0.5 * reach;
}

// A site of one polygon (placed by the caller); returns its id.
int push_polygon_site(SiteSet& set, SiteKind kind, int q, const Cavity& cavity) {
  Site s;
  s.kind = kind;
  s.polygon = q;
  s.polygons = {q};
  s.vertices = vertices_of(cavity, s.polygons);
  set.sites.push_back(s);
  const int id = static_cast<int>(set.sites.size()) - 1;
  (kind == SiteKind::ExternalMirror ? set.external_of : set.internal_of)[q] = id;
  return id;
}

int add_polygon_site(SiteSet& set, int q, const Cavity& cavity, const std::vector<Vec3>& coords,
                     const std::vector<PolygonFrame>& frames) {
  const int id = push_polygon_site(set, SiteKind::InternalPolygon, q, cavity);
  place_polygon_site(set, id, initial_t(set, q, frames), cavity, coords, frames);
  return id;
}

int add_mirror_site(SiteSet& set, int q, const Cavity& cavity, const std::vector<PolygonFrame>& frames) {
  const int id = push_polygon_site(set, SiteKind::ExternalMirror, q, cavity);
  update_mirror(set, q, frames);
  return id;
}

}  // namespace

// Largest t of polygon q's internal site that keeps its sphere (and its reflection's) clearly
// empty, within the site's own cap (end faces, place_end_face_sites).
double max_t(const SiteSet& set, int q, const std::vector<PolygonFrame>& frames) {
  const int in = set.internal_of[q];
  const double cap = in >= 0 ? set.sites[in].t_cap : kInf;
  return std::min(0.95 * 2.0 * initial_t(set, q, frames), cap);
}

double min_t(const std::vector<PolygonFrame>& frames, int q) { return 1.0001 * kMinT * frames[q].radius; }

namespace {

// A hash of what the correction's next iteration depends on: every site's kind, liveness, point and
// weight, and how recently it was shrunk (only whether within kNoGrowAfterShrink matters).
uint64_t correction_state_hash(const SiteSet& set, const std::vector<int>& shrunk_at, int it, int no_grow_after_shrink) {
  uint64_t h = 0x9e3779b97f4a7c15ull;
  auto mix = [&](uint64_t word) {  // a word at a time: splitmix64's finaliser on the running value
    h ^= word + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
    h = (h ^ (h >> 30)) * 0xbf58476d1ce4e5b9ull;
    h = (h ^ (h >> 27)) * 0x94d049bb133111ebull;
    h ^= h >> 31;
  };
  auto bits = [](double v) {
    uint64_t u;
    std::memcpy(&u, &v, sizeof u);
    return u;
  };
  mix(set.sites.size());
  for (size_t s = 0; s < set.sites.size(); ++s) {
    const Site& site = set.sites[s];
    mix(static_cast<uint64_t>(site.kind) * 2 + (site.alive ? 1 : 0));
    if (!site.alive) continue;
    mix(bits(site.p.x)), mix(bits(site.p.y)), mix(bits(site.p.z)), mix(bits(site.w2));
    const int since = s < shrunk_at.size() ? it - shrunk_at[s] : no_grow_after_shrink + 1;
    mix(static_cast<uint64_t>(std::min(since, no_grow_after_shrink + 1)));
  }
  return h;
}

// Whether shrink_or_split can still change site s: boxes can be split, polygon sites (or
// the partner of a reflection) can move while above their minimal distance.
bool can_shrink(const SiteSet& set, int s, const std::vector<PolygonFrame>& frames) {
  const Site& site = set.sites[s];
  int in = s;
  if (site.kind == SiteKind::ExternalMirror) in = set.internal_of[site.polygon];
  const Site& p = set.sites[in];
  if (p.kind != SiteKind::InternalPolygon) return true;
  return p.t > 1.0001 * kMinT * frames[p.polygon].radius;
}

// Condition (6) for a pair holds when f = |P_l - P_s|^2 - w_l^2 + w_s^2 >= 0 (l the larger
// weight, s the smaller). With w^2 = rho^2 + t^2 along the dual lines, f is linear in the larger
// site's t: returns d f / d(-t) for larger site a against smaller site b (2 h for a polygon site, -2 h
// for a reflection, which moves with its internal partner; h the height of b above a's polygon):
// positive when moving a toward its polygon raises f. NaN when a has no such parameter (a box: split it).
double shrink_gain_of_larger(const SiteSet& set, int a, int b, const std::vector<PolygonFrame>& frames) {
  const Site& sa = set.sites[a];
  if (sa.kind != SiteKind::InternalPolygon && sa.kind != SiteKind::ExternalMirror) return std::nan("");
  if (sa.kind == SiteKind::ExternalMirror && set.sites[set.internal_of[sa.polygon]].kind != SiteKind::InternalPolygon)
    return std::nan("");
  const PolygonFrame& f = frames[sa.polygon];
  const double h = dot(set.sites[b].p - f.center, f.normal);
  return sa.kind == SiteKind::ExternalMirror ? -2 * h : 2 * h;
}

// Whether growing the smaller site `small` of a violating pair (up to its largest t) can satisfy
// (6): f(t) = 2 t^2 - 2 h t + c is convex in its t (h: height of the larger site above its
// polygon), so it must be past the minimum (t > h / 2) and the upper root within reach; below the
// minimum only moving toward the polygon helps.
bool grow_satisfies(const SiteSet& set, int small, int large, const std::vector<PolygonFrame>& frames) {
  const Site& s = set.sites[small];
  const Site& l = set.sites[large];
  const PolygonFrame& f = frames[s.polygon];
  const double h = dot(l.p - f.center, f.normal);
  if (!(s.t > 0.5 * h)) return false;
  const double c = norm2(l.p - f.center) - l.w2 + (s.w2 - s.t * s.t);
  const double disc = h * h - 2 * c;
  if (disc < 0) return true;
  return 0.5 * (h + std::sqrt(disc)) <= max_t(set, s.polygon, frames);
}

// Where moving the smaller site `small` of a violating pair toward its polygon satisfies (6) when
// its minimal distance kMinT rho is not close enough: f(t) = 2 t^2 - 2 h t + c (grow_satisfies) holds
// for t up to its lower root c / (h + sqrt(h^2 - 2 c)), below kMinT rho when c, f at the polygon, is
// tiny (c is an affine mean of the larger site's powers at the smaller polygon's vertices: a sliver
// triangle whose long edge lies on the larger site's sphere; docs/transition.md, "Below the minimal
// distance"). Returns half that root (a margin for the other pairs), or NaN when there is none
// (c <= 0: the pair fails at the polygon itself) or it would be closer than kMinDeepT rho (the site
// would all but coincide with its reflection).
double deep_t_satisfying(const SiteSet& set, int small, int large, const std::vector<PolygonFrame>& frames) {
  const Site& s = set.sites[small];
  const Site& l = set.sites[large];
  const PolygonFrame& f = frames[s.polygon];
  const double h = dot(l.p - f.center, f.normal);
  const double c = norm2(l.p - f.center) - l.w2 + (s.w2 - s.t * s.t);
  const double disc = h * h - 2 * c;
  if (!(h > 0) || !(c > 0) || disc < 0) return std::nan("");
  const double t = 0.5 * c / (h + std::sqrt(disc));
  return t >= kMinDeepT * f.radius ? t : std::nan("");
}

bool can_grow(const SiteSet& set, int s, const std::vector<PolygonFrame>& frames) {
  const Site& site = set.sites[s];
  return site.kind == SiteKind::InternalPolygon && site.t < 0.9999 * max_t(set, site.polygon, frames);
}

// Replaces a fixed box site by per-polygon sites (internal) or mirrors (external).
void split_box(SiteSet& set, int s, const Cavity& cavity, const std::vector<Vec3>& coords,
               const std::vector<PolygonFrame>& frames) {
  Site& box = set.sites[s];
  if (!box.alive) return;
  box.alive = false;
  ++set.splits;
  const std::vector<int> polygons = box.polygons;  // copy: push_back below reallocates
  const bool internal = box.kind == SiteKind::InternalBox;
  for (int q : polygons) {
    if (internal) {
      add_polygon_site(set, q, cavity, coords, frames);
    } else {
      add_mirror_site(set, q, cavity, frames);
      // A polygon site was placed for a box partner; its mirror now bounds t too.
      const int in = set.internal_of[q];
      if (set.sites[in].kind == SiteKind::InternalPolygon)
        place_polygon_site(set, in, std::min(set.sites[in].t, initial_t(set, q, frames)), cavity, coords, frames);
    }
  }
}

// Sites whose sphere strictly holds a cavity vertex that is not theirs. Only sites moved or
// created since their last check are examined (the vertices do not move).
std::vector<int> non_empty_sites(SiteSet& set, const Cavity& cavity, const std::vector<Vec3>& coords) {
  std::vector<std::pair<double, int32_t>> by_x;
  by_x.reserve(cavity.vertices.size());
  for (int32_t v : cavity.vertices) by_x.push_back({coords[v].x, v});
  std::sort(by_x.begin(), by_x.end());
  std::vector<int> bad;
  for (size_t s = 0; s < set.sites.size(); ++s) {
    Site& site = set.sites[s];
    if (!site.alive || site.kind == SiteKind::Guard || site.kind == SiteKind::Free || !site.unchecked) continue;
    site.unchecked = false;
    const double r = std::sqrt(site.w2);
    auto it = std::lower_bound(by_x.begin(), by_x.end(), std::make_pair(site.p.x - r, INT32_MIN));
    for (; it != by_x.end() && it->first <= site.p.x + r; ++it) {
      if (std::binary_search(site.vertices.begin(), site.vertices.end(), it->second)) continue;
      if (norm2(coords[it->second] - site.p) - site.w2 < -kEmptySlack * site.w2) {
        bad.push_back(static_cast<int>(s));
        site.unchecked = true;
        break;
      }
    }
  }
  return bad;
}

// Short label of a site for the correction's diagnostics: its kind and, for polygon sites, the
// side and orientation of its polygon (reservoir faces, "res", or on the outer surface, "surf": x/y/z normal).
std::string site_label(const SiteSet& set, int s, const Cavity& cavity, const std::vector<PolygonFrame>& frames) {
  const Site& site = set.sites[s];
  switch (site.kind) {
    case SiteKind::InternalBox: return "box";
    case SiteKind::ExternalBox: return "ext-box";
    case SiteKind::Free: return "free";
    case SiteKind::Guard: return "guard";
    default: break;
  }
  const int q = site.polygon;
  // "surf": a corner-point cavity's triangle on the model's outer surface (docs/corner-point.md).
  std::string side = cavity.faces[q].side == FaceSide::Well ? "well"
                     : cavity.faces[q].patch == kOuterBoundary ? "surf"
                                                                : "res";
  if (cavity.faces[q].side == FaceSide::Reservoir) {
    const Vec3 n = frames[q].normal;
    side += std::abs(n.z) > 0.5 ? "-z" : std::abs(n.y) > 0.5 ? "-y" : "-x";
  }
  int in = site.kind == SiteKind::ExternalMirror ? set.internal_of[q] : s;
  const bool at_min = set.sites[in].kind == SiteKind::InternalPolygon &&
                      set.sites[in].t <= 1.0001 * kMinT * frames[q].radius;
  return (site.kind == SiteKind::ExternalMirror ? "mirror-" : "") + side + (at_min ? "@min" : "");
}

// Wall columns under an outer-boundary plane (docs/transition.md, "Wall columns"). Two sites of
// wall polygons stacked along a plane's axis, at heights t_1 (nearer the plane) and t_2 off their
// wall, compare on the plane at distance x from the wall as pow_2 - pow_1 = -2 x (t_2 - t_1) +
// (d_2^2 - d_1^2) (d: depths below the plane): with t_2 > t_1 the deeper cell wins the plane far
// from the wall, its site projecting outside its boundary face there. The height off the wall
// of every site down a column is held to the smallest one above it (a polygon site is lowered and
// capped, a box split, its new sites held at the next round): the deeper sites then never take
// the plane from the shallower ones. Returns the number of sites changed.
int align_wall_columns(SiteSet& set, const Cavity& cavity, const std::vector<Vec3>& coords,
                       const std::vector<PolygonFrame>& frames) {
  if (cavity.mirrors.empty()) return 0;
  struct Rect {
    Vec3 lo, hi;
  };
  const int nq = static_cast<int>(cavity.faces.size());
  std::vector<Rect> rect(nq);
  std::vector<int> flat(nq, -1);
  for (int q = 0; q < nq; ++q) {
    const ConstrainedFace& f = cavity.faces[q];
    if (f.side != FaceSide::Reservoir || f.nodes.empty()) continue;
    Rect r{coords[f.nodes[0]], coords[f.nodes[0]]};
    for (int32_t v : f.nodes)
      for (int k = 0; k < 3; ++k) r.lo[k] = std::min(r.lo[k], coords[v][k]), r.hi[k] = std::max(r.hi[k], coords[v][k]);
    rect[q] = r;
    for (int k = 0; k < 3; ++k)
      if (r.lo[k] == r.hi[k]) flat[q] = k;
  }
  // Height of polygon q's internal site off its wall (a box site: its centre's distance).
  auto height = [&](int q) {
    const int s = set.internal_of[q];
    return dot(set.sites[s].p - frames[q].center, frames[q].normal);
  };
  int changed = 0;
  for (const MirrorPlane& m : cavity.mirrors) {
    const int a = m.axis;
    // Wall polygons of this plane (normal across its axis), keyed by their wall, their extent
    // across the column and the end of their extent along the axis that faces the plane.
    using Key = std::tuple<int, int, double, double, double, double>;
    std::map<Key, int> by_near_end;
    auto key = [&](int q, double end) {
      const int k = flat[q], b = 3 - a - k;
      return Key{k, frames[q].normal[k] > 0 ? 1 : -1, rect[q].lo[k], rect[q].lo[b], rect[q].hi[b], end};
    };
    const bool plane_above = [&] {  // the plane bounds the cavity from above along its axis
      for (const ConstrainedFace& f : cavity.faces)  // the polygons: cavity.vertices holds the images too
        for (int32_t v : f.nodes)
          if (coords[v][a] > m.value) return false;
      return true;
    }();
    auto near_end = [&](int q) { return plane_above ? rect[q].hi[a] : rect[q].lo[a]; };
    auto far_end = [&](int q) { return plane_above ? rect[q].lo[a] : rect[q].hi[a]; };
    std::vector<int> tops;
    for (int q = 0; q < nq; ++q) {
      if (flat[q] < 0 || flat[q] == a || set.internal_of[q] < 0) continue;
      by_near_end[key(q, near_end(q))] = q;
      if (near_end(q) == m.value) tops.push_back(q);
    }
    for (int q : tops) {
      double lowest = height(q);
      for (auto it = by_near_end.find(key(q, far_end(q))); it != by_near_end.end();
           it = by_near_end.find(key(it->second, far_end(it->second)))) {
        const int below = it->second, s = set.internal_of[below];
        Site& site = set.sites[s];
        const double h = height(below);
        if (h > lowest * (1 + kColumnSlack)) {
          if (site.kind == SiteKind::InternalPolygon) {
            const double t = std::max(lowest, min_t(frames, below));
            site.t_cap = std::min(site.t_cap, t);
            place_polygon_site(set, s, t, cavity, coords, frames);
          } else if (site.kind == SiteKind::InternalBox) {
            split_box(set, s, cavity, coords, frames);
          }
          ++changed;
        }
        // A split box's polygon sites start at their initial heights: the next round holds them.
        lowest = std::min(lowest, height(below));
      }
    }
  }
  return changed;
}

}  // namespace

PolygonFrame fit_polygon(const std::vector<int32_t>& nodes, const std::vector<Vec3>& coords) {
  PolygonFrame f;
  const size_t n = nodes.size();
  Vec3 g, area;
  for (size_t i = 0; i < n; ++i) {
    g += coords[nodes[i]];
    area += cross(coords[nodes[i]], coords[nodes[(i + 1) % n]]);
  }
  g = g / static_cast<double>(n);
  f.normal = normalized(area);
  double edges = 0;
  for (size_t i = 0; i < n; ++i) edges += norm(coords[nodes[(i + 1) % n]] - coords[nodes[i]]);
  f.mean_edge = edges / static_cast<double>(n);

  // An axis-aligned rectangle (every reservoir face): exact centre and axis normal, so that
  // lattice sites stay exactly co-spherical with it.
  Vec3 lo = coords[nodes[0]], hi = lo;
  for (int32_t v : nodes)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], coords[v][k]);
      hi[k] = std::max(hi[k], coords[v][k]);
    }
  int flat_axis = -1, flat_count = 0;
  for (int k = 0; k < 3; ++k)
    if (lo[k] == hi[k]) flat_axis = k, ++flat_count;
  bool rectangle = n == 4 && flat_count == 1;
  if (rectangle)
    for (int32_t v : nodes)
      for (int k = 0; k < 3; ++k)
        if (coords[v][k] != lo[k] && coords[v][k] != hi[k]) rectangle = false;
  if (rectangle) {
    f.center = 0.5 * (lo + hi);
    f.center[flat_axis] = lo[flat_axis];
    Vec3 axis;
    axis[flat_axis] = f.normal[flat_axis] > 0 ? 1.0 : -1.0;
    f.normal = axis;
  } else {
    // Least-squares circle in the mean plane: a^2 + b^2 = 2 ca a + 2 cb b + k.
    const Vec3 ref = std::abs(f.normal.x) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    const Vec3 u = normalized(cross(f.normal, ref)), w = cross(f.normal, u);
    double m[3][4] = {{0, 0, 0, 0}, {0, 0, 0, 0}, {0, 0, 0, 0}};
    for (int32_t v : nodes) {
      const Vec3 d = coords[v] - g;
      const double row[3] = {dot(d, u), dot(d, w), 1.0};
      const double rhs = row[0] * row[0] + row[1] * row[1];
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) m[i][j] += row[i] * row[j];
        m[i][3] += row[i] * rhs;
      }
    }
    for (int c = 0; c < 3; ++c) {  // Gaussian elimination with partial pivoting
      int piv = c;
      for (int r = c + 1; r < 3; ++r)
        if (std::abs(m[r][c]) > std::abs(m[piv][c])) piv = r;
      for (int k = 0; k < 4; ++k) std::swap(m[c][k], m[piv][k]);
      for (int r = 0; r < 3; ++r) {
        if (r == c || m[c][c] == 0) continue;
        const double fac = m[r][c] / m[c][c];
        for (int k = c; k < 4; ++k) m[r][k] -= fac * m[c][k];
      }
    }
    const double ca = 0.5 * m[0][3] / m[0][0], cb = 0.5 * m[1][3] / m[1][1];
    f.center = g + ca * u + cb * w;
  }
  double r2 = 0;
  for (int32_t v : nodes) r2 += norm2(coords[v] - f.center);
  f.radius = std::sqrt(r2 / static_cast<double>(n));
  for (int32_t v : nodes) f.circle_error = std::max(f.circle_error, std::abs(norm(coords[v] - f.center) - f.radius));
  return f;
}

SiteSet make_sites(const Cavity& cavity, const std::vector<Vec3>& coords, const ReservoirGrid& grid,
                   const std::vector<PolygonFrame>& frames, std::vector<std::string>& notes) {
  SiteSet set;
  const int nq = static_cast<int>(cavity.faces.size());
  set.internal_of.assign(nq, -1);
  set.external_of.assign(nq, -1);
  // Group reservoir polygons by deactivated (inside) and active (outside) cell; std::map
  // keeps the site order deterministic.
  // In a corner-point cavity (cells not boxes) no polygon has a box site.
  std::map<int32_t, std::vector<int>> by_inside, by_outside;
  for (int q = 0; q < nq && cavity.cells_are_boxes; ++q) {
    const ConstrainedFace& cf = cavity.faces[q];
    if (cf.side != FaceSide::Reservoir) continue;
    if (cf.inside_cell >= 0) by_inside[cf.inside_cell].push_back(q);
    if (cf.outside_cell >= 0) by_outside[cf.outside_cell].push_back(q);
  }
  // External sites first (placing a polygon site needs to know its partner's kind).
  // A reservoir cell's centre with the half-diagonal weight, shared by its polygons.
  auto add_box_site = [&](SiteKind kind, int cell, const std::vector<int>& polygons, std::vector<int>& site_of) {
    Site s;
    s.kind = kind;
    s.reservoir_cell = cell;
    const Box b = reservoir_box(grid, cell);
    s.p = b.center;
    s.w2 = b.w2;
    s.polygons = polygons;
    s.vertices = vertices_of(cavity, polygons);
    set.sites.push_back(s);
    for (int q : polygons) site_of[q] = static_cast<int>(set.sites.size()) - 1;
  };
  for (const auto& [cell, polygons] : by_outside) add_box_site(SiteKind::ExternalBox, cell, polygons, set.external_of);
  // Internal sites: a box site per deactivated cell with n > 1 polygons (P = V, the
  // intersection of their dual lines = the cell centre), a polygon site otherwise.
  for (const auto& [cell, polygons] : by_inside)
    if (polygons.size() > 1) add_box_site(SiteKind::InternalBox, cell, polygons, set.internal_of);
  for (int q = 0; q < nq; ++q) {
    if (set.external_of[q] >= 0) continue;
    // Well polygons, end caps, and reservoir polygons on the outer boundary: mirrors.
    // Their position is set once the internal site exists.
    Site s;
    s.kind = SiteKind::ExternalMirror;
    s.polygon = q;
    s.polygons = {q};
    s.vertices = vertices_of(cavity, s.polygons);
    set.sites.push_back(s);
    set.external_of[q] = static_cast<int>(set.sites.size()) - 1;
  }
  for (int q = 0; q < nq; ++q)
    if (set.internal_of[q] < 0) add_polygon_site(set, q, cavity, coords, frames);
  for (int q = 0; q < nq; ++q) update_mirror(set, q, frames);
  for (int q = 0; q < nq; ++q)
    if (frames[q].inner_tets == 0) {
      std::ostringstream os;
      os << "polygon " << q << ": no attached Delaunay tetrahedron inside the cavity (not Delaunay admissible)";
      if (notes.size() < 50) notes.push_back(os.str());
    }
  return set;
}

void shrink_or_split(SiteSet& set, int s, double alpha, const Cavity& cavity, const std::vector<Vec3>& coords,
                     const ReservoirGrid& /*grid*/, const std::vector<PolygonFrame>& frames) {
  Site& site = set.sites[s];
  if (!site.alive) return;
  switch (site.kind) {
    case SiteKind::InternalPolygon:
      place_polygon_site(set, s, shrunk(site.t, alpha, frames[site.polygon].radius), cavity, coords, frames);
      break;
    case SiteKind::ExternalMirror: {
      const int in = set.internal_of[site.polygon];
      if (set.sites[in].kind == SiteKind::InternalPolygon)
        place_polygon_site(set, in, shrunk(set.sites[in].t, alpha, frames[site.polygon].radius), cavity, coords,
                           frames);
      else
        split_box(set, in, cavity, coords, frames);
      break;
    }
    case SiteKind::InternalBox:
    case SiteKind::ExternalBox:
      split_box(set, s, cavity, coords, frames);
      break;
    case SiteKind::Free:  // placed by place_tip_sites, which re-validates them after every move
      site.alive = false;
      break;
    case SiteKind::Guard:
    case SiteKind::Image:  // power diagram only (build_power_cells)
      break;
  }
}

int place_end_face_sites(SiteSet& set, const Cavity& cavity, const std::vector<Vec3>& coords,
                         const std::vector<WellBlock>& blocks, const std::vector<PolygonFrame>& frames) {
  int moved = 0;
  for (const WellEnd& end : well_ends(cavity, blocks)) {
    // Rounding of the block's node construction is ~1e-16 x the coordinates.
    const double tol = 1e-7 * std::max(end.radii.back(), norm(end.center));
    for (size_t q = 0; q < cavity.faces.size(); ++q) {
      const ConstrainedFace& f = cavity.faces[q];
      if (f.side != FaceSide::Well || f.well != end.well) continue;
      bool on_plane = true;
      for (int32_t v : f.nodes) on_plane = on_plane && std::abs(dot(coords[v] - end.center, end.axis)) <= tol;
      const int s = set.internal_of[q];
      if (!on_plane || s < 0 || set.sites[s].kind != SiteKind::InternalPolygon) continue;
      // Mirror of the ring cell's FV centre (half a segment behind the face), within the
      // polygon's empty-sphere range; the correction may lower it, never raise it above.
      const double t = std::min(kEndFaceHeight * end.end_length, max_t(set, static_cast<int>(q), frames));
      set.sites[s].t_cap = t;
      place_polygon_site(set, s, t, cavity, coords, frames);
      ++moved;
    }
  }
  return moved;
}

int enforce_empty_spheres(SiteSet& set, const Cavity& cavity, const std::vector<Vec3>& coords,
                          const ReservoirGrid& grid, const std::vector<PolygonFrame>& frames) {
  int fixes = 0;
  for (int round = 0; round < 60; ++round) {
    const std::vector<int> bad = non_empty_sites(set, cavity, coords);
    if (bad.empty()) break;
    for (int s : bad) shrink_or_split(set, s, kShrink, cavity, coords, grid, frames);
    fixes += static_cast<int>(bad.size());
  }
  set.emptiness_fixes += fixes;
  return fixes;
}

int correct_sites(SiteSet& set, const Cavity& cavity, const std::vector<Vec3>& coords, const ReservoirGrid& grid,
                  const std::vector<PolygonFrame>& frames, int max_iterations, int* iterations) {
  int corrections = 0;
  int left = 0;
  std::vector<char> stuck;
  // Iteration at which each site was last moved toward its polygon: a site shrunk for one pair
  // and grown back for another in alternate iterations would cycle (measured near hemispherical
  // end caps, where neighbouring cap polygons differ in size); once shrunk it is not grown for a
  // few iterations, so the other pair's larger site must shrink instead.
  std::map<std::string, int> pair_kinds;  // at the last iteration: "large > small" site labels
  std::vector<int> shrunk_at(set.sites.size(), -1000);
  constexpr int kNoGrowAfterShrink = 3;
  int column_rounds = 0;
  constexpr int kMaxColumnRounds = 8;
  // The iterations are deterministic in the sites' state: a state met again would be met forever
  // (a cycle of shrinks and growths), so the correction stops there rather than at the cap.
  std::set<uint64_t> states_seen;
  bool cycled = false;
  for (int it = 1; it <= max_iterations; ++it) {
    *iterations = it;
    const bool cycling = !states_seen.insert(correction_state_hash(set, shrunk_at, it, kNoGrowAfterShrink)).second;
    const bool last = it == max_iterations || cycling;
    cycled = cycling;
    // A pair is examined when |Pi Pj|^2 <= max(wi^2, wj^2): each site looks for the others
    // within its own radius (x-sorted window), and a pair seen from both sides is counted
    // once, from its smaller index.
    std::vector<int> order;
    for (size_t s = 0; s < set.sites.size(); ++s)
      if (set.sites[s].alive && set.sites[s].kind != SiteKind::Guard) order.push_back(static_cast<int>(s));
    std::sort(order.begin(), order.end(), [&](int a, int b) {
      return set.sites[a].p.x < set.sites[b].p.x || (set.sites[a].p.x == set.sites[b].p.x && a < b);
    });
    std::vector<double> xs(order.size());
    for (size_t k = 0; k < order.size(); ++k) xs[k] = set.sites[order[k]].p.x;
    std::vector<char> fix(set.sites.size(), 0), grow(set.sites.size(), 0), involved(set.sites.size(), 0);
    std::vector<double> deep(set.sites.size(), kInf);  // below the minimal distance (deep_t_satisfying)
    int n = 0;
    for (size_t a = 0; a < order.size(); ++a) {
      const int i = order[a];
      const Site& si = set.sites[i];
      const double r = std::sqrt(si.w2);
      const size_t lo = static_cast<size_t>(std::lower_bound(xs.begin(), xs.end(), si.p.x - r) - xs.begin());
      for (size_t b = lo; b < order.size() && xs[b] <= si.p.x + r; ++b) {
        const int j = order[b];
        if (j == i) continue;
        const Site& sj = set.sites[j];
        const double d2 = norm2(sj.p - si.p);
        if (d2 > si.w2) continue;
        if (d2 <= sj.w2 && j < i) continue;  // found from j's side too
        if (std::abs(si.w2 - sj.w2) <= d2) continue;  // condition (6)
        // (6) fails: the radical plane passes beyond the smaller-weight site, which is thus
        // outside its own cell. Only transition cells must be auto-centred.
        const int large = si.w2 > sj.w2 ? i : j, small = si.w2 > sj.w2 ? j : i;
        if (!set.sites[small].internal()) continue;
        ++n;
        if (last) ++pair_kinds[site_label(set, large, cavity, frames) + " > " + site_label(set, small, cavity, frames)];
        involved[large] = involved[small] = 1;
        // The larger weight moves toward its polygon (5.5.2) when that helps (the smaller site in
        // front of its polygon); a box is split. Otherwise the smaller site moves: away from its
        // polygon only if that can satisfy (6) (grow_satisfies), else toward it; a box is split.
        const bool small_may_grow = can_grow(set, small, frames) &&
                                    (small >= static_cast<int>(shrunk_at.size()) ||
                                     it - shrunk_at[small] > kNoGrowAfterShrink);
        const double gain_large = shrink_gain_of_larger(set, large, small, frames);
        if (std::isnan(gain_large) || (gain_large > 0 && can_shrink(set, large, frames))) {
          fix[large] = 1;
        } else {
          if (set.sites[small].kind != SiteKind::InternalPolygon) fix[small] = 1;  // a box: split
          else if (small_may_grow && grow_satisfies(set, small, large, frames)) grow[small] = 1;
          else if (can_shrink(set, small, frames)) fix[small] = 1;
          else if (const double t = deep_t_satisfying(set, small, large, frames); !std::isnan(t))
            deep[small] = std::min(deep[small], t);
          else if (small_may_grow) grow[small] = 1;
          else fix[large] = 1;
        }
      }
    }
    corrections += n;
    left = n;
    if (n == 0) {
      // Converged: hold the wall columns under boundary planes, and correct again if that moved
      // a site (a bounded number of times, and not after the last iteration, which could not
      // correct it; the self-check judges the mesh either way).
      if (column_rounds++ == kMaxColumnRounds || last ||
          align_wall_columns(set, cavity, coords, frames) == 0)
        return corrections;
      enforce_empty_spheres(set, cavity, coords, grid, frames);
      shrunk_at.resize(set.sites.size(), -1000);
      continue;
    }
    if (last) {
      stuck.assign(fix.size(), 0);
      for (size_t s = 0; s < fix.size(); ++s) stuck[s] = fix[s] || grow[s] || involved[s] || deep[s] < kInf;
      break;
    }
    for (size_t s = 0; s < fix.size(); ++s)
      if (fix[s]) {
        shrink_or_split(set, static_cast<int>(s), kShrink, cavity, coords, grid, frames);
        // A split box appends its per-polygon sites: they are new, and may be held below.
        shrunk_at.resize(set.sites.size(), -1000);
        shrunk_at[s] = it;
        // A reflection shrinks by moving its internal partner: hold that one too.
        const Site& site = set.sites[s];
        if (site.kind == SiteKind::ExternalMirror && site.polygon >= 0 && set.internal_of[site.polygon] >= 0)
          shrunk_at[set.internal_of[site.polygon]] = it;
      }
    for (size_t s = 0; s < deep.size(); ++s)
      if (deep[s] < set.sites[s].t && !fix[s] && set.sites[s].alive && set.sites[s].kind == SiteKind::InternalPolygon) {
        place_polygon_site(set, static_cast<int>(s), deep[s], cavity, coords, frames);
        shrunk_at[s] = it;
      }
    for (size_t s = 0; s < grow.size(); ++s)
      if (grow[s] && !fix[s] && !(deep[s] < kInf) && set.sites[s].alive && set.sites[s].kind == SiteKind::InternalPolygon) {
        const Site& site = set.sites[s];
        place_polygon_site(set, static_cast<int>(s), std::min(site.t / kShrink, max_t(set, site.polygon, frames)),
                           cavity, coords, frames);
      }
    enforce_empty_spheres(set, cavity, coords, grid, frames);
  }
  std::ostringstream os;
  os << "transition: site correction did not converge "
     << (cycled ? "(iteration " + std::to_string(*iterations) + " repeats an earlier one: a cycle)"
                : "after " + std::to_string(max_iterations) + " iterations")
     << " (" << left << " pairs left";
  {
    std::vector<std::pair<int, std::string>> by_count;
    for (const auto& [k, v] : pair_kinds) by_count.push_back({-v, k});
    std::sort(by_count.begin(), by_count.end());
    for (size_t k = 0; k < by_count.size() && k < 4; ++k) os << (k ? ", " : ": ") << -by_count[k].first << " " << by_count[k].second;
  }
  os << ")";
  std::vector<int32_t> polygons;
  for (size_t s = 0; s < stuck.size(); ++s)
    if (stuck[s]) polygons.insert(polygons.end(), set.sites[s].polygons.begin(), set.sites[s].polygons.end());
  std::sort(polygons.begin(), polygons.end());
  polygons.erase(std::unique(polygons.begin(), polygons.end()), polygons.end());
  std::vector<int32_t> cells = cells_behind(cavity, coords, frames, polygons);
  throw TransitionError(os.str(), std::move(polygons), std::move(cells));
}

std::vector<int32_t> cells_behind(const Cavity& cavity, const std::vector<Vec3>& coords,
                                  const std::vector<PolygonFrame>& frames, const std::vector<int32_t>& polygons) {
  std::vector<int32_t> cells;
  std::vector<int32_t> near_vertices;
  for (int32_t q : polygons) {
    const ConstrainedFace& f = cavity.faces[q];
    if (f.side == FaceSide::Reservoir) {
      if (f.outside_cell >= 0) cells.push_back(f.outside_cell);
      continue;
    }
    // A well polygon: the cavity vertices inside its diametral sphere, or nearest to it.
    const PolygonFrame& fr = frames[q];
    for (int32_t v : cavity.vertices) {
      const Vec3 x = coords[v] - fr.center;
      const double h = dot(x, fr.normal);
      if (h > 0 && norm2(x) < 4.0 * fr.radius * fr.radius) near_vertices.push_back(v);
    }
  }
  std::sort(near_vertices.begin(), near_vertices.end());
  for (const ConstrainedFace& f : cavity.faces) {
    if (f.side != FaceSide::Reservoir || f.outside_cell < 0) continue;
    for (int32_t v : f.nodes)
      if (std::binary_search(near_vertices.begin(), near_vertices.end(), v)) {
        cells.push_back(f.outside_cell);
        break;
      }
  }
  std::sort(cells.begin(), cells.end());
  cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
  return cells;
}

}  // namespace hm::transition_detail
