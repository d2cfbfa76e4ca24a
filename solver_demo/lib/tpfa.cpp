#include "tpfa.hpp"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/Sparse>
#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "ordering.hpp"

namespace hm {

namespace {

/// One boundary term of cell `cell`: c/mu (p_cell - p_ext), c already divided by mu.
struct BoundaryTerm {
  int32_t cell;
  double c;      // transmissibility / mu
  double p_ext;  // the external pressure seen at the cell's depth (gravity included)
  int well;      // >= 0: counts toward that well's rate
};

double hydrostatic_gradient(const FlowProblem& pb) {
  return pb.gravity ? pb.density * kGravity / 1e5 : 0.0;  // bar per m of depth
}

void check_problem(const FlowProblem& pb, const Transmissibilities& tr) {
  if (pb.mesh == nullptr || pb.geo == nullptr) throw std::invalid_argument("solve_tpfa: mesh or geometry missing");
  const PolyMesh& m = *pb.mesh;
  const int nf = m.n_faces();
  if (static_cast<int>(tr.face.size()) != nf || static_cast<int>(tr.half_owner.size()) != nf)
    throw std::invalid_argument("solve_tpfa: transmissibilities do not match the mesh (" + std::to_string(tr.face.size()) +
                                " values for " + std::to_string(nf) + " faces)");
  if (static_cast<int>(pb.geo->face_centroid.size()) != nf)
    throw std::invalid_argument("solve_tpfa: geometry does not match the mesh");
  if (!(pb.viscosity_cp > 0) || !std::isfinite(pb.viscosity_cp))
    throw std::invalid_argument("solve_tpfa: viscosity must be > 0");
  if (!std::isfinite(pb.density)) throw std::invalid_argument("solve_tpfa: density is not finite");
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

/// Every boundary term of the problem: Dirichlet outer faces, wellbore faces, extra connections.
std::vector<BoundaryTerm> boundary_terms(const FlowProblem& pb, const Transmissibilities& tr) {
  const PolyMesh& m = *pb.mesh;
  const MeshGeometry& g = *pb.geo;
  const double mu = pb.viscosity_cp, grad = hydrostatic_gradient(pb);
  std::map<int, const WellControl*> control;
  for (const WellControl& wc : pb.wells) control[wc.well] = &wc;
  std::vector<BoundaryTerm> terms;
  for (int f = 0; f < m.n_faces(); ++f) {
    if (m.face_neighbour[f] >= 0) continue;
    const int32_t o = m.face_owner[f], patch = m.face_patch[f];
    const double z_cell = m.cell_fv_center[o].z, z_face = g.face_centroid[f].z;
    if (patch == kOuterBoundary && pb.outer_dirichlet) {
      const double p = pb.outer_dirichlet(g.face_centroid[f]);
      if (std::isnan(p)) continue;
      terms.push_back({o, tr.half_owner[f] / mu, p + grad * (z_cell - z_face), -1});
    } else if (is_wellbore_patch(patch)) {
      const int w = well_of_patch(patch);
      if (pb.wellbore_pressure) {
        terms.push_back({o, tr.face[f] / mu, pb.wellbore_pressure(g.face_centroid[f]) + grad * (z_cell - z_face), w});
      } else if (auto it = control.find(w); it != control.end()) {
        terms.push_back({o, tr.face[f] / mu, it->second->bhp + grad * (z_cell - it->second->ref_depth), w});
      }
    }
  }
  for (const WellConnection& wc : pb.connections) {
    const double z_cell = m.cell_fv_center[wc.cell].z;
    if (pb.wellbore_pressure) {
      terms.push_back({wc.cell, wc.cf / mu, pb.wellbore_pressure(wc.point) + grad * (z_cell - wc.point.z), wc.well});
    } else if (auto it = control.find(wc.well); it != control.end()) {
      terms.push_back({wc.cell, wc.cf / mu, it->second->bhp + grad * (z_cell - it->second->ref_depth), wc.well});
    }
  }
  for (const BoundaryTerm& t : terms)
    if (!std::isfinite(t.c) || !std::isfinite(t.p_ext))
      throw std::invalid_argument("solve_tpfa: non-finite boundary term at cell " + std::to_string(t.cell));
  return terms;
}

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

}  // namespace

TpfaSystem assemble_tpfa(const FlowProblem& pb, const Transmissibilities& tr) {
  check_problem(pb, tr);
  const PolyMesh& m = *pb.mesh;
  const int n = m.n_cells();
  const double mu = pb.viscosity_cp, grad = hydrostatic_gradient(pb);
  TpfaSystem sys;
  sys.n = n;
  sys.rhs.assign(n, 0.0);
  std::vector<double> diag(n, 0.0);
  sys.row_ptr.assign(n + 1, 0);
  // Row c: the neighbours through c's interior faces, merged (two cells may share several faces).
  std::vector<std::pair<int32_t, double>> row;
  for (int c = 0; c < n; ++c) {
    row.clear();
    for (const int32_t* it = m.cell_begin(c); it != m.cell_end(c); ++it) {
      const int32_t f = *it, o = m.face_owner[f], nb = m.face_neighbour[f];
      if (nb < 0) continue;
      const double t = tr.face[f] / mu;
      if (!std::isfinite(t)) throw std::invalid_argument("solve_tpfa: non-finite transmissibility on face " + std::to_string(f));
      const int32_t other = o == c ? nb : o;
      row.push_back({other, -t});
      diag[c] += t;
      sys.rhs[c] += t * grad * (m.cell_fv_center[c].z - m.cell_fv_center[other].z);
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
  const std::vector<BoundaryTerm> terms = boundary_terms(pb, tr);
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

std::vector<double> well_rates(const FlowProblem& pb, const Transmissibilities& tr, const std::vector<double>& p) {
  check_problem(pb, tr);
  std::vector<double> q(well_count(pb), 0.0);
  for (const BoundaryTerm& t : boundary_terms(pb, tr))
    if (t.well >= 0) q[t.well] += t.c * (p[t.cell] - t.p_ext);
  return q;
}

FlowSolution solve_tpfa(const FlowProblem& pb, const Transmissibilities& tr) {
  return solve_tpfa(pb, tr, LinearSolverOptions{});
}

FlowSolution solve_tpfa(const FlowProblem& pb, const Transmissibilities& tr, const LinearSolverOptions& opt) {
  const TpfaSystem sys = assemble_tpfa(pb, tr);
  const LinearSolveResult r = solve_spd(sys, opt);
  FlowSolution sol;
  sol.pressure = r.x;
  sol.iterations = r.iterations;
  sol.relative_residual = r.relative_residual;
  sol.solver = r.solver;
  if (!r.converged)
    throw std::runtime_error("solve_tpfa: " + r.solver + " did not reach the relative residual " +
                             std::to_string(opt.tolerance) + " in " + std::to_string(r.iterations) +
                             " iterations (true relative residual " + std::to_string(r.relative_residual) + ")");
  sol.well_rate_m3_per_day = well_rates(pb, tr, sol.pressure);
  return sol;
}

}  // namespace hm
