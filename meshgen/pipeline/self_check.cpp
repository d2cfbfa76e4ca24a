#include "self_check.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

#include "meshgen/core/mesh_builder.hpp"

#include "fvcheck/lib/transmissibility.hpp"
#include "meshgen/core/progress.hpp"

namespace hm {

namespace {

bool finite(Vec3 p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); }

// Cells whose data a file takes and which are not finite numbers (each cell once, ascending).
SelfCheckFailure non_finite_cells(const PolyMesh& mesh, const MeshGeometry& geo) {
  SelfCheckFailure f;
  f.check = "finite";
  const Transmissibilities trans = compute_transmissibilities(mesh, geo);
  std::vector<char> bad(mesh.n_cells(), 0);
  for (int c = 0; c < mesh.n_cells(); ++c) {
    bool ok = finite(mesh.cell_fv_center[c]) && finite(mesh.cell_perm[c]) && std::isfinite(mesh.cell_porosity[c]) &&
              std::isfinite(geo.cell_volume[c]) && finite(geo.cell_centroid[c]);
    for (const int32_t* fp = mesh.cell_begin(c); ok && fp != mesh.cell_end(c); ++fp)
      for (const int32_t* v = mesh.face_begin(*fp); ok && v != mesh.face_end(*fp); ++v) ok = finite(mesh.nodes[*v]);
    bad[c] = !ok;
  }
  for (int fc = 0; fc < mesh.n_faces(); ++fc) {
    const bool ok = finite(geo.face_area[fc]) && finite(geo.face_centroid[fc]) && std::isfinite(trans.face[fc]) &&
                    std::isfinite(trans.half_owner[fc]) && std::isfinite(trans.half_neighbour[fc]);
    if (ok) continue;
    bad[mesh.face_owner[fc]] = 1;
    if (mesh.face_neighbour[fc] >= 0) bad[mesh.face_neighbour[fc]] = 1;
  }
  for (int c = 0; c < mesh.n_cells(); ++c)
    if (bad[c]) {
      ++f.violations;
      if (f.cells.size() < 10) f.cells.push_back(c);
    }
  return f;
}

std::string cell_text(const PolyMesh& mesh, int32_t c, const std::vector<int32_t>& cell_cavity) {
  std::ostringstream os;
  os << c;
  if (mesh.cell_region[c] == kReservoir) {
    const auto& ijk = mesh.cell_ijk[c];
    os << " (reservoir " << ijk[0] << "," << ijk[1] << "," << ijk[2] << ")";
  } else if (mesh.cell_region[c] == kWell) {
    const RadialCellInfo& r = mesh.cell_radial[c];
    os << " (well " << r.well << " ring " << r.ring << " sector " << r.sector << ")";
  } else if (c < static_cast<int32_t>(cell_cavity.size()) && cell_cavity[c] >= 0) {
    os << " (transition, cavity " << cell_cavity[c] << ")";
  }
  return os.str();
}

}  // namespace

SelfCheck self_check(const PolyMesh& mesh, const MeshGeometry& geo, const BuildReport& build,
                     const std::vector<int32_t>& cell_cavity, const std::vector<std::vector<int>>& cavity_wells,
                     const CaseSpec& cs) {
  SelfCheck out;
  const CsrReport csr = check_csr_invariants(mesh);
  if (!csr.ok) {
    out.failures.push_back({"structure", 1, {}, 0, false, -1, {}});
    out.message = "self-check: the mesh arrays are inconsistent: " + (csr.problems.empty() ? "?" : csr.problems[0]);
    return out;
  }
  const CheckOptions opt;  // fvcheck's defaults: what `fvcheck mesh.vtu` would apply
  Progress progress("self-check", 8);
  std::vector<CheckResult> checks;
  checks.push_back(check_conformity(mesh, geo, opt, &build)), progress.advance();
  checks.push_back(check_closure(mesh, geo, opt)), progress.advance();
  checks.push_back(check_volume(mesh, geo, opt)), progress.advance();
  // The shape checks hold for every cell we make; a corner-point model's cells are the user's and
  // are exempt (PolyMesh::reservoir_cells_are_model, docs/mesh-layout.md).
  for (CheckResult& r : check_shapes(mesh, geo, opt)) checks.push_back(std::move(r));
  progress.advance(4);
  for (const CheckResult& r : checks) {
    if (r.ok()) continue;
    SelfCheckFailure f;
    f.check = r.name;
    f.violations = r.violations;
    f.worst = r.worst;
    for (const auto& [name, n] : r.counts)
      if (n > 0) f.counts.push_back({name, n});
    f.per_face = r.id_kind == IdKind::Face;
    if (f.per_face && !r.worst_ids.empty()) f.neighbour = mesh.face_neighbour[r.worst_ids[0]];
    // worst_ids are the worst values, violating or not: the first `violations` of them violate.
    for (size_t i = 0; i < r.worst_ids.size() && static_cast<int64_t>(i) < r.violations; ++i) {
      const int32_t id = r.worst_ids[i];
      const int32_t c = r.id_kind == IdKind::Face ? mesh.face_owner[id] : id;
      if (std::find(f.cells.begin(), f.cells.end(), c) == f.cells.end()) f.cells.push_back(c);
    }
    out.failures.push_back(std::move(f));
  }
  if (SelfCheckFailure f = non_finite_cells(mesh, geo); f.violations > 0) out.failures.push_back(std::move(f));
  if (out.failures.empty()) return out;

  std::set<int> wells;
  std::ostringstream os;
  os << "self-check: the mesh fails";
  for (size_t i = 0; i < out.failures.size(); ++i) {
    const SelfCheckFailure& f = out.failures[i];
    os << (i ? "; " : " ") << f.check << " (" << f.violations << (f.check == "orthogonality" || f.check == "planarity" ? " faces" : " cells");
    for (size_t k = 0; k < f.cells.size() && k < 3; ++k) os << (k ? ", " : ": cell ") << cell_text(mesh, f.cells[k], cell_cavity);
    if (f.check == "conformity")
      for (const auto& [name, n] : f.counts) os << "; " << name << " " << n;
    if (f.check == "orthogonality" || f.check == "planarity") {
      os << "; worst " << f.worst << " degrees";
      if (f.per_face)
        os << ", " << (f.neighbour >= 0 ? "toward cell " + cell_text(mesh, f.neighbour, cell_cavity) : std::string("a boundary face"));
    }
    os << ")";
    for (int32_t c : f.cells) {
      if (mesh.cell_region[c] == kWell && mesh.cell_radial[c].well >= 0) wells.insert(mesh.cell_radial[c].well);
      if (c < static_cast<int32_t>(cell_cavity.size()) && cell_cavity[c] >= 0 &&
          cell_cavity[c] < static_cast<int32_t>(cavity_wells.size()))
        wells.insert(cavity_wells[cell_cavity[c]].begin(), cavity_wells[cell_cavity[c]].end());
    }
  }
  out.wells.assign(wells.begin(), wells.end());
  if (!out.wells.empty()) {
    os << "; at";
    for (size_t i = 0; i < out.wells.size(); ++i) {
      const int w = out.wells[i];
      os << (i ? ", " : " ") << "wells[" << w << "]";
      if (w >= 0 && w < static_cast<int>(cs.wells.size())) os << " (" << cs.wells[w].name << ")";
    }
  }
  out.message = os.str();
  return out;
}

}  // namespace hm
