#include "ordering.hpp"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/Sparse>
#include <algorithm>
#include <boost/graph/adjacency_list.hpp>
#include <boost/graph/cuthill_mckee_ordering.hpp>
#include <boost/graph/properties.hpp>
#include <cmath>
#include <cstdlib>

namespace hm {

namespace {

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

// The CSR arrays of a symmetric matrix are also its CSC arrays.
SpMat to_eigen(const TpfaSystem& sys) {
  SpMat a(sys.n, sys.n);
  a.resizeNonZeros(static_cast<Eigen::Index>(sys.val.size()));
  std::copy(sys.row_ptr.begin(), sys.row_ptr.end(), a.outerIndexPtr());
  std::copy(sys.col.begin(), sys.col.end(), a.innerIndexPtr());
  std::copy(sys.val.begin(), sys.val.end(), a.valuePtr());
  return a;
}

double true_relative_residual(const TpfaSystem& sys, const std::vector<double>& x) {
  double r2 = 0, b2 = 0;
  for (int i = 0; i < sys.n; ++i) {
    double ax = 0;
    for (int32_t k = sys.row_ptr[i]; k < sys.row_ptr[i + 1]; ++k) ax += sys.val[k] * x[sys.col[k]];
    const double r = sys.rhs[i] - ax;
    r2 += r * r;
    b2 += sys.rhs[i] * sys.rhs[i];
  }
  return b2 > 0 ? std::sqrt(r2 / b2) : std::sqrt(r2);
}

LinearSolveResult cg_ic(const TpfaSystem& sys, const LinearSolverOptions& opt) {
  LinearSolveResult res;
  res.solver = "eigen-cg-ic(natural)";
  res.x.assign(sys.n, 0.0);
  if (sys.n == 0) {
    res.converged = true;
    return res;
  }
  const SpMat a = to_eigen(sys);
  const Eigen::Map<const Eigen::VectorXd> b(sys.rhs.data(), sys.n);
  Eigen::ConjugateGradient<SpMat, Eigen::Lower | Eigen::Upper,
                           Eigen::IncompleteCholesky<double, Eigen::Lower, Eigen::NaturalOrdering<int>>>
      cg;
  cg.setTolerance(opt.tolerance);
  cg.setMaxIterations(opt.max_iterations);
  cg.compute(a);
  if (cg.info() != Eigen::Success) {
    res.solver += " (incomplete Cholesky failed: the matrix is not positive definite)";
    return res;
  }
  Eigen::Map<Eigen::VectorXd> x(res.x.data(), sys.n);
  x = cg.solve(b);
  res.iterations = static_cast<int>(cg.iterations());
  res.converged = cg.info() == Eigen::Success;
  res.relative_residual = true_relative_residual(sys, res.x);
  return res;
}

}  // namespace

std::vector<int32_t> reverse_cuthill_mckee(const TpfaSystem& sys) {
  using Graph = boost::adjacency_list<boost::vecS, boost::vecS, boost::undirectedS,
                                      boost::property<boost::vertex_color_t, boost::default_color_type,
                                                      boost::property<boost::vertex_degree_t, int>>>;
  Graph g(sys.n);
  for (int i = 0; i < sys.n; ++i)
    for (int32_t k = sys.row_ptr[i]; k < sys.row_ptr[i + 1]; ++k)
      if (sys.col[k] > i) boost::add_edge(i, sys.col[k], g);
  std::vector<Graph::vertex_descriptor> order(sys.n);
  // Cuthill-McKee written backwards = reverse Cuthill-McKee; every component is visited.
  boost::cuthill_mckee_ordering(g, order.rbegin(), boost::get(boost::vertex_color, g), boost::make_degree_map(g));
  return std::vector<int32_t>(order.begin(), order.end());
}

TpfaSystem permute_system(const TpfaSystem& sys, const std::vector<int32_t>& perm) {
  std::vector<int32_t> inv(sys.n);
  for (int i = 0; i < sys.n; ++i) inv[perm[i]] = i;
  TpfaSystem out;
  out.n = sys.n;
  out.row_ptr.assign(sys.n + 1, 0);
  out.rhs.resize(sys.n);
  out.col.reserve(sys.col.size());
  out.val.reserve(sys.val.size());
  std::vector<std::pair<int32_t, double>> row;
  for (int i = 0; i < sys.n; ++i) {
    const int32_t old = perm[i];
    out.rhs[i] = sys.rhs[old];
    row.clear();
    for (int32_t k = sys.row_ptr[old]; k < sys.row_ptr[old + 1]; ++k) row.push_back({inv[sys.col[k]], sys.val[k]});
    std::sort(row.begin(), row.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [j, v] : row) out.col.push_back(j), out.val.push_back(v);
    out.row_ptr[i + 1] = static_cast<int32_t>(out.col.size());
  }
  return out;
}

int matrix_bandwidth(const TpfaSystem& sys) {
  int bw = 0;
  for (int i = 0; i < sys.n; ++i)
    for (int32_t k = sys.row_ptr[i]; k < sys.row_ptr[i + 1]; ++k) bw = std::max(bw, std::abs(sys.col[k] - i));
  return bw;
}

LinearSolveResult solve_spd(const TpfaSystem& sys, const LinearSolverOptions& opt) {
  if (opt.ordering == CellOrdering::Natural) return cg_ic(sys, opt);
  const std::vector<int32_t> perm = reverse_cuthill_mckee(sys);
  LinearSolveResult r = cg_ic(permute_system(sys, perm), opt);
  std::vector<double> x(sys.n);
  for (int i = 0; i < sys.n; ++i) x[perm[i]] = r.x[i];
  r.x = std::move(x);
  r.solver = "eigen-cg-ic(rcm)";
  return r;
}

}  // namespace hm
