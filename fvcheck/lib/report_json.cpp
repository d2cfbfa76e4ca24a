#include "report_json.hpp"

#include <cmath>

namespace hm {

namespace {
using nlohmann::json;

// JSON has no inf/NaN: such values become null.
json num(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

json stats_json(const Stats& s) { return {{"count", s.count}, {"min", num(s.min)}, {"max", num(s.max)}, {"mean", num(s.mean)}}; }

json check_json(const CheckResult& c) {
  json j;
  if (c.skipped) {
    j["skipped"] = true;
    j["ok"] = false;
    return j;
  }
  j["ok"] = c.ok();
  j["violations"] = c.violations;
  j["worst"] = num(c.worst);
  j["worst_ids"] = c.worst_ids;
  j["id_kind"] = c.id_kind == IdKind::Face ? "face" : "cell";
  for (const auto& [name, n] : c.counts) j["counts"][name] = n;
  for (const auto& [name, ids] : c.id_lists) j["examples"][name] = ids;
  for (const auto& [name, x] : c.measures) j[name] = num(x);
  return j;
}
}  // namespace

json report_json(const FvReport& r) {
  json j;
  j["ok"] = r.ok();
  j["source"] = r.source;
  j["cells"] = r.cells;
  j["faces"] = r.faces;
  j["nodes"] = r.nodes;
  j["boundary_faces"] = r.boundary_faces;
  j["model_cells_not_judged"] = r.model_cells_not_judged;
  j["connections_without_face"] = r.connections_without_face;
  j["structure"] = {{"ok", r.structure.ok}, {"problems", r.structure.problems}};
  j["options"] = {{"rel_tol", r.options.rel_tol},
                  {"closure_tol", r.options.closure_tol},
                  {"volume_rel_tol", r.options.volume_rel_tol},
                  {"min_orthogonality_deg", r.options.min_orthogonality_deg},
                  {"max_planarity_deg", r.options.max_planarity_deg}};
  j["checks"] = json::object();
  for (const CheckResult& c : r.checks) j["checks"][c.name] = check_json(c);
  json q;
  q["Q_S"] = stats_json(r.q_s_all);
  q["Q_O"] = stats_json(r.q_o_all);
  q["Q_P"] = stats_json(r.q_p_all);
  q["metric"] = r.k_metric ? "permeability" : "euclidean";
  if (!r.k_angle_cell.empty()) {
    q["K_nonorthogonality_deg"] = stats_json(r.k_angle_all);
    q["K_nonorthogonality_interior_deg"] = stats_json(r.k_angle_interior_all);
  }
  q["by_region"] = json::object();
  for (const RegionQuality& rq : r.by_region) {
    q["by_region"][rq.name] = {{"region", rq.region},
                               {"cells", rq.cells},
                               {"Q_S", stats_json(rq.q_s)},
                               {"Q_O", stats_json(rq.q_o)},
                               {"Q_P", stats_json(rq.q_p)}};
    if (!r.k_angle_cell.empty()) {
      q["by_region"][rq.name]["K_nonorthogonality_deg"] = stats_json(rq.k_angle);
      q["by_region"][rq.name]["K_nonorthogonality_interior_deg"] = stats_json(rq.k_angle_interior);
    }
  }
  q["openfoam_skewness"] = {{"max", num(r.openfoam_skewness.max)},
                            {"worst_face", r.openfoam_skewness.worst_face},
                            {"faces_above_checkmesh_limit", r.openfoam_skewness.above_limit},
                            {"checkmesh_limit", kCheckMeshSkewnessLimit}};
  const NonOrthogonalitySummary& no = r.openfoam_nonorthogonality;
  q["openfoam_nonorthogonality_deg"] = {{"max", num(no.max)},
                                        {"average", num(no.average)},
                                        {"worst_face", no.worst_face},
                                        {"severe_faces", no.severe},
                                        {"checkmesh_severe_threshold", kCheckMeshSevereNonOrthogonality},
                                        {"error_faces", no.errors}};
  j["quality"] = q;
  if (r.transmissibility.present)
    j["transmissibility"] = {{"count", r.transmissibility.count},
                             {"min", num(r.transmissibility.min)},
                             {"max", num(r.transmissibility.max)},
                             {"negative", r.transmissibility.negative},
                             {"negative_halves", r.transmissibility.negative_halves},
                             {"negative_faces", r.transmissibility.negative_faces}};
  j["notes"] = r.notes;
  return j;
}

}  // namespace hm
