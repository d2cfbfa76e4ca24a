// The radial block alone in an anisotropic medium (issue 15, docs/anisotropy.md): built in the
// permeability frame (x' = S^-1 x) and mapped back, it reproduces the exact elliptic solution
// p = p_w + (p_R - p_w) ln(r' / r_w') / ln(R' / r_w') (r' the scaled distance from the axis) to
// round-off, for kv/kh 0.1 and 0.01 and kx/ky 3, vertical, deviated and horizontal axes; the same
// physical mesh with Euclidean transmissibilities (metric_scale reset) is not exact.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "block_mesh.hpp"
#include "fvcheck/lib/transmissibility.hpp"
#include "meshgen/core/fv_quality.hpp"
#include "meshgen/grids/well_block.hpp"
#include "meshgen/pipeline/permeability_frame.hpp"
#include "solver_demo/lib/tpfa.hpp"

using namespace hm;

namespace {

constexpr double kPi = 3.14159265358979323846;

struct AnisoCase {
  Vec3 a, b;            // straight trajectory
  Vec3 k{100, 100, 10};  // mD
  int rings = 6, sectors = 12;
};

CaseSpec physical_spec(const AnisoCase& ac) {
  CaseSpec cs;
  cs.name = "aniso_radial";
  cs.metric = MeshMetric::Permeability;
  cs.reservoir.x = {-1e4, 1e4};
  cs.reservoir.y = {-1e4, 1e4};
  cs.reservoir.z = {-1e4, 1e4};
  cs.reservoir.permeability = ac.k;
  WellSpec w;
  w.name = "W";
  w.trajectory = {ac.a, ac.b};
  w.radius = 0.1;
  w.drainage_radius = 8.0;
  w.rings = ac.rings;
  w.sectors = ac.sectors;
  w.segment_length = 4.0;
  w.end_caps = EndCaps::Flat;
  cs.wells.push_back(w);
  return cs;
}

struct Errors {
  double pressure = 0, rate = 0, k_angle_deg = 0;
};

// The block built in the case's permeability frame and mapped back; its outer ring and end faces
// on kOuterBoundary.
PolyMesh anisotropic_block(const AnisoCase& ac, const CaseSpec& phys, const CaseSpec& scaled,
                           const PermeabilityFrame& frame) {
  WellBlock block = make_well_block(scaled, 0, ac.sectors);
  const int n_seg = block.layers - 1;
  for (size_t c = 0; c < block.cell_faces.size(); ++c) {
    const RadialCellInfo& r = block.cell_attrs[c].radial;
    block.cell_attrs[c].perm = ac.k;
    if (r.ring == ac.rings - 1) block.cell_faces[c][1].patch = kOuterBoundary;
    if (r.segment == 0) block.cell_faces[c][4].patch = kOuterBoundary;
    if (r.segment == n_seg - 1) block.cell_faces[c][5].patch = kOuterBoundary;
  }
  PolyMesh m = hm_test::assemble_block(block);
  unscale_mesh(m, FrameUnmapper(frame, phys.reservoir));
  return m;
}

// euclidean_trans: the same physical mesh, transmissibilities computed as if it were Euclidean.
Errors solve_block(const AnisoCase& ac, bool euclidean_trans) {
  const CaseSpec phys = physical_spec(ac);
  const PermeabilityFrame frame = permeability_frame(phys);
  const CaseSpec scaled = scaled_case(phys, frame);
  PolyMesh m = anisotropic_block(ac, phys, scaled, frame);
  const MeshGeometry g = compute_geometry(m);
  Errors e;
  // Interior and wellbore faces (the block's end faces are boundary faces here, whose FV centre to
  // face centroid line is not normal to them in either metric; in a hybrid mesh they are interior).
  const std::vector<double> angle = face_k_nonorthogonality(m, g);
  for (int f = 0; f < m.n_faces(); ++f)
    if (m.face_neighbour[f] >= 0 || is_wellbore_patch(m.face_patch[f])) e.k_angle_deg = std::max(e.k_angle_deg, angle[f]);
  if (euclidean_trans) m.metric_scale = {1, 1, 1};

  const WellSpec& ws = scaled.wells[0];
  const Vec3 as = ws.trajectory[0], bs = ws.trajectory[1], ds = normalized(bs - as);
  const double r_w = ws.radius, R = ws.drainage_radius, length = norm(bs - as);
  const double p_w = 150, p_R = 200, mu = 0.7, log_ratio = std::log(R / r_w);
  auto p_exact = [&](double r) { return p_w + (p_R - p_w) * std::log(r / r_w) / log_ratio; };
  FlowProblem pb;
  pb.mesh = &m;
  pb.geo = &g;
  pb.viscosity_cp = mu;
  pb.gravity = false;
  pb.wells = {{0, p_w, ac.a.z}};
  pb.outer_dirichlet = [&](Vec3 x) {
    const double s = dot(to_scaled(frame, x) - as, ds);
    if (std::fabs(s) < 1e-9 * length || std::fabs(s - length) < 1e-9 * length) return std::nan("");  // end faces
    return p_R;
  };
  const FlowSolution sol = solve_tpfa(pb, compute_transmissibilities(m, g));
  for (int c = 0; c < m.n_cells(); ++c) {
    const Vec3 xs = to_scaled(frame, m.cell_fv_center[c]) - as;
    const double r = norm(xs - dot(xs, ds) * ds);  // the scaled radius of the FV centre
    e.pressure = std::max(e.pressure, std::fabs(sol.pressure[c] - p_exact(r)) / (p_R - p_w));
  }
  const double k0 = std::cbrt(ac.k.x * ac.k.y * ac.k.z);
  const double q_exact = kDarcyMetric * 2 * kPi * k0 * length * (p_R - p_w) / (mu * log_ratio);
  e.rate = sol.well_rate_m3_per_day.at(0) / q_exact - 1;
  return e;
}

struct Named {
  const char* name;
  AnisoCase ac;
};

std::vector<Named> cases() {
  const Vec3 kv01{100, 100, 10}, kv001{100, 100, 1}, kxy3{300, 100, 10};
  return {
      {"vertical kv/kh 0.1", {{0, 0, 1000}, {0, 0, 1012}, kv01}},
      {"vertical kv/kh 0.01", {{0, 0, 1000}, {0, 0, 1012}, kv001}},
      {"vertical kx/ky 3", {{0, 0, 1000}, {0, 0, 1012}, kxy3}},
      {"deviated kv/kh 0.1", {{10, -5, 1000}, {30, 7, 1021}, kv01}},
      {"deviated kv/kh 0.01", {{10, -5, 1000}, {30, 7, 1021}, kv001}},
      {"deviated kx/ky 3", {{10, -5, 1000}, {30, 7, 1021}, kxy3}},
      {"horizontal kv/kh 0.1", {{0, 0, 1000}, {40, 0, 1000}, kv01}},
      {"horizontal kv/kh 0.01", {{0, 0, 1000}, {40, 0, 1000}, kv001}},
      {"horizontal kx/ky 3", {{0, 0, 1000}, {0, 40, 1000}, kxy3}},
  };
}

}  // namespace

TEST(AnisotropicRadialBlock, ReproducesTheExactEllipticSolutionToRoundOff) {
  for (const Named& n : cases()) {
    const Errors e = solve_block(n.ac, false);
    std::printf("%-24s pressure %.2e  rate %.2e  max K-non-orthogonality %.2e deg\n", n.name, e.pressure, e.rate,
                e.k_angle_deg);
    EXPECT_LT(e.pressure, 1e-10) << n.name;
    EXPECT_LT(std::fabs(e.rate), 1e-10) << n.name;
    EXPECT_LT(e.k_angle_deg, 1e-6) << n.name;
  }
}

// Fail pair: the same physical (elliptic) block with the Euclidean formulas is not exact.
TEST(AnisotropicRadialBlock, EuclideanTransmissibilitiesOnTheSameBlockAreNotExact) {
  for (const Named& n : cases()) {
    const Errors e = solve_block(n.ac, true);
    std::printf("%-24s Euclidean T: pressure %.2e  rate %.2e\n", n.name, e.pressure, e.rate);
    EXPECT_GT(std::fabs(e.rate), 1e-3) << n.name;
  }
}

// The block alone: volume preserved by the frame (det S = 1), and the scaled radius of the
// wellbore is Peaceman's equivalent radius (checked in test_permeability_frame.cpp).
TEST(AnisotropicRadialBlock, FrameKeepsTheBlockVolume) {
  for (const Named& n : cases()) {
    const CaseSpec phys = physical_spec(n.ac);
    const PermeabilityFrame frame = permeability_frame(phys);
    const CaseSpec scaled = scaled_case(phys, frame);
    const PolyMesh m = anisotropic_block(n.ac, phys, scaled, frame);
    const MeshGeometry g = compute_geometry(m);
    double v = 0;
    for (double x : g.cell_volume) v += x;
    const double exact = exact_well_block_volume(scaled, 0, n.ac.sectors);
    EXPECT_NEAR(v / exact, 1.0, 1e-12) << n.name;
  }
}
