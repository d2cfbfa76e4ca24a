// The job for a true corner-point model (reservoir.grdecl that is not a box grid): the model's
// active cells as the mesh's reservoir cells (meshgen/grids/corner_point_grid.hpp), checked like
// every mesh. With wells (docs/corner-point.md): well blocks, cavities of model cells whose
// boundary faces are constrained triangles (meshgen/cavity/cavity_corner_point.hpp), and one
// transition per cavity with a polygon site and a mirror per triangle (no box site).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "fvcheck/lib/checks.hpp"
#include "hybrid_mesh.hpp"
#include "meshgen/cavity/cavity_corner_point.hpp"
#include "meshgen/grids/corner_point_grid.hpp"
#include "meshgen/grids/corner_point_multipliers.hpp"
#include "meshgen/pipeline/local_frame.hpp"
#include "meshgen/core/two_point.hpp"
#include "perforations.hpp"
#include "transition_assembly.hpp"

namespace hm {

namespace {

class Stages {
 public:
  Stages(HybridMesh& out, const PipelineOptions& opts) : out_(out), opts_(opts) {}
  void mark(const std::string& s) {
    const auto now = std::chrono::steady_clock::now();
    out_.timings_s.push_back({s, std::chrono::duration<double>(now - last_).count()});
    last_ = now;
    if (opts_.on_stage) opts_.on_stage(s);
  }

 private:
  HybridMesh& out_;
  const PipelineOptions& opts_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

std::vector<char> all_present(const CornerPointModel& m) { return std::vector<char>(m.actnum.size(), 1); }

// The model's transmissibility multipliers on the mesh's faces, with notes on what they reach.
void apply_model_multipliers(HybridMesh& out, const CornerPointModel& model, const CornerPointCellFaces* cells,
                             const std::vector<char>& active, const std::vector<Vec3>& coords) {
  FaceMultipliers fm = face_multipliers(out.mesh, model, cells, active, coords);
  if (fm.unmatched_walls > 0)
    throw MeshingError("assembly", {},
                       "assembly: " + std::to_string(fm.unmatched_walls) +
                           " faces between model cells and near-well cells are none of the cavities' triangles: the "
                           "model's transmissibility multipliers cannot be placed on them");
  out.mesh.face_trans_mult = std::move(fm.face);
  if (fm.model_faces + fm.wall_faces > 0)
    out.notes.push_back("reservoir: the model's transmissibility multipliers (MULTX..MULTZ-, FAULTS/MULTFLT) act on " +
                        std::to_string(fm.model_faces) + " faces between model cells and " + std::to_string(fm.wall_faces) +
                        " faces between model cells and near-well cells (docs/corner-point.md)");
  if (!model.edit_nnc.empty()) {
    const int64_t missed = static_cast<int64_t>(model.edit_nnc.size()) - fm.edit_nnc_pairs_on_faces;
    out.notes.push_back("reservoir: the model's EDITNNC names " + std::to_string(model.edit_nnc.size()) +
                        " cell pairs; it multiplies the " + std::to_string(fm.edit_nnc_faces) + " faces between " +
                        std::to_string(fm.edit_nnc_pairs_on_faces) + " of them" +
                        (missed > 0 ? "; " + std::to_string(missed) +
                                          " share no face in the mesh (cells that do not touch, or replaced by near-well "
                                          "cells), as OPM Flow finds no connection to edit"
                                    : std::string()) +
                        " (docs/corner-point.md, \"NNC and EDITNNC\")");
  }
  if (fm.unpinched_faces > 0)
    out.notes.push_back("reservoir: " + std::to_string(fm.unpinched_faces) +
                        " faces join cells of a column across layers of zero thickness; the model has no PINCH, so "
                        "they carry no flow (as in OPM Flow: docs/corner-point.md, \"Pinched-out layers\")");
  if (fm.pinch_faces > 0)
    out.notes.push_back("reservoir: " + std::to_string(fm.pinch_faces) +
                        " faces join cells of a column across layers of zero thickness, connected as PINCH asks "
                        "(MULTZ option " + std::string(model.pinch.multz_all ? "ALL" : "TOP") + ")");
  if (fm.inside_cavities > 0) {
    char range[96];
    std::snprintf(range, sizeof range, "%.6g to %.6g", fm.inside_min, fm.inside_max);
    out.notes.push_back("cavity: " + std::to_string(fm.inside_cavities) +
                        " model faces between cavity cells carry transmissibility multipliers (" + range +
                        ") that the near-well cells replacing those cells do not (docs/corner-point.md)");
  }
}

// The deck's NNCs as the mesh's connections without a face. A pair's cells are the mesh cells of the
// two model cells it names; in a refined model the two children, one of each, whose FV centres are
// nearest (the deck gives one transmissibility between two cells, not a distribution over children).
// A pair with a cell that is inactive or replaced by near-well cells has nothing to connect, as in OPM
// Flow's run of a deck whose cell is inactive.
void attach_deck_nncs(HybridMesh& out, const CornerPointModel& model) {
  if (model.nnc.empty()) return;
  PolyMesh& m = out.mesh;
  std::map<int64_t, std::vector<int32_t>> cells_of;  // cell of the model as read -> its mesh cells
  for (const CornerPointModel::Nnc& e : model.nnc) cells_of[e.a], cells_of[e.b];
  for (int c = 0; c < m.n_cells(); ++c)
    if (const int32_t natural = out.reservoir_cell_of[c]; natural >= 0)
      if (auto it = cells_of.find(cell_as_read(model, natural)); it != cells_of.end()) it->second.push_back(c);
  int64_t missing = 0, among_children = 0;
  for (const CornerPointModel::Nnc& e : model.nnc) {
    const std::vector<int32_t>&ca = cells_of[e.a], &cb = cells_of[e.b];
    if (ca.empty() || cb.empty()) {
      ++missing;
      continue;
    }
    std::array<int32_t, 2> pair{ca[0], cb[0]};
    double best = norm2(m.cell_fv_center[ca[0]] - m.cell_fv_center[cb[0]]);
    for (const int32_t x : ca)
      for (const int32_t y : cb)
        if (const double d = norm2(m.cell_fv_center[x] - m.cell_fv_center[y]); d < best) best = d, pair = {x, y};
    among_children += ca.size() > 1 || cb.size() > 1;
    m.nnc_cells.push_back(pair);
    m.nnc_trans.push_back(e.trans);
  }
  std::string note = "reservoir: the deck's NNC connects " + std::to_string(m.n_nncs()) + " of its " +
                     std::to_string(model.nnc.size()) + " cell pairs in the mesh, as connections without a face";
  if (among_children > 0)
    note += "; " + std::to_string(among_children) + " of them join the refined cells' children nearest each other";
  if (missing > 0)
    note += "; " + std::to_string(missing) + " name a cell that is inactive or replaced by near-well cells and connect nothing";
  out.notes.push_back(note + " (docs/corner-point.md, \"NNC and EDITNNC\")");
}

// OPM Flow's connection of the cells of a column above and below cells its MINPV processing removed
// (measured against flow 2022.10, docs/corner-point.md, "MINPV"): its corner-point halves from each
// cell's centre (mean of its 8 corners) to the centre of its own face toward the gap (the upper cell's
// bottom, the lower cell's top), both with the upper cell's bottom as the area vector, K_zz, harmonic;
// times the connection's multiplier (column_connection_multiplier). METRIC.
double minpv_transmissibility(const CornerPointModel& model, int64_t upper, int64_t lower) {
  auto mean = [](const std::array<Vec3, 8>& q, int first, int count) {
    Vec3 s{0, 0, 0};
    for (int i = first; i < first + count; ++i) s = s + q[i];
    return s / count;
  };
  const std::array<Vec3, 8> u = cell_corners(model, static_cast<size_t>(upper)), l = cell_corners(model, static_cast<size_t>(lower));
  // The vector area of the upper cell's bottom, corners 4, 5, 7, 6 in cyclic order.
  const Vec3 area = 0.5 * cross(u[7] - u[4], u[6] - u[5]);
  auto perm = [&](int64_t c) {
    const size_t i = static_cast<size_t>(c);
    return Vec3{model.permx[i], model.permy[i], model.permz[i]};
  };
  const double hu = opm_half_transmissibility(area, perm(upper), mean(u, 4, 4) - mean(u, 0, 8), 2);
  const double hl = opm_half_transmissibility(area, perm(lower), mean(l, 0, 4) - mean(l, 0, 8), 2);
  if (!(hu > 0) || !(hl > 0)) return 0.0;
  return kDarcyMetric / (1 / hu + 1 / hl) * column_connection_multiplier(model, upper, lower);
}

// The model's MINPV connections (CornerPointModel::minpv_connections) as connections without a face
// between the mesh's cells (faces the two cells may share where the removed cells have no thickness
// carry nothing: connection_multiplier). A refined model connects each child column's two children.
void attach_minpv_connections(HybridMesh& out, const CornerPointModel& model) {
  if (model.minpv_connections.empty()) return;
  PolyMesh& m = out.mesh;
  const int64_t nxy = int64_t(model.nx) * model.ny;
  std::map<int64_t, int32_t> mesh_cell;  // natural index of `model` -> mesh cell
  for (int c = 0; c < m.n_cells(); ++c)
    if (out.reservoir_cell_of[c] >= 0) mesh_cell[out.reservoir_cell_of[c]] = c;
  std::map<int64_t, std::vector<int64_t>> children;  // cell as read -> its cells in `model`
  for (const auto& [up, low] : model.minpv_connections) children[up];
  for (int64_t c = 0; c < static_cast<int64_t>(model.n_cells()); ++c)
    if (auto it = children.find(cell_as_read(model, c)); it != children.end()) it->second.push_back(c);
  const int64_t parent_nxy = model.parent_cell.empty() ? nxy : int64_t(model.parent_nx) * model.parent_ny;
  // Layers split at fault steps: the upper cell's lowest meshed child connects to the lower cell's
  // highest meshed child (children of zero thickness are not meshed).
  std::vector<int64_t> first_layer(static_cast<size_t>(model.parent_nz) + 1, 0);  // per layer as read
  for (int k = static_cast<int>(model.parent_layer.size()) - 1; k >= 0; --k) first_layer[model.parent_layer[k]] = k;
  if (!model.parent_layer.empty()) first_layer.back() = model.nz;
  auto meshed_child = [&](int64_t column, int64_t layer_as_read, bool lowest) -> int64_t {
    for (int64_t a = first_layer[layer_as_read + 1] - 1; a >= first_layer[layer_as_read]; --a) {
      const int64_t k = lowest ? a : first_layer[layer_as_read] + first_layer[layer_as_read + 1] - 1 - a;
      if (mesh_cell.count(column + k * nxy)) return column + k * nxy;
    }
    return -1;
  };
  int64_t faces = 0, missing = 0;
  for (const auto& [up, low] : model.minpv_connections)
    for (int64_t cu : children[up]) {
      int64_t cl = cu + (low / parent_nxy - up / parent_nxy) * nxy;
      if (!model.parent_layer.empty()) {
        if (cu / nxy != first_layer[up / parent_nxy]) continue;  // one connection per column
        const int64_t up_mesh = meshed_child(cu % nxy, up / parent_nxy, true), low_mesh = meshed_child(cu % nxy, low / parent_nxy, false);
        if (up_mesh < 0 || low_mesh < 0) {
          ++missing;
          continue;
        }
        cu = up_mesh, cl = low_mesh;
      }
      const auto iu = mesh_cell.find(cu), il = mesh_cell.find(cl);
      if (iu == mesh_cell.end() || il == mesh_cell.end()) {
        ++missing;
        continue;
      }
      bool share = false;
      for (const int32_t* f = m.cell_begin(iu->second); f != m.cell_end(iu->second) && !share; ++f)
        share = m.face_owner[*f] == il->second || m.face_neighbour[*f] == il->second;
      faces += share;
      m.nnc_cells.push_back({iu->second, il->second});
      m.nnc_trans.push_back(minpv_transmissibility(model, cu, cl));
    }
  out.notes.push_back("reservoir: MINPV: " + std::to_string(model.minpv_connections.size()) +
                      " pairs of cells connected across the removed cells, as connections without a face (" +
                      std::to_string(faces) + " of them between cells that also touch where the removed cells have no "
                      "thickness: those faces carry nothing)" +
                      (missing > 0 ? ", " + std::to_string(missing) + " with a cell replaced by near-well cells" : std::string()) +
                      " (docs/corner-point.md, \"MINPV\")");
}

std::string well_names(const CaseSpec& cs, const std::vector<int>& wells) {
  std::string s;
  for (int w : wells) s += (s.empty() ? "" : ", ") + ("wells[" + std::to_string(w) + "] (" + cs.wells[w].name + ")");
  return s;
}

// Wells in the model: blocks, cavities (enlarged where a transition asks, at most
// kMaxEnlargements times), transitions; then the cells are added to the builder that holds the
// nodes (the radial cells' rock needs the cavities' model cells).
HybridMesh build_corner_point_wells(const CaseSpec& input, const PipelineOptions& opts) {
  const CornerPointModel& model = *input.reservoir.corner_point;
  CaseSpec cs = input;
  HybridMesh out;
  out.notes = cs.notes;
  Stages stage(out, opts);
  out.grid = make_reservoir_grid(cs.reservoir);  // index arithmetic only (nx, ny, nz)
  const int nw = static_cast<int>(cs.wells.size());
  for (int w = 0; w < nw; ++w) {
    WellSpec& ws = cs.wells[w];
    try {
      out.blocks.push_back(make_gabriel_well_block(cs, w));
    } catch (const InputError& e) {
      if (!(ws.end_caps == EndCaps::Hemisphere && ws.end_caps_fallback)) throw;
      ws.end_caps = EndCaps::Flat;
      out.notes.push_back("wells[" + std::to_string(w) + "]: closed with flat ends (end_caps: auto): " + e.what());
      out.blocks.push_back(make_gabriel_well_block(cs, w));
    }
  }
  stage.mark("well_blocks");

  // Nodes: the model's, then each block's.
  MeshBuilder builder;
  const CornerPointCellFaces faces = corner_point_cell_faces(model, all_present(model), builder);
  std::vector<std::vector<int32_t>> well_nodes;
  for (const WellBlock& blk : out.blocks) well_nodes.push_back(add_well_block_nodes(blk, builder));
  std::vector<Vec3> coords(builder.n_nodes());
  for (int32_t i = 0; i < builder.n_nodes(); ++i) coords[i] = builder.node(i);
  const int32_t base = builder.n_nodes();

  TransitionOptions topts;
  topts.optimize = opts.optimize && cs.transition.optimize;
  topts.g_remove = cs.transition.gamma[1];
  topts.g_expand = cs.transition.gamma[2];
  topts.written_origin = opts.written_origin;
  constexpr int kMaxEnlargements = 5;
  std::vector<int32_t> extra;
  std::string asked_by;  // the latest refusal that enlarged a cavity
  std::vector<TransitionCells> transitions;
  // Transitions of a round's cavities are built concurrently (at most opts.threads); a cavity that
  // an enlargement left as it was (same wells, cells and faces) keeps the transition it had. Every
  // refusal of a round enlarges its cavity at once; results are taken in cavity order, so the mesh
  // does not depend on scheduling or on opts.threads.
  struct Built {
    std::vector<int> wells;
    std::vector<int32_t> deactivated;
    size_t faces = 0;
    TransitionCells cells;
  };
  std::vector<Built> cache;
  for (int round = 0;; ++round) {
    try {
      out.cavities = build_corner_point_cavities(cs, model, faces, out.blocks, well_nodes, coords, extra);
    } catch (const InputError& e) {
      if (extra.empty()) throw;
      throw MeshingError("transition", {},
                         asked_by + "; the cavity enlarged for it cannot be built: " + e.what());
    }
    const int nk = static_cast<int>(out.cavities.cavities.size());
    for (int k = 0; k < nk; ++k) {
      const auto problems = check_cavity_manifold(out.cavities.cavities[k], coords);
      if (!problems.empty())
        throw MeshingError("cavity", out.cavities.cavities[k].wells,
                           "cavity " + std::to_string(k) + " of " + well_names(cs, out.cavities.cavities[k].wells) +
                               " in the corner-point model: boundary is not a closed 2-manifold: " + problems[0]);
    }
    if (!opts.build_transition) break;
    std::vector<std::optional<TransitionOutcome>> outcomes(nk);
    std::vector<int> to_build;
    for (int k = 0; k < nk; ++k) {
      const Cavity& cav = out.cavities.cavities[k];
      for (Built& b : cache)
        if (!b.wells.empty() && b.wells == cav.wells && b.deactivated == cav.deactivated_cells && b.faces == cav.faces.size()) {
          outcomes[k] = TransitionOutcome{std::move(b.cells), std::nullopt};
          b.wells.clear();  // used
          break;
        }
      if (!outcomes[k]) to_build.push_back(k), ++out.transition_builds;
    }
    build_transitions(to_build, out.cavities.cavities, coords, out.grid, out.blocks, base, topts, opts.threads, outcomes);
    // A face toward a model cell is judged by the self-check from the site to its flux point: one
    // that would fail it moves that wall away now, like the transition's own refusals.
    for (int k : to_build)
      if (outcomes[k]->ok())
        if (auto r = model_wall_orthogonality_refusal(outcomes[k]->cells, out.cavities.cavities[k], coords,
                                                      CheckOptions{}.min_orthogonality_deg))
          outcomes[k] = TransitionOutcome{{}, std::move(r)};
    if (auto all = all_transitions(outcomes)) {
      transitions = std::move(*all);
      break;
    }
    cache.clear();
    for (int k = 0; k < nk; ++k) {
      const Cavity& cav = out.cavities.cavities[k];
      if (outcomes[k]->ok()) {
        cache.push_back({cav.wells, cav.deactivated_cells, cav.faces.size(), std::move(outcomes[k]->cells)});
        continue;
      }
      const TransitionRefusal& r = *outcomes[k]->refusal;
      if (round >= kMaxEnlargements || r.cells_to_deactivate.empty())
        throw MeshingError("transition", cav.wells,
                           "transition of the cavity of " + well_names(cs, cav.wells) + " in the corner-point model: " +
                               r.reason + (round > 0 ? " (after " + std::to_string(round) + " cavity enlargements)" : "") +
                               " (docs/corner-point.md)");
      extra.insert(extra.end(), r.cells_to_deactivate.begin(), r.cells_to_deactivate.end());
      asked_by = r.reason;
      out.notes.push_back("cavity: " + std::to_string(r.cells_to_deactivate.size()) +
                          " model cells deactivated so that the transition of " + well_names(cs, cav.wells) +
                          " can be built (" + r.reason + ")");
    }
  }
  if (!model.parent_cell.empty())
    out.notes.push_back("reservoir: the model's columns near the wells are refined (reservoir.near_well_cell_size): " +
                        std::to_string(model.parent_nx) + " x " + std::to_string(model.parent_ny) + " -> " +
                        std::to_string(model.nx) + " x " + std::to_string(model.ny) + " columns, " +
                        std::to_string(model.nz) + " layers (docs/corner-point.md)");
  for (const WellBlock& b : out.blocks)
    for (const std::string& n : b.notes) out.notes.push_back(n);
  for (const std::string& n : out.cavities.notes) out.notes.push_back(n);
  out.cavity_node_coords = coords;
  stage.mark(opts.build_transition ? "cavities_and_transition" : "cavities");

  // Rock of the near-well cells: the model cell their FV centre lies in (the cavities' cells).
  std::vector<int32_t> dead;
  for (const Cavity& cav : out.cavities.cavities) dead.insert(dead.end(), cav.deactivated_cells.begin(), cav.deactivated_cells.end());
  std::sort(dead.begin(), dead.end());
  const CornerPointLocator rock_of(model, faces, dead, coords);
  auto set_rock = [&](CellAttributes& at) {
    assign_reservoir_rock(cs.reservoir, rock_of.cell_at_or_nearest(at.fv_center), at);
  };
  for (WellBlock& b : out.blocks)
    for (CellAttributes& at : b.cell_attrs) set_rock(at);

  for (size_t w = 0; w < out.blocks.size(); ++w) add_well_block_cells(out.blocks[w], well_nodes[w], builder);
  add_corner_point_cells(model, faces, cs.reservoir, out.cavities.reservoir_active, builder,
                         transition_capacity(transitions));
  stage.mark("reservoir_cells");
  const TransitionCellMaps maps = add_transition_cells(transitions, set_rock, builder, out.transition_reports);
  out.mesh = builder.finish(&out.build_report);
  fill_cell_maps(out, maps);
  if (out.build_report.ok) apply_model_multipliers(out, model, &faces, out.cavities.reservoir_active, coords);
  attach_deck_nncs(out, model);
  attach_minpv_connections(out, model);
  round_to_written_frame(out.mesh, opts.written_origin);
  out.geometry = compute_geometry(out.mesh);
  stage.mark("assembly_geometry");
  std::vector<int> all_wells(nw);
  for (int w = 0; w < nw; ++w) all_wells[w] = w;
  if (opts.build_transition && !out.build_report.ok)
    throw MeshingError("assembly", all_wells,
                       "assembly: the hybrid mesh in the corner-point model is not conforming: " +
                           (out.build_report.problems.empty() ? std::string("?") : out.build_report.problems[0]));
  close_unperforated_wellbore(out.mesh, out.geometry, cs);
  if (!opts.build_transition) return out;
  summarize_transitions(out, transitions, coords);
  std::vector<std::vector<int>> cavity_wells;
  for (const Cavity& c : out.cavities.cavities) cavity_wells.push_back(c.wells);
  out.mesh.reservoir_cells_are_model = cs.reservoir.corner_point != nullptr;
  out.self_check = self_check(out.mesh, out.geometry, out.build_report, out.cell_cavity, cavity_wells, cs);
  stage.mark("self_check");
  if (!out.self_check.ok()) throw MeshingError("self-check", out.self_check.wells, out.self_check.message);
  return out;
}

}  // namespace

HybridMesh build_corner_point_mesh(const CaseSpec& cs, const PipelineOptions& opts) {
  const CornerPointModel& model = *cs.reservoir.corner_point;
  if (!cs.wells.empty()) return build_corner_point_wells(cs, opts);
  HybridMesh out;
  out.notes = cs.notes;  // what reading the case found
  Stages stage(out, opts);
  out.grid = make_reservoir_grid(cs.reservoir);  // index arithmetic only (nx, ny, nz)
  MeshBuilder builder;
  const CornerPointCells cells = add_corner_point_cells(model, cs.reservoir, all_present(model), builder);
  out.mesh = builder.finish(&out.build_report);
  stage.mark("reservoir_cells");
  fill_cell_maps(out, TransitionCellMaps{});
  if (out.build_report.ok) apply_model_multipliers(out, model, nullptr, all_present(model), {});
  attach_deck_nncs(out, model);
  attach_minpv_connections(out, model);
  round_to_written_frame(out.mesh, opts.written_origin);
  out.geometry = compute_geometry(out.mesh);
  stage.mark("assembly_geometry");
  if (cells.zero_volume_cells > 0)
    out.notes.push_back("reservoir: " + std::to_string(cells.zero_volume_cells) +
                        " active cells of zero thickness on all their pillars are not meshed (OPM Flow drops them: pore "
                        "volume 0)");
  out.notes.push_back("reservoir: corner-point model meshed as its " + std::to_string(out.mesh.n_cells()) + " cells (" +
                      std::to_string(cells.fault_faces) + " fault faces, " + std::to_string(cells.crossing_nodes) +
                      " edge crossings on faults)");
  if (!out.build_report.ok)
    throw MeshingError("assembly", {},
                       "assembly: the corner-point cells do not conform: " +
                           (out.build_report.problems.empty() ? std::string("?") : out.build_report.problems[0]));
  if (!opts.build_transition) return out;
  out.mesh.reservoir_cells_are_model = cs.reservoir.corner_point != nullptr;
  out.self_check = self_check(out.mesh, out.geometry, out.build_report, out.cell_cavity, {}, cs);
  stage.mark("self_check");
  if (!out.self_check.ok()) throw MeshingError("self-check", {}, out.self_check.message);
  return out;
}

}  // namespace hm
