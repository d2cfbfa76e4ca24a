// Single-phase, steady two-point flux (TPFA) solver on a PolyMesh: exactly the discrete equation
// OPM Flow solves for the exported deck (docs/solver.md). Incompressible:
//
//   sum_j T_ij/mu (p_i - p_j - G (z_i - z_j)) + sum_conn CF/mu (p_i - (BHP + G (z_i - z_ref))) = 0,
//   G = rho g / 1e5 (bar/m), g = 9.80665, z = depth of the FV centre (positive down).
//
// Slightly compressible (OPM's PVTW with zero viscosibility, `FlowProblem::compressibility` > 0):
// the steady surface-volume balance
//
//   sum_j T_ij/mu b_up (p_i - p_j - g (rho_i + rho_j)/2 (z_i - z_j)) + sum_conn CF/mu b_i (p_i - p_conn) = 0,
//   b(p) = (1 + X + X^2/2) / B_ref, X = c (p - p_ref), rho = rho_s b, b_up of the upstream cell,
//   p_conn(z) the still wellbore column dp/dz = rho_s b(p) g from (z_ref, BHP).
//
// Units (Eclipse METRIC): p in bar, T and CF in cP.rm3/day/bar, mu in cP, rates in m3/day (surface
// volumes; equal to reservoir volumes when incompressible with B_ref = 1).
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "fvcheck/lib/transmissibility.hpp"
#include "meshgen/core/geometry.hpp"
#include "meshgen/core/polymesh.hpp"

namespace hm {

constexpr double kGravity = 9.80665;  ///< m/s2, as OPM

/// Bottom-hole pressure control of well `well` (index in the case): bhp in bar at depth
/// ref_depth (m; the case's convention is the first trajectory point's z).
struct WellControl {
  int well = 0;
  double bhp = 0;
  double ref_depth = 0;
};

/// A well connection not given by wellbore faces (Peaceman wells on a Cartesian grid):
/// q = cf/mu (p_cell - p_conn). `point` is where `FlowProblem::wellbore_pressure` is evaluated
/// when it is set (e.g. the midpoint of the trajectory inside the cell).
struct WellConnection {
  int well = 0;
  int32_t cell = -1;
  double cf = 0;  ///< cP.rm3/day/bar
  Vec3 point;
};

struct FlowProblem {
  const PolyMesh* mesh = nullptr;
  const MeshGeometry* geo = nullptr;
  double viscosity_cp = 1;
  double density = 1000;  ///< kg/m3; with compressibility > 0 the surface density rho_s (rho = rho_s b(p))
  /// Slightly compressible water as OPM's PVTW `p_ref B_ref c mu 0`: inverse formation volume factor
  /// b(p) = (1 + X + X^2/2) / B_ref, X = c (p - p_ref); the viscosity stays mu (zero viscosibility).
  /// 0 = incompressible (b = 1, one linear solve).
  double compressibility = 0;          ///< 1/bar
  double reference_pressure = 0;       ///< bar (PVTW item 1)
  double formation_volume_factor = 1;  ///< B_ref, rm3/sm3 (PVTW item 2)
  bool gravity = true;
  /// Controls of the wells whose wellbore faces / connections produce or inject. Wellbore
  /// faces of a well without a control are closed (no flow), unless wellbore_pressure is set.
  std::vector<WellControl> wells;
  /// Extra connections (Peaceman); the wellbore faces of the mesh are connections too.
  std::vector<WellConnection> connections;
  /// Outer boundary: no-flow by default. When set, every face on kOuterBoundary gets
  /// p = outer_dirichlet(x_b) through the owner's half-transmissibility, x_b the face's boundary
  /// flux point (boundary_flux_points: the foot of the perpendicular from the owner's FV centre,
  /// the face centroid for a box cell); a face for
  /// which it returns NaN stays no-flow (mixed boundaries).
  std::function<double(Vec3)> outer_dirichlet;
  /// Optional: overrides BHP on every wellbore face (evaluated at the face centroid) and every
  /// extra connection (at its `point`): the accuracy study imposes the exact p on the wellbore.
  std::function<double(Vec3)> wellbore_pressure;
};

/// Linear solver choice; the defaults are the library's (docs/solver.md has the measurements).
enum class CellOrdering { Natural, ReverseCuthillMcKee };

struct LinearSolverOptions {
  double tolerance = 1e-12;      ///< relative residual ||b - A p|| / ||b||
  int max_iterations = 20000;
  CellOrdering ordering = CellOrdering::Natural;
};

struct FlowSolution {
  std::vector<double> pressure;              ///< n_cells, bar
  std::vector<double> well_rate_m3_per_day;  ///< per well index (size: highest well seen + 1); > 0 produced
  int iterations = 0;                        ///< linear iterations, summed over the nonlinear ones
  double relative_residual = 0;              ///< ||b - A p|| / ||b|| of the last linear solve, recomputed
  int nonlinear_iterations = 1;              ///< Picard iterations (1 when incompressible)
  /// Mass balance of the final pressure: max over cells of |net surface outflow| (m3/day), the
  /// nonlinear terms evaluated at that pressure (mass_balance_residual).
  double max_cell_imbalance = 0;
  std::string solver;                        ///< e.g. "eigen-cg-ic(natural)"
};

/// Assembles and solves (Picard iteration on b and rho when compressibility > 0, each step a
/// symmetric system with the upstream b frozen, to a pressure change < 1e-11 relative). Throws std::invalid_argument for an ill-posed problem (no mesh, a
/// connected group of cells with no pressure reference, non-finite input) and
/// std::runtime_error when the linear solver fails to reach the tolerance.
FlowSolution solve_tpfa(const FlowProblem& problem, const Transmissibilities& trans);
FlowSolution solve_tpfa(const FlowProblem& problem, const Transmissibilities& trans,
                        const LinearSolverOptions& options);

/// The assembled system (exposed for the benchmarks and tests): A p = b, A symmetric,
/// CSR over rows, lower and upper parts both stored.
struct TpfaSystem {
  int n = 0;
  std::vector<int32_t> row_ptr, col;
  std::vector<double> val;
  std::vector<double> rhs;
};
/// The incompressible system (b = 1, rho = density), whatever the problem's compressibility.
TpfaSystem assemble_tpfa(const FlowProblem& problem, const Transmissibilities& trans);

/// Pressure of well `control`'s still fluid column at `depth`: BHP + rho g (depth - ref_depth)
/// when incompressible, else the exact solution of dp/dz = rho_s b(p) g / 1e5 through
/// (ref_depth, BHP): with u = 1 + X, atan(u) grows linearly in depth (c rho_s g / (2e5 B_ref)).
/// OPM's connection densities (rho_s b at the mean pressure of consecutive connections) converge
/// to this column. Gravity off: BHP.
double wellbore_column_pressure(const FlowProblem& problem, const WellControl& control, double depth);

/// Inverse formation volume factor b(p) of the problem's fluid (1 when incompressible).
double inverse_formation_volume_factor(const FlowProblem& problem, double pressure);

/// Net surface outflow of every cell (faces + connections) at a pressure field with the
/// nonlinear terms evaluated at that field: zero at the solution.
std::vector<double> mass_balance_residual(const FlowProblem& problem, const Transmissibilities& trans,
                                          const std::vector<double>& pressure);

/// Rates per well of a pressure field, with the same terms as the assembly:
/// q = CF/mu b(p_cell) (p_cell - p_conn), surface m3/day. Sized like FlowSolution::well_rate_m3_per_day.
std::vector<double> well_rates(const FlowProblem& problem, const Transmissibilities& trans,
                               const std::vector<double>& pressure);

}  // namespace hm
