// A fully penetrating vertical well (examples/vertical_through.yaml, the producer alone) in a box
// with no-flow top and bottom and the exact 2D radial pressure imposed on the lateral boundary:
// p(r) = p_w + q mu ln(r / r_w) / (2 pi k h) is the exact solution (harmonic, z-independent), so
// the TPFA rate must be q and the pressures p(r). Fail half: the same well completed only from
// 12 m below the top to 12 m above the bottom (the blocks end inside, the cavity reaches the
// planes) misses q by far more: the rate sees the meshed (connected) length.
#include <gtest/gtest.h>

#include <cmath>

#include "meshgen/pipeline/hybrid_mesh.hpp"
#include "solver_demo/lib/tpfa.hpp"

namespace {

using namespace hm;

constexpr double kPi = 3.14159265358979323846;

struct RadialResult {
  double rate_error = 0;      // q_mesh / q - 1
  double max_p_error = 0;     // max |p - p_exact| / drawdown over all cells
  double near_well_error = 0; // same, over the radial cells
};

RadialResult solve_radial(const std::vector<Vec3>& trajectory) {
  CaseSpec cs = load_case(std::string(HM_SOURCE_DIR) + "/examples/vertical_through.yaml");
  cs.wells.resize(1);
  cs.wells[0].trajectory = trajectory;
  const double k = 100;
  cs.reservoir.permeability = {k, k, k};
  PipelineOptions opts;
  opts.optimize = false;
  const HybridMesh h = build_hybrid_mesh(cs, opts);
  EXPECT_TRUE(h.build_report.ok);
  const double top = cs.reservoir.z.front(), bottom = cs.reservoir.z.back(), height = bottom - top;
  const double c = 36, mu = 1, r_w = cs.wells[0].radius, p_w = 150, q = 1000;  // rm3/day
  auto p_exact = [&](Vec3 x) {
    return p_w + q * mu / (2 * kPi * kDarcyMetric * k * height) * std::log(std::hypot(x.x - c, x.y - c) / r_w);
  };
  FlowProblem pb;
  pb.mesh = &h.mesh;
  pb.geo = &h.geometry;
  pb.viscosity_cp = mu;
  pb.gravity = false;
  pb.wells = {{0, p_w, top}};
  pb.outer_dirichlet = [&](Vec3 x) { return (x.z == top || x.z == bottom) ? std::nan("") : p_exact(x); };
  const FlowSolution sol = solve_tpfa(pb, compute_transmissibilities(h.mesh, h.geometry));
  RadialResult r;
  // (cells on the axis beyond a partially penetrating well's ends have p_exact = -inf: skipped)
  r.rate_error = sol.well_rate_m3_per_day.at(0) / q - 1;
  const double drawdown = p_exact({0, c, 0}) - p_w;
  for (int cell = 0; cell < h.mesh.n_cells(); ++cell) {
    if (std::hypot(h.mesh.cell_fv_center[cell].x - c, h.mesh.cell_fv_center[cell].y - c) < r_w) continue;
    const double e = std::fabs(sol.pressure[cell] - p_exact(h.mesh.cell_fv_center[cell])) / drawdown;
    r.max_p_error = std::max(r.max_p_error, e);
    if (h.mesh.cell_region[cell] == kWell) r.near_well_error = std::max(r.near_well_error, e);
  }
  return r;
}

TEST(BoundaryRadial, FullyPenetratingWellMatchesTheExactRadialSolution) {
  const RadialResult full = solve_radial({{36, 36, 990}, {36, 36, 1070}});
  std::printf("[ figures  ] fully penetrating: rate error %.3g %%, pressure error max %.3g %% (radial cells %.3g %%) "
              "of the drawdown\n",
              100 * full.rate_error, 100 * full.max_p_error, 100 * full.near_well_error);
  // Measured -1.02 % and 0.91 % (outermost ring, largest near the top; 4 rings of ratio 2.66: the
  // ring-to-transition fluxes of the log field, docs/accuracy.md); no spike at the boundary ends.
  EXPECT_LT(std::fabs(full.rate_error), 1.5e-2);
  EXPECT_LT(full.max_p_error, 1.5e-2);
  EXPECT_LT(full.near_well_error, 1.5e-2);
  // Fail half: completed over 36 of the 60 m.
  const RadialResult part = solve_radial({{36, 36, 1012}, {36, 36, 1048}});
  std::printf("[ figures  ] partially penetrating (36 of 60 m): rate error %.3g %%, pressure error max %.3g %%\n",
              100 * part.rate_error, 100 * part.max_p_error);
  EXPECT_LT(part.rate_error, -0.2);
  EXPECT_GT(part.near_well_error, 0.05);
}

}  // namespace
