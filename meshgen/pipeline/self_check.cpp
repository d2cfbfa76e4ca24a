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

// The cells of a corner-point model (reservoir cells when the case has one): the user's cells, whose
// faces are in general neither planar nor orthogonal to the centre-to-centre segments.
std::vector<char> model_cells(const PolyMesh& mesh, const CaseSpec& cs) {
  std::vector<char> model(mesh.n_cells(), 0);
  if (cs.reservoir.corner_point)
    for (int c = 0; c < mesh.n_cells(); ++c) model[c] = mesh.cell_region[c] == kReservoir;
  return model;
}

// The cells with keep[c] as a mesh of their own (faces toward the others become boundary faces);
// `cell_of` maps its cells back.
PolyMesh kept_cells(const PolyMesh& mesh, const std::vector<char>& keep, std::vector<int32_t>* cell_of) {
  MeshBuilder b;
  std::vector<int32_t> node(mesh.n_nodes(), -1);
  std::vector<CellFace> faces;
  for (int c = 0; c < mesh.n_cells(); ++c) {
    if (!keep[c]) continue;
    faces.clear();
    for (const int32_t* fp = mesh.cell_begin(c); fp != mesh.cell_end(c); ++fp) {
      CellFace f;
      for (const int32_t* v = mesh.face_begin(*fp); v != mesh.face_end(*fp); ++v) {
        if (node[*v] < 0) node[*v] = b.add_node(mesh.nodes[*v]);
        f.nodes.push_back(node[*v]);
      }
      if (mesh.face_owner[*fp] != c) std::reverse(f.nodes.begin(), f.nodes.end());
      const int32_t other = mesh.face_owner[*fp] == c ? mesh.face_neighbour[*fp] : mesh.face_owner[*fp];
      f.patch = other < 0 ? mesh.face_patch[*fp] : (keep[other] ? kInteriorFace : kOuterBoundary);
      faces.push_back(std::move(f));
    }
    CellAttributes at;
    at.region = mesh.cell_region[c];
    at.fv_center = mesh.cell_fv_center[c];
    at.ijk = mesh.cell_ijk[c];
    at.perm = mesh.cell_perm[c];
    at.porosity = mesh.cell_porosity[c];
    at.radial = mesh.cell_radial[c];
    b.add_cell(faces, at);
    cell_of->push_back(c);
  }
  BuildReport report;
  PolyMesh sub = b.finish(&report);
  sub.metric_scale = mesh.metric_scale;
  return sub;
}

}  // namespace

SelfCheck self_check(const PolyMesh& mesh, const MeshGeometry& geo, const BuildReport& build,
                     const std::vector<int32_t>& cell_cavity, const std::vector<std::vector<int>>& cavity_wells,
                     const CaseSpec& cs) {
  SelfCheck out;
  const CsrReport csr = check_csr_invariants(mesh);
  if (!csr.ok) {
    out.failures.push_back({"structure", 1, {}});
    out.message = "self-check: the mesh arrays are inconsistent: " + (csr.problems.empty() ? "?" : csr.problems[0]);
    return out;
  }
  const CheckOptions opt;  // fvcheck's defaults: what `fvcheck mesh.vtu` would apply
  Progress progress("self-check", 8);
  std::vector<CheckResult> checks;
  checks.push_back(check_conformity(mesh, geo, opt, &build)), progress.advance();
  checks.push_back(check_closure(mesh, geo, opt)), progress.advance();
  checks.push_back(check_volume(mesh, geo, opt)), progress.advance();
  // The shape checks (convexity, orthogonality, auto-centring, planarity) hold for every cell we
  // make; the cells of a corner-point model are the user's and are exempt (docs/mesh-layout.md).
  const std::vector<char> model = model_cells(mesh, cs);
  const bool has_model = std::find(model.begin(), model.end(), 1) != model.end();
  std::vector<int32_t> cell_of;
  PolyMesh sub;
  if (has_model) {
    std::vector<char> ours(model.size());
    for (size_t c = 0; c < model.size(); ++c) ours[c] = !model[c];
    sub = kept_cells(mesh, ours, &cell_of);
  }
  const PolyMesh& shaped = has_model ? sub : mesh;
  const MeshGeometry sub_geo = has_model ? compute_geometry(sub) : MeshGeometry{};
  const MeshGeometry& shaped_geo = has_model ? sub_geo : geo;
  std::vector<CheckResult> shape;
  if (shaped.n_cells() > 0) {
    shape.push_back(check_convexity(shaped, shaped_geo, opt)), progress.advance();
    shape.push_back(check_orthogonality(shaped, shaped_geo, opt)), progress.advance();
    shape.push_back(check_auto_centering(shaped, shaped_geo, opt)), progress.advance();
    shape.push_back(check_planarity(shaped, shaped_geo, opt)), progress.advance();
  }
  for (CheckResult& r : shape) {
    if (has_model) {  // ids of the kept cells' mesh -> cells of the whole mesh
      for (int32_t& id : r.worst_ids) id = cell_of[r.id_kind == IdKind::Face ? sub.face_owner[id] : id];
      r.id_kind = IdKind::Cell;
    }
    checks.push_back(std::move(r));
  }
  for (const CheckResult& r : checks) {
    if (r.ok()) continue;
    SelfCheckFailure f;
    f.check = r.name;
    f.violations = r.violations;
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
