#include "transmissibility.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include "meshgen/core/fv_quality.hpp"
#include "meshgen/core/parallel.hpp"

namespace hm {

namespace {

Vec3 times_perm(Vec3 perm, Vec3 v) { return {perm.x * v.x, perm.y * v.y, perm.z * v.z}; }

/// Standard TPFA half: t = A n . K c / |c|^2, c from the FV centre to the face centroid.
double generic_half(Vec3 area_out, Vec3 perm, Vec3 c) { return dot(area_out, times_perm(perm, c)) / norm2(c); }


/// Power/Voronoi cell: the face is orthogonal to the site-to-site segment, so the flux is
/// A k_n / d with d the signed distance from the site to the face plane (n . c), exact for
/// K-orthogonal cells. The generic form would divide by |c| >= n . c and underestimate.
double orthogonal_half(Vec3 area_out, Vec3 perm, Vec3 c) {
  const double a = norm(area_out);
  if (a == 0) return 0;
  const Vec3 n = area_out / a;
  return a * dot(n, times_perm(perm, n)) / dot(n, c);
}

/// Radial structure of one well cell: which of its faces are ring faces, and its transverse k.
struct RadialSides {
  int32_t inner = -1;  ///< face at r_in (wellbore face for ring 0)
  int32_t outer = -1;  ///< face at r_out
  double k_perp = 0;
};

bool same_column(const RadialCellInfo& a, const RadialCellInfo& b) {
  return a.well == b.well && a.sector == b.sector && a.segment == b.segment && a.band == b.band;
}

// Integral of f over the planar polygon of face f_id: fan from the node mean, each triangle
// split into n^2 similar ones, centroid rule (second order; the integrands below are smooth on
// the face: n = 24 keeps the flux of the tip log field within 1e-4 on the cap faces of 6 to 24
// sectors, test EndCapTransmissibility.*; only cap faces are integrated).
template <class F>
double integrate_over_face(const PolyMesh& m, int32_t face, F f) {
  constexpr int n = 24;
  const int k = m.face_size(face);
  const int32_t* v = m.face_begin(face);
  Vec3 mid;
  for (int i = 0; i < k; ++i) mid += m.nodes[v[i]];
  mid = mid / static_cast<double>(k);
  double sum = 0;
  for (int i = 0; i < k; ++i) {
    const Vec3 p0 = mid, e1 = (m.nodes[v[i]] - mid) / n, e2 = (m.nodes[v[(i + 1) % k]] - mid) / n;
    const double area = 0.5 * norm(cross(e1, e2));
    for (int a = 0; a < n; ++a)
      for (int b = 0; a + b < n; ++b) {
        const Vec3 base = p0 + static_cast<double>(a) * e1 + static_cast<double>(b) * e2;
        sum += area * f(base + (1.0 / 3.0) * (e1 + e2));                       // upright triangle
        if (a + b + 1 < n) sum += area * f(base + (2.0 / 3.0) * (e1 + e2));  // inverted one
      }
  }
  return sum;
}

Vec3 unit_out(const PolyMesh& m, const MeshGeometry& g, int32_t f, int c) {
  return normalized(m.face_sign(f, c) * g.face_area[f]);
}

RadialSides classify_radial_cell(const PolyMesh& m, const MeshGeometry& g, int c) {
  const RadialCellInfo& me = m.cell_radial[c];
  RadialSides out;
  std::vector<int32_t> angular, wellbore, other;
  Vec3 axial_sum;  // outward areas of axial faces, previous segment's side flipped
  for (const int32_t* fp = m.cell_begin(c); fp != m.cell_end(c); ++fp) {
    const int32_t f = *fp;
    const int32_t nb = m.face_owner[f] == c ? m.face_neighbour[f] : m.face_owner[f];
    if (nb < 0) {
      const int32_t p = m.face_patch[f];
      // A closed (unperforated) wellbore face is still the cell's inner side; it carries no flow.
      const bool wall = (is_wellbore_patch(p) && well_of_patch(p) == me.well) ||
                        (is_closed_wellbore_patch(p) && well_of_closed_patch(p) == me.well);
      if (me.ring == 0 && wall)
        wellbore.push_back(f);
      else
        other.push_back(f);
      continue;
    }
    const RadialCellInfo& o = m.cell_radial[nb];
    if (o.well >= 0 && same_column(me, o) && o.ring == me.ring - 1) {
      out.inner = f;
    } else if (o.well >= 0 && same_column(me, o) && o.ring == me.ring + 1) {
      out.outer = f;
    } else if (o.well == me.well && o.ring == me.ring && o.segment == me.segment && o.sector != me.sector) {
      angular.push_back(f);
    } else if (o.well == me.well && o.ring == me.ring && o.sector == me.sector && o.segment != me.segment) {
      const Vec3 a = m.face_sign(f, c) * g.face_area[f];
      axial_sum += o.segment > me.segment ? a : -a;
    } else {
      other.push_back(f);
    }
  }
  if (me.ring == 0 && !wellbore.empty()) {
    // Normally exactly one wellbore face; if several, the one facing away from the outer ring face.
    out.inner = wellbore[0];
    if (wellbore.size() > 1 && out.outer >= 0) {
      const Vec3 n_out = unit_out(m, g, out.outer, c);
      for (int32_t f : wellbore)
        if (dot(unit_out(m, g, f, c), n_out) < dot(unit_out(m, g, out.inner, c), n_out)) out.inner = f;
    }
    for (int32_t f : wellbore)
      if (f != out.inner) other.push_back(f);
  }
  // Outermost ring: its outer face borders a transition cell or the boundary; among the faces
  // left, it is the one whose normal is most opposite to the inner face's.
  if (out.outer < 0 && out.inner >= 0) {
    const Vec3 n_in = unit_out(m, g, out.inner, c);
    double best = 0;
    for (int32_t f : other) {
      const double d = dot(unit_out(m, g, f, c), n_in);
      if (d < best) best = d, out.outer = f;
    }
  }
  // Well axis: normal to both angular faces (exact for a straight leg); else normal to an
  // angular face and the inner face; else along the axial faces.
  Vec3 axis;
  double quality = 0;
  auto consider = [&](Vec3 a, Vec3 b) {
    const double s = norm(a) * norm(b);
    if (s == 0) return;
    const Vec3 d = cross(a, b);
    if (norm(d) / s > quality) quality = norm(d) / s, axis = d;
  };
  auto area_of = [&](int32_t f) { return m.face_sign(f, c) * g.face_area[f]; };
  if (angular.size() >= 2) consider(area_of(angular[0]), area_of(angular[1]));
  if (quality < 1e-3 && out.inner >= 0)
    for (int32_t f : angular) consider(area_of(out.inner), area_of(f));
  if (quality < 1e-3 && norm(axial_sum) > 0) axis = axial_sum, quality = 1;
  const Vec3 k = m.cell_perm[c];
  out.k_perp = quality >= 1e-3 ? transverse_permeability(k, normalized(axis)) : std::cbrt(k.x * k.y * k.z);
  return out;
}

// theta L k / |ln(r_f / r_c)| with L the face's own mean length along the axis,
// |A_f| / (2 r_f sin(theta / 2)) (the face is a chord strip of that width). On a straight leg
// that is the cell's axial length; in a bend wedge the ring faces are trapezoids longer on
// the outside of the bend and shorter on the inside, and the cell's axial length would
// misstate their flow (measured on the bent accuracy case with the earlier bisector-plane
// bends: lateral error 2.44 % -> 0.31 % of the drawdown, docs/accuracy.md).
// `r_log` is the radius the log form runs to: the ring polygon's circumradius r_face, except
// on the outermost ring's face toward a transition cell (outer_face_radius).
double log_half(const RadialCellInfo& r, double r_face, double k_perp, double face_area, double r_log) {
  const double chord = 2.0 * r_face * std::sin(0.5 * r.angle);
  const double length = chord > 0 ? face_area / chord : r.length;
  return r.angle * length * k_perp / std::fabs(std::log(r_log / r.r_center));
}

// The outermost ring's outer face is a chord; the transition cell beyond measures its half from
// the chord plane (power-cell form), so the radial half must stop there too, or the band between
// chord and arc r_out is counted on both sides (docs/accuracy.md, diagnosis item 3). It runs to
// the face centroid's distance from the axis: r_center + the centroid's signed offset from the
// FV centre along the face's outward normal (both lie on the sector's mid-angle ray;
// r_out cos(theta/2) for a straight leg). Falls back on r_out when the result is not in
// (r_center, r_out] (a chord inside r_center: 3 or 4 sectors with close rings).
double outer_face_radius(const RadialCellInfo& r, Vec3 area_out, Vec3 fv_center, Vec3 face_centroid) {
  const double a = norm(area_out);
  if (!(a > 0)) return r.r_out;
  const double r_f = r.r_center + dot(face_centroid - fv_center, area_out) / a;
  return r_f > r.r_center && r_f <= r.r_out ? r_f : r.r_out;
}

// Hemispherical end cap (RadialCellInfo::band >= 0). Near a well's end the field is, to
// leading order, that of a semi-infinite line source ending at the cap centre E:
// p = C (ln rho + ln(1 + cos psi)) (rho = |x - E|, psi from the outward axis), whose radial
// part has the flux density k C / rho along x - E. A shell face's flux is then
// k C * integral over the face of n.(x - E) / rho^2 dA (= the integral of rho over its solid
// angle), and the potential difference from the FV centre (distance r_center, on the ray
// through the face's circumcentre) to the face is C ln(r_log / r_center): the half below is
// exact for that part of the field, as log_half is for 2D radial flow. r_log as for the
// cylinder: the sphere radius, or the face plane's distance on the outermost face toward a
// transition cell.
double cap_log_half(const PolyMesh& m, int32_t face, const RadialCellInfo& r, Vec3 area_out, Vec3 perm,
                    double r_log) {
  const double a = norm(area_out);
  if (!(a > 0)) return 0;
  const Vec3 n = area_out / a;
  const double weight = integrate_over_face(m, face, [&](Vec3 x) {
    const Vec3 d = x - r.cap_center;
    return std::fabs(dot(n, d)) / norm2(d);
  });
  return dot(n, times_perm(perm, n)) * weight / std::fabs(std::log(r_log / r.r_center));
}

// A cap cell's meridian and cone faces carry the angular part of the field, whose flux
// density falls as 1 / rho across the face (rho from E) while the two-point form assumes it
// uniform: the face's area is replaced by r_center * integral of dA / rho (for a cone face
// spanning rings r_in..r_out, 2 r_center / (r_in + r_out) = 0.94 at the shipped ring ratio).
double cap_angular_factor(const PolyMesh& m, int32_t face, const RadialCellInfo& r, double area) {
  if (!(area > 0)) return 1;
  return r.r_center * integrate_over_face(m, face, [&](Vec3 x) { return 1.0 / norm(x - r.cap_center); }) / area;
}

/// Harmonic combination written with reciprocals so that a zero half gives 0 and an infinite
/// half gives the other one.
double harmonic(double t1, double t2) { return 1.0 / (1.0 / t1 + 1.0 / t2); }

bool is_bad(double t) { return !(t >= 0) || std::isinf(t); }

/// The axis (0, 1, 2 for I, J, K) of a face between two model cells a, b: the index that differs.
int model_face_axis(const PolyMesh& m, int32_t a, int32_t b) {
  return m.cell_ijk[a][0] != m.cell_ijk[b][0] ? 0 : m.cell_ijk[a][1] != m.cell_ijk[b][1] ? 1 : 2;
}

/// OPM computes one transmissibility per pair of model cells (EclTransmissibility with CpGrid): the
/// pair's area vector (`faceAreaNormalEcl`: the vector area of the face or fault overlap they share) and,
/// on each side, the distance from the cell centre (the mean of its 8 corners: the FV centre) to the
/// centre of that cell's whole face (`faceCenterEcl`: the mean of the face's 4 corners, whatever part of
/// it the neighbour touches). The mesh may store the shared face as several faces (a whole face with
/// stations on its edges as triangles about a node at the mean of its 4 corners, an overlap cut at a
/// crossing); the pair's value is shared among them by area.
void opm_pair_halves(const PolyMesh& m, const MeshGeometry& g, double unit, Transmissibilities* t) {
  std::map<std::pair<int32_t, int32_t>, std::vector<int32_t>> pairs;
  for (int32_t f = 0; f < m.n_faces(); ++f) {
    const int32_t o = m.face_owner[f], n = m.face_neighbour[f];
    if (n < 0 || m.cell_region[o] != kReservoir || m.cell_region[n] != kReservoir) continue;
    if (m.cell_ijk[o][0] < 0 || m.cell_ijk[n][0] < 0) continue;
    pairs[{std::min(o, n), std::max(o, n)}].push_back(f);
  }
  // Side 2 axis + (0: toward +index, 1: toward -index) of cell a toward its pair's other cell b.
  auto side = [&](int32_t a, int32_t b) {
    const int axis = model_face_axis(m, a, b);
    return 2 * axis + (m.cell_ijk[b][axis] > m.cell_ijk[a][axis] ? 0 : 1);
  };
  // Pass 1: the whole faces (a plain quad, or the triangles about the node at the mean of the 4 corners)
  // give the centre of that side of both cells.
  std::vector<std::array<Vec3, 6>> centre(m.n_cells());
  std::vector<std::array<char, 6>> known(m.n_cells(), std::array<char, 6>{0, 0, 0, 0, 0, 0});
  for (const auto& [cells, faces] : pairs) {
    int32_t apex = -1;
    Vec3 c{0, 0, 0};
    if (faces.size() == 1 && m.face_size(faces[0]) == 4) {
      for (auto it = m.face_begin(faces[0]); it != m.face_end(faces[0]); ++it) c += 0.25 * m.nodes[*it];
    } else if (faces.size() >= 3) {
      for (auto it = m.face_begin(faces[0]); it != m.face_end(faces[0]) && apex < 0; ++it) {
        bool in_all = true;
        for (int32_t f : faces)
          in_all = in_all && m.face_size(f) == 3 && std::find(m.face_begin(f), m.face_end(f), *it) != m.face_end(f);
        if (in_all) apex = *it;
      }
      if (apex < 0) continue;
      c = m.nodes[apex];
    } else {
      continue;
    }
    const int32_t a = cells.first, b = cells.second;
    centre[a][side(a, b)] = c;
    known[a][side(a, b)] = 1;
    centre[b][side(b, a)] = c;
    known[b][side(b, a)] = 1;
  }
  // The centre of cell a's face toward b: known, or through the opposite face (the 8 corners' mean is
  // the mean of the two faces' centres), else the area-weighted centroid of the shared faces (a cell
  // with fault overlaps on both sides of an axis: OPM's value is not reproduced there).
  auto face_centre = [&](int32_t a, int32_t b, Vec3 fallback) {
    const int sd = side(a, b), opposite = sd ^ 1;
    if (known[a][sd]) return centre[a][sd];
    if (known[a][opposite]) return 2.0 * m.cell_fv_center[a] - centre[a][opposite];
    return fallback;
  };
  for (const auto& [cells, faces] : pairs) {
    const int32_t a = cells.first, b = cells.second;
    Vec3 area{0, 0, 0}, centroid{0, 0, 0};
    double total = 0;
    for (int32_t f : faces) {
      const double w = norm(g.face_area[f]);
      area += m.face_sign(f, a) * g.face_area[f];
      centroid += w * g.face_centroid[f];
      total += w;
    }
    if (!(total > 0)) continue;
    centroid = centroid / total;
    const int axis = model_face_axis(m, a, b);
    const double ha = unit * opm_half_transmissibility(area, m.cell_perm[a], face_centre(a, b, centroid) - m.cell_fv_center[a], axis);
    const double hb =
        unit * opm_half_transmissibility(-1.0 * area, m.cell_perm[b], face_centre(b, a, centroid) - m.cell_fv_center[b], axis);
    for (int32_t f : faces) {
      const double w = norm(g.face_area[f]) / total;
      t->half_owner[f] = w * (m.face_owner[f] == a ? ha : hb);
      t->half_neighbour[f] = w * (m.face_owner[f] == a ? hb : ha);
      t->face[f] = harmonic(t->half_owner[f], t->half_neighbour[f]);
    }
  }
}

}  // namespace

double transverse_permeability(Vec3 k, Vec3 a) {
  return std::sqrt(k.y * k.z * a.x * a.x + k.x * k.z * a.y * a.y + k.x * k.y * a.z * a.z);
}

PolyMesh in_metric_frame(const PolyMesh& m) {
  PolyMesh out = m;
  const Vec3 s = m.metric_scale;
  const double det = s.x * s.y * s.z;
  auto down = [&](Vec3 x) { return Vec3{x.x / s.x, x.y / s.y, x.z / s.z}; };
  for (Vec3& p : out.nodes) p = down(p);
  for (Vec3& p : out.cell_fv_center) p = down(p);
  for (RadialCellInfo& r : out.cell_radial)
    if (r.band >= 0) r.cap_center = down(r.cap_center);
  // K' = det(S) S^-1 K S^-1: the flux through every face is the same in both frames.
  for (Vec3& k : out.cell_perm) k = {det * k.x / (s.x * s.x), det * k.y / (s.y * s.y), det * k.z / (s.z * s.z)};
  out.metric_scale = {1, 1, 1};
  return out;
}

TransmissibilityOptions deck_transmissibility_options() {
  TransmissibilityOptions o;
  o.reservoir_halves_opm = true;
  return o;
}

Transmissibilities compute_transmissibilities(const PolyMesh& m, const MeshGeometry& g,
                                              const TransmissibilityOptions& opt) {
  // A mesh built in a permeability frame (docs/anisotropy.md): every formula below is applied
  // in that frame, where the mesh is orthogonal and its radial data are given.
  if (!(m.metric_scale == Vec3{1, 1, 1})) {
    const PolyMesh scaled = in_metric_frame(m);
    return compute_transmissibilities(scaled, compute_geometry(scaled), opt);
  }
  const int nf = m.n_faces(), nc = m.n_cells();
  std::vector<RadialSides> radial(nc);
  if (opt.exact_radial)
    for (int c = 0; c < nc; ++c)
      if (m.cell_radial[c].well >= 0) radial[c] = classify_radial_cell(m, g, c);

  const double unit = opt.metric_units ? kDarcyMetric : 1.0;
  // A boundary face's half ends on its boundary flux point (docs/fvcheck.md, "Boundary faces"):
  // the foot of the perpendicular from the FV centre when it lies in the face, where the
  // solver takes the Dirichlet value; an interior face's half on its centroid.
  auto half = [&](int c, int32_t f) {
    const Vec3 area_out = m.face_sign(f, c) * g.face_area[f];
    const Vec3 to_face = boundary_flux_point(m, g, f) - m.cell_fv_center[c];
    const RadialSides& rs = radial[c];
    const RadialCellInfo& rc = m.cell_radial[c];
    if (opt.exact_radial && rc.well >= 0 && rc.band >= 0) {
      if (f == rs.inner) return unit * cap_log_half(m, f, rc, area_out, m.cell_perm[c], rc.r_in);
      if (f == rs.outer) {
        const int32_t nb = m.face_owner[f] == c ? m.face_neighbour[f] : m.face_owner[f];
        const double r_log = nb >= 0 && m.cell_region[nb] == kTransition
                                 ? outer_face_radius(rc, area_out, m.cell_fv_center[c], g.face_centroid[f])
                                 : rc.r_out;
        return unit * cap_log_half(m, f, rc, area_out, m.cell_perm[c], r_log);
      }
      const int32_t nb = m.face_owner[f] == c ? m.face_neighbour[f] : m.face_owner[f];
      const bool angular = nb >= 0 && m.cell_radial[nb].well == rc.well && m.cell_radial[nb].segment == rc.segment;
      const double factor = angular ? cap_angular_factor(m, f, rc, norm(area_out)) : 1.0;
      return unit * factor * orthogonal_half(area_out, m.cell_perm[c], to_face);
    }
    if (f == rs.inner) return unit * log_half(rc, rc.r_in, rs.k_perp, norm(area_out), rc.r_in);
    if (f == rs.outer) {
      const int32_t nb = m.face_owner[f] == c ? m.face_neighbour[f] : m.face_owner[f];
      const double r_log = nb >= 0 && m.cell_region[nb] == kTransition
                               ? outer_face_radius(rc, area_out, m.cell_fv_center[c], g.face_centroid[f])
                               : rc.r_out;
      return unit * log_half(rc, rc.r_out, rs.k_perp, norm(area_out), r_log);
    }
    if (m.cell_region[c] == kTransition) return unit * orthogonal_half(area_out, m.cell_perm[c], to_face);
    // A radial cell's angular and axial faces: the neighbour's FV centre is the mirror image of
    // this one through the face (same radius, the next sector, or the next segment of the same
    // straight part or wedge), so the face is orthogonal to the segment between them and the
    // orthogonal form is exact for a linear field; across the joint between a straight part
    // and a wedge, and on the block's end faces, it is the orthogonal part only.
    // The generic form would divide by |c|^2 and lose the radial offset between the FV centre
    // and the face centroid (a 0.2 m end segment of ring 5: half the transmissibility).
    if (opt.exact_radial && rc.well >= 0) return unit * orthogonal_half(area_out, m.cell_perm[c], to_face);
    if (opt.reservoir_halves_opm && m.cell_region[c] == kReservoir) {
      // The face's axis: between two model cells, the index that differs (across a fault: I or J;
      // across a pinched-out layer: K); otherwise (a cavity's triangle, a boundary face) the largest
      // component of the face's normal in the model's frame.
      const int32_t nb = m.face_owner[f] == c ? m.face_neighbour[f] : m.face_owner[f];
      int axis = -1;
      if (nb >= 0 && m.cell_region[nb] == kReservoir && m.cell_ijk[c][0] >= 0 && m.cell_ijk[nb][0] >= 0)
        axis = model_face_axis(m, c, nb);
      if (axis < 0) {
        const Vec3 a{std::abs(area_out.x), std::abs(area_out.y), std::abs(area_out.z)};
        axis = a.x >= a.y && a.x >= a.z ? 0 : a.y >= a.z ? 1 : 2;
      }
      return unit * opm_half_transmissibility(area_out, m.cell_perm[c], to_face, axis);
    }
    return unit * generic_half(area_out, m.cell_perm[c], to_face);
  };

  Transmissibilities t;
  t.half_owner.assign(nf, 0.0);
  t.half_neighbour.assign(nf, 0.0);
  t.face.assign(nf, 0.0);
  std::vector<uint8_t> bad(nf, 0);  // per face, counted in face order below
  parallel_ranges(nf, [&](int64_t fb, int64_t fe) {
    for (int f = static_cast<int>(fb); f < fe; ++f) {
      const int32_t o = m.face_owner[f], n = m.face_neighbour[f];
      t.half_owner[f] = half(o, f);
      bad[f] = is_bad(t.half_owner[f]);
      if (n >= 0) {
        t.half_neighbour[f] = half(n, f);
        bad[f] += is_bad(t.half_neighbour[f]);
        t.face[f] = harmonic(t.half_owner[f], t.half_neighbour[f]);
      } else if (is_wellbore_patch(m.face_patch[f])) {
        t.face[f] = t.half_owner[f];
      }
    }
  }, 256);  // small chunks: the end-cap faces (a quadrature each) lie together
  if (opt.reservoir_halves_opm) opm_pair_halves(m, g, unit, &t);
  // A corner-point model's multipliers act on the connection, not on its halves (as in OPM Flow).
  if (!m.face_trans_mult.empty())
    for (int f = 0; f < nf; ++f) t.face[f] *= m.face_trans_mult[f];
  // Connections without a face carry the deck's value (METRIC); mD.m without the Darcy constant.
  t.nnc = m.nnc_trans;
  if (!opt.metric_units)
    for (double& v : t.nnc) v /= kDarcyMetric;
  for (int f = 0; f < nf; ++f) {
    if (!bad[f]) continue;
    t.negative += bad[f];
    if (static_cast<int>(t.negative_faces.size()) < kMaxListedNegative) t.negative_faces.push_back(f);
  }
  return t;
}

std::vector<std::vector<std::pair<int32_t, double>>> well_connection_factors(const PolyMesh& m,
                                                                             const Transmissibilities& t, int n_wells) {
  std::vector<std::map<int32_t, double>> sums(std::max(n_wells, 0));
  for (int f = 0; f < m.n_faces(); ++f) {
    if (m.face_neighbour[f] >= 0 || !is_wellbore_patch(m.face_patch[f])) continue;
    const int w = well_of_patch(m.face_patch[f]);
    if (w < n_wells) sums[w][m.face_owner[f]] += t.face[f];
  }
  std::vector<std::vector<std::pair<int32_t, double>>> out(sums.size());
  for (size_t w = 0; w < sums.size(); ++w) out[w].assign(sums[w].begin(), sums[w].end());
  return out;
}

}  // namespace hm
