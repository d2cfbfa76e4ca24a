#include "tpfa.hpp"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/Sparse>
#include <algorithm>
#include <limits>
#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>

#include "meshgen/core/fv_quality.hpp"
#include "ordering.hpp"

namespace hm {

namespace {

/// One boundary term of cell `cell`: c (p_cell - p_ext), c = transmissibility b / mu.
struct BoundaryTerm {
  int32_t cell;
  double c;      // transmissibility * b / mu
  double p_ext;  // the external pressure seen at the cell's depth (gravity included)
  int well;      // >= 0: counts toward that well's rate
};

/// Every group of face-connected cells must see at least one boundary term, else the
/// pressure is defined up to a constant there (the matrix is singular).
void check_references(const TpfaSystem& sys, const std::vector<BoundaryTerm>& terms) {
  std::vector<char> anchored(sys.n, 0), seen(sys.n, 0);
  for (const BoundaryTerm& t : terms)
    if (t.c != 0) anchored[t.cell] = 1;
  std::vector<int32_t> stack;
  for (int s = 0; s < sys.n; ++s) {
    if (seen[s]) continue;
    bool ok = false;
    int size = 0;
    stack.assign(1, s);
    seen[s] = 1;
    while (!stack.empty()) {
      const int32_t c = stack.back();
      stack.pop_back();
      ++size;
      ok = ok || anchored[c];
      for (int32_t k = sys.row_ptr[c]; k < sys.row_ptr[c + 1]; ++k) {
        const int32_t d = sys.col[k];
        if (d != c && sys.val[k] != 0 && !seen[d]) seen[d] = 1, stack.push_back(d);
      }
    }
    if (!ok)
      throw std::invalid_argument("solve_tpfa: " + std::to_string(size) + " connected cells (cell " + std::to_string(s) +
                                  " among them) have no pressure reference (no well, no Dirichlet face)");
  }
}


/// The pressure-dependent coefficients of one linearisation: per cell b and density (kg/m3), and
/// the pressure that decides the upstream cell of each face (empty: incompressible, b = 1).
struct FluidState {
  std::vector<double> b, rho;
  const std::vector<double>* p = nullptr;
};

double inverse_fvf(const FlowProblem& pb, double pressure) {
  if (pb.compressibility == 0) return 1.0;
  const double x = pb.compressibility * (pressure - pb.reference_pressure);
  return (1.0 + x * (1.0 + x / 2.0)) / pb.formation_volume_factor;  // OPM's ConstantCompressibilityWaterPvt
}

bool compressible(const FlowProblem& pb) { return pb.compressibility != 0; }

FluidState fluid_state(const FlowProblem& pb, const std::vector<double>* p) {
  FluidState s;
  const int n = pb.mesh->n_cells();
  s.b.assign(n, 1.0);
  s.rho.assign(n, pb.density);
  if (p != nullptr && compressible(pb)) {
    s.p = p;
    for (int c = 0; c < n; ++c) {
      s.b[c] = inverse_fvf(pb, (*p)[c]);
      s.rho[c] = pb.density * s.b[c];
    }
  }
  return s;
}

double gravity_factor(const FlowProblem& pb) { return pb.gravity ? kGravity / 1e5 : 0.0; }  // bar per (kg/m3 . m)

void check_problem(const FlowProblem& pb, const Transmissibilities& tr) {
  if (pb.mesh == nullptr || pb.geo == nullptr) throw std::invalid_argument("solve_tpfa: mesh or geometry missing");
  const PolyMesh& m = *pb.mesh;
  const int nf = m.n_faces();
  if (static_cast<int>(tr.face.size()) != nf || static_cast<int>(tr.half_owner.size()) != nf)
    throw std::invalid_argument("solve_tpfa: transmissibilities do not match the mesh (" + std::to_string(tr.face.size()) +
                                " values for " + std::to_string(nf) + " faces)");
  if (tr.nnc.size() != m.nnc_cells.size())
    throw std::invalid_argument("solve_tpfa: transmissibilities do not match the mesh (" + std::to_string(tr.nnc.size()) +
                                " values for " + std::to_string(m.nnc_cells.size()) + " connections without a face)");
  for (size_t k = 0; k < tr.nnc.size(); ++k)
    if (!std::isfinite(tr.nnc[k]))
      throw std::invalid_argument("solve_tpfa: non-finite transmissibility of connection " + std::to_string(k));
  if (static_cast<int>(pb.geo->face_centroid.size()) != nf)
    throw std::invalid_argument("solve_tpfa: geometry does not match the mesh");
  if (!(pb.viscosity_cp > 0) || !std::isfinite(pb.viscosity_cp))
    throw std::invalid_argument("solve_tpfa: viscosity must be > 0");
  if (!std::isfinite(pb.density)) throw std::invalid_argument("solve_tpfa: density is not finite");
  if (!(pb.compressibility >= 0) || !std::isfinite(pb.compressibility) || !std::isfinite(pb.reference_pressure) ||
      !(pb.formation_volume_factor > 0) || !std::isfinite(pb.formation_volume_factor))
    throw std::invalid_argument("solve_tpfa: compressibility must be >= 0, reference pressure finite, B_ref > 0");
  // The incompressible solve works in reservoir volumes with b = 1: a B_ref other than 1 would
  // silently change the meaning of the rates (surface volumes need the compressible path).
  if (pb.compressibility == 0 && pb.formation_volume_factor != 1)
    throw std::invalid_argument("solve_tpfa: B_ref must be 1 when compressibility is 0");
  for (const WellConnection& wc : pb.connections)
    if (wc.cell < 0 || wc.cell >= m.n_cells() || wc.well < 0 || !std::isfinite(wc.cf))
      throw std::invalid_argument("solve_tpfa: bad connection (well " + std::to_string(wc.well) + ", cell " +
                                  std::to_string(wc.cell) + ")");
  for (const WellControl& wc : pb.wells)
    if (wc.well < 0 || !std::isfinite(wc.bhp) || !std::isfinite(wc.ref_depth))
      throw std::invalid_argument("solve_tpfa: bad well control for well " + std::to_string(wc.well));
}

int well_count(const FlowProblem& pb) {
  int n = 0;
  const PolyMesh& m = *pb.mesh;
  for (int f = 0; f < m.n_faces(); ++f)
    if (m.face_neighbour[f] < 0 && is_wellbore_patch(m.face_patch[f])) n = std::max(n, well_of_patch(m.face_patch[f]) + 1);
  for (const WellConnection& wc : pb.connections) n = std::max(n, wc.well + 1);
  for (const WellControl& wc : pb.wells) n = std::max(n, wc.well + 1);
  return n;
}

double column_pressure(const FlowProblem& pb, const WellControl& ctl, double depth) {
  const double g_s = pb.density * gravity_factor(pb) / pb.formation_volume_factor;  // bar/m at b B_ref = 1
  const double dz = depth - ctl.ref_depth;
  if (!compressible(pb)) return ctl.bhp + pb.density * gravity_factor(pb) * dz;
  // u = 1 + X obeys du / (u^2 + 1) = c g_s dz / 2: atan(u) = atan(u0) + y, y = c g_s dz / 2. With
  // t = tan(y), u = (u0 + t) / (1 - u0 t), so X = (X0 + t (2 + X0)) / (1 - u0 t); divided by c with
  // t / c = (g_s dz / 2) tan(y)/y, which stays exact when c dz is tiny.
  const double c = pb.compressibility, x0 = c * (ctl.bhp - pb.reference_pressure), y = c * g_s * dz / 2;
  const double t = std::tan(y), tan_ratio = y == 0 ? 1.0 : t / y;
  return pb.reference_pressure + ((ctl.bhp - pb.reference_pressure) + g_s * dz / 2 * tan_ratio * (2 + x0)) /
                                     (1 - (1 + x0) * t);
}

/// Every boundary term of the problem: Dirichlet outer faces, wellbore faces, extra connections.
std::vector<BoundaryTerm> boundary_terms(const FlowProblem& pb, const Transmissibilities& tr, const FluidState& st) {
  const PolyMesh& m = *pb.mesh;
  const MeshGeometry& g = *pb.geo;
  const double mu = pb.viscosity_cp, gf = gravity_factor(pb);
  std::map<int, const WellControl*> control;
  for (const WellControl& wc : pb.wells) control[wc.well] = &wc;
  std::vector<BoundaryTerm> terms;
  // The Dirichlet value of an outer face is taken at its boundary flux point, where its
  // half-transmissibility ends (docs/fvcheck.md, "Boundary faces").
  const std::vector<Vec3> flux_point = pb.outer_dirichlet ? boundary_flux_points(m, g) : std::vector<Vec3>{};
  for (int f = 0; f < m.n_faces(); ++f) {
    if (m.face_neighbour[f] >= 0) continue;
    const int32_t o = m.face_owner[f], patch = m.face_patch[f];
    const double z_cell = m.cell_fv_center[o].z;
    const double grad_cell = st.rho[o] * gf;
    if (patch == kOuterBoundary && pb.outer_dirichlet) {
      const Vec3 x_b = flux_point[f];
      const double p = pb.outer_dirichlet(x_b);
      if (std::isnan(p)) continue;
      terms.push_back({o, tr.half_owner[f] / mu * st.b[o], p + grad_cell * (z_cell - x_b.z), -1});
    } else if (is_wellbore_patch(patch)) {
      const double z_face = g.face_centroid[f].z;
      const int w = well_of_patch(patch);
      if (pb.wellbore_pressure) {
        terms.push_back(
            {o, tr.face[f] / mu * st.b[o], pb.wellbore_pressure(g.face_centroid[f]) + grad_cell * (z_cell - z_face), w});
      } else if (auto it = control.find(w); it != control.end()) {
        terms.push_back({o, tr.face[f] / mu * st.b[o],
                         column_pressure(pb, *it->second, z_cell), w});
      }
    }
  }
  for (const WellConnection& wc : pb.connections) {
    const double z_cell = m.cell_fv_center[wc.cell].z;
    const double c = wc.cf / mu * st.b[wc.cell];
    if (pb.wellbore_pressure) {
      terms.push_back({wc.cell, c, pb.wellbore_pressure(wc.point) + st.rho[wc.cell] * gf * (z_cell - wc.point.z), wc.well});
    } else if (auto it = control.find(wc.well); it != control.end()) {
      terms.push_back({wc.cell, c, column_pressure(pb, *it->second, z_cell), wc.well});
    }
  }
  for (const BoundaryTerm& t : terms)
    if (!std::isfinite(t.c) || !std::isfinite(t.p_ext))
      throw std::invalid_argument("solve_tpfa: non-finite boundary term at cell " + std::to_string(t.cell));
  return terms;
}

/// A connection (a face, or a connection without a face) seen from cell c towards `other`: the
/// coefficient T b_up / mu and the gravity term G (z_c - z_other) of its potential difference
/// p_c - p_other - G (z_c - z_other).
struct FaceTerm {
  double coef, gravity_drop;
};
/// The connection of transmissibility `trans` between cells a and b (a face's owner and neighbour, an
/// NNC's pair): its upstream b is decided once from a's side (a tie goes to a), so that both rows use
/// the same b and the matrix stays symmetric.
FaceTerm connection_term(const FlowProblem& pb, const FluidState& st, double trans, int32_t a, int32_t b, int32_t c,
                         int32_t other) {
  const PolyMesh& m = *pb.mesh;
  const double t = trans / pb.viscosity_cp;
  // OPM: density = mean of the two cells' densities; mobility b/mu of the upstream cell.
  const double drop =
      (st.rho[c] + st.rho[other]) / 2 * gravity_factor(pb) * (m.cell_fv_center[c].z - m.cell_fv_center[other].z);
  double b_up = 1.0;
  if (st.p != nullptr) {
    const double dz = m.cell_fv_center[a].z - m.cell_fv_center[b].z;
    const double dphi = (*st.p)[a] - (*st.p)[b] - (st.rho[a] + st.rho[b]) / 2 * gravity_factor(pb) * dz;
    b_up = dphi >= 0 ? st.b[a] : st.b[b];
  }
  return {t * b_up, drop};
}
FaceTerm face_term(const FlowProblem& pb, const Transmissibilities& tr, const FluidState& st, int32_t f, int32_t c,
                   int32_t other) {
  if (!std::isfinite(tr.face[f]))
    throw std::invalid_argument("solve_tpfa: non-finite transmissibility on face " + std::to_string(f));
  return connection_term(pb, st, tr.face[f], pb.mesh->face_owner[f], pb.mesh->face_neighbour[f], c, other);
}
FaceTerm nnc_term(const FlowProblem& pb, const Transmissibilities& tr, const FluidState& st, int k, int32_t c) {
  const auto [a, b] = pb.mesh->nnc_cells[k];
  return connection_term(pb, st, tr.nnc[k], a, b, c, c == a ? b : a);
}

TpfaSystem assemble_with(const FlowProblem& pb, const Transmissibilities& tr, const FluidState& st) {
  const PolyMesh& m = *pb.mesh;
  const int n = m.n_cells();
  TpfaSystem sys;
  sys.n = n;
  sys.rhs.assign(n, 0.0);
  std::vector<double> diag(n, 0.0);
  sys.row_ptr.assign(n + 1, 0);
  // Row c: the neighbours through c's interior faces, merged (two cells may share several faces).
  // The upstream b of a face is the same seen from both cells, so the matrix stays symmetric.
  std::vector<std::pair<int32_t, double>> row;
  std::vector<std::vector<int>> nncs_of(m.nnc_cells.empty() ? 0 : n);
  for (int k = 0; k < m.n_nncs(); ++k)
    for (const int32_t c : m.nnc_cells[k]) nncs_of[c].push_back(k);
  for (int c = 0; c < n; ++c) {
    row.clear();
    if (!nncs_of.empty())
      for (const int k : nncs_of[c]) {
        const FaceTerm ct = nnc_term(pb, tr, st, k, c);
        const auto [a, b] = m.nnc_cells[k];
        row.push_back({c == a ? b : a, -ct.coef});
        diag[c] += ct.coef;
        sys.rhs[c] += ct.coef * ct.gravity_drop;
      }
    for (const int32_t* it = m.cell_begin(c); it != m.cell_end(c); ++it) {
      const int32_t f = *it, o = m.face_owner[f], nb = m.face_neighbour[f];
      if (nb < 0) continue;
      const int32_t other = o == c ? nb : o;
      const FaceTerm ft = face_term(pb, tr, st, f, c, other);
      row.push_back({other, -ft.coef});
      diag[c] += ft.coef;
      sys.rhs[c] += ft.coef * ft.gravity_drop;
    }
    row.push_back({c, 0.0});
    std::sort(row.begin(), row.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    int32_t last = -1;
    for (const auto& [j, v] : row) {
      if (j == last) {
        sys.val.back() += v;
      } else {
        sys.col.push_back(j);
        sys.val.push_back(v);
        last = j;
      }
    }
    sys.row_ptr[c + 1] = static_cast<int32_t>(sys.col.size());
  }
  const std::vector<BoundaryTerm> terms = boundary_terms(pb, tr, st);
  for (const BoundaryTerm& t : terms) {
    diag[t.cell] += t.c;
    sys.rhs[t.cell] += t.c * t.p_ext;
  }
  for (int c = 0; c < n; ++c)
    for (int32_t k = sys.row_ptr[c]; k < sys.row_ptr[c + 1]; ++k)
      if (sys.col[k] == c) sys.val[k] += diag[c];
  check_references(sys, terms);
  return sys;
}

}  // namespace

TpfaSystem assemble_tpfa(const FlowProblem& pb, const Transmissibilities& tr) {
  check_problem(pb, tr);
  return assemble_with(pb, tr, fluid_state(pb, nullptr));
}

double inverse_formation_volume_factor(const FlowProblem& pb, double pressure) { return inverse_fvf(pb, pressure); }

double wellbore_column_pressure(const FlowProblem& pb, const WellControl& control, double depth) {
  return column_pressure(pb, control, depth);
}

std::vector<double> well_rates(const FlowProblem& pb, const Transmissibilities& tr, const std::vector<double>& p) {
  check_problem(pb, tr);
  std::vector<double> q(well_count(pb), 0.0);
  for (const BoundaryTerm& t : boundary_terms(pb, tr, fluid_state(pb, &p)))
    if (t.well >= 0) q[t.well] += t.c * (p[t.cell] - t.p_ext);
  return q;
}

std::vector<double> mass_balance_residual(const FlowProblem& pb, const Transmissibilities& tr,
                                          const std::vector<double>& p) {
  check_problem(pb, tr);
  const PolyMesh& m = *pb.mesh;
  const FluidState st = fluid_state(pb, &p);
  std::vector<double> r(m.n_cells(), 0.0);
  for (int f = 0; f < m.n_faces(); ++f) {
    const int32_t o = m.face_owner[f], nb = m.face_neighbour[f];
    if (nb < 0) continue;
    const FaceTerm ft = face_term(pb, tr, st, f, o, nb);
    const double flux = ft.coef * (p[o] - p[nb] - ft.gravity_drop);  // surface volume from o to nb
    r[o] += flux;
    r[nb] -= flux;
  }
  for (int k = 0; k < m.n_nncs(); ++k) {
    const auto [a, b] = m.nnc_cells[k];
    const FaceTerm ct = nnc_term(pb, tr, st, k, a);
    const double flux = ct.coef * (p[a] - p[b] - ct.gravity_drop);
    r[a] += flux;
    r[b] -= flux;
  }
  for (const BoundaryTerm& t : boundary_terms(pb, tr, st)) r[t.cell] += t.c * (p[t.cell] - t.p_ext);
  return r;
}

FlowSolution solve_tpfa(const FlowProblem& pb, const Transmissibilities& tr) {
  return solve_tpfa(pb, tr, LinearSolverOptions{});
}

FlowSolution solve_tpfa(const FlowProblem& pb, const Transmissibilities& tr, const LinearSolverOptions& opt) {
  check_problem(pb, tr);
  FlowSolution sol;
  sol.iterations = 0;
  sol.nonlinear_iterations = 0;
  // Picard: b, rho and the upstream choice frozen at the last pressure (the first step at
  // p_ref, i.e. the incompressible system when B_ref = 1). The contraction factor is about
  // c * (pressure spread), ~1e-3 for water, so a few steps reach the round-off of the linear solve.
  constexpr int kMaxPicard = 30;
  constexpr double kPicardTolerance = 1e-11;  // max |p_new - p| relative to max |p|
  // Where the linear solve's own round-off is above kPicardTolerance (rock over eight orders of
  // magnitude, Reek), the change stops shrinking: converged once it no longer halves and is below this.
  constexpr double kPicardNoiseTolerance = 1e-8;
  std::vector<double> p(pb.mesh->n_cells(), pb.reference_pressure);
  double previous_change = std::numeric_limits<double>::infinity();
  for (;;) {
    const TpfaSystem sys = assemble_with(pb, tr, fluid_state(pb, compressible(pb) ? &p : nullptr));
    const LinearSolveResult r = solve_spd(sys, opt);
    ++sol.nonlinear_iterations;
    sol.iterations += r.iterations;
    sol.relative_residual = r.relative_residual;
    sol.solver = r.solver;
    if (!r.converged)
      throw std::runtime_error("solve_tpfa: " + r.solver + " did not reach the relative residual " +
                               std::to_string(opt.tolerance) + " in " + std::to_string(r.iterations) +
                               " iterations (true relative residual " + std::to_string(r.relative_residual) + ")");
    double change = 0, scale = 0;
    for (size_t c = 0; c < p.size(); ++c) {
      change = std::max(change, std::abs(r.x[c] - p[c]));
      scale = std::max(scale, std::abs(r.x[c]));
    }
    p = r.x;
    if (!compressible(pb) || change <= kPicardTolerance * scale) break;
    if (change <= kPicardNoiseTolerance * scale && change > 0.5 * previous_change) break;
    previous_change = change;
    if (sol.nonlinear_iterations >= kMaxPicard) {
      char last[64];
      std::snprintf(last, sizeof last, "%.3g bar of %.6g", change, scale);
      throw std::runtime_error("solve_tpfa: the compressible iteration did not converge in " +
                               std::to_string(kMaxPicard) + " steps (last change " + last + ")");
    }
  }
  if (compressible(pb)) sol.solver += "+picard";
  sol.pressure = std::move(p);
  sol.well_rate_m3_per_day = well_rates(pb, tr, sol.pressure);
  for (double r : mass_balance_residual(pb, tr, sol.pressure))
    sol.max_cell_imbalance = std::max(sol.max_cell_imbalance, std::abs(r));
  return sol;
}

}  // namespace hm
