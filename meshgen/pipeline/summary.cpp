#include "summary.hpp"

#include "meshgen/case/grdecl.hpp"


namespace hm {

namespace {
nlohmann::json stats_json(const Stats& s) { return {{"min", s.min}, {"max", s.max}, {"mean", s.mean}}; }
}  // namespace

nlohmann::json to_json(const TransitionQuality& q) {
  return {{"vertices", q.vertices},  {"faces", q.faces},          {"cells", q.cells},
          {"Q_S", stats_json(q.q_s)}, {"Q_O", stats_json(q.q_o)}, {"Q_P", stats_json(q.q_p)}};
}

nlohmann::json make_summary(const CaseSpec& cs, const HybridMesh& h) {
  nlohmann::json j;
  j["case"] = cs.name;
  int by_region[3] = {0, 0, 0};
  for (int32_t r : h.mesh.cell_region) ++by_region[r];
  j["cells"] = {{"reservoir", by_region[kReservoir]},
                {"transition", by_region[kTransition]},
                {"well", by_region[kWell]},
                {"total", h.mesh.n_cells()}};
  j["nodes"] = h.mesh.n_nodes();
  j["faces"] = h.mesh.n_faces();
  j["connections_without_face"] = h.mesh.n_nncs();  // a model's NNC and MINPV connections
  j["cavities"] = h.cavities.cavities.size();
  if (const auto& m = cs.reservoir.corner_point) {
    const bool refined = !m->parent_cell.empty();
    j["corner_point"] = {{"model", {refined ? m->parent_nx : m->nx, refined ? m->parent_ny : m->ny,
                                    m->parent_layer.empty() ? m->nz : m->parent_nz}},
                         {"meshed", {m->nx, m->ny, m->nz}}};
  }
  nlohmann::json cav = nlohmann::json::array();
  for (size_t k = 0; k < h.cavities.cavities.size(); ++k) {
    const Cavity& c = h.cavities.cavities[k];
    std::vector<std::string> names;
    for (int w : c.wells) names.push_back(cs.wells[h.blocks[w].well].name);
    int res_faces = 0, well_faces = 0;
    for (const auto& f : c.faces) (f.side == FaceSide::Reservoir ? res_faces : well_faces)++;
    cav.push_back({{"wells", names},
                   {"deactivated_reservoir_cells", c.deactivated_cells.size()},
                   {"constrained_faces", {{"reservoir", res_faces}, {"well", well_faces}}},
                   {"vertices", c.vertices.size()},
                   {"dilation_used", c.dilation_used}});
  }
  j["cavity_list"] = cav;
  nlohmann::json wells = nlohmann::json::array();
  std::vector<int> open_faces(cs.wells.size(), 0), closed_faces(cs.wells.size(), 0);
  for (int f = 0; f < h.mesh.n_faces(); ++f) {
    const int32_t p = h.mesh.face_patch[f];
    if (is_wellbore_patch(p) && well_of_patch(p) < static_cast<int>(cs.wells.size())) ++open_faces[well_of_patch(p)];
    if (is_closed_wellbore_patch(p) && well_of_closed_patch(p) < static_cast<int>(cs.wells.size()))
      ++closed_faces[well_of_closed_patch(p)];
  }
  for (const WellBlock& b : h.blocks)
    wells.push_back({{"name", cs.wells[b.well].name},
                     {"wellbore_faces", {{"open", open_faces[b.well]}, {"closed", closed_faces[b.well]}}},
                     {"rings", b.rings},
                     {"sectors", b.sectors},
                     {"sectors_requested", b.sectors_requested},
                     {"segments", b.layers - 1},
                     {"end_caps", b.hemisphere_caps ? "hemisphere" : "flat"}});
  j["wells"] = wells;
  j["notes"] = h.notes;
  j["metric"] = {{"frame", h.frame.identity() ? "euclidean" : "permeability"},
                 {"scale", {h.frame.scale.x, h.frame.scale.y, h.frame.scale.z}},
                 {"permeability", {h.frame.k.x, h.frame.k.y, h.frame.k.z}}};
  if (!h.transition_reports.empty()) {
    nlohmann::json t;
    t["before"] = to_json(h.transition_before);
    t["in_mesh"] = {{"Q_O", stats_json(h.transition_q_o_in_mesh)}};
    if (h.optimized) {
      t["after"] = to_json(h.transition_after);
      double transition_s = 0, optimize_s = 0;
      for (const TransitionReport& r : h.transition_reports)
        transition_s += r.seconds_delaunay + r.seconds_sites + r.seconds_power, optimize_s += r.seconds_optimize;
      t["optimization"] = {{"rounds", h.optimize_report.rounds},
                           {"moves_proposed", h.optimize_report.proposed},
                           {"moves_kept", h.optimize_report.kept},
                           {"moves_refused", h.optimize_report.refused},
                           {"moves_invalid", h.optimize_report.invalid},
                           {"seconds_transition", transition_s},
                           {"seconds_optimize", optimize_s}};
    }
    int corrections = 0, hidden = 0, snapped = 0, removed = 0, slivers = 0, skew_steps = 0, repairs = 0, internal = 0,
        external = 0, free = 0, dropped = 0;
    for (const TransitionReport& r : h.transition_reports) {
      corrections += r.site_corrections;
      hidden += r.hidden_sites;
      snapped += r.snapped_vertices;
      removed += r.removed_faces;
      slivers += r.sliver_removals;
      skew_steps += r.skew_steps;
      repairs += r.repairs;
      internal += r.internal_sites;
      external += r.external_sites;
      free += r.free_sites;
      dropped += r.dropped_tip_sites;
    }
    // "free": the internal sites with no constrained polygon (tip sites, docs/transition.md).
    t["sites"] = {{"internal", internal}, {"external", external}, {"free", free}};
    t["dropped_tip_sites"] = dropped;
    t["site_corrections"] = corrections;
    t["hidden_sites"] = hidden;
    t["snapped_vertices"] = snapped;
    t["removed_faces"] = removed;
    t["sliver_removals"] = slivers;
    t["skew_steps"] = skew_steps;
    t["repairs"] = repairs;
    t["builds"] = h.transition_builds;  // transition meshes built, refused ones included
    j["transition"] = t;
  }
  double total = 0;
  nlohmann::json t = nlohmann::json::object();
  for (const auto& [stage, s] : h.timings_s) {
    t[stage] = s;
    total += s;
  }
  t["total"] = total;
  j["timings_s"] = t;
  j["mesh_volume"] = total_volume(h.geometry);
  return j;
}

}  // namespace hm
