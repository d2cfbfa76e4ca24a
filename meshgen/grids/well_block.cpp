// Structured radial well block (paper sections 2 and 5.1); layout in well_block.hpp.
//
// Geometry. Leg k of the trajectory polyline carries a right-handed frame (u_k, v_k, d_k);
// leg k's frame is leg k-1's turned by the minimal rotation taking d_{k-1} to d_k (about
// d_{k-1} x d_k): the rotation-minimising (parallel transport) frame, which does not twist.
// A node of the cross-section with axis point P and plane normal m is where the line
// P + e + t d_k (e = r (cos phi u_k + sin phi v_k)) meets the plane: t = -m.e / m.d_k.
// Cross-sections inside a leg and at the two trajectory ends are perpendicular (t = 0); at a
// bend vertex the plane is the bisector plane m = normalize(d_{k-1} + d_k), where the node
// lines of both legs meet, so the bend layer is shared by both legs. Every edge along the
// trajectory is therefore parallel to its leg: every face is planar (two parallel sides, or
// inside a cross-section plane), and with the FV centre on the cell's mid-angle radial line
// the ring and angular faces are orthogonal to the centre-to-centre segments.
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
// Requires d1 . d2 > -1 (bends above 120 degrees are rejected before).
Vec3 rotate_minimal(Vec3 x, Vec3 d1, Vec3 d2) {
  const Vec3 k = cross(d1, d2);
  const double c = dot(d1, d2);
  return c * x + cross(k, x) + (dot(k, x) / (1.0 + c)) * k;
}

double angle_degrees(Vec3 d1, Vec3 d2) { return std::atan2(norm(cross(d1, d2)), dot(d1, d2)) * 180.0 / kPi; }

struct Leg {
  Vec3 a, b;       // trajectory points at its ends
  Vec3 d, u, v;    // right-handed frame, d along the leg
  double length = 0;
  Vec3 m_start, m_end;  // normals of the cross-section planes at its ends
  double bend_start = -1, bend_end = -1;  // bend angles (degrees) at its ends, -1 at a trajectory end
  int segments = 1;
};

struct Layer {
  Vec3 p;   // axis point
  Vec3 m;   // plane normal
  int leg;  // the leg whose frame places the nodes (the incoming leg at a bend)
};

// Offset along d of the node at in-frame offset e in the plane through the axis point with
// normal m; exactly 0 in a perpendicular plane.
double plane_offset(Vec3 m, Vec3 d, Vec3 e) { return m == d ? 0.0 : -dot(m, e) / dot(m, d); }

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

// Legs with their directions, bend angles, cross-section planes and transported frames.
std::vector<Leg> make_legs(const WellSpec& ws, int w) {
  const std::vector<Vec3>& traj = ws.trajectory;
  const int n_legs = static_cast<int>(traj.size()) - 1;
  std::vector<Leg> legs(n_legs);
  for (int k = 0; k < n_legs; ++k) {
    Leg& g = legs[k];
    g.a = traj[k];
    g.b = traj[k + 1];
    g.length = norm(g.b - g.a);
    g.d = (g.b - g.a) / g.length;
  }
  for (int k = 1; k < n_legs; ++k) {
    const double deg = angle_degrees(legs[k - 1].d, legs[k].d);
    if (deg > 120.0)
      throw InputError(well_key(w) + ".trajectory: bend of " + num(deg) + " degrees at point " + std::to_string(k) +
                       " exceeds the 120-degree limit");
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
  for (int k = 0; k < n_legs; ++k) {
    legs[k].m_start = k == 0 ? legs[k].d : normalized(legs[k - 1].d + legs[k].d);
    legs[k].m_end = k == n_legs - 1 ? legs[k].d : normalized(legs[k].d + legs[k + 1].d);
  }
  return legs;
}

std::vector<double> ring_radii(const WellSpec& ws) {
  std::vector<double> radii(ws.rings + 1);
  const double ratio = ws.drainage_radius / ws.radius;
  for (int i = 0; i <= ws.rings; ++i) radii[i] = ws.radius * std::pow(ratio, static_cast<double>(i) / ws.rings);
  radii[0] = ws.radius;
  radii[ws.rings] = ws.drainage_radius;
  return radii;
}

std::string bend_phrase(const Leg& g) {
  if (g.bend_start >= 0 && g.bend_end >= 0) return "its bends of " + num(g.bend_start) + " and " + num(g.bend_end) + " degrees";
  return "its bend of " + num(std::max(g.bend_start, g.bend_end)) + " degrees";
}

// Splits each leg into segments of equal length, n = max(1, round(L / segment_length)),
// lowered while a cross-section would not lie strictly beyond the previous one along every
// node line (the bisector planes at bends tilt the end cross-sections by up to
// r tan(bend / 2)). Throws when even one segment does not clear the leg's bends.
void choose_segments(const CaseSpec& cs, int w, const std::vector<double>& radii, const std::vector<double>& cos_s,
                     const std::vector<double>& sin_s, std::vector<Leg>& legs, std::vector<std::string>& notes) {
  const WellSpec& ws = cs.wells[w];
  const double inf = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < legs.size(); ++k) {
    Leg& g = legs[k];
    // Along its node line, a node sits at axial position t_a (start plane), j L / n
    // (interior planes), L + t_b (end plane).
    double max_ta = -inf, max_minus_tb = -inf, max_span = -inf;
    for (double r : radii)
      for (size_t s = 0; s < cos_s.size(); ++s) {
        const Vec3 e = r * (cos_s[s] * g.u + sin_s[s] * g.v);
        const double ta = plane_offset(g.m_start, g.d, e), tb = plane_offset(g.m_end, g.d, e);
        max_ta = std::max(max_ta, ta);
        max_minus_tb = std::max(max_minus_tb, -tb);
        max_span = std::max(max_span, ta - tb);
      }
    const double L = g.length;
    const int n0 = std::max(1L, std::lround(L / ws.segment_length));
    int n = n0;
    while (n >= 2 && !(max_ta < L / n && (n - 1) * L / n < L - max_minus_tb)) --n;
    if (n == 1 && !(max_span < L))
      throw InputError(well_key(w) + ".trajectory: leg " + std::to_string(k) + " too short for " + bend_phrase(g) +
                       " (needs > " + num(max_span) + " m with drainage radius " + num(ws.drainage_radius) + ")");
    if (n < n0)
      notes.push_back(well_label(cs, w) + ": leg " + std::to_string(k) + " split into " + std::to_string(n) +
                      " segments of " + num(L / n) + " m instead of " + std::to_string(n0) +
                      " so that its cross-sections clear " + bend_phrase(g));
    g.segments = n;
  }
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
// - the bends: the outer surface is mitred at the bisector plane, its quads next to it are
//   trapezoids with an obtuse corner on the bend layer, inside the diametral sphere of the
//   long axial edge when the quad is narrow; more sectors make it worse.
struct GabrielDiagnosis {
  int total = 0, end_face = 0, bend = 0, other = 0;
  int bend_point = -1;       // trajectory point of the first bend with violations
  double bend_degrees = 0;
};

GabrielDiagnosis diagnose_gabriel(const WellBlock& block, const std::vector<Vec3>& trajectory) {
  GabrielDiagnosis diag;
  const std::vector<GabrielViolation> violations = gabriel_violations(block.nodes, block.surface_faces);
  diag.total = static_cast<int>(violations.size());
  if (violations.empty()) return diag;
  // Bend layers are exactly the layers centred on interior trajectory points.
  std::vector<int> layer_point(block.layers, -1);
  for (int l = 1; l + 1 < block.layers; ++l)
    for (size_t k = 1; k + 1 < trajectory.size(); ++k)
      if (block.layer_center[l] == trajectory[k]) layer_point[l] = static_cast<int>(k);
  const int per_layer = (block.rings + 1) * block.sectors;
  const int last = block.layers - 1;
  for (const GabrielViolation& v : violations) {
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
    diag.bend_degrees = angle_degrees(d1, d2);
  }
  return diag;
}

// Smallest sector count whose end faces are Gabriel for the ring ratio q = r_{i+1} / r_i.
int min_end_face_sectors(double ratio) {
  int n = 4;
  while (std::cos(2.0 * kPi / n) < 1.0 / ratio) ++n;
  return n;
}

double regular_polygon_area(int n, double r) { return 0.5 * n * r * r * std::sin(2.0 * kPi / n); }

}  // namespace

WellBlock make_well_block(const CaseSpec& cs, int w, int sectors) {
  if (w < 0 || w >= static_cast<int>(cs.wells.size())) throw std::out_of_range("make_well_block: no well " + std::to_string(w));
  const WellSpec& ws = cs.wells[w];
  validate_well(ws, w, sectors);

  WellBlock block;
  block.well = w;
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

  std::vector<Leg> legs = make_legs(ws, w);
  choose_segments(cs, w, block.radii, cos_s, sin_s, legs, block.notes);

  // Layers: trajectory start, interior split points, bend vertices, end.
  std::vector<Layer> layers;
  std::vector<int> segment_leg;
  layers.push_back({legs[0].a, legs[0].d, 0});
  for (int k = 0; k < static_cast<int>(legs.size()); ++k) {
    const Leg& g = legs[k];
    for (int j = 1; j < g.segments; ++j)
      layers.push_back({g.a + (static_cast<double>(j) / g.segments) * (g.b - g.a), g.d, k});
    layers.push_back({g.b, g.m_end, k});
    for (int j = 0; j < g.segments; ++j) segment_leg.push_back(k);
  }
  const int n_layers = static_cast<int>(layers.size());
  block.layers = n_layers;
  for (const Layer& ly : layers) block.layer_center.push_back(ly.p);

  // Nodes: local id = (layer * (rings + 1) + ring) * sectors + sector.
  const int rings = ws.rings;
  const int per_layer = (rings + 1) * sectors;
  block.nodes.reserve(static_cast<size_t>(n_layers) * per_layer);
  for (const Layer& ly : layers) {
    const Leg& g = legs[ly.leg];
    for (int i = 0; i <= rings; ++i)
      for (int s = 0; s < sectors; ++s) {
        const Vec3 e = block.radii[i] * (cos_s[s] * g.u + sin_s[s] * g.v);
        block.nodes.push_back(ly.p + e + plane_offset(ly.m, g.d, e) * g.d);
      }
  }
  auto node = [&](int l, int i, int s) { return static_cast<int32_t>((l * (rings + 1) + i) * sectors + s % sectors); };

  // Cells: id = (segment * rings + ring) * sectors + sector.
  const int32_t wellbore = wellbore_patch(w);
  const double sector_angle = 2.0 * kPi / sectors;
  const int n_segments = n_layers - 1;
  block.cell_faces.reserve(static_cast<size_t>(n_segments) * rings * sectors);
  block.cell_attrs.reserve(static_cast<size_t>(n_segments) * rings * sectors);
  for (int l = 0; l < n_segments; ++l) {
    const Leg& g = legs[segment_leg[l]];
    const double length = norm(layers[l + 1].p - layers[l].p);
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
        faces[4] = {{a, b, c, d}, kInteriorFace};                       // axial face on layer l
        faces[5] = {{a2, d2, c2, b2}, kInteriorFace};                   // axial face on layer l + 1
        const double vol = hexahedron_volume(block.nodes, faces);
        if (!(vol > 0))
          throw InputError(well_key(w) + ".trajectory: radial cell (ring " + std::to_string(i) + ", sector " +
                           std::to_string(s) + ", segment " + std::to_string(l) + ") is inverted (volume " + num(vol) +
                           " m3)");
        CellAttributes at;
        at.region = kWell;
        at.perm = cs.reservoir.permeability;
        at.porosity = cs.reservoir.porosity;
        RadialCellInfo& rad = at.radial;
        rad.well = w;
        rad.ring = i;
        rad.sector = s;
        rad.segment = l;
        rad.r_in = block.radii[i];
        rad.r_out = block.radii[i + 1];
        rad.r_center = std::sqrt(rad.r_in * rad.r_out);
        rad.angle = sector_angle;
        rad.length = length;
        const double phi_mid = (s + 0.5) * sector_angle;
        // On the radial line at the mid angle, halfway between where the line parallel to
        // the leg at radius r_center meets the two cross-section planes: the axis midpoint
        // on straight legs (ring and angular faces exactly orthogonal); next to a bend it
        // follows the mitre, so the centre stays inside the cell on the inner side of the
        // bend (there the ring faces are only nearly orthogonal). A position shared by all
        // rings of a sector was tried: it makes the axial faces at the bend almost parallel
        // to the centre-to-centre segments (Q_O of 2 degrees, negative transmissibilities).
        const Vec3 e_mid = rad.r_center * (std::cos(phi_mid) * g.u + std::sin(phi_mid) * g.v);
        const Vec3 x0 = layers[l].p + e_mid + plane_offset(layers[l].m, g.d, e_mid) * g.d;
        const Vec3 x1 = layers[l + 1].p + e_mid + plane_offset(layers[l + 1].m, g.d, e_mid) * g.d;
        at.fv_center = 0.5 * (x0 + x1);
        block.cell_faces.push_back(std::move(faces));
        block.cell_attrs.push_back(at);
      }
  }
  auto cell = [&](int l, int i, int s) { return static_cast<int32_t>((l * rings + i) * sectors + s); };

  // Outer surface, normals out of the block.
  auto add_surface = [&](std::vector<int32_t> poly, int32_t c, int32_t patch) {
    block.surface_faces.push_back(std::move(poly));
    block.surface_cell.push_back(c);
    block.surface_patch.push_back(patch);
  };
  for (int l = 0; l < n_segments; ++l)
    for (int s = 0; s < sectors; ++s)
      add_surface(block.cell_faces[cell(l, rings - 1, s)][1].nodes, cell(l, rings - 1, s), kInteriorFace);
  for (int i = 0; i < rings; ++i)
    for (int s = 0; s < sectors; ++s) {
      add_surface(block.cell_faces[cell(0, i, s)][4].nodes, cell(0, i, s), kInteriorFace);
      add_surface(block.cell_faces[cell(n_segments - 1, i, s)][5].nodes, cell(n_segments - 1, i, s), kInteriorFace);
    }
  std::vector<int32_t> start_cap, end_cap;
  for (int s = 0; s < sectors; ++s) {
    start_cap.push_back(node(0, 0, sectors - 1 - s));
    end_cap.push_back(node(n_layers - 1, 0, s));
  }
  add_surface(std::move(start_cap), -1, wellbore);
  add_surface(std::move(end_cap), -1, wellbore);
  return block;
}

int count_gabriel_violations(const WellBlock& block) {
  return static_cast<int>(gabriel_violations(block.nodes, block.surface_faces).size());
}

WellBlock make_gabriel_well_block(const CaseSpec& cs, int w) {
  if (w < 0 || w >= static_cast<int>(cs.wells.size()))
    throw std::out_of_range("make_gabriel_well_block: no well " + std::to_string(w));
  const WellSpec& ws = cs.wells[w];
  const int requested = ws.sectors;
  int sectors = requested;
  WellBlock block;
  // Raising sectors only helps the end faces (see diagnose_gabriel): stop as soon as a
  // violation elsewhere appears, since more sectors make the bends worse.
  for (;;) {
    block = make_well_block(cs, w, sectors);
    const GabrielDiagnosis diag = diagnose_gabriel(block, ws.trajectory);
    if (diag.total == 0) break;
    const std::string label = well_label(cs, w);
    if (diag.bend > 0)
      throw InputError(label + ": the outer surface of the radial block is not Gabriel next to the bend of " +
                       num(diag.bend_degrees) + " degrees at trajectory point " + std::to_string(diag.bend_point) +
                       " with " + std::to_string(sectors) + " sectors (" + std::to_string(diag.bend) +
                       " surface vertices inside diametral spheres of edges meeting the bisector plane, where the"
                       " mitred surface has obtuse quads; more sectors make it worse, fewer sectors or a gentler"
                       " bend help" +
                       (sectors > requested ? "; the end faces needed " + std::to_string(sectors) + " sectors" : "") +
                       ")");
    if (diag.other > 0)
      throw InputError(label + ": the outer surface of the radial block is not Gabriel with " +
                       std::to_string(sectors) + " sectors (" + std::to_string(diag.other) + " violations)");
    const int next = sectors % 2 == 0 ? sectors + 2 : sectors + 1;
    if (next > 4 * requested) {
      const double ratio = block.radii[1] / block.radii[0];
      throw InputError(label + ": the end faces of the radial block are not Gabriel even with " +
                       std::to_string(sectors) + " sectors (4x the " + std::to_string(requested) + " requested, " +
                       std::to_string(diag.end_face) + " violations): the ring radius ratio " + num(ratio) +
                       " needs cos(2 pi / sectors) >= 1 / " + num(ratio) + ", i.e. at least " +
                       std::to_string(min_end_face_sectors(ratio)) + " sectors; use fewer rings");
    }
    sectors = next;
  }
  block.sectors_requested = requested;
  if (sectors != requested)
    block.notes.push_back(well_label(cs, w) + ": sectors raised from " + std::to_string(requested) + " to " +
                          std::to_string(sectors) + " for the Gabriel condition");
  return block;
}

std::vector<int32_t> add_well_block(const WellBlock& block, MeshBuilder& builder) {
  std::vector<int32_t> ids(block.nodes.size());
  for (size_t i = 0; i < block.nodes.size(); ++i) ids[i] = builder.add_node(block.nodes[i]);
  for (size_t c = 0; c < block.cell_faces.size(); ++c) {
    std::vector<CellFace> faces = block.cell_faces[c];
    for (CellFace& f : faces)
      for (int32_t& v : f.nodes) v = ids[v];
    builder.add_cell(faces, block.cell_attrs[c]);
  }
  return ids;
}

double exact_well_block_volume(const CaseSpec& cs, int w, int sectors) {
  const WellSpec& ws = cs.wells.at(w);
  const double annulus = regular_polygon_area(sectors, ws.drainage_radius) - regular_polygon_area(sectors, ws.radius);
  double length = 0;
  for (size_t k = 0; k + 1 < ws.trajectory.size(); ++k) length += norm(ws.trajectory[k + 1] - ws.trajectory[k]);
  return annulus * length;
}

}  // namespace hm
