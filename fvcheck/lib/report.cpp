#include "report.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <utility>

#include "meshgen/core/progress.hpp"

namespace hm {

bool FvReport::ok() const {
  if (!structure.ok) return false;
  for (const CheckResult& c : checks)
    if (!c.ok()) return false;
  if (!transmissibility.ok()) return false;
  return !checks.empty();
}

const CheckResult* FvReport::find(const std::string& name) const {
  for (const CheckResult& c : checks)
    if (c.name == name) return &c;
  return nullptr;
}

FvReport run_fvcheck(const PolyMesh& mesh, const CheckOptions& opt, const std::vector<double>& h_ref,
                     const BuildReport* build, MeshGeometry* geometry_out) {
  FvReport r;
  r.options = opt;
  r.cells = mesh.n_cells();
  r.faces = mesh.n_faces();
  r.nodes = mesh.n_nodes();
  r.connections_without_face = mesh.n_nncs();
  r.structure = check_csr_invariants(mesh);
  if (!r.structure.ok) {
    for (const char* name :
         {"convexity", "conformity", "closure", "volume", "orthogonality", "auto_centering", "planarity"}) {
      CheckResult c;
      c.name = name;
      c.skipped = true;
      r.checks.push_back(c);
    }
    return r;
  }
  for (int f = 0; f < mesh.n_faces(); ++f) r.boundary_faces += mesh.face_neighbour[f] < 0;
  r.cell_region = mesh.cell_region;
  r.k_metric = !(mesh.metric_scale == Vec3{1, 1, 1});
  Progress progress("checks", 9);
  MeshGeometry geo = compute_geometry(mesh);
  progress.advance();
  const CellScales scales = compute_cell_scales(mesh, opt.rel_tol);  // volume and auto-centering
  std::vector<CheckResult> shapes = check_shapes(mesh, geo, opt, &scales, &r.model_cells_not_judged);
  progress.advance(4);
  r.checks.push_back(std::move(shapes[0]));
  r.checks.push_back(check_conformity(mesh, geo, opt, build)), progress.advance();
  r.checks.push_back(check_closure(mesh, geo, opt)), progress.advance();
  r.checks.push_back(check_volume(mesh, geo, opt, scales)), progress.advance();
  for (int i = 1; i < 4; ++i) r.checks.push_back(std::move(shapes[i]));
  r.q_s = cell_shape_quality(mesh, h_ref);
  // Q_O and Q_P of every cell, the model's too (the checks' values cover only the judged cells).
  const bool whole = r.model_cells_not_judged == 0;
  r.q_o_cell = cell_min_of_faces(mesh, r.k_metric || !whole ? face_orthogonality(mesh, geo) : r.find("orthogonality")->values);
  bool has_perm = true;
  for (const Vec3& k : mesh.cell_perm)
    has_perm = has_perm && k.x > 0 && k.y > 0 && k.z > 0 && std::isfinite(k.x + k.y + k.z);
  if (has_perm) {
    std::vector<double> face_angle = face_k_nonorthogonality(mesh, geo);
    r.k_angle_cell = cell_max_of_faces(mesh, face_angle);
    for (int f = 0; f < mesh.n_faces(); ++f)
      if (mesh.face_neighbour[f] < 0) face_angle[f] = 0;
    r.k_angle_interior_cell = cell_max_of_faces(mesh, face_angle);
    r.k_angle_all = stats_of(r.k_angle_cell);
    r.k_angle_interior_all = stats_of(r.k_angle_interior_cell);
  }
  r.q_p_cell = cell_max_of_faces(mesh, whole ? r.find("planarity")->values : face_planarity(mesh, geo));
  r.q_s_all = stats_of(r.q_s);
  r.q_o_all = stats_of(r.q_o_cell);
  r.q_p_all = stats_of(r.q_p_cell);
  r.by_region = quality_by_region(mesh, r.q_s, r.q_o_cell, r.q_p_cell, r.k_angle_cell, r.k_angle_interior_cell);
  const CheckMeshFigures foam = checkmesh_figures(mesh);
  r.openfoam_skewness = foam.skewness;
  r.openfoam_nonorthogonality = foam.nonorthogonality;
  if (geometry_out) *geometry_out = std::move(geo);
  return r;
}

TransmissibilitySummary summarize_transmissibilities(const std::vector<double>& t) {
  TransmissibilitySummary s;
  s.present = true;
  bool first = true;
  for (size_t f = 0; f < t.size(); ++f) {
    const double v = t[f];
    if (!std::isfinite(v) || v < 0) {
      ++s.negative;
      if (s.negative_faces.size() < 10) s.negative_faces.push_back(static_cast<int32_t>(f));
    }
    if (v == 0 || std::isnan(v)) continue;
    ++s.count;
    s.min = first ? v : std::min(s.min, v);
    s.max = first ? v : std::max(s.max, v);
    first = false;
  }
  return s;
}

std::string openfoam_skewness_text(const SkewnessSummary& s) {
  std::ostringstream os;
  os << "checkMesh skewness: max " << s.max;
  if (s.above_limit == 0) return os.str() + ", no face above checkMesh's limit of 4";
  const bool one = s.above_limit == 1;
  os << ", " << s.above_limit << (one ? " face" : " faces") << " above checkMesh's limit of 4: checkMesh reports "
     << (one ? "it" : "them") << " (\"Failed 1 mesh checks\") on the OpenFOAM export";
  return os.str();
}

std::string openfoam_nonorthogonality_text(const NonOrthogonalitySummary& s) {
  char line[160];
  std::snprintf(line, sizeof line, "checkMesh non-orthogonality: max %.6g, average %.6g deg", s.max, s.average);
  std::ostringstream os;
  os << line;
  if (s.severe > 0)
    os << ", " << s.severe << (s.severe == 1 ? " face" : " faces") << " above its warning threshold of "
       << kCheckMeshSevereNonOrthogonality;
  if (s.errors == 0) return os.str();
  const bool one = s.errors == 1;
  os << ", " << s.errors << (one ? " face" : " faces") << " at 90 deg or more: checkMesh reports "
     << (one ? "it" : "them") << " (\"Failed 1 mesh checks\") on the OpenFOAM export";
  return os.str();
}

std::string report_summary_text(const FvReport& r) {
  std::ostringstream os;
  os << "fvcheck: " << (r.source.empty() ? "mesh" : r.source) << ": " << r.cells << " cells, " << r.faces
     << " faces, " << r.nodes << " nodes\n";
  for (const std::string& n : r.notes) os << "  note: " << n << "\n";
  if (r.model_cells_not_judged > 0)
    os << "  convexity, orthogonality, auto-centering and planarity judge the " << r.cells - r.model_cells_not_judged
       << " near-well cells; the " << r.model_cells_not_judged << " cells of the corner-point model are the user's\n";
  if (!r.structure.ok) {
    os << "  structure       FAILED (checks skipped)\n";
    for (const std::string& p : r.structure.problems) os << "    " << p << "\n";
  }
  char line[256];
  for (const CheckResult& c : r.checks) {
    if (c.skipped) continue;
    std::snprintf(line, sizeof line, "  %-15s %-6s %8lld violations   worst %.6g", c.name.c_str(),
                  c.ok() ? "ok" : "FAILED", static_cast<long long>(c.violations), c.worst);
    os << line;
    if (!c.ok() && !c.worst_ids.empty()) {
      os << "   worst " << (c.id_kind == IdKind::Face ? "faces" : "cells") << ":";
      for (size_t i = 0; i < c.worst_ids.size() && i < 5; ++i) os << " " << c.worst_ids[i];
    }
    os << "\n";
  }
  if (r.structure.ok) {
    std::snprintf(line, sizeof line, "  quality: Q_S %.3f/%.3f/%.3f  Q_O %.2f/%.2f/%.2f deg  Q_P %.2f/%.2f/%.2f deg (min/max/mean)\n",
                  r.q_s_all.min, r.q_s_all.max, r.q_s_all.mean, r.q_o_all.min, r.q_o_all.max, r.q_o_all.mean,
                  r.q_p_all.min, r.q_p_all.max, r.q_p_all.mean);
    os << line;
    os << "  " << openfoam_skewness_text(r.openfoam_skewness) << "\n";
    os << "  " << openfoam_nonorthogonality_text(r.openfoam_nonorthogonality) << "\n";
  }
  if (!r.k_angle_cell.empty()) {
    os << "  K-non-orthogonality (deg, max/mean):";
    std::snprintf(line, sizeof line, " all %.3g/%.3g", r.k_angle_all.max, r.k_angle_all.mean);
    os << line;
    for (const RegionQuality& rq : r.by_region) {
      std::snprintf(line, sizeof line, "  %s %.3g/%.3g", rq.name.c_str(), rq.k_angle.max, rq.k_angle.mean);
      os << line;
    }
    os << (r.k_metric ? "  (permeability-frame mesh: orthogonality checked in the K metric)\n" : "\n");
    std::snprintf(line, sizeof line, "    interior faces only:          all %.3g/%.3g", r.k_angle_interior_all.max,
                  r.k_angle_interior_all.mean);
    os << line;
    for (const RegionQuality& rq : r.by_region) {
      std::snprintf(line, sizeof line, "  %s %.3g/%.3g", rq.name.c_str(), rq.k_angle_interior.max, rq.k_angle_interior.mean);
      os << line;
    }
    os << "\n";
  }
  if (r.transmissibility.present) {
    std::snprintf(line, sizeof line, "  transmissibility: %lld faces, min %.6g, max %.6g, negative %lld (halves %lld)\n",
                  static_cast<long long>(r.transmissibility.count), r.transmissibility.min, r.transmissibility.max,
                  static_cast<long long>(r.transmissibility.negative),
                  static_cast<long long>(r.transmissibility.negative_halves));
    os << line;
  }
  if (r.transmissibility.present && !r.transmissibility.ok())
    os << "  transmissibility FAILED: negative or non-finite values (first faces:" <<
        [&] {
          std::string ids;
          for (int32_t f : r.transmissibility.negative_faces) ids += " " + std::to_string(f);
          return ids;
        }() << ")\n";
  os << "result: " << (r.ok() ? "OK" : "FAILED") << "\n";
  return os.str();
}


}  // namespace hm
