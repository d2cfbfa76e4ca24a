// Linear-solver measurements for the TPFA systems (docs/solver.md): Eigen CG + incomplete
// Cholesky in the natural order, after reverse Cuthill-McKee, with Eigen's AMD ordering, and
// (when built with hypre) BoomerAMG-preconditioned PCG. Every variant solves to the library's
// tolerance, 1e-12 relative residual; counters give iterations and the true residual.
//
// Run: build with -DHM_BUILD_BENCH=ON, then  bin/bench_solver --benchmark_counters_tabular=true
// (HM_BENCH_1M=1 adds the 1,000,000-cell Cartesian system; it takes a few minutes).
#include <benchmark/benchmark.h>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/Sparse>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>

#include "fvcheck/lib/transmissibility.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"
#include "solver_demo/lib/accuracy.hpp"
#include "solver_demo/lib/ordering.hpp"
#include "solver_demo/lib/peaceman.hpp"
#include "solver_demo/lib/tpfa.hpp"

#ifdef HM_HAVE_HYPRE
#include <HYPRE.h>
#include <HYPRE_krylov.h>
#include <HYPRE_parcsr_ls.h>
#include <mpi.h>
#endif

namespace {

using hm::TpfaSystem;

/// Outer faces at a hydrostatic 200 bar, the wells at their BHP (or two Peaceman wells), gravity.
TpfaSystem flowing_system(const hm::PolyMesh& mesh, const hm::MeshGeometry& geo,
                          const std::vector<hm::WellConnection>& connections,
                          const std::vector<hm::WellControl>& wells) {
  hm::FlowProblem pb;
  pb.mesh = &mesh;
  pb.geo = &geo;
  pb.connections = connections;
  pb.wells = wells;
  const double z0 = mesh.nodes.empty() ? 0.0 : mesh.nodes[0].z;
  pb.outer_dirichlet = [z0](hm::Vec3 x) { return 200.0 + 1000 * hm::kGravity / 1e5 * (x.z - z0); };
  return hm::assemble_tpfa(pb, hm::compute_transmissibilities(mesh, geo));
}

TpfaSystem cartesian_system(int nx, int ny, int nz, hm::Vec3 perm) {
  hm::ReservoirSpec spec;
  for (int i = 0; i <= nx; ++i) spec.x.push_back(10.0 * i);
  for (int j = 0; j <= ny; ++j) spec.y.push_back(10.0 * j);
  for (int k = 0; k <= nz; ++k) spec.z.push_back(1000 + 2.0 * k);
  spec.permeability = perm;
  const hm::CartesianMesh cm = hm::make_cartesian_mesh(spec);
  hm::WellSpec prod, inj;
  prod.trajectory = {{nx * 2.5 + 5, ny * 2.5 + 5, 1000}, {nx * 2.5 + 5, ny * 2.5 + 5, 1000 + 2.0 * nz}};
  inj.trajectory = {{nx * 7.5 + 5, ny * 7.5 + 5, 1000}, {nx * 7.5 + 5, ny * 7.5 + 5, 1000 + 2.0 * nz}};
  std::vector<hm::WellConnection> conn = hm::peaceman_connections(cm, prod, 0);
  for (hm::WellConnection c : hm::peaceman_connections(cm, inj, 1)) conn.push_back(c);
  return flowing_system(cm.mesh, cm.geo, conn, {{0, 150, 1000}, {1, 260, 1000}});
}

/// The vertical accuracy case refined twice in every direction (~212,000 cells), well at BHP.
TpfaSystem hybrid_system() {
  const hm::CaseSpec cs =
      hm::refine_case(hm::load_case(std::string(HM_SOURCE_DIR) + "/examples/accuracy_vertical.yaml"), 2);
  const hm::HybridMesh h = hm::build_hybrid_mesh(cs);
  return flowing_system(h.mesh, h.geometry, {}, {{0, cs.wells[0].bhp, cs.wells[0].trajectory[0].z}});
}

const TpfaSystem& system_named(const std::string& name) {
  static std::map<std::string, std::unique_ptr<TpfaSystem>> cache;
  auto& slot = cache[name];
  if (!slot) {
    if (name == "cartesian_100k_iso") slot = std::make_unique<TpfaSystem>(cartesian_system(50, 50, 40, {100, 100, 100}));
    if (name == "cartesian_100k_aniso") slot = std::make_unique<TpfaSystem>(cartesian_system(50, 50, 40, {100, 100, 10}));
    if (name == "cartesian_1m_aniso") slot = std::make_unique<TpfaSystem>(cartesian_system(100, 100, 100, {100, 100, 10}));
    if (name == "hybrid_212k") slot = std::make_unique<TpfaSystem>(hybrid_system());
  }
  return *slot;
}

const TpfaSystem& rcm_system_named(const std::string& name) {
  static std::map<std::string, std::unique_ptr<TpfaSystem>> cache;
  auto& slot = cache[name];
  if (!slot) {
    const TpfaSystem& sys = system_named(name);
    slot = std::make_unique<TpfaSystem>(hm::permute_system(sys, hm::reverse_cuthill_mckee(sys)));
  }
  return *slot;
}

void report(benchmark::State& state, const hm::LinearSolveResult& r, const TpfaSystem& sys) {
  state.counters["cells"] = sys.n;
  state.counters["iterations"] = r.iterations;
  state.counters["rel_residual"] = r.relative_residual;
  state.counters["bandwidth"] = hm::matrix_bandwidth(sys);
  if (!r.converged) state.SkipWithError("did not converge");
}

// The library's solver (incomplete Cholesky factorisation + CG) on the system as numbered.
void BM_CgIcNatural(benchmark::State& state, std::string name) {
  const TpfaSystem& sys = system_named(name);
  hm::LinearSolveResult r;
  for (auto _ : state) r = hm::solve_spd(sys, {});
  report(state, r, sys);
}

// The same on the RCM-renumbered system (the renumbering itself is BM_RcmOrdering).
void BM_CgIcRcm(benchmark::State& state, std::string name) {
  const TpfaSystem& sys = rcm_system_named(name);
  hm::LinearSolveResult r;
  for (auto _ : state) r = hm::solve_spd(sys, {});
  report(state, r, sys);
}

void BM_RcmOrdering(benchmark::State& state, std::string name) {
  const TpfaSystem& sys = system_named(name);
  for (auto _ : state) {
    TpfaSystem p = hm::permute_system(sys, hm::reverse_cuthill_mckee(sys));
    benchmark::DoNotOptimize(p.val.data());
  }
  state.counters["cells"] = sys.n;
}

// Eigen's default ordering for IncompleteCholesky (AMD), for reference.
void BM_CgIcAmd(benchmark::State& state, std::string name) {
  const TpfaSystem& sys = system_named(name);
  using SpMat = Eigen::SparseMatrix<double>;
  SpMat a(sys.n, sys.n);
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < sys.n; ++i)
    for (int k = sys.row_ptr[i]; k < sys.row_ptr[i + 1]; ++k) t.emplace_back(i, sys.col[k], sys.val[k]);
  a.setFromTriplets(t.begin(), t.end());
  const Eigen::Map<const Eigen::VectorXd> b(sys.rhs.data(), sys.n);
  int iterations = 0;
  double err = 0;
  for (auto _ : state) {
    Eigen::ConjugateGradient<SpMat, Eigen::Lower | Eigen::Upper, Eigen::IncompleteCholesky<double>> cg;
    cg.setTolerance(1e-12);
    cg.setMaxIterations(20000);
    cg.compute(a);
    Eigen::VectorXd x = cg.solve(b);
    iterations = static_cast<int>(cg.iterations());
    err = (b - a * x).norm() / b.norm();
  }
  state.counters["cells"] = sys.n;
  state.counters["iterations"] = iterations;
  state.counters["rel_residual"] = err;
}

#ifdef HM_HAVE_HYPRE
// BoomerAMG (HMIS coarsening, extended+i interpolation, l1 Gauss-Seidel: hypre's recommended
// 3D settings) as the preconditioner of PCG, one MPI rank, setup + solve timed.
void BM_HypreBoomerAmgPcg(benchmark::State& state, std::string name) {
  const TpfaSystem& sys = system_named(name);
  const HYPRE_BigInt n = sys.n;
  HYPRE_IJMatrix A;
  HYPRE_IJMatrixCreate(MPI_COMM_WORLD, 0, n - 1, 0, n - 1, &A);
  HYPRE_IJMatrixSetObjectType(A, HYPRE_PARCSR);
  HYPRE_IJMatrixInitialize(A);
  std::vector<HYPRE_Int> ncols(sys.n);
  std::vector<HYPRE_BigInt> rows(sys.n), cols(sys.col.begin(), sys.col.end());
  for (int i = 0; i < sys.n; ++i) ncols[i] = sys.row_ptr[i + 1] - sys.row_ptr[i], rows[i] = i;
  HYPRE_IJMatrixSetValues(A, sys.n, ncols.data(), rows.data(), cols.data(), sys.val.data());
  HYPRE_IJMatrixAssemble(A);
  HYPRE_ParCSRMatrix pa;
  HYPRE_IJMatrixGetObject(A, reinterpret_cast<void**>(&pa));
  auto vector = [&](const std::vector<double>& v, HYPRE_IJVector* out, HYPRE_ParVector* par) {
    HYPRE_IJVectorCreate(MPI_COMM_WORLD, 0, n - 1, out);
    HYPRE_IJVectorSetObjectType(*out, HYPRE_PARCSR);
    HYPRE_IJVectorInitialize(*out);
    HYPRE_IJVectorSetValues(*out, sys.n, rows.data(), v.data());
    HYPRE_IJVectorAssemble(*out);
    HYPRE_IJVectorGetObject(*out, reinterpret_cast<void**>(par));
  };
  HYPRE_IJVector b, x;
  HYPRE_ParVector pb, px;
  vector(sys.rhs, &b, &pb);
  const std::vector<double> zero(sys.n, 0.0);
  vector(zero, &x, &px);
  HYPRE_Int iterations = 0;
  double setup_s = 0;
  for (auto _ : state) {
    HYPRE_IJVectorSetValues(x, sys.n, rows.data(), zero.data());
    HYPRE_Solver pcg, amg;
    HYPRE_ParCSRPCGCreate(MPI_COMM_WORLD, &pcg);
    HYPRE_PCGSetMaxIter(pcg, 1000);
    HYPRE_PCGSetTol(pcg, 1e-12);
    HYPRE_PCGSetTwoNorm(pcg, 1);
    HYPRE_PCGSetPrintLevel(pcg, 0);
    HYPRE_BoomerAMGCreate(&amg);
    HYPRE_BoomerAMGSetPrintLevel(amg, 0);
    HYPRE_BoomerAMGSetCoarsenType(amg, 10);  // HMIS
    HYPRE_BoomerAMGSetInterpType(amg, 6);    // extended+i
    HYPRE_BoomerAMGSetPMaxElmts(amg, 4);
    HYPRE_BoomerAMGSetRelaxType(amg, 8);     // l1 Gauss-Seidel (symmetric)
    HYPRE_BoomerAMGSetStrongThreshold(amg, 0.5);
    HYPRE_BoomerAMGSetNumSweeps(amg, 1);
    HYPRE_BoomerAMGSetTol(amg, 0.0);
    HYPRE_BoomerAMGSetMaxIter(amg, 1);
    HYPRE_PCGSetPrecond(pcg, reinterpret_cast<HYPRE_PtrToSolverFcn>(HYPRE_BoomerAMGSolve),
                        reinterpret_cast<HYPRE_PtrToSolverFcn>(HYPRE_BoomerAMGSetup), amg);
    const auto t0 = std::chrono::steady_clock::now();
    HYPRE_ParCSRPCGSetup(pcg, pa, pb, px);
    setup_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    HYPRE_ParCSRPCGSolve(pcg, pa, pb, px);
    HYPRE_PCGGetNumIterations(pcg, &iterations);
    HYPRE_BoomerAMGDestroy(amg);
    HYPRE_ParCSRPCGDestroy(pcg);
  }
  std::vector<double> sol(sys.n);
  HYPRE_IJVectorGetValues(x, sys.n, rows.data(), sol.data());
  double r2 = 0, b2 = 0;
  for (int i = 0; i < sys.n; ++i) {
    double ax = 0;
    for (int k = sys.row_ptr[i]; k < sys.row_ptr[i + 1]; ++k) ax += sys.val[k] * sol[sys.col[k]];
    r2 += (sys.rhs[i] - ax) * (sys.rhs[i] - ax);
    b2 += sys.rhs[i] * sys.rhs[i];
  }
  state.counters["cells"] = sys.n;
  state.counters["iterations"] = iterations;
  state.counters["rel_residual"] = std::sqrt(r2 / b2);
  state.counters["setup_s"] = setup_s;
  HYPRE_IJVectorDestroy(b);
  HYPRE_IJVectorDestroy(x);
  HYPRE_IJMatrixDestroy(A);
}
#endif

void register_all() {
  std::vector<std::string> names = {"cartesian_100k_iso", "cartesian_100k_aniso", "hybrid_212k"};
  const char* big = std::getenv("HM_BENCH_1M");
  if (big && std::string(big) == "1") names.push_back("cartesian_1m_aniso");
  for (const std::string& n : names) {
    benchmark::RegisterBenchmark(("CgIcNatural/" + n).c_str(), BM_CgIcNatural, n)->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("CgIcRcm/" + n).c_str(), BM_CgIcRcm, n)->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("RcmOrdering/" + n).c_str(), BM_RcmOrdering, n)->Unit(benchmark::kMillisecond);
    if (n != "cartesian_1m_aniso")
      benchmark::RegisterBenchmark(("CgIcAmd/" + n).c_str(), BM_CgIcAmd, n)->Unit(benchmark::kMillisecond);
#ifdef HM_HAVE_HYPRE
    benchmark::RegisterBenchmark(("HypreBoomerAmgPcg/" + n).c_str(), BM_HypreBoomerAmgPcg, n)
        ->Unit(benchmark::kMillisecond);
#endif
  }
}

}  // namespace

int main(int argc, char** argv) {
#ifdef HM_HAVE_HYPRE
  MPI_Init(&argc, &argv);
  HYPRE_Init();
#endif
  register_all();
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
#ifdef HM_HAVE_HYPRE
  HYPRE_Finalize();
  MPI_Finalize();
#endif
  return 0;
}
