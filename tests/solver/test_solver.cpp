// The TPFA solver: exactness on a radial block, hydrostatics, the OPM Flow equation term by term,
// orderings, and Peaceman's known behaviour on a 2D-like Cartesian grid.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <random>
#include <stdexcept>

#include "block_mesh.hpp"
#include "fvcheck/lib/transmissibility.hpp"
#include "meshgen/grids/well_block.hpp"
#include "solver_demo/lib/line_source.hpp"
#include "solver_demo/lib/ordering.hpp"
#include "solver_demo/lib/peaceman.hpp"
#include "solver_demo/lib/tpfa.hpp"

using namespace hm;

namespace {

constexpr double kPi = 3.14159265358979323846;

// ---------------------------------------------------------------- radial block

struct RadialCase {
  std::vector<Vec3> trajectory;
  double r_w = 0.1, r_out = 8.0;
  int rings = 6, sectors = 12;
  double segment_length = 4.0;
  double k = 100;  // isotropic, mD
};

CaseSpec radial_case_spec(const RadialCase& rc) {
  CaseSpec cs;
  cs.name = "radial";
  cs.reservoir.x = {-1e4, 1e4};
  cs.reservoir.y = {-1e4, 1e4};
  cs.reservoir.z = {-1e4, 1e4};
  cs.reservoir.permeability = {rc.k, rc.k, rc.k};
  WellSpec w;
  w.name = "W";
  w.trajectory = rc.trajectory;
  w.radius = rc.r_w;
  w.drainage_radius = rc.r_out;
  w.rings = rc.rings;
  w.sectors = rc.sectors;
  w.segment_length = rc.segment_length;
  w.end_caps = EndCaps::Flat;  // a block with flat end faces (no-flow): 2D radial flow
  cs.wells.push_back(w);
  return cs;
}

/// A radial block alone: its outer (ring face of the last ring) and end faces on kOuterBoundary.
PolyMesh radial_block_mesh(const RadialCase& rc) {
  const CaseSpec cs = radial_case_spec(rc);
  WellBlock block = make_well_block(cs, 0, rc.sectors);
  const int n_seg = block.layers - 1;
  for (size_t c = 0; c < block.cell_faces.size(); ++c) {
    const RadialCellInfo& r = block.cell_attrs[c].radial;
    if (r.ring == rc.rings - 1) block.cell_faces[c][1].patch = kOuterBoundary;
    if (r.segment == 0) block.cell_faces[c][4].patch = kOuterBoundary;
    if (r.segment == n_seg - 1) block.cell_faces[c][5].patch = kOuterBoundary;
  }
  return hm_test::assemble_block(block);
}

struct RadialErrors {
  double pressure = 0, rate = 0;
};

/// Radial flow p(r) = p_w + (p_R - p_w) ln(r / r_w) / ln(R / r_w) through the block: p_w as the
/// BHP (no gravity), the outer faces at p(R) (projected to r = R: the ring model's outer radius,
/// or, with at_face_centroid, p at the face centroid), end faces no-flow (NaN).
RadialErrors radial_errors(const RadialCase& rc, bool at_face_centroid, bool exact_radial = true) {
  const PolyMesh m = radial_block_mesh(rc);
  const MeshGeometry g = compute_geometry(m);
  const double p_w = 150, p_R = 200, mu = 0.7;
  const Vec3 a = rc.trajectory.front(), b = rc.trajectory.back(), d = normalized(b - a);
  const double log_ratio = std::log(rc.r_out / rc.r_w);
  auto p_exact = [&](double r) { return p_w + (p_R - p_w) * std::log(r / rc.r_w) / log_ratio; };
  FlowProblem pb;
  pb.mesh = &m;
  pb.geo = &g;
  pb.viscosity_cp = mu;
  pb.gravity = false;
  pb.wells = {{0, p_w, a.z}};
  pb.outer_dirichlet = [&](Vec3 x) {
    const double s = dot(x - a, d), length = norm(b - a);
    if (std::fabs(s) < 1e-9 * length || std::fabs(s - length) < 1e-9 * length) return std::nan("");  // end faces
    return at_face_centroid ? p_exact(norm(x - a - s * d)) : p_R;
  };
  TransmissibilityOptions to;
  to.exact_radial = exact_radial;
  const FlowSolution sol = solve_tpfa(pb, compute_transmissibilities(m, g, to));
  RadialErrors e;
  for (int c = 0; c < m.n_cells(); ++c)
    e.pressure = std::max(e.pressure, std::fabs(sol.pressure[c] - p_exact(m.cell_radial[c].r_center)) / (p_R - p_w));
  const double length = norm(b - a);
  const double q_exact = kDarcyMetric * 2 * kPi * rc.k * length * (p_R - p_w) / (mu * log_ratio);
  e.rate = sol.well_rate_m3_per_day.at(0) / q_exact - 1;
  return e;
}

TEST(RadialBlock, VerticalBlockReproducesTheLogProfileToRoundOff) {
  RadialCase rc;
  rc.trajectory = {{0, 0, 1000}, {0, 0, 1012}};
  const RadialErrors e = radial_errors(rc, false);
  EXPECT_LT(e.pressure, 1e-10);
  EXPECT_LT(std::fabs(e.rate), 1e-10);
}

TEST(RadialBlock, DeviatedBlockWithManyRingsIsExactToo) {
  RadialCase rc;
  rc.trajectory = {{10, -5, 1000}, {30, 7, 1021}};
  rc.rings = 20;
  rc.sectors = 16;
  rc.r_out = 50;
  const RadialErrors e = radial_errors(rc, false);
  EXPECT_LT(e.pressure, 1e-10);
  EXPECT_LT(std::fabs(e.rate), 1e-10);
}

// Fail pairs: the same block is not exact with the generic (distance) form, nor when the outer
// pressure is taken at the chord faces' centroids (radius R cos(pi/S)) while the log form ends
// at the arc r = R: the two halves of an outer face must refer to the same point.
TEST(RadialBlock, GenericFormOrChordCentroidPressureIsNotExact) {
  RadialCase rc;
  rc.trajectory = {{0, 0, 1000}, {0, 0, 1012}};
  EXPECT_GT(std::fabs(radial_errors(rc, false, false).rate), 0.01);
  const RadialErrors chord = radial_errors(rc, true);
  std::printf("outer pressure at the chord centroids: rate error %.4f %%, pressure error %.4f %% of the drawdown\n",
              100 * chord.rate, 100 * chord.pressure);
  // Over-resistance of the band between chord and arc: the rate is too HIGH by
  // ln(cos(pi/12)) / ln(R / r_w) relative to p(R) - p_w... measured, not tuned: > 0.5 %.
  EXPECT_GT(std::fabs(chord.rate), 0.005);
}

// ---------------------------------------------------------------- gravity

CartesianMesh column(const std::vector<double>& z) {
  ReservoirSpec spec;
  spec.x = {0, 10};
  spec.y = {0, 20};
  spec.z = z;
  spec.permeability = {50, 80, 7};
  return make_cartesian_mesh(spec);
}

const std::vector<double> kColumnZ = {1000, 1003, 1010, 1011.5, 1020, 1032, 1033, 1050};

TEST(Gravity, ColumnWithTopPressureIsHydrostatic) {
  const CartesianMesh cm = column(kColumnZ);
  FlowProblem pb;
  pb.mesh = &cm.mesh;
  pb.geo = &cm.geo;
  pb.density = 1030;
  pb.viscosity_cp = 0.4;
  const double p_top = 123.4;
  pb.outer_dirichlet = [&](Vec3 x) { return x.z == kColumnZ.front() ? p_top : std::nan(""); };
  const FlowSolution sol = solve_tpfa(pb, compute_transmissibilities(cm.mesh, cm.geo));
  const double grad = 1030 * kGravity / 1e5;
  for (int c = 0; c < cm.mesh.n_cells(); ++c) {
    const double expect = p_top + grad * (cm.mesh.cell_fv_center[c].z - kColumnZ.front());
    EXPECT_NEAR(sol.pressure[c], expect, 1e-11 * expect) << "cell " << c;
  }
  EXPECT_LT(sol.relative_residual, 1e-11);
}

TEST(Gravity, ColumnWithAWellAtItsReferenceDepthIsHydrostaticAndStill) {
  const CartesianMesh cm = column(kColumnZ);
  FlowProblem pb;
  pb.mesh = &cm.mesh;
  pb.geo = &cm.geo;
  pb.density = 850;
  const int deep = 5;
  pb.connections = {{0, deep, 3.7, cm.mesh.cell_fv_center[deep]}};
  pb.wells = {{0, 250.0, 1001.0}};
  const FlowSolution sol = solve_tpfa(pb, compute_transmissibilities(cm.mesh, cm.geo));
  const double grad = 850 * kGravity / 1e5;
  for (int c = 0; c < cm.mesh.n_cells(); ++c) {
    const double expect = 250.0 + grad * (cm.mesh.cell_fv_center[c].z - 1001.0);
    EXPECT_NEAR(sol.pressure[c], expect, 1e-11 * expect) << "cell " << c;
  }
  EXPECT_NEAR(sol.well_rate_m3_per_day.at(0), 0.0, 1e-9);
}

TEST(Gravity, ColumnWithoutPressureReferenceIsRejected) {
  const CartesianMesh cm = column(kColumnZ);
  FlowProblem pb;
  pb.mesh = &cm.mesh;
  pb.geo = &cm.geo;
  EXPECT_THROW(solve_tpfa(pb, compute_transmissibilities(cm.mesh, cm.geo)), std::invalid_argument);
  // A well without a control leaves the column floating too.
  pb.connections = {{0, 2, 1.0, {}}};
  EXPECT_THROW(solve_tpfa(pb, compute_transmissibilities(cm.mesh, cm.geo)), std::invalid_argument);
  pb.wells = {{0, 200.0, 1000.0}};
  EXPECT_NO_THROW(solve_tpfa(pb, compute_transmissibilities(cm.mesh, cm.geo)));
}

// ---------------------------------------------------------------- the OPM Flow equation

/// A heterogeneous 7 x 5 x 4 box, a producer and an injector (connections), gravity on.
struct TwoWellBox {
  CartesianMesh cm;
  FlowProblem pb;
  Transmissibilities tr;
};

TwoWellBox two_well_box() {
  TwoWellBox t;
  ReservoirSpec spec;
  spec.x = {0, 10, 25, 30, 41, 60, 70, 90};
  spec.y = {0, 15, 20, 40, 50, 66};
  spec.z = {1000, 1004, 1011, 1013, 1030};
  t.cm = make_cartesian_mesh(spec);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (Vec3& k : t.cm.mesh.cell_perm) k = {10 + 300 * u(rng), 10 + 300 * u(rng), 1 + 30 * u(rng)};
  t.tr = compute_transmissibilities(t.cm.mesh, t.cm.geo);
  t.pb.mesh = &t.cm.mesh;
  t.pb.geo = &t.cm.geo;
  t.pb.viscosity_cp = 0.8;
  t.pb.density = 1010;
  t.pb.connections = {{0, 3, 12.0, {}}, {0, 3 + 35, 9.0, {}}, {1, 33 + 70, 20.0, {}}};
  t.pb.wells = {{0, 150.0, 1002.0}, {1, 260.0, 1012.0}};
  return t;
}

TEST(OpmEquation, EveryCellBalancesTheStatedFluxesWithGravity) {
  const TwoWellBox t = two_well_box();
  const FlowSolution sol = solve_tpfa(t.pb, t.tr);
  const PolyMesh& m = t.cm.mesh;
  const double mu = t.pb.viscosity_cp, grad = t.pb.density * kGravity / 1e5;
  std::vector<double> res(m.n_cells(), 0.0), scale(m.n_cells(), 0.0);
  auto z = [&](int c) { return m.cell_fv_center[c].z; };
  for (int f = 0; f < m.n_faces(); ++f) {
    const int o = m.face_owner[f], n = m.face_neighbour[f];
    if (n < 0) continue;
    const double q = t.tr.face[f] / mu * (sol.pressure[o] - sol.pressure[n] - grad * (z(o) - z(n)));
    res[o] += q, res[n] -= q;
    scale[o] += std::fabs(q), scale[n] += std::fabs(q);
  }
  std::vector<double> rate(2, 0.0);
  for (const WellConnection& wc : t.pb.connections) {
    const WellControl& ctl = t.pb.wells[wc.well];
    const double q = wc.cf / mu * (sol.pressure[wc.cell] - (ctl.bhp + grad * (z(wc.cell) - ctl.ref_depth)));
    res[wc.cell] += q;
    scale[wc.cell] += std::fabs(q);
    rate[wc.well] += q;
  }
  for (int c = 0; c < m.n_cells(); ++c) EXPECT_LT(std::fabs(res[c]), 1e-9 * scale[c] + 1e-12) << "cell " << c;
  EXPECT_GT(rate[0], 1.0);  // the producer produces
  EXPECT_LT(rate[1], -1.0);  // the injector injects
  for (int w = 0; w < 2; ++w) EXPECT_NEAR(sol.well_rate_m3_per_day[w], rate[w], 1e-9 * std::fabs(rate[w]));
  // Incompressible, no-flow boundary: what is injected is produced.
  EXPECT_NEAR(rate[0] + rate[1], 0.0, 1e-9 * rate[0]);
}

TEST(OpmEquation, WithoutGravityTheSolutionChanges) {
  TwoWellBox t = two_well_box();
  const FlowSolution with = solve_tpfa(t.pb, t.tr);
  t.pb.gravity = false;
  const FlowSolution without = solve_tpfa(t.pb, t.tr);
  EXPECT_GT(std::fabs(with.well_rate_m3_per_day[0] - without.well_rate_m3_per_day[0]),
            1e-3 * std::fabs(with.well_rate_m3_per_day[0]));
}

// ---------------------------------------------------------------- slightly compressible water

double inverse_fvf(double c, double p_ref, double p) {  // OPM PVTW, B_ref = 1
  const double x = c * (p - p_ref);
  return 1 + x + x * x / 2;
}

// A still column fed by a well at the top cell's depth: the discrete hydrostatic recurrence
// p_k - p_{k-1} = g (rho_k + rho_{k-1})/2 (z_k - z_{k-1}), rho = rho_s b(p), solved cell by cell
// with a scalar Newton, is what the solver must return (zero rate).
TEST(Compressible, StillColumnFollowsTheDiscreteHydrostaticRecurrence) {
  const CartesianMesh cm = column(kColumnZ);
  const PolyMesh& m = cm.mesh;
  FlowProblem pb;
  pb.mesh = &m;
  pb.geo = &cm.geo;
  pb.density = 1020;
  pb.compressibility = 1e-3;  // large, so that the density change is visible
  pb.reference_pressure = 100;
  const double bhp = 180, z0 = m.cell_fv_center[0].z;
  pb.connections = {{0, 0, 5.0, m.cell_fv_center[0]}};
  pb.wells = {{0, bhp, z0}};
  const FlowSolution sol = solve_tpfa(pb, compute_transmissibilities(m, cm.geo));
  const double gf = kGravity / 1e5;
  std::vector<double> expect(m.n_cells());
  expect[0] = bhp;
  double max_density_effect = 0;
  for (int k = 1; k < m.n_cells(); ++k) {
    const double dz = m.cell_fv_center[k].z - m.cell_fv_center[k - 1].z, pa = expect[k - 1];
    const double rho_a = 1020 * inverse_fvf(1e-3, 100, pa);
    double p = pa + rho_a * gf * dz;
    for (int it = 0; it < 50; ++it) {
      const double f = p - pa - (rho_a + 1020 * inverse_fvf(1e-3, 100, p)) / 2 * gf * dz;
      const double df = 1 - 1020 * 1e-3 * (1 + 1e-3 * (p - 100)) / 2 * gf * dz;
      p -= f / df;
    }
    expect[k] = p;
    max_density_effect = std::max(max_density_effect, std::fabs(p - (bhp + 1020 * gf * (m.cell_fv_center[k].z - z0))));
  }
  for (int c = 0; c < m.n_cells(); ++c) EXPECT_NEAR(sol.pressure[c], expect[c], 1e-11 * expect[c]) << "cell " << c;
  EXPECT_NEAR(sol.well_rate_m3_per_day.at(0), 0.0, 1e-8);
  EXPECT_GT(sol.nonlinear_iterations, 1);
  // Fail half: the density change is far above the tolerance, so an incompressible column fails.
  EXPECT_GT(max_density_effect, 1e-4 * bhp);
}

/// The surface-volume balance of every cell, written out independently of the solver:
/// faces T/mu b_up (p_i - p_j - g (rho_i + rho_j)/2 (z_i - z_j)) with b_up of the upstream cell,
/// connections CF/mu b_i (p_i - p_conn), p_conn the still wellbore column (wellbore_column_pressure,
/// checked by WellboreColumnSolvesItsODE).
struct Balance {
  std::vector<double> res, scale, rate;
};
Balance compressible_balance(const TwoWellBox& t, const std::vector<double>& p) {
  const PolyMesh& m = t.cm.mesh;
  const double mu = t.pb.viscosity_cp, gf = kGravity / 1e5, c = t.pb.compressibility, pr = t.pb.reference_pressure;
  Balance b{std::vector<double>(m.n_cells(), 0.0), std::vector<double>(m.n_cells(), 0.0), std::vector<double>(2, 0.0)};
  auto z = [&](int i) { return m.cell_fv_center[i].z; };
  auto rho = [&](int i) { return t.pb.density * inverse_fvf(c, pr, p[i]); };
  for (int f = 0; f < m.n_faces(); ++f) {
    const int o = m.face_owner[f], n = m.face_neighbour[f];
    if (n < 0) continue;
    const double dphi = p[o] - p[n] - (rho(o) + rho(n)) / 2 * gf * (z(o) - z(n));
    const double q = t.tr.face[f] / mu * inverse_fvf(c, pr, dphi >= 0 ? p[o] : p[n]) * dphi;
    b.res[o] += q, b.res[n] -= q;
    b.scale[o] += std::fabs(q), b.scale[n] += std::fabs(q);
  }
  for (const WellConnection& wc : t.pb.connections) {
    const WellControl& ctl = t.pb.wells[wc.well];
    const double q =
        wc.cf / mu * inverse_fvf(c, pr, p[wc.cell]) * (p[wc.cell] - wellbore_column_pressure(t.pb, ctl, z(wc.cell)));
    b.res[wc.cell] += q;
    b.scale[wc.cell] += std::fabs(q);
    b.rate[wc.well] += q;
  }
  return b;
}

TEST(Compressible, EveryCellBalancesSurfaceVolumesWithUpwindMobilityAndMeanDensity) {
  TwoWellBox t = two_well_box();
  t.pb.compressibility = 2e-3;  // 20x water's, so every term matters
  t.pb.reference_pressure = 200;
  const FlowSolution sol = solve_tpfa(t.pb, t.tr);
  const Balance b = compressible_balance(t, sol.pressure);
  for (size_t c = 0; c < b.res.size(); ++c) EXPECT_LT(std::fabs(b.res[c]), 1e-9 * b.scale[c] + 1e-12) << "cell " << c;
  for (int w = 0; w < 2; ++w) EXPECT_NEAR(sol.well_rate_m3_per_day[w], b.rate[w], 1e-9 * std::fabs(b.rate[w]));
  // Steady and closed: surface volumes in = out (reservoir volumes would not balance).
  EXPECT_NEAR(b.rate[0] + b.rate[1], 0.0, 1e-9 * b.rate[0]);
  EXPECT_LT(sol.max_cell_imbalance, 1e-9 * b.rate[0]);
  const std::vector<double> r = mass_balance_residual(t.pb, t.tr, sol.pressure);
  for (size_t c = 0; c < r.size(); ++c) EXPECT_NEAR(r[c], b.res[c], 1e-9 * b.scale[c] + 1e-12);
  // Fail half: the incompressible solution of the same wells breaks this balance.
  FlowProblem inc = t.pb;
  inc.compressibility = 0;
  const FlowSolution sol0 = solve_tpfa(inc, t.tr);
  const Balance b0 = compressible_balance(t, sol0.pressure);
  double worst = 0;
  for (size_t c = 0; c < b0.res.size(); ++c) worst = std::max(worst, std::fabs(b0.res[c]) / (b0.scale[c] + 1e-300));
  EXPECT_GT(worst, 1e-4);
}

// The wellbore column against a fine RK4 integration of dp/dz = rho_s b(p) g, above and below the
// reference depth; with c -> 0 it is the incompressible column to round-off.
TEST(Compressible, WellboreColumnSolvesItsODE) {
  FlowProblem pb;
  pb.density = 1020;
  pb.compressibility = 4e-4;
  pb.reference_pressure = 220;
  pb.formation_volume_factor = 1.02;
  const WellControl ctl{0, 260.0, 1000.0};
  for (double depth : {700.0, 990.0, 1000.0, 1060.0, 1500.0}) {
    const int steps = 20000;
    const double h = (depth - ctl.ref_depth) / steps;
    auto f = [&](double p) { return pb.density * inverse_formation_volume_factor(pb, p) * kGravity / 1e5; };
    double p = ctl.bhp;
    for (int i = 0; i < steps; ++i) {
      const double k1 = f(p), k2 = f(p + h / 2 * k1), k3 = f(p + h / 2 * k2), k4 = f(p + h * k3);
      p += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
    EXPECT_NEAR(wellbore_column_pressure(pb, ctl, depth), p, 1e-11 * p) << "depth " << depth;
    // Fail half: the column at the reference density differs.
    if (depth != ctl.ref_depth) {
      EXPECT_GT(std::fabs(wellbore_column_pressure(pb, ctl, depth) - (260 + 1020 / 1.02 * kGravity / 1e5 * (depth - 1000))),
                1e-5 * p);
    }
  }
  pb.compressibility = 1e-14;
  EXPECT_NEAR(wellbore_column_pressure(pb, ctl, 1060), 260 + 1020 / 1.02 * kGravity / 1e5 * 60, 1e-12 * 260);
  pb.gravity = false;
  EXPECT_EQ(wellbore_column_pressure(pb, ctl, 1060), 260.0);
}

TEST(Compressible, TinyCompressibilityIsTheIncompressibleSolve) {
  TwoWellBox t = two_well_box();
  const FlowSolution inc = solve_tpfa(t.pb, t.tr);
  EXPECT_EQ(inc.nonlinear_iterations, 1);
  t.pb.compressibility = 1e-12;
  t.pb.reference_pressure = 200;
  const FlowSolution c = solve_tpfa(t.pb, t.tr);
  for (size_t i = 0; i < c.pressure.size(); ++i) EXPECT_NEAR(c.pressure[i], inc.pressure[i], 1e-9 * inc.pressure[i]);
  for (int w = 0; w < 2; ++w)
    EXPECT_NEAR(c.well_rate_m3_per_day[w], inc.well_rate_m3_per_day[w], 1e-8 * std::fabs(inc.well_rate_m3_per_day[w]));
}

TEST(Compressible, BadFluidDataIsRejected) {
  TwoWellBox t = two_well_box();
  t.pb.compressibility = -1e-5;
  EXPECT_THROW(solve_tpfa(t.pb, t.tr), std::invalid_argument);
  t.pb.compressibility = 1e-5;
  t.pb.formation_volume_factor = 0;
  EXPECT_THROW(solve_tpfa(t.pb, t.tr), std::invalid_argument);
  // B_ref only has a meaning on the compressible path.
  t.pb.compressibility = 0;
  t.pb.formation_volume_factor = 1.02;
  EXPECT_THROW(solve_tpfa(t.pb, t.tr), std::invalid_argument);
  t.pb.formation_volume_factor = 1;
  EXPECT_NO_THROW(solve_tpfa(t.pb, t.tr));
}

// ---------------------------------------------------------------- orderings

TEST(Ordering, ReverseCuthillMcKeeNarrowsAScrambledMatrixAndGivesTheSameSolution) {
  const TwoWellBox t = two_well_box();
  const TpfaSystem sys = assemble_tpfa(t.pb, t.tr);
  std::vector<int32_t> shuffle(sys.n);
  std::iota(shuffle.begin(), shuffle.end(), 0);
  std::shuffle(shuffle.begin(), shuffle.end(), std::mt19937(3));
  const TpfaSystem scrambled = permute_system(sys, shuffle);
  const std::vector<int32_t> rcm = reverse_cuthill_mckee(scrambled);
  // A permutation: every row exactly once.
  std::vector<int32_t> sorted = rcm;
  std::sort(sorted.begin(), sorted.end());
  for (int i = 0; i < sys.n; ++i) ASSERT_EQ(sorted[i], i);
  const TpfaSystem ordered = permute_system(scrambled, rcm);
  EXPECT_LT(matrix_bandwidth(ordered), matrix_bandwidth(scrambled) / 2);
  EXPECT_LE(matrix_bandwidth(ordered), 2 * matrix_bandwidth(sys));

  LinearSolverOptions natural, reordered;
  reordered.ordering = CellOrdering::ReverseCuthillMcKee;
  const LinearSolveResult a = solve_spd(scrambled, natural), b = solve_spd(scrambled, reordered);
  ASSERT_TRUE(a.converged);
  ASSERT_TRUE(b.converged);
  EXPECT_EQ(b.solver, "eigen-cg-ic(rcm)");
  for (int i = 0; i < sys.n; ++i) EXPECT_NEAR(a.x[i], b.x[i], 1e-9 * std::fabs(a.x[i]));
  // Unscrambled, the solution is solve_tpfa's.
  const FlowSolution sol = solve_tpfa(t.pb, t.tr);
  for (int i = 0; i < sys.n; ++i) EXPECT_NEAR(a.x[i], sol.pressure[shuffle[i]], 1e-9 * sol.pressure[shuffle[i]]);
}

// ---------------------------------------------------------------- Peaceman

TEST(Peaceman, EquivalentRadiusAndProjections) {
  // Square cell, isotropic: r_o = 0.28 sqrt(2) dx / 2 = 0.198 dx.
  EXPECT_NEAR(peaceman_radius(10, 10, 50, 50), 0.28 / std::sqrt(2.0) * 10, 1e-12);
  // Anisotropic: Peaceman's formula.
  const double ro = peaceman_radius(10, 20, 100, 400);
  EXPECT_NEAR(ro, 0.28 * std::sqrt(2 * 100 + 0.5 * 400) / (std::pow(4, 0.25) + std::pow(0.25, 0.25)), 1e-12);
  // A well along x sees (dy, dz, ky, kz); a diagonal well in a cube combines three equal indices.
  const Vec3 size{6, 8, 3}, perm{100, 200, 20};
  const double wi_x = peaceman_connection_factor(size, perm, {5, 0, 0}, 0.1);
  EXPECT_NEAR(wi_x, kDarcyMetric * 2 * kPi * std::sqrt(200.0 * 20) * 5 / std::log(peaceman_radius(8, 3, 200, 20) / 0.1),
              1e-12 * wi_x);
  const double one = peaceman_connection_factor({4, 4, 4}, {70, 70, 70}, {2, 0, 0}, 0.1);
  EXPECT_NEAR(peaceman_connection_factor({4, 4, 4}, {70, 70, 70}, {2, 2, 2}, 0.1), std::sqrt(3.0) * one, 1e-12 * one);
  // A cell smaller than the wellbore has no Peaceman index.
  EXPECT_THROW(peaceman_connection_factor({0.3, 0.3, 5}, perm, {0, 0, 5}, 0.1), std::invalid_argument);
}

TEST(Peaceman, TrajectoryPiecesAddUpToTheTrajectory) {
  ReservoirGrid g;
  g.x = {0, 3, 7, 8, 15};
  g.y = {0, 5, 10};
  g.z = {0, 2, 3, 9};
  const std::vector<Vec3> traj = {{0.5, 0.5, 0.5}, {14, 9, 8}, {14, 1, 8.5}};
  const std::vector<TrajectoryInCell> cells = trajectory_cells(g, traj);
  double length = 0;
  Vec3 extent;
  for (const TrajectoryInCell& tc : cells) {
    length += tc.length;
    extent += tc.extent;
    // The midpoint of the pieces lies in the cell (both legs are straight inside a cell here).
    const Vec3 lo = g.cell_lo(tc.grid_cell), hi = g.cell_hi(tc.grid_cell);
    for (int d = 0; d < 3; ++d) EXPECT_TRUE(tc.midpoint[d] >= lo[d] && tc.midpoint[d] <= hi[d]);
  }
  EXPECT_NEAR(length, norm(traj[1] - traj[0]) + norm(traj[2] - traj[1]), 1e-12);
  EXPECT_NEAR(extent.x, 13.5, 1e-12);
  EXPECT_NEAR(extent.y, 8.5 + 8, 1e-12);
  EXPECT_NEAR(extent.z, 7.5 + 0.5, 1e-12);
  EXPECT_EQ(cells.front().grid_cell, g.cell_index(0, 0, 0));
  EXPECT_EQ(cells.back().grid_cell, g.cell_index(3, 0, 2));
}

struct PeacemanResult {
  double rate_error = 0;       // q / q_exact - 1
  double near_well_error = 0;  // max over the 4 face neighbours of the well cell, / drawdown
};

/// 2D-like grid (one layer), n x n square cells, vertical well through the centre cell, the
/// exact radial p(r) on the lateral boundary, no flow on top and bottom (Peaceman's setting).
PeacemanResult peaceman_2d(int n, double dx, double r_o_override = 0) {
  ReservoirSpec spec;
  for (int i = 0; i <= n; ++i) spec.x.push_back(i * dx), spec.y.push_back(i * dx);
  const double h = 10;
  spec.z = {1000, 1000 + h};
  const double k = 100, mu = 1, r_w = 0.1;
  spec.permeability = {k, k, k};
  const CartesianMesh cm = make_cartesian_mesh(spec);
  const double c = n * dx / 2;
  WellSpec ws;
  ws.trajectory = {{c, c, 1000}, {c, c, 1000 + h}};
  ws.radius = r_w;
  std::vector<WellConnection> conn = peaceman_connections(cm, ws, 0);
  EXPECT_EQ(conn.size(), 1u);
  if (r_o_override > 0) conn[0].cf = kDarcyMetric * 2 * kPi * k * h / std::log(r_o_override / r_w);
  const double p_w = 150, q = 1000;  // rm3/day
  auto p_exact = [&](Vec3 x) {
    const double r = std::hypot(x.x - c, x.y - c);
    return p_w + q * mu / (2 * kPi * kDarcyMetric * k * h) * std::log(r / r_w);
  };
  FlowProblem pb;
  pb.mesh = &cm.mesh;
  pb.geo = &cm.geo;
  pb.viscosity_cp = mu;
  pb.gravity = false;
  pb.connections = conn;
  pb.wells = {{0, p_w, 1000}};
  pb.outer_dirichlet = [&](Vec3 x) { return (x.z == 1000 || x.z == 1000 + h) ? std::nan("") : p_exact(x); };
  const FlowSolution sol = solve_tpfa(pb, compute_transmissibilities(cm.mesh, cm.geo));
  PeacemanResult r;
  r.rate_error = sol.well_rate_m3_per_day[0] / q - 1;
  const double drawdown = p_exact({0, c, 0}) - p_w;  // at the lateral boundary
  const int mid = n / 2;
  for (auto [di, dj] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
    const int cell = cm.mesh_cell[cm.grid.cell_index(mid + di, mid + dj, 0)];
    r.near_well_error = std::max(r.near_well_error,
                                 std::fabs(sol.pressure[cell] - p_exact(cm.mesh.cell_fv_center[cell])) / drawdown);
  }
  return r;
}

// Reference (near-well-accuracy.md): rate within 0.02 %, ~0.74 % of the drawdown next to the
// well; a naive r_o = dx / 2 loses 13-14 % of the rate.
TEST(Peaceman, VerticalWellOn2DGridHasPeacemansKnownAccuracy) {
  for (int n : {21, 41}) {
    const PeacemanResult r = peaceman_2d(n, 10);
    std::printf("Peaceman %d x %d: rate error %.4f %%, next to the well %.4f %% of the drawdown\n", n, n,
                100 * r.rate_error, 100 * r.near_well_error);
    EXPECT_LT(std::fabs(r.rate_error), 1e-3) << n;
    EXPECT_GT(r.near_well_error, 0.004) << n;
    EXPECT_LT(r.near_well_error, 0.012) << n;
  }
  const PeacemanResult naive = peaceman_2d(41, 10, 5.0);
  std::printf("naive r_o = dx/2: rate error %.3f %%\n", 100 * naive.rate_error);
  EXPECT_LT(naive.rate_error, -0.08);
  EXPECT_GT(naive.rate_error, -0.16);
}

// ---------------------------------------------------------------- line source

TEST(LineSource, PotentialIsHarmonicAndItsGradientIsRight) {
  const std::vector<Vec3> poly = {{0, 0, 0}, {0, 0, 10}, {6, 0, 18}};
  const double h = 1e-4;
  for (Vec3 x : {Vec3{0.3, 0.1, 4}, Vec3{2, -1, 13}, Vec3{-3, 2, -2}, Vec3{5, 5, 25}}) {
    double lap = 0;
    Vec3 fd;
    for (int d = 0; d < 3; ++d) {
      Vec3 e;
      e[d] = h;
      const double pp = polyline_potential(x + e, poly), pm = polyline_potential(x - e, poly);
      lap += (pp - 2 * polyline_potential(x, poly) + pm) / (h * h);
      fd[d] = (pp - pm) / (2 * h);
    }
    const Vec3 g = polyline_potential_gradient(x, poly);
    EXPECT_LT(std::fabs(lap), 1e-4 * norm2(g)) << x.x;
    EXPECT_LT(norm(g - fd), 1e-6 * norm(g)) << x.x;
  }
}

TEST(LineSource, LongSegmentIsTheRadialLawAndStableNearTheLine) {
  const Vec3 a{0, 0, 0}, b{0, 0, 1e4};
  // Near the middle: phi ~ ln(4 s (L - s) / d^2) = const - 2 ln d.
  const double d1 = 0.1, d2 = 10;
  const double diff = segment_potential({d1, 0, 5e3}, a, b) - segment_potential({d2, 0, 5e3}, a, b);
  EXPECT_NEAR(diff, 2 * std::log(d2 / d1), 1e-5);
  // Very close to the line the cancellation-free form keeps every digit of ln(4 s (L - s) / d^2).
  const double tiny = 1e-7;
  EXPECT_NEAR(segment_potential({tiny, 0, 2e3}, a, b), std::log(4 * 2e3 * 8e3 / (tiny * tiny)), 1e-9);
  EXPECT_TRUE(std::isinf(segment_potential({0, 0, 2e3}, a, b)));
}

// The exact rate of the accuracy study is q' x length: the flux of -grad(phi) through any closed
// surface around the source is 4 pi L (phi ~ -2 ln d near the line).
TEST(LineSource, FluxThroughABoxAroundTheSourceIs4PiLength) {
  const std::vector<Vec3> poly = {{0, 0, 0}, {0, 0, 4}, {3, 0, 8}};
  const double length = 4 + 5;
  const Vec3 lo{-2, -3, -1.5}, hi{5, 2.5, 9};
  const int n = 160;
  double flux = 0;
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
      const double w1 = (hi[a1] - lo[a1]) / n, w2 = (hi[a2] - lo[a2]) / n;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          Vec3 x;
          x[axis] = side ? hi[axis] : lo[axis];
          x[a1] = lo[a1] + (i + 0.5) * w1;
          x[a2] = lo[a2] + (j + 0.5) * w2;
          flux -= polyline_potential_gradient(x, poly)[axis] * (side ? 1 : -1) * w1 * w2;
        }
    }
  EXPECT_NEAR(flux / (4 * kPi * length), 1.0, 1e-4);
}

TEST(LineSource, FieldHitsItsTwoReferencePressuresAndInsetShortensTheSource) {
  const std::vector<Vec3> poly = {{100, 100, 1000}, {100, 100, 1040}};
  const LineSourceField f = make_line_source_field(poly, 0.1, 150, 200, 24, 0.1);
  const FieldReference ref = field_reference(poly);
  EXPECT_NEAR(f.pressure(ref.mid + 0.1 * ref.normal), 150, 1e-10);
  EXPECT_NEAR(f.pressure(ref.mid + 24 * ref.normal), 200, 1e-10);
  EXPECT_NEAR(f.source_length(), 39.8, 1e-12);
  // Wellbore: a face centroid inside the wellbore is moved out to r_w along its perpendicular.
  EXPECT_NEAR(f.wellbore_pressure({100.09, 100, 1020}), f.pressure({100.1, 100, 1020}), 1e-12);
  // An end-cap centroid (on the axis at an end) gets the mean over the cap disc, which lies
  // between the centre value and the rim value.
  const double cap = f.wellbore_pressure({100, 100, 1040});
  EXPECT_GT(cap, std::min(f.pressure({100, 100, 1040}), f.pressure({100.1, 100, 1040})));
  EXPECT_LT(cap, std::max(f.pressure({100, 100, 1040}), f.pressure({100.1, 100, 1040})));
}

}  // namespace
