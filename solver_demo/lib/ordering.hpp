// The linear solver behind solve_tpfa: Eigen conjugate gradient preconditioned by incomplete
// Cholesky (natural ordering of the given rows), optionally after a reverse Cuthill-McKee
// renumbering (Boost.Graph). Measurements that chose the default: docs/solver.md.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "tpfa.hpp"

namespace hm {

struct LinearSolveResult {
  std::vector<double> x;
  int iterations = 0;
  double relative_residual = 0;  ///< true residual ||b - A x|| / ||b|| (0 when b = 0)
  bool converged = false;        ///< the iteration reached the tolerance
  std::string solver;
};

/// Solves the symmetric positive definite system (zero right-hand side gives x = 0).
LinearSolveResult solve_spd(const TpfaSystem& sys, const LinearSolverOptions& options);

/// Reverse Cuthill-McKee order of the matrix graph: perm[new] = old (Boost.Graph,
/// pseudo-peripheral start per connected component).
std::vector<int32_t> reverse_cuthill_mckee(const TpfaSystem& sys);

/// P A P^T with P given by perm[new] = old; the right-hand side is permuted too.
TpfaSystem permute_system(const TpfaSystem& sys, const std::vector<int32_t>& perm);

/// Bandwidth max |i - j| over the stored entries (how much an ordering tightened the matrix).
int matrix_bandwidth(const TpfaSystem& sys);

}  // namespace hm
