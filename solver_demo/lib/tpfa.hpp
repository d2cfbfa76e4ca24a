// Single-phase, incompressible, steady two-point flux (TPFA) solver on a PolyMesh: exactly the
// discrete equation OPM Flow solves for the exported deck (docs/solver.md):
//
//   sum_j T_ij/mu (p_i - p_j - G (z_i - z_j)) + sum_conn CF/mu (p_i - (BHP + G (z_i - z_ref))) = 0,
//   G = rho g / 1e5 (bar/m), g = 9.80665, z = depth of the FV centre (positive down).
//
// Units (Eclipse METRIC): p in bar, T and CF in cP.rm3/day/bar, mu in cP, rates in rm3/day.
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
  double density = 1000;  ///< kg/m3
  bool gravity = true;
  /// Controls of the wells whose wellbore faces / connections produce or inject. Wellbore
  /// faces of a well without a control are closed (no flow), unless wellbore_pressure is set.
  std::vector<WellControl> wells;
  /// Extra connections (Peaceman); the wellbore faces of the mesh are connections too.
  std::vector<WellConnection> connections;
  /// Outer boundary: no-flow by default. When set, every face on kOuterBoundary gets
  /// p = outer_dirichlet(face centroid) through the owner's half-transmissibility; a face for
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
  int iterations = 0;
  double relative_residual = 0;              ///< ||b - A p|| / ||b||, recomputed after the solve
  std::string solver;                        ///< e.g. "eigen-cg-ic(natural)"
};

/// Assembles and solves. Throws std::invalid_argument for an ill-posed problem (no mesh, a
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
TpfaSystem assemble_tpfa(const FlowProblem& problem, const Transmissibilities& trans);

/// Rates per well (and per connection) of a pressure field, with the same terms as the
/// assembly: q = CF/mu (p_cell - p_conn). Sized like FlowSolution::well_rate_m3_per_day.
std::vector<double> well_rates(const FlowProblem& problem, const Transmissibilities& trans,
                               const std::vector<double>& pressure);

}  // namespace hm
