// Tip sites (docs/transition.md "Tip sites"): free sites of weight 0 graded around each well
// end, so that the transition cells beyond a tip grow with the distance from it instead of
// being a single layer of needles standing on the block's end faces. CGAL-free.
//
// Why a free site is safe for conformity: at a point x of a constrained polygon the power of
// the polygon's own internal site is |x - O|^2 - rho^2 <= 0 (the sphere passes through the
// polygon's circle), while a weight-0 site F has |x - F|^2 > 0: F never takes a point of a
// constrained polygon, and since constrained vertices keep power 0 w.r.t. their own sites and
// positive power w.r.t. F, they stay power vertices. F lies in its own (convex) cell iff it is
// outside every other site's sphere; that cell then contains F, inside the cavity, and touches
// no polygon, so it lies inside the cavity. Existing sites stay in their cells (power -w^2 <= 0
// at their own position, |P - F|^2 >= 0 for F).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <numeric>

#include "transition_internal.hpp"

namespace hm::transition_detail {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kGoldenAngle = 2.39996322972865332;  // pi (3 - sqrt(5))
// Shells per ring: the shell radii grow by the ring ratio^(1/kShellsPerRing). The linear
// two-point flux of a log field between sites a ratio x apart is off by about (x-1)^2/12;
// at the ring ratio of the shipped cases (2.07) one shell per ring would give ~4 %, two ~1 %.
constexpr int kShellsPerRing = 2;
// Shells continue to this multiple of the drainage radius (candidates outside the cavity or
// inside other sites' spheres are dropped anyway).
constexpr double kShellReach = 2.0;
// Clearance of a free site from every other site's sphere, every cavity vertex and the well
// blocks, in units of the local radial step: keeps its cell (and its neighbours') well shaped.
constexpr double kClearance = 0.25;
// Bends: the sites' spheres keep this fraction of the gap between the focal line and the inner
// side of the bend (fillet radius - drainage radius) from the focal line, and free sites are
// placed on it every kBendAxisSpacing x that gap (docs/transition.md, "Bends").
constexpr double kBendAxisClearance = 0.25;
constexpr double kBendAxisSpacing = 0.5;
// Free sites on a focal line start this fraction of a spacing off the symmetric positions
// (no free site in the bend's plane: symmetric placements make co-spherical quadruples).
constexpr double kBendAxisOffset = 0.137;
// Positions tried per free site of a focal line, the nominal one and kBendAxisShifts shifted.
constexpr int kBendAxisShifts = 4;

struct Obstacle {
  Vec3 p;
  double radius = 0;  ///< sphere radius (site weight), 0 for a point
};

Vec3 any_perpendicular(Vec3 a) {
  const Vec3 ref = std::abs(a.x) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  return normalized(cross(a, ref));
}

// Reservoir cell holding x strictly (-1 outside the grid or on a grid plane).
int cell_at(const ReservoirGrid& grid, Vec3 x) {
  int ijk[3];
  const std::vector<double>* axes[3] = {&grid.x, &grid.y, &grid.z};
  for (int k = 0; k < 3; ++k) {
    const std::vector<double>& c = *axes[k];
    const auto it = std::upper_bound(c.begin(), c.end(), x[k]);
    if (it == c.begin() || it == c.end() || *(it - 1) == x[k]) return -1;
    ijk[k] = static_cast<int>(it - c.begin()) - 1;
  }
  return grid.cell_index(ijk[0], ijk[1], ijk[2]);
}

// Whether x is within `margin` of the block (its legs as cylinders of the outer radius, cut
// at the end planes; spheres at the wedge stations cover the joints between pieces, and at
// the end points the hemispherical caps if it has them).
bool near_block(const WellBlock& b, Vec3 x, double margin) {
  const double r = b.radii.back() + margin;
  const std::vector<Vec3>& c = b.layer_center;
  for (size_t k = 0; k + 1 < c.size(); ++k) {
    const Vec3 d = c[k + 1] - c[k];
    const double len = norm(d);
    if (len == 0) continue;
    const Vec3 a = d / len;
    const double s = dot(x - c[k], a);
    if (s < 0 || s > len) continue;
    if (norm(x - c[k] - s * a) < r) return true;
  }
  for (size_t k = 1; k + 1 < c.size(); ++k)
    if (b.layer_bend[k] >= 0 && norm(x - c[k]) < r) return true;  // a wedge station
  if (b.hemisphere_caps && !c.empty() && (norm(x - c.front()) < r || norm(x - c.back()) < r)) return true;
  return false;
}

// The part of a bend's focal line (well_block.hpp, BendAxis) that the wedge cells on the inside
// of the bend reach: the fan of wedge polygons at angle phi from the bend's inner side
// converges on it at rho tan(phi) from the arc's centre; |s| <= rho covers phi <= 45 degrees.
struct FocalSegment {
  int well = -1;
  Vec3 a, b;               ///< end points
  double clearance = 0;    ///< what sites keep from it (and free sites from every sphere)
  double spacing = 0;      ///< of the free sites placed on it
};

std::vector<FocalSegment> focal_segments(const Cavity& cavity, const std::vector<WellBlock>& blocks) {
  std::vector<FocalSegment> out;
  for (const WellBlock& b : blocks) {
    if (std::find(cavity.wells.begin(), cavity.wells.end(), b.well) == cavity.wells.end() || b.radii.empty()) continue;
    for (const BendAxis& ax : b.bend_axes) {
      const double gap = ax.fillet_radius - b.radii.back();  // focal line to the inner side
      if (!(gap > 0)) continue;
      FocalSegment f;
      f.well = b.well;
      f.a = ax.center - ax.fillet_radius * ax.axis;
      f.b = ax.center + ax.fillet_radius * ax.axis;
      f.clearance = kBendAxisClearance * gap;
      f.spacing = kBendAxisSpacing * gap;
      out.push_back(f);
    }
  }
  return out;
}

double distance_to_segment(Vec3 x, Vec3 a, Vec3 b) {
  const Vec3 d = b - a;
  const double s = std::clamp(dot(x - a, d) / norm2(d), 0.0, 1.0);
  return norm(x - (a + s * d));
}

// Power of x w.r.t. site s.
double power_of(const Site& s, Vec3 x) { return norm2(x - s.p) - s.w2; }

// Plane sites (docs/transition.md, "Plane sites"). A transition cell whose site lies at depth D
// under an outer-boundary plane and whose face in the plane does not hold the site's foot is
// measured towards the nearest point of that face (its boundary flux point): beyond D from the
// foot the pair is below 45 degrees. The slabs of the cells of an inclined column of sites (the
// lateral well polygons of a deviated block, one per segment) meet a plane above the block
// displaced down-dip from their feet by about D tan(inclination). Where a plane point y is owned
// by such a site (its foot not in its own cell, y farther than kPlaneReach D from the foot), a
// free site is placed at depth delta under y: a weight-0 site F outside every sphere has at
// its foot power delta^2, and a site P deeper than F has there |y - P|^2 - w^2 >= |F - P|^2 +
// delta^2 - w^2 > delta^2, so F's face in the plane holds F's foot. Lattice spacing: the deep
// owners lose the plane points between free sites when 0.75 h^2 < D^2 - w^2 (the farthest
// point of a square of side h from its corner sites at depth h / 2).
constexpr double kPlaneReach = 0.8;        // owner's foot distance / depth that calls for plane sites
constexpr double kPlaneSpacingSafety = 0.8;
constexpr double kPlaneMinSpacing = 1e-3;  // of the block radius: below it no lattice is laid
// The lattice is shifted per point by a low-discrepancy (Weyl) sequence, off its symmetric
// positions: kPlaneJitter of a lattice step in plan, kPlaneDepthJitter of the depth.
constexpr double kWeylA = 0.618034, kWeylB = 0.414214;  // golden ratio - 1, sqrt(2) - 1
constexpr double kPlaneJitter = 0.2, kPlaneDepthJitter = 0.1;

template <class TryPlace>
int place_plane_sites(SiteSet& set, const Cavity& cavity, const std::vector<Vec3>& coords,
                      const std::vector<WellBlock>& blocks, TryPlace&& try_place) {
  double r_out = 0;
  for (const WellBlock& b : blocks)
    if (std::find(cavity.wells.begin(), cavity.wells.end(), b.well) != cavity.wells.end() && !b.radii.empty())
      r_out = std::max(r_out, b.radii.back());
  if (!(r_out > 0)) return 0;
  std::vector<int> owners;
  for (size_t s = 0; s < set.sites.size(); ++s)
    if (set.sites[s].alive && set.sites[s].internal()) owners.push_back(static_cast<int>(s));
  auto owner_at = [&](Vec3 y) {
    int best = -1;
    double pb = kInf;
    for (int s : owners) {
      const double p = power_of(set.sites[s], y);
      if (p < pb) pb = p, best = s;
    }
    return best;
  };
  int added = 0;
  for (const MirrorPlane& m : cavity.mirrors) {
    const int a = m.axis, u = (a + 1) % 3, v = (a + 2) % 3;
    Vec3 lo{kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf};
    double inward = 0;
    for (const ConstrainedFace& f : cavity.faces)
      for (int32_t id : f.nodes) {
        for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], coords[id][k]), hi[k] = std::max(hi[k], coords[id][k]);
        if (coords[id][a] != m.value) inward = coords[id][a] > m.value ? 1 : -1;
      }
    if (inward == 0) continue;
    auto on_plane = [&](double cu, double cv) {
      Vec3 y;
      y[a] = m.value, y[u] = cu, y[v] = cv;
      return y;
    };
    auto depth = [&](const Site& s) { return inward * (s.p[a] - m.value); };
    // Owners of the plane points on a lattice of spacing r_out that see them too obliquely.
    const int nu = std::max(1, static_cast<int>(std::ceil((hi[u] - lo[u]) / r_out)));
    const int nv = std::max(1, static_cast<int>(std::ceil((hi[v] - lo[v]) / r_out)));
    // The owner of plane point y when it sees y too obliquely (its foot not in its cell, y beyond
    // kPlaneReach times its depth from the foot), else -1.
    std::map<int, bool> owns_foot;
    auto oblique_owner = [&](Vec3 y) {
      const int o = owner_at(y);
      if (o < 0) return -1;
      const Site& so = set.sites[o];
      const double d = depth(so);
      Vec3 foot = so.p;
      foot[a] = m.value;
      if (!(d > 0) || norm(y - foot) <= kPlaneReach * d) return -1;
      auto it = owns_foot.find(o);
      if (it == owns_foot.end()) it = owns_foot.emplace(o, owner_at(foot) == o).first;
      return it->second ? -1 : o;
    };
    double need = kInf;  // smallest D^2 - w^2 of an oblique owner
    for (int i = 0; i < nu; ++i)
      for (int j = 0; j < nv; ++j) {
        const int o = oblique_owner(
            on_plane(lo[u] + (i + 0.5) * (hi[u] - lo[u]) / nu, lo[v] + (j + 0.5) * (hi[v] - lo[v]) / nv));
        if (o < 0) continue;
        const double d = depth(set.sites[o]);
        // A site whose sphere reaches the plane keeps free sites off its foot: it sets no spacing.
        if (d * d > set.sites[o].w2) need = std::min(need, d * d - set.sites[o].w2);
      }
    if (!(need < kInf)) continue;
    const double h = std::min(r_out, kPlaneSpacingSafety * std::sqrt(need / 0.75));
    if (!(h > kPlaneMinSpacing * r_out)) continue;
    const int mu = std::max(1, static_cast<int>(std::ceil((hi[u] - lo[u]) / h)));
    const int mv = std::max(1, static_cast<int>(std::ceil((hi[v] - lo[v]) / h)));
    for (int i = 0; i < mu; ++i)
      for (int j = 0; j < mv; ++j) {
        // Off the symmetric lattice (co-circular quadruples of sites, with their images
        // co-spherical octuples, make power vertices that are only rounded).
        const double ju = std::fmod(kWeylA * (j + 1) + kWeylB * i, 1.0) - 0.5;
        const double jv = std::fmod(kWeylB * (i + 1) + kWeylA * j, 1.0) - 0.5;
        const Vec3 y = on_plane(lo[u] + (i + 0.5 + kPlaneJitter * ju) * (hi[u] - lo[u]) / mu,
                                lo[v] + (j + 0.5 + kPlaneJitter * jv) * (hi[v] - lo[v]) / mv);
        if (oblique_owner(y) < 0) continue;
        Vec3 f = y;
        f[a] += inward * 0.5 * h * (1.0 + kPlaneDepthJitter * ju);
        const size_t before = set.sites.size();
        try_place(f, kClearance * h);
        added += static_cast<int>(set.sites.size() - before);
      }
  }
  return added;
}

}  // namespace

int cap_sites_off_bend_axes(SiteSet& set, const Cavity& cavity, const std::vector<Vec3>& coords,
                            const std::vector<WellBlock>& blocks, const std::vector<PolygonFrame>& frames) {
  const std::vector<FocalSegment> segments = focal_segments(cavity, blocks);
  int capped = 0;
  for (const FocalSegment& fs : segments) {
    for (size_t q = 0; q < cavity.faces.size(); ++q) {
      const ConstrainedFace& face = cavity.faces[q];
      const int s = set.internal_of[q];
      if (s < 0 || (face.side == FaceSide::Well && face.well != fs.well)) continue;
      if (set.sites[s].kind != SiteKind::InternalPolygon) continue;
      const PolygonFrame& f = frames[q];
      // Sphere of the site at t (through the polygon's circle) clear of the segment by the clearance.
      auto clear_at = [&](double t) {
        return distance_to_segment(f.center + t * f.normal, fs.a, fs.b) >= std::sqrt(f.radius * f.radius + t * t) + fs.clearance;
      };
      double hi = set.sites[s].t, lo = min_t(frames, static_cast<int>(q));
      if (clear_at(hi) || !clear_at(lo)) continue;
      for (int it = 0; it < 40; ++it) {
        const double mid = 0.5 * (lo + hi);
        (clear_at(mid) ? lo : hi) = mid;
      }
      set.sites[s].t_cap = std::min(set.sites[s].t_cap, lo);
      place_polygon_site(set, s, lo, cavity, coords, frames);
      ++capped;
    }
  }
  return capped;
}

std::vector<WellEnd> well_ends(const Cavity& cavity, const std::vector<WellBlock>& blocks) {
  std::vector<WellEnd> ends;
  for (const WellBlock& b : blocks) {
    if (std::find(cavity.wells.begin(), cavity.wells.end(), b.well) == cavity.wells.end()) continue;
    const std::vector<Vec3>& c = b.layer_center;
    if (c.size() < 2 || b.radii.size() < 2) continue;
    // An end lying in an outer-boundary plane has no end faces and nothing beyond it.
    WellEnd e;
    e.well = b.well;
    e.radii = b.radii;
    e.center = c.front();
    e.axis = normalized(c[0] - c[1]);
    e.end_length = norm(c[0] - c[1]);
    if (!b.boundary_end[0]) ends.push_back(e);
    e.center = c.back();
    e.axis = normalized(c[c.size() - 1] - c[c.size() - 2]);
    e.end_length = norm(c[c.size() - 1] - c[c.size() - 2]);
    if (!b.boundary_end[1]) ends.push_back(e);
  }
  return ends;
}

int place_tip_sites(SiteSet& set, const Cavity& cavity, const std::vector<Vec3>& coords, const ReservoirGrid& grid,
                    const std::vector<WellBlock>& blocks) {
  for (Site& s : set.sites)
    if (s.kind == SiteKind::Free) s.alive = false;
  const std::vector<WellEnd> ends = well_ends(cavity, blocks);
  const std::vector<FocalSegment> segments = focal_segments(cavity, blocks);
  if (ends.empty() && segments.empty() && cavity.mirrors.empty()) return 0;

  // Obstacles sorted by x - radius: every live site's sphere and every cavity vertex.
  // Through an outer-boundary plane a free site must also clear the images of the spheres (its
  // own image is then its neighbour across the plane): the images join the obstacles.
  std::vector<Obstacle> obstacles;
  for (const Site& s : set.sites)
    if (s.alive && s.kind != SiteKind::Guard) {
      obstacles.push_back({s.p, std::sqrt(s.w2)});
      for (const MirrorPlane& m : cavity.mirrors) obstacles.push_back({reflect(s.p, m), std::sqrt(s.w2)});
    }
  for (int32_t v : cavity.vertices) obstacles.push_back({coords[v], 0.0});
  double max_radius = 0;
  for (const Obstacle& o : obstacles) max_radius = std::max(max_radius, o.radius);
  std::sort(obstacles.begin(), obstacles.end(), [](const Obstacle& a, const Obstacle& b) { return a.p.x < b.p.x; });
  std::vector<double> xs(obstacles.size());
  for (size_t k = 0; k < obstacles.size(); ++k) xs[k] = obstacles[k].p.x;
  std::vector<Vec3> placed;
  auto clear = [&](Vec3 f, double delta) {
    const size_t lo = static_cast<size_t>(
        std::lower_bound(xs.begin(), xs.end(), f.x - max_radius - delta) - xs.begin());
    for (size_t k = lo; k < obstacles.size() && xs[k] <= f.x + max_radius + delta; ++k)
      if (norm(f - obstacles[k].p) < obstacles[k].radius + delta) return false;
    for (const Vec3& p : placed) {
      if (norm(f - p) < delta) return false;
      for (const MirrorPlane& m : cavity.mirrors)
        if (norm(f - reflect(p, m)) < delta) return false;
    }
    for (const MirrorPlane& m : cavity.mirrors)
      if (norm(f - reflect(f, m)) < delta) return false;
    return true;
  };

  int added = 0;
  auto try_place = [&](Vec3 f, double delta) {
    const int cell = cavity.locate_cell ? cavity.locate_cell(f) : cell_at(grid, f);
    if (cell < 0 || !std::binary_search(cavity.deactivated_cells.begin(), cavity.deactivated_cells.end(), cell))
      return;
    bool in_block = false;
    for (const WellBlock& blk : blocks) in_block = in_block || near_block(blk, f, delta);
    if (in_block || !clear(f, delta)) return;
    Site s;
    s.kind = SiteKind::Free;
    s.p = f;
    s.w2 = 0;
    s.clearance = delta;
    s.unchecked = false;
    set.sites.push_back(s);
    placed.push_back(f);
    ++added;
  };
  // Bends first: a free cell on the focal line ends the fans of wedge cells that would
  // otherwise all meet on it (degenerate power vertices).
  for (const FocalSegment& fs : segments) {
    const int n = std::max(2, static_cast<int>(std::lround(norm(fs.b - fs.a) / fs.spacing)));
    for (int k = 0; k < n; ++k) {
      // A position in some sphere's clearance moves toward the segment's middle, by eighths of a
      // spacing up to half of one, to where the line leaves that sphere.
      const double toward_middle = k + 0.5 + kBendAxisOffset < 0.5 * n ? 1.0 : -1.0;
      for (int step = 0; step <= kBendAxisShifts; ++step) {
        const int before = added;
        const double at = k + 0.5 + kBendAxisOffset + toward_middle * step * 0.5 / kBendAxisShifts;
        try_place(fs.a + (at / n) * (fs.b - fs.a), fs.clearance);
        if (added > before) break;
      }
    }
  }
  for (const WellEnd& end : ends) {
    const double r0 = end.radii.front(), r_out = end.radii.back();
    const int rings = static_cast<int>(end.radii.size()) - 1;
    const double ratio = std::pow(std::pow(r_out / r0, 1.0 / rings), 1.0 / kShellsPerRing);
    if (!(ratio > 1.0001)) continue;
    const double step = ratio - 1.0;  // radial step / radius
    // Polar bands at 0, dphi, ..., pi/2 - dphi/2 so that the cells are about as wide as thick.
    const int bands = std::max(1, static_cast<int>(std::lround(0.5 * kPi / std::min(step, 0.8) - 0.5)));
    const double dphi = 0.5 * kPi / (bands + 0.5);
    const Vec3 u = any_perpendicular(end.axis), v = cross(end.axis, u);
    int shell = 1;
    for (double radius = r0 * ratio; radius <= kShellReach * r_out; radius *= ratio, ++shell) {
      const double delta = kClearance * step * radius;
      for (int b = 0; b <= bands; ++b) {
        const double phi = b * dphi;
        const int n_az = b == 0 ? 1 : std::max(3, static_cast<int>(std::lround(2.0 * kPi * std::sin(phi) / dphi)));
        for (int k = 0; k < n_az; ++k) {
          // Each band turned by a golden-angle multiple: no free site in the meridian plane of
          // another band's or of the sectors' (symmetric placements make co-spherical and
          // coplanar quadruples of sites, whose power vertices are only rounded).
          const double psi = 2.0 * kPi * k / n_az + kGoldenAngle * (b + 3 * shell);
          const Vec3 f = end.center + radius * (std::cos(phi) * end.axis +
                                                std::sin(phi) * (std::cos(psi) * u + std::sin(psi) * v));
          try_place(f, delta);
        }
      }
    }
  }
  place_plane_sites(set, cavity, coords, blocks, try_place);  // counted by try_place
  return added;
}

int drop_blocked_tip_sites(SiteSet& set, const std::vector<MirrorPlane>& planes) {
  int dropped = 0;
  for (Site& f : set.sites) {
    if (!f.alive || f.kind != SiteKind::Free) continue;
    for (const Site& s : set.sites) {
      if (!s.alive || s.kind == SiteKind::Free || s.kind == SiteKind::Guard) continue;
      bool blocked = norm(f.p - s.p) < std::sqrt(s.w2) + f.clearance;
      for (const MirrorPlane& m : planes)
        blocked = blocked || norm(f.p - reflect(s.p, m)) < std::sqrt(s.w2) + f.clearance;
      if (blocked) {
        f.alive = false;
        ++dropped;
        break;
      }
    }
  }
  return dropped;
}

namespace {
// The internal sites in cell order (the cells of a diagram are those of its live internal sites).
std::vector<int> sites_of_cells(const SiteSet& set) {
  std::vector<int> site_of_cell;
  for (size_t s = 0; s < set.sites.size(); ++s)
    if (set.sites[s].alive && set.sites[s].internal()) site_of_cell.push_back(static_cast<int>(s));
  return site_of_cell;
}

// Calls visit(cells) once per distinct face of the first n_cells cells (a face: its set of nodes),
// in no particular order, `cells` holding each cell once per face it has with that node set, ascending.
template <class Visit>
void for_each_face_group(const TransitionCells& out, size_t n_cells, const Visit& visit) {
  std::vector<int32_t> nodes;  // each face's nodes, sorted, one after the other
  std::vector<size_t> begin;
  std::vector<int> cell;
  for (size_t c = 0; c < n_cells; ++c)
    for (const CellFace& f : out.cells[c]) {
      begin.push_back(nodes.size());
      nodes.insert(nodes.end(), f.nodes.begin(), f.nodes.end());
      std::sort(nodes.begin() + static_cast<long>(begin.back()), nodes.end());
      cell.push_back(static_cast<int>(c));
    }
  begin.push_back(nodes.size());
  auto first = [&](int k) { return nodes.begin() + static_cast<long>(begin[k]); };
  auto last = [&](int k) { return nodes.begin() + static_cast<long>(begin[k + 1]); };
  auto same = [&](int a, int b) { return std::equal(first(a), last(a), first(b), last(b)); };
  // By a hash of the node set first (equal sets are then adjacent), the sets themselves on ties.
  std::vector<uint64_t> hash(cell.size());
  for (size_t k = 0; k < cell.size(); ++k) {
    uint64_t h = 0xcbf29ce484222325ULL;
    for (auto it = first(static_cast<int>(k)); it != last(static_cast<int>(k)); ++it)
      h = (h ^ static_cast<uint32_t>(*it)) * 0x100000001b3ULL;
    hash[k] = h;
  }
  std::vector<int> order(cell.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    if (hash[a] != hash[b]) return hash[a] < hash[b];
    if (std::lexicographical_compare(first(a), last(a), first(b), last(b))) return true;
    return !std::lexicographical_compare(first(b), last(b), first(a), last(a)) && a < b;
  });
  std::vector<int> cells;
  for (size_t i = 0; i < order.size();) {
    size_t j = i;
    cells.clear();
    while (j < order.size() && same(order[i], order[j])) cells.push_back(cell[order[j++]]);
    visit(cells);
    i = j;
  }
}
}  // namespace

std::vector<int> tip_sites_in_bad_cells(const SiteSet& set, const TransitionCells& out) {
  const std::vector<int> site_of_cell = sites_of_cells(set);
  const size_t n_cells = std::min(out.cells.size(), site_of_cell.size());
  std::vector<int> bad;
  for (size_t c = 0; c < n_cells; ++c)
    if (out.cells[c].size() < 4 && set.sites[site_of_cell[c]].kind == SiteKind::Free) bad.push_back(site_of_cell[c]);
  for_each_face_group(out, n_cells, [&](const std::vector<int>& cells) {
    if (cells.size() <= 2) return;
    for (int c : cells)
      if (set.sites[site_of_cell[c]].kind == SiteKind::Free) bad.push_back(site_of_cell[c]);
  });
  std::sort(bad.begin(), bad.end());
  bad.erase(std::unique(bad.begin(), bad.end()), bad.end());
  return bad;
}

std::vector<int> sites_in_duplicate_faces(const SiteSet& set, const TransitionCells& out) {
  const std::vector<int> site_of_cell = sites_of_cells(set);
  std::vector<int> bad;
  for_each_face_group(out, std::min(out.cells.size(), site_of_cell.size()), [&](const std::vector<int>& cells) {
    if (cells.size() <= 2 && (cells.size() < 2 || cells[0] != cells[1])) return;
    for (int c : cells) bad.push_back(site_of_cell[c]);
  });
  std::sort(bad.begin(), bad.end());
  bad.erase(std::unique(bad.begin(), bad.end()), bad.end());
  return bad;
}

}  // namespace hm::transition_detail
