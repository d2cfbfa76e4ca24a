// Transmissibilities: textbook Cartesian value, the orthogonal form of power cells, exact radial
// flow through a ring block (log form) versus the distance-based form, negative halves reported.
#include <gtest/gtest.h>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "fvcheck/lib/transmissibility.hpp"
#include "meshgen/core/fv_quality.hpp"
#include "meshgen/core/geometry.hpp"
#include "meshgen/core/mesh_builder.hpp"

using namespace hm;

namespace {

constexpr double kPi = 3.14159265358979323846;

/// Adds a convex cell given by unoriented faces: each face is oriented so that its normal points
/// away from the mean of the cell's nodes.
int32_t add_convex_cell(MeshBuilder& b, const std::vector<std::vector<int32_t>>& faces,
                        const std::vector<int32_t>& patches, const CellAttributes& at) {
  std::vector<Vec3> pts;
  Vec3 mean;
  int count = 0;
  for (const auto& f : faces)
    for (int32_t v : f) mean += b.node(v), ++count;
  mean = mean / count;
  for (int32_t i = 0; i < b.n_nodes(); ++i) pts.push_back(b.node(i));
  std::vector<CellFace> out;
  for (size_t i = 0; i < faces.size(); ++i) {
    Vec3 area, centroid;
    polygon_area_centroid(pts, faces[i].data(), faces[i].data() + faces[i].size(), &area, &centroid);
    CellFace cf{faces[i], patches[i]};
    if (dot(area, centroid - mean) < 0) std::reverse(cf.nodes.begin(), cf.nodes.end());
    out.push_back(cf);
  }
  return b.add_cell(out, at);
}

/// Hexahedron with corners n[bit0 = +a, bit1 = +b, bit2 = +c]; all faces get `patch`.
int32_t add_hex(MeshBuilder& b, const int32_t n[8], const CellAttributes& at, int32_t patch = kOuterBoundary) {
  return add_convex_cell(b,
                         {{n[0], n[2], n[3], n[1]},
                          {n[4], n[5], n[7], n[6]},
                          {n[0], n[1], n[5], n[4]},
                          {n[2], n[6], n[7], n[3]},
                          {n[0], n[4], n[6], n[2]},
                          {n[1], n[3], n[7], n[5]}},
                         std::vector<int32_t>(6, patch), at);
}

PolyMesh finish_ok(MeshBuilder& b) {
  BuildReport rep;
  PolyMesh m = b.finish(&rep);
  EXPECT_TRUE(rep.ok) << (rep.problems.empty() ? "" : rep.problems[0]);
  return m;
}

/// Two axis-aligned boxes [x0,x1] and [x1,x2] x [0,dy] x [0,dz] sharing the face x = x1.
PolyMesh box_pair(double x0, double x1, double x2, double dy, double dz, Vec3 k1, Vec3 k2, int32_t region, Vec3 site1,
                  Vec3 site2) {
  MeshBuilder b;
  const double xs[3] = {x0, x1, x2};
  int32_t id[3][2][2];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k) id[i][j][k] = b.add_node({xs[i], dy * j, dz * k});
  for (int i = 0; i < 2; ++i) {
    int32_t n[8];
    for (int c = 0; c < 8; ++c) n[c] = id[i + (c & 1)][(c >> 1) & 1][(c >> 2) & 1];
    CellAttributes at;
    at.region = region;
    at.perm = i == 0 ? k1 : k2;
    at.fv_center = i == 0 ? site1 : site2;
    add_hex(b, n, at);
  }
  return finish_ok(b);
}

int interior_face(const PolyMesh& m) {
  for (int f = 0; f < m.n_faces(); ++f)
    if (m.face_neighbour[f] >= 0) return f;
  return -1;
}

// ---------------------------------------------------------------- radial ring block

struct RingSpec {
  int rings = 5, sectors = 8, segments = 2;
  double r_w = 0.1, r_outer = 50.0, height = 12.0;
  Vec3 origin{0, 0, 0};
  Vec3 e1{1, 0, 0}, e2{0, 1, 0}, axis{0, 0, 1};  // right-handed orthonormal frame, axis along the well
  Vec3 perm{100, 100, 100};
  bool transition_shell = false;  // one region-1 cell per (sector, segment) between r_outer and 2 r_outer
};

double ring_radius(const RingSpec& s, int i) { return s.r_w * std::pow(s.r_outer / s.r_w, double(i) / s.rings); }

/// A straight radial block: polygons of `sectors` nodes at radii r_w * (R/r_w)^(i/rings); ring-0
/// inner faces on wellbore_patch(0); outer faces on kOuterBoundary (or shared with the shell).
PolyMesh ring_block(const RingSpec& s) {
  MeshBuilder b;
  const int n_rad = s.rings + 1 + (s.transition_shell ? 1 : 0);
  const double dz = s.height / s.segments, theta = 2 * kPi / s.sectors;
  std::vector<int32_t> id((s.segments + 1) * n_rad * s.sectors);
  auto node = [&](int l, int i, int j) -> int32_t& { return id[(l * n_rad + i) * s.sectors + (j % s.sectors)]; };
  for (int l = 0; l <= s.segments; ++l)
    for (int i = 0; i < n_rad; ++i)
      for (int j = 0; j < s.sectors; ++j) {
        const double r = i <= s.rings ? ring_radius(s, i) : 2 * s.r_outer;
        node(l, i, j) =
            b.add_node(s.origin + (l * dz) * s.axis + r * std::cos(j * theta) * s.e1 + r * std::sin(j * theta) * s.e2);
      }
  for (int l = 0; l < s.segments; ++l)
    for (int i = 0; i + 1 < n_rad; ++i)
      for (int j = 0; j < s.sectors; ++j) {
        const bool shell = i == s.rings;
        const int32_t a = node(l, i, j), bb = node(l, i, j + 1), c = node(l + 1, i, j + 1), d = node(l + 1, i, j);
        const int32_t a2 = node(l, i + 1, j), b2 = node(l, i + 1, j + 1), c2 = node(l + 1, i + 1, j + 1),
                      d2 = node(l + 1, i + 1, j);
        const int32_t inner_patch = i == 0 ? wellbore_patch(0) : kInteriorFace;
        const int32_t outer_patch = i + 2 == n_rad ? kOuterBoundary : kInteriorFace;
        const int32_t bottom = l == 0 ? kOuterBoundary : kInteriorFace;
        const int32_t top = l + 1 == s.segments ? kOuterBoundary : kInteriorFace;
        CellAttributes at;
        at.perm = s.perm;
        const double r_in = i <= s.rings ? ring_radius(s, i) : s.r_outer;
        const double r_out = i < s.rings ? ring_radius(s, i + 1) : 2 * s.r_outer;
        const double mid = (j + 0.5) * theta;
        const double r_c = shell ? 0.5 * (r_in + r_out) * std::cos(0.5 * theta) : std::sqrt(r_in * r_out);
        at.fv_center = s.origin + ((l + 0.5) * dz) * s.axis + r_c * std::cos(mid) * s.e1 + r_c * std::sin(mid) * s.e2;
        if (shell) {
          at.region = kTransition;
        } else {
          at.region = kWell;
          at.radial = {0, i, j, l, r_in, r_out, r_c, theta, dz, -1, {}};
        }
        add_convex_cell(
            b, {{a, bb, c, d}, {a2, b2, c2, d2}, {a, a2, d2, d}, {bb, b2, c2, c}, {a, bb, b2, a2}, {d, c, c2, d2}},
            {inner_patch, outer_patch, kInteriorFace, kInteriorFace, bottom, top}, at);
      }
  return finish_ok(b);
}

/// Outer boundary faces of the outermost ring (Dirichlet faces at r = R): not normal to the axis.
bool is_dirichlet_face(const PolyMesh& m, const MeshGeometry& g, const RingSpec& s, int f) {
  return m.face_neighbour[f] < 0 && m.face_patch[f] == kOuterBoundary &&
         std::fabs(dot(normalized(g.face_area[f]), s.axis)) < 1e-9;
}

struct SteadyResult {
  std::vector<double> p;
  double rate = 0;  // produced through the wellbore faces, rm3/day
};

/// Steady single-phase TPFA: p_w on the wellbore faces, p_R on the Dirichlet faces through their
/// owner half-transmissibility, no flow elsewhere. `face_t` and `dirichlet_t` are per face.
SteadyResult solve_steady(const PolyMesh& m, const MeshGeometry& g, const RingSpec& s,
                          const std::vector<double>& face_t, const std::vector<double>& dirichlet_t, double p_w,
                          double p_R, double mu) {
  const int n = m.n_cells();
  std::vector<Eigen::Triplet<double>> trip;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
  for (int f = 0; f < m.n_faces(); ++f) {
    const int o = m.face_owner[f], nb = m.face_neighbour[f];
    if (nb >= 0) {
      const double t = face_t[f] / mu;
      trip.emplace_back(o, o, t), trip.emplace_back(nb, nb, t);
      trip.emplace_back(o, nb, -t), trip.emplace_back(nb, o, -t);
    } else if (is_wellbore_patch(m.face_patch[f])) {
      trip.emplace_back(o, o, face_t[f] / mu);
      rhs[o] += face_t[f] / mu * p_w;
    } else if (is_dirichlet_face(m, g, s, f)) {
      trip.emplace_back(o, o, dirichlet_t[f] / mu);
      rhs[o] += dirichlet_t[f] / mu * p_R;
    }
  }
  Eigen::SparseMatrix<double> a(n, n);
  a.setFromTriplets(trip.begin(), trip.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(a);
  EXPECT_EQ(solver.info(), Eigen::Success);
  const Eigen::VectorXd p = solver.solve(rhs);
  SteadyResult r;
  r.p.assign(p.data(), p.data() + n);
  for (int f = 0; f < m.n_faces(); ++f)
    if (m.face_neighbour[f] < 0 && is_wellbore_patch(m.face_patch[f]))
      r.rate += face_t[f] / mu * (r.p[m.face_owner[f]] - p_w);
  return r;
}

struct RadialErrors {
  double pressure = 0;  // max |p - p_exact(r_c)| / (p_R - p_w)
  double rate = 0;      // q / q_exact - 1
};

constexpr double kPw = 150.0, kPR = 200.0, kMu = 0.7;

RadialErrors errors_against_exact(const PolyMesh& m, const RingSpec& s, const SteadyResult& r) {
  const double k = std::sqrt(s.perm.x * s.perm.y);
  const double log_ratio = std::log(s.r_outer / s.r_w);
  const double q_exact = kDarcyMetric * 2 * kPi * k * s.height * (kPR - kPw) / (kMu * log_ratio);
  RadialErrors e;
  for (int c = 0; c < m.n_cells(); ++c) {
    const double p_exact = kPw + (kPR - kPw) * std::log(m.cell_radial[c].r_center / s.r_w) / log_ratio;
    e.pressure = std::max(e.pressure, std::fabs(r.p[c] - p_exact) / (kPR - kPw));
  }
  e.rate = r.rate / q_exact - 1;
  return e;
}

/// Distance-based ("linear") TPFA on the same rings and nodes: t = theta r_f L k / |r_f - r_c| on
/// ring faces (cylindrical face area over the node-to-face distance); other faces unchanged.
void linear_ring_transmissibilities(const PolyMesh& m, const MeshGeometry& g, const RingSpec& s,
                                    const Transmissibilities& exact, std::vector<double>* face_t,
                                    std::vector<double>* dirichlet_t) {
  const double k = std::sqrt(s.perm.x * s.perm.y);
  auto lin = [&](int c, double r_f) {
    const RadialCellInfo& r = m.cell_radial[c];
    return kDarcyMetric * r.angle * r_f * r.length * k / std::fabs(r_f - r.r_center);
  };
  *face_t = exact.face;
  *dirichlet_t = exact.half_owner;
  for (int f = 0; f < m.n_faces(); ++f) {
    const int o = m.face_owner[f], nb = m.face_neighbour[f];
    const RadialCellInfo& ro = m.cell_radial[o];
    if (nb >= 0) {
      const RadialCellInfo& rn = m.cell_radial[nb];
      if (ro.sector != rn.sector || ro.segment != rn.segment) continue;
      const int lo = ro.ring < rn.ring ? o : nb, hi = ro.ring < rn.ring ? nb : o;
      const double r_f = m.cell_radial[lo].r_out;
      (*face_t)[f] = 1.0 / (1.0 / lin(lo, r_f) + 1.0 / lin(hi, r_f));
    } else if (is_wellbore_patch(m.face_patch[f])) {
      (*face_t)[f] = lin(o, ro.r_in);
    } else if (is_dirichlet_face(m, g, s, f)) {
      (*dirichlet_t)[f] = lin(o, ro.r_out);
    }
  }
}

}  // namespace

// ---------------------------------------------------------------- Cartesian and power cells

TEST(Transmissibility, CartesianPairMatchesTextbookValue) {
  const double dx1 = 3.0, dx2 = 7.5, dy = 4.0, dz = 2.5;
  const Vec3 k1{120, 40, 5}, k2{35, 80, 2};
  PolyMesh m = box_pair(0, dx1, dx1 + dx2, dy, dz, k1, k2, kReservoir, {0.5 * dx1, 0.5 * dy, 0.5 * dz},
                        {dx1 + 0.5 * dx2, 0.5 * dy, 0.5 * dz});
  const MeshGeometry g = compute_geometry(m);
  const Transmissibilities t = compute_transmissibilities(m, g);
  const int f = interior_face(m);
  ASSERT_GE(f, 0);
  const double area = dy * dz;
  const double textbook = kDarcyMetric * area / (dx1 / (2 * k1.x) + dx2 / (2 * k2.x));
  EXPECT_NEAR(t.face[f], textbook, 1e-14 * textbook);
  EXPECT_EQ(t.negative, 0);
  // Boundary faces carry a half but no face transmissibility; the raw unit drops CDARCY only.
  TransmissibilityOptions raw;
  raw.metric_units = false;
  const Transmissibilities tr = compute_transmissibilities(m, g, raw);
  for (int h = 0; h < m.n_faces(); ++h) {
    if (h != f) {
      EXPECT_EQ(t.face[h], 0.0);
    }
    EXPECT_GT(t.half_owner[h], 0.0);
    EXPECT_NEAR(tr.half_owner[h] * kDarcyMetric, t.half_owner[h], 1e-15 * t.half_owner[h]);
  }
}

TEST(Transmissibility, DarcyConstantIsTheMetricUnitConversion) {
  // 1 mD = 9.869233e-16 m2, 1 cP = 1e-3 Pa.s, 1 bar = 1e5 Pa, 1 day = 86400 s.
  EXPECT_NEAR(9.869233e-16 / 1e-3 * 1e5 * 86400, kDarcyMetric, 5e-9);
}

TEST(Transmissibility, PowerCellUsesDistanceToFacePlaneGenericFormulaDoesNot) {
  // Sites displaced along the face (still orthogonal to it): the power-cell form is exactly A k / d,
  // the generic form on the same geometry is smaller by d^2 / |c|^2.
  const Vec3 k{50, 50, 50};
  const Vec3 s1{0.5, 0.8, 0.5}, s2{1.5, 0.8, 0.5};
  PolyMesh power = box_pair(0, 1, 2, 1, 1, k, k, kTransition, s1, s2);
  PolyMesh hexa = box_pair(0, 1, 2, 1, 1, k, k, kReservoir, s1, s2);
  const Transmissibilities tp = compute_transmissibilities(power, compute_geometry(power));
  const Transmissibilities th = compute_transmissibilities(hexa, compute_geometry(hexa));
  const int fp = interior_face(power), fh = interior_face(hexa);
  const double exact_half = kDarcyMetric * 1.0 * k.x / 0.5;
  EXPECT_NEAR(tp.half_owner[fp], exact_half, 1e-14 * exact_half);
  EXPECT_NEAR(tp.half_neighbour[fp], exact_half, 1e-14 * exact_half);
  EXPECT_NEAR(tp.face[fp], 0.5 * exact_half, 1e-14 * exact_half);
  const double generic_half = exact_half * 0.25 / (0.25 + 0.09);
  EXPECT_NEAR(th.half_owner[fh], generic_half, 1e-14 * exact_half);
  EXPECT_LT(th.face[fh], tp.face[fp] * 0.75);
}

// ---------------------------------------------------------------- negative half-transmissibilities

TEST(Transmissibility, PowerCellSiteBeyondFacePlaneIsCountedNegative) {
  for (double site_x : {0.5, 1.2}) {  // pass / fail pair
    MeshBuilder b;
    int32_t n[8];
    for (int c = 0; c < 8; ++c) n[c] = b.add_node({double(c & 1), double((c >> 1) & 1), double((c >> 2) & 1)});
    CellAttributes at;
    at.region = kTransition;
    at.perm = {10, 10, 10};
    at.fv_center = {site_x, 0.5, 0.5};
    add_hex(b, n, at);
    PolyMesh m = finish_ok(b);
    const MeshGeometry g = compute_geometry(m);
    const Transmissibilities t = compute_transmissibilities(m, g);
    int f_plus_x = -1;
    for (int f = 0; f < m.n_faces(); ++f)
      if (std::fabs(g.face_centroid[f].x - 1.0) < 1e-12) f_plus_x = f;
    ASSERT_GE(f_plus_x, 0);
    if (site_x < 1) {
      EXPECT_EQ(t.negative, 0);
      EXPECT_TRUE(t.negative_faces.empty());
    } else {
      EXPECT_EQ(t.negative, 1);
      ASSERT_EQ(t.negative_faces.size(), 1u);
      EXPECT_EQ(t.negative_faces[0], f_plus_x);
      // Kept with its sign: A k / (n . c) with n . c = -0.2.
      const double expected = kDarcyMetric * 10.0 / -0.2;
      EXPECT_NEAR(t.half_owner[f_plus_x], expected, 1e-14 * std::fabs(expected));
    }
  }
}

namespace {

// Parallelepiped spanned by a = (1,1,0), b = (0.95,0.3,0), c = (0,0,1), a reservoir cell with its
// centroid as FV centre and K = (kx, 1, 1). On the two faces spanned by b and c, n . c > 0 but
// n . K c < 0 when kx >> ky.
const Vec3 kSkewA{1, 1, 0}, kSkewB{0.95, 0.3, 0}, kSkewC{0, 0, 1};
PolyMesh skewed_parallelepiped(double kx) {
  MeshBuilder b;
  int32_t n[8];
  for (int c = 0; c < 8; ++c)
    n[c] = b.add_node(double(c & 1) * kSkewA + double((c >> 1) & 1) * kSkewB + double((c >> 2) & 1) * kSkewC);
  CellAttributes at;
  at.region = kReservoir;
  at.perm = {kx, 1, 1};
  at.fv_center = 0.5 * (kSkewA + kSkewB + kSkewC);
  add_hex(b, n, at);
  return finish_ok(b);
}

}  // namespace

TEST(Transmissibility, SkewedAnisotropicHexahedronGivesNegativeGenericHalves) {
  const Vec3 eb = kSkewB, ec = kSkewC;
  for (double kx : {1.0, 1000.0}) {  // pass / fail pair
    PolyMesh m = skewed_parallelepiped(kx);
    const MeshGeometry g = compute_geometry(m);
    const Transmissibilities t = compute_transmissibilities(m, g);
    if (kx == 1.0) {
      EXPECT_EQ(t.negative, 0);
    } else {
      EXPECT_EQ(t.negative, 2);
      ASSERT_EQ(t.negative_faces.size(), 2u);
      for (int32_t f : t.negative_faces) {
        EXPECT_LT(t.half_owner[f], 0.0);  // not abs()'d
        EXPECT_NEAR(std::fabs(dot(normalized(g.face_area[f]), normalized(cross(eb, ec)))), 1.0, 1e-12);
      }
    }
  }
}

// The deck's convention (deck_transmissibility_options): a reservoir cell's half is OPM's corner-point
// one, K_dd |A . c| / |c|^2 with d the face's axis, never negative; on the skewed anisotropic
// parallelepiped above (two negative generic halves) it differs from the checker's signed default.
TEST(Transmissibility, DeckOptionsGiveReservoirCellsOpmsCornerPointHalves) {
  const PolyMesh m = skewed_parallelepiped(1000);
  const MeshGeometry g = compute_geometry(m);
  const Transmissibilities signed_t = compute_transmissibilities(m, g);
  const Transmissibilities deck_t = compute_transmissibilities(m, g, deck_transmissibility_options());
  EXPECT_EQ(signed_t.negative, 2);
  EXPECT_EQ(deck_t.negative, 0);
  const std::vector<Vec3> end = boundary_flux_points(m, g);
  const Vec3 k = m.cell_perm[0];
  for (int f = 0; f < m.n_faces(); ++f) {
    const Vec3 a = m.face_sign(f, 0) * g.face_area[f], c = end[f] - m.cell_fv_center[0];
    const Vec3 n{std::fabs(a.x), std::fabs(a.y), std::fabs(a.z)};
    const double kd = n.x >= n.y && n.x >= n.z ? k.x : n.y >= n.z ? k.y : k.z;
    const double expected = kDarcyMetric * kd * std::fabs(dot(a, c)) / norm2(c);
    EXPECT_NEAR(deck_t.half_owner[f], expected, 1e-14 * expected) << f;
    EXPECT_GT(deck_t.half_owner[f], 0.0) << f;
  }
  for (int32_t f : signed_t.negative_faces) EXPECT_LT(signed_t.half_owner[f], 0.0);
}

// OPM computes one transmissibility per pair of model cells from the pair's vector area and, on each
// side, the centre of the cell's whole face (the mean of its 4 corners). Two model cells sharing a
// twisted face get that value whether the mesh stores the face as one quad or as the triangles about the
// node at the mean of its corners (how the mesh stores a whole face with stations on its edges).
TEST(Transmissibility, DeckOptionsGiveOnePairValueWhateverTheSharedFaceIsStoredAs) {
  double pair_t[2] = {0, 0};
  // Corners on the pillar lines x = 0, 10, 20.
  auto point = [](int i, int j, int k) {
    Vec3 p{10.0 * i, 8.0 * j, 3.0 * k};
    if (i == 1 && j == 1 && k == 1) p = {10.6, 8, 3.4};  // the shared face is twisted
    return p;
  };
  const Vec3 perm{100, 20, 5};
  for (int stored = 0; stored < 2; ++stored) {
    MeshBuilder b;
    int32_t id[3][2][2];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 2; ++j)
        for (int k = 0; k < 2; ++k) id[i][j][k] = b.add_node(point(i, j, k));
    const Vec3 mid = 0.25 * (point(1, 0, 0) + point(1, 1, 0) + point(1, 0, 1) + point(1, 1, 1));
    const int32_t apex = stored == 1 ? b.add_node(mid) : -1;
    for (int c = 0; c < 2; ++c) {
      int32_t n[8];
      Vec3 centre{0, 0, 0};
      for (int q = 0; q < 8; ++q) {
        n[q] = id[c + (q & 1)][(q >> 1) & 1][(q >> 2) & 1];
        centre += 0.125 * point(c + (q & 1), (q >> 1) & 1, (q >> 2) & 1);
      }
      CellAttributes at;
      at.region = kReservoir;
      at.perm = perm;
      at.fv_center = centre;
      at.ijk = {c, 0, 0};
      const int32_t shared_side = c == 0 ? 1 : 0;  // the x = 10 face: +a of cell 0, -a of cell 1
      std::vector<std::vector<int32_t>> faces{{n[0], n[2], n[3], n[1]}, {n[4], n[5], n[7], n[6]},
                                              {n[0], n[1], n[5], n[4]}, {n[2], n[6], n[7], n[3]}};
      const std::vector<int32_t> x_faces[2] = {{n[0], n[4], n[6], n[2]}, {n[1], n[3], n[7], n[5]}};
      for (int side = 0; side < 2; ++side) {
        const std::vector<int32_t>& q = x_faces[side];
        if (side == shared_side && stored == 1)
          for (int e = 0; e < 4; ++e) faces.push_back({apex, q[e], q[(e + 1) % 4]});
        else
          faces.push_back(q);
      }
      add_convex_cell(b, faces, std::vector<int32_t>(faces.size(), kOuterBoundary), at);
    }
    const PolyMesh m = finish_ok(b);
    const Transmissibilities t = compute_transmissibilities(m, compute_geometry(m), deck_transmissibility_options());
    int shared = 0;
    for (int f = 0; f < m.n_faces(); ++f)
      if (m.face_neighbour[f] >= 0) pair_t[stored] += t.face[f], ++shared;
    EXPECT_EQ(shared, stored == 0 ? 1 : 4);
    // OPM's value by hand: vector area of the quad (half the cross product of its diagonals).
    const Vec3 area = 0.5 * cross(point(1, 1, 0) - point(1, 0, 1), point(1, 1, 1) - point(1, 0, 0));
    double h[2];
    for (int c = 0; c < 2; ++c) {
      Vec3 centre{0, 0, 0};
      for (int q = 0; q < 8; ++q) centre += 0.125 * point(c + (q & 1), (q >> 1) & 1, (q >> 2) & 1);
      const Vec3 d = mid - centre;
      h[c] = kDarcyMetric * perm.x * std::fabs(dot(area, d)) / norm2(d);
    }
    const double expected = 1 / (1 / h[0] + 1 / h[1]);
    EXPECT_NEAR(pair_t[stored], expected, 1e-12 * expected) << "stored as " << (stored ? "triangles" : "a quad");
  }
  EXPECT_NEAR(pair_t[0], pair_t[1], 1e-12 * pair_t[0]);
}

// ---------------------------------------------------------------- radial ring blocks

TEST(Transmissibility, RadialBlockReproducesSteadyRadialFlowExactly) {
  for (double ratio : {500.0, std::exp(12.5)})
    for (int rings : {5, 10, 20, 40})
      for (int sectors : {8, 16}) {
        RingSpec s;
        s.rings = rings;
        s.sectors = sectors;
        s.r_outer = s.r_w * ratio;
        // A 27 km wide, 12 m thick block: the huge axial transmissibilities of its outer cells
        // (zero flow) would only add round-off (1e-10), so that geometry gets a single segment.
        s.segments = ratio > 1000 ? 1 : 2;
        const PolyMesh m = ring_block(s);
        const MeshGeometry g = compute_geometry(m);
        const Transmissibilities t = compute_transmissibilities(m, g);
        EXPECT_EQ(t.negative, 0);
        const SteadyResult r = solve_steady(m, g, s, t.face, t.half_owner, kPw, kPR, kMu);
        const RadialErrors e = errors_against_exact(m, s, r);
        std::printf("log form, %2d rings x %2d sectors, R/rw %.0f: rate error %.2e, pressure error %.2e\n", rings,
                    sectors, ratio, e.rate, e.pressure);
        EXPECT_LE(e.pressure, 1e-10) << rings << " rings, " << sectors << " sectors, R/rw " << ratio;
        EXPECT_LE(std::fabs(e.rate), 1e-10) << rings << " rings, " << sectors << " sectors, R/rw " << ratio;
      }
}

TEST(Transmissibility, AnisotropicVerticalRadialBlockIsExactWithGeometricMeanPermeability) {
  RingSpec s;
  s.rings = 10;
  s.sectors = 16;
  s.perm = {50, 200, 3};  // exact solution uses k = sqrt(kx ky) = 100
  const PolyMesh m = ring_block(s);
  const MeshGeometry g = compute_geometry(m);
  const Transmissibilities t = compute_transmissibilities(m, g);
  const RadialErrors e = errors_against_exact(m, s, solve_steady(m, g, s, t.face, t.half_owner, kPw, kPR, kMu));
  EXPECT_LE(e.pressure, 1e-10);
  EXPECT_LE(std::fabs(e.rate), 1e-10);
}

TEST(Transmissibility, DistanceBasedRingTransmissibilityGivesTheKnownRateErrors) {
  // Same rings, same nodes (r_c = sqrt(r_in r_out)), only the half-transmissibility form changes.
  // Per ring of log-width x = ln(R/rw)/N the linear form has resistance 2 sinh(x/2) instead of x,
  // so the rate error is x / (2 sinh(x/2)) - 1. The reference figures (-22, -6.2, -1.6, -0.4 %)
  // are this at ln(R/rw) = 12.5.
  const double reference[4] = {-0.22, -0.062, -0.016, -0.004};
  const int ring_counts[4] = {5, 10, 20, 40};
  for (int sectors : {8, 16})
    for (int i = 0; i < 4; ++i) {
      RingSpec s;
      s.rings = ring_counts[i];
      s.sectors = sectors;
      s.r_outer = s.r_w * std::exp(12.5);
      s.segments = 1;  // see RadialBlockReproducesSteadyRadialFlowExactly
      const PolyMesh m = ring_block(s);
      const MeshGeometry g = compute_geometry(m);
      const Transmissibilities t = compute_transmissibilities(m, g);
      std::vector<double> face_t, dirichlet_t;
      linear_ring_transmissibilities(m, g, s, t, &face_t, &dirichlet_t);
      const RadialErrors e = errors_against_exact(m, s, solve_steady(m, g, s, face_t, dirichlet_t, kPw, kPR, kMu));
      const double x = 12.5 / s.rings;
      std::printf("linear form, %2d rings x %2d sectors, ln(R/rw) 12.5: rate error %.3f %%, pressure error %.3f %%\n",
                  s.rings, sectors, 100 * e.rate, 100 * e.pressure);
      EXPECT_NEAR(e.rate, x / (2 * std::sinh(x / 2)) - 1, 1e-10) << s.rings << " rings";
      EXPECT_NEAR(e.rate, reference[i], 0.1 * std::fabs(reference[i])) << s.rings << " rings";
    }
}

TEST(Transmissibility, GenericFormOnPolygonalRingsIsFarFromExact) {
  // exact_radial = false: the generic form on the chord faces. Errors measured for docs/transmissibility.md.
  for (int sectors : {8, 16})
    for (int rings : {5, 10, 20, 40}) {
      RingSpec s;
      s.rings = rings;
      s.sectors = sectors;
      const PolyMesh m = ring_block(s);
      const MeshGeometry g = compute_geometry(m);
      TransmissibilityOptions generic;
      generic.exact_radial = false;
      const Transmissibilities t = compute_transmissibilities(m, g, generic);
      const RadialErrors e = errors_against_exact(m, s, solve_steady(m, g, s, t.face, t.half_owner, kPw, kPR, kMu));
      std::printf("generic form, %2d rings x %2d sectors, R/rw 500: rate error %.3f %%, pressure error %.3f %%\n",
                  rings, sectors, 100 * e.rate, 100 * e.pressure);
      EXPECT_GT(std::fabs(e.rate), 1e-3);
    }
}

TEST(Transmissibility, RingZeroConnectionFactorIsTheLogForm) {
  // Vertical, horizontal (along x) and deviated wells in an anisotropic medium: the axis comes from
  // the cell's geometry, k is sqrt(det K) over the plane normal to the axis (projected here on an
  // explicit basis, independently of transverse_permeability).
  const Vec3 perm{40, 250, 9};
  const Vec3 dev_axis = normalized(Vec3{0.3, -0.5, 0.8});
  const Vec3 dev_e1 = normalized(cross(dev_axis, Vec3{1, 0, 0}));
  const Vec3 frames[3][3] = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                             {{0, 1, 0}, {0, 0, 1}, {1, 0, 0}},
                             {dev_e1, cross(dev_axis, dev_e1), dev_axis}};
  for (const auto& fr : frames) {
    RingSpec s;
    s.rings = 4;
    s.sectors = 12;
    s.segments = 3;
    s.origin = {10, -20, 1500};
    s.e1 = fr[0], s.e2 = fr[1], s.axis = fr[2];
    s.perm = perm;
    const PolyMesh m = ring_block(s);
    const MeshGeometry g = compute_geometry(m);
    const Transmissibilities t = compute_transmissibilities(m, g);
    auto kp = [&](Vec3 u, Vec3 v) { return dot(u, Vec3{perm.x * v.x, perm.y * v.y, perm.z * v.z}); };
    const double k_perp = std::sqrt(kp(s.e1, s.e1) * kp(s.e2, s.e2) - kp(s.e1, s.e2) * kp(s.e2, s.e1));
    const double r1 = ring_radius(s, 1), r_c = std::sqrt(s.r_w * r1);
    const double theta = 2 * kPi / s.sectors, length = s.height / s.segments;
    const double cf = kDarcyMetric * theta * length * k_perp / std::log(r_c / s.r_w);
    int wellbore_faces = 0;
    for (int f = 0; f < m.n_faces(); ++f) {
      if (!is_wellbore_patch(m.face_patch[f])) continue;
      ++wellbore_faces;
      // The face's axial length comes from its area (rounding of the fan: ~1e-12 relative).
      EXPECT_NEAR(t.face[f], cf, 1e-11 * cf);
      EXPECT_EQ(t.face[f], t.half_owner[f]);
    }
    EXPECT_EQ(wellbore_faces, s.sectors * s.segments);
    EXPECT_NEAR(transverse_permeability(perm, s.axis), k_perp, 1e-12 * k_perp);

    const auto wells = well_connection_factors(m, t, 1);
    ASSERT_EQ(wells.size(), 1u);
    ASSERT_EQ(wells[0].size(), size_t(s.sectors * s.segments));
    double total = 0;
    for (size_t i = 0; i < wells[0].size(); ++i) {
      EXPECT_EQ(m.cell_radial[wells[0][i].first].ring, 0);
      if (i > 0) {
        EXPECT_LT(wells[0][i - 1].first, wells[0][i].first);
      }
      total += wells[0][i].second;
    }
    const double total_exact = kDarcyMetric * 2 * kPi * s.height * k_perp / std::log(r_c / s.r_w);
    EXPECT_NEAR(total, total_exact, 1e-12 * total_exact);
  }
}

namespace {

// The faces between a ring cell and a transition cell of a ring block with a transition
// shell, with the face's radial (well) and shell (transition) cell and their half values.
struct ShellFace {
  int face, radial, shell;
  double half_radial, half_shell;
};

std::vector<ShellFace> shell_faces(const PolyMesh& m, const Transmissibilities& t) {
  std::vector<ShellFace> out;
  for (int f = 0; f < m.n_faces(); ++f) {
    const int o = m.face_owner[f], n = m.face_neighbour[f];
    if (n < 0 || (m.cell_region[o] == kTransition) == (m.cell_region[n] == kTransition)) continue;
    const bool owner_radial = m.cell_region[o] == kWell;
    out.push_back({f, owner_radial ? o : n, owner_radial ? n : o, owner_radial ? t.half_owner[f] : t.half_neighbour[f],
                   owner_radial ? t.half_neighbour[f] : t.half_owner[f]});
  }
  return out;
}

// A 3-ring block wrapped in a transition shell, with its transmissibilities.
struct ShellBlock {
  RingSpec s;
  PolyMesh m;
  MeshGeometry g;
  Transmissibilities t;
};

ShellBlock shell_block(int sectors) {
  ShellBlock b;
  b.s.rings = 3;
  b.s.sectors = sectors;
  b.s.transition_shell = true;
  b.m = ring_block(b.s);
  b.g = compute_geometry(b.m);
  b.t = compute_transmissibilities(b.m, b.g);
  return b;
}

}  // namespace

TEST(Transmissibility, OutermostRingFaceToTransitionCellUsesLogFormOnRadialSide) {
  const ShellBlock b = shell_block(8);
  const RingSpec& s = b.s;
  const PolyMesh& m = b.m;
  const MeshGeometry& g = b.g;
  const Transmissibilities& t = b.t;
  EXPECT_EQ(t.negative, 0);
  const double theta = 2 * kPi / s.sectors, length = s.height / s.segments, k = 100;
  int checked = 0;
  for (const ShellFace& sf : shell_faces(m, t)) {
    const int f = sf.face, shell = sf.shell, o = m.face_owner[f];
    const RadialCellInfo& r = m.cell_radial[sf.radial];
    ASSERT_EQ(r.ring, s.rings - 1);
    // The radial half runs to the chord face (its centroid is r_out cos(theta/2) from the
    // axis), where the shell's half starts: the band between chord and arc is counted once.
    const double r_face = r.r_out * std::cos(0.5 * theta);
    EXPECT_NEAR(norm(g.face_centroid[f] - Vec3{0, 0, g.face_centroid[f].z}), r_face, 1e-12 * r_face);
    const double log_half = kDarcyMetric * theta * length * k / std::log(r_face / r.r_center);
    const double t_shell = sf.half_shell;
    EXPECT_NEAR(sf.half_radial, log_half, 1e-13 * log_half);
    // Shell side: power-cell form A k / (n . c).
    const Vec3 n_out = normalized((shell == o ? 1.0 : -1.0) * g.face_area[f]);
    const double d = dot(n_out, g.face_centroid[f] - m.cell_fv_center[shell]);
    const double orth = kDarcyMetric * norm(g.face_area[f]) * k / d;
    EXPECT_NEAR(t_shell, orth, 1e-13 * orth);
    EXPECT_NEAR(t.face[f], 1.0 / (1.0 / log_half + 1.0 / orth), 1e-13 * orth);
    ++checked;
  }
  EXPECT_EQ(checked, s.sectors * s.segments);
}

TEST(Transmissibility, OutermostRingFaceCountsTheChordArcBandOnce) {
  // Exact radial flow between the outermost ring's FV centre (r_c) and a transition site on
  // the sector's mid-angle ray at r_s: theta L k / ln(r_s / r_c). The mesh's two-point value
  // (radial log half to the chord + power-cell half from the chord) must be closer to it than
  // the radial half to the arc r_out would be, for coarse and fine sectors. (What is left is
  // the linear power-cell half over r_s / r_f = 1.3-1.5 here.)
  for (int sectors : {6, 8, 12, 24}) {
    const ShellBlock b = shell_block(sectors);
    const RingSpec& s = b.s;
    const PolyMesh& m = b.m;
    const Transmissibilities& t = b.t;
    EXPECT_EQ(t.negative, 0);
    const double theta = 2 * kPi / s.sectors, length = s.height / s.segments, k = 100;
    int checked = 0;
    for (const ShellFace& sf : shell_faces(m, t)) {
      const int f = sf.face;
      const RadialCellInfo& r = m.cell_radial[sf.radial];
      const Vec3 site = m.cell_fv_center[sf.shell];
      const double r_s = norm(site - Vec3{0, 0, site.z});
      const double exact = kDarcyMetric * theta * length * k / std::log(r_s / r.r_center);
      const double arc =
          1.0 / (std::log(r.r_out / r.r_center) / (kDarcyMetric * theta * length * k) + 1.0 / sf.half_shell);
      const double err_mesh = std::fabs(t.face[f] / exact - 1), err_arc = std::fabs(arc / exact - 1);
      EXPECT_LT(err_mesh, err_arc) << sectors << " sectors";
      if (checked == 0)
        std::printf("%2d sectors, r_s / r_out %.3f: two-point error %.4f %% (radial half to the arc: %.4f %%)\n",
                    sectors, r_s / r.r_out, 100 * (t.face[f] / exact - 1), 100 * (arc / exact - 1));
      ++checked;
    }
    EXPECT_EQ(checked, s.sectors * s.segments);
  }
}

TEST(Transmissibility, RadialCellAngularAndAxialFacesUseTheOrthogonalForm) {
  // Neighbours across an angular or axial face of a radial block are mirror images through the
  // face, so t = A k / d with d the distance from the FV centre to the face plane: axially half
  // the segment length, angularly r_c sin(theta / 2). The generic form would be smaller (it
  // divides by |c|^2, c reaching the face centroid at another radius).
  RingSpec s;
  s.rings = 4;
  s.sectors = 8;
  s.segments = 3;
  const PolyMesh m = ring_block(s);
  const MeshGeometry g = compute_geometry(m);
  const Transmissibilities t = compute_transmissibilities(m, g);
  TransmissibilityOptions generic;
  generic.exact_radial = false;
  const Transmissibilities tg = compute_transmissibilities(m, g, generic);
  const double theta = 2 * kPi / s.sectors, length = s.height / s.segments, k = 100;
  int axial = 0, angular = 0;
  for (int f = 0; f < m.n_faces(); ++f) {
    const int o = m.face_owner[f], n = m.face_neighbour[f];
    if (n < 0) continue;
    const RadialCellInfo &a = m.cell_radial[o], &b = m.cell_radial[n];
    const double area = norm(g.face_area[f]);
    if (a.ring == b.ring && a.sector == b.sector) {
      const double expected = kDarcyMetric * area * k / length;  // two halves of length / 2
      EXPECT_NEAR(t.face[f], expected, 1e-12 * expected);
      EXPECT_LT(tg.face[f], expected * (1 - 1e-6));
      ++axial;
    } else if (a.ring == b.ring && a.segment == b.segment) {
      const double d = a.r_center * std::sin(0.5 * theta);
      const double expected = kDarcyMetric * area * k / (2 * d);
      EXPECT_NEAR(t.face[f], expected, 1e-12 * expected);
      EXPECT_LT(tg.face[f], expected * (1 - 1e-6));
      ++angular;
    }
  }
  EXPECT_EQ(axial, s.rings * s.sectors * (s.segments - 1));
  EXPECT_EQ(angular, s.rings * s.sectors * s.segments);
}
