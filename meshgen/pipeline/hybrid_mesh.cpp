#include "hybrid_mesh.hpp"

#include <algorithm>
#include <chrono>
#include <optional>
#include <set>
#include <stdexcept>

#include "meshgen/core/progress.hpp"
#include "meshgen/pipeline/local_frame.hpp"
#include "perforations.hpp"
#include "transition_assembly.hpp"

namespace hm {

TransitionQuality transition_quality(const PolyMesh& mesh, const MeshGeometry& geo, const std::vector<double>& h_ref) {
  TransitionQuality q;
  std::vector<bool> is_transition(mesh.n_cells());
  std::set<int32_t> faces, vertices;
  for (int c = 0; c < mesh.n_cells(); ++c) {
    is_transition[c] = mesh.cell_region[c] == kTransition;
    if (!is_transition[c]) continue;
    ++q.cells;
    for (const int32_t* f = mesh.cell_begin(c); f != mesh.cell_end(c); ++f) {
      faces.insert(*f);
      vertices.insert(mesh.face_begin(*f), mesh.face_end(*f));
    }
  }
  q.vertices = static_cast<int>(vertices.size());
  q.faces = static_cast<int>(faces.size());
  q.q_s = stats_of(cell_shape_quality(mesh, h_ref), is_transition);
  // The paper's Table 2 measure, kept comparable: on a cavity's own submesh its constrained polygons
  // are boundary faces, measured from the site to their centroid (their flux point is the site's
  // foot, so the checked measure would be 90 by construction there).
  q.q_o = stats_of(cell_min_of_faces(mesh, face_orthogonality(mesh, geo, BoundaryPoint::Centroid)), is_transition);
  q.q_p = stats_of(cell_max_of_faces(mesh, face_planarity(mesh, geo)), is_transition);
  return q;
}

Stats transition_orthogonality_in_mesh(const PolyMesh& mesh, const MeshGeometry& geo) {
  std::vector<double> q_o(mesh.n_cells(), 90.0);
  std::vector<bool> is_transition(mesh.n_cells());
  for (int c = 0; c < mesh.n_cells(); ++c) {
    is_transition[c] = mesh.cell_region[c] == kTransition;
    if (!is_transition[c]) continue;
    for (const int32_t* f = mesh.cell_begin(c); f != mesh.cell_end(c); ++f)
      q_o[c] = std::min(q_o[c], face_orthogonality_of(mesh, geo, *f, boundary_flux_point(mesh, geo, *f)));
  }
  return stats_of(q_o, is_transition);
}

namespace {

Stats merged(const Stats& a, const Stats& b) {
  if (a.count == 0) return b;
  if (b.count == 0) return a;
  Stats s;
  s.count = a.count + b.count;
  s.min = std::min(a.min, b.min);
  s.max = std::max(a.max, b.max);
  s.mean = (a.mean * static_cast<double>(a.count) + b.mean * static_cast<double>(b.count)) / static_cast<double>(s.count);
  return s;
}

}  // namespace

void add_quality(TransitionQuality& total, const TransitionQuality& q) {
  total.vertices += q.vertices;
  total.faces += q.faces;
  total.cells += q.cells;
  total.q_s = merged(total.q_s, q.q_s);
  total.q_o = merged(total.q_o, q.q_o);
  total.q_p = merged(total.q_p, q.q_p);
}

namespace {

class StageTimer {
 public:
  StageTimer(std::vector<std::pair<std::string, double>>* out, const PipelineOptions& opts) : out_(out), opts_(opts) {}
  void mark(const std::string& stage) {
    const auto now = std::chrono::steady_clock::now();
    out_->push_back({stage, std::chrono::duration<double>(now - last_).count()});
    if (opts_.on_stage) opts_.on_stage(stage);
    last_ = std::chrono::steady_clock::now();
  }

 private:
  std::vector<std::pair<std::string, double>>* out_;
  const PipelineOptions& opts_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

}  // namespace

namespace {

// "wells[0] (P1), wells[2] (P2)"
std::string well_list(const CaseSpec& cs, const std::vector<int>& wells) {
  std::string s;
  for (int w : wells) s += (s.empty() ? "" : ", ") + ("wells[" + std::to_string(w) + "] (" + cs.wells[w].name + ")");
  return s.empty() ? std::string("no well") : s;
}

bool share_a_well(const std::vector<int>& a, const std::vector<int>& b) {
  for (int w : a)
    if (std::find(b.begin(), b.end(), w) != b.end()) return true;
  return false;
}

// end_caps: auto, per well, before meshing: hemispherical caps if the capped block can be built
// (building the Gabriel block is the caps' feasibility test; its InputError is the refusal),
// flat ends otherwise.
WellBlock block_with_feasible_caps(CaseSpec& cs, int w, std::vector<std::string>& flat_because) {
  WellSpec& ws = cs.wells[w];
  if (ws.end_caps == EndCaps::Hemisphere && ws.end_caps_fallback) {
    try {
      return make_gabriel_well_block(cs, w);
    } catch (const InputError& e) {
      ws.end_caps = EndCaps::Flat;
      flat_because[w] = e.what();
    }
  }
  return make_gabriel_well_block(cs, w);
}

// Reservoir cells deactivated so that one cavity's transition can be built, and why.
struct Enlargement {
  std::vector<int> wells;  ///< the wells of the cavity that asked
  std::vector<int32_t> cells;
  std::string reason;
  int round = 0;
};

// A transition mesh kept for the next round: valid while its cavity is the same (same wells,
// same caps, same deactivated cells, hence the same constrained polygons).
struct CachedTransition {
  std::vector<int> wells;
  std::vector<EndCaps> caps;
  std::vector<int32_t> deactivated;
  size_t faces = 0;
  std::vector<int32_t> well_offset;  ///< builder id of each block's first node when it was built
  TransitionCells cells;
};

// Builder ids of constrained nodes: the reservoir's first, then block by block; free nodes
// from base_node_id on. Moves a cached transition's ids to this round's layout.
void renumber(TransitionCells& t, int32_t reservoir_nodes, const std::vector<int32_t>& old_offset,
              const std::vector<int32_t>& new_offset, int32_t new_base) {
  auto map = [&](int32_t v) {
    if (v >= t.base_node_id) return v - t.base_node_id + new_base;
    if (v < reservoir_nodes) return v;
    const size_t w = std::upper_bound(old_offset.begin(), old_offset.end(), v) - old_offset.begin() - 1;
    return v - old_offset[w] + new_offset[w];
  };
  for (auto& cell : t.cells)
    for (CellFace& f : cell)
      for (int32_t& v : f.nodes) v = map(v);
  if (t.unoptimized) {  // the raw diagram kept for the before/after figures: same node layout
    auto raw = std::make_shared<TransitionCells>(*t.unoptimized);
    renumber(*raw, reservoir_nodes, old_offset, new_offset, new_base);
    t.unoptimized = std::move(raw);
  }
  t.base_node_id = new_base;
}

std::string caps_hint(const CaseSpec& cs, const std::vector<int>& wells) {
  for (int w : wells)
    if (cs.wells[w].end_caps == EndCaps::Hemisphere)
      return "; with hemispherical end caps next to coarse reservoir cells, refining the reservoir beyond the "
             "well ends or wells[i].end_caps: flat may help (docs/case-format.md)";
  return "; refining the reservoir cells around the well, a smaller drainage_radius or moving the well away from "
         "coarse cells may help (docs/transition.md, known limits)";
}

}  // namespace

// The job: well blocks (end caps decided per well), cavities, one transition per cavity. A
// transition that refuses its cavity says why and which reservoir cells to deactivate; only that
// cavity's transition is built again, with those cells deactivated (a local dilation), at most
// kMaxEnlargements times; then its auto-capped wells get flat ends and only its transition is
// built again. The other cavities keep their transitions.
HybridMesh build_hybrid_mesh_euclidean(const CaseSpec& input, const PipelineOptions& opts) {
  HybridMesh out;
  out.notes = input.notes;  // what reading the case changed
  StageTimer timer(&out.timings_s, opts);
  CaseSpec cs = input;  // end caps as meshed
  const int nw = static_cast<int>(cs.wells.size());

  out.grid = make_reservoir_grid(cs.reservoir);
  std::vector<std::string> flat_because(nw);
  for (int w = 0; w < nw; ++w) out.blocks.push_back(block_with_feasible_caps(cs, w, flat_because));
  timer.mark("well_blocks");

  constexpr int kMaxEnlargements = 5;  // per cavity, and as many again with flat ends
  std::vector<Enlargement> enlargements;
  std::vector<CachedTransition> cache;
  std::vector<TransitionCells> transitions;
  std::vector<int32_t> res_nodes;
  MeshBuilder builder;
  std::vector<Vec3> coords;
  auto flatten = [&](const std::vector<int>& wells, const std::string& why) {
    bool any = false;
    for (int w : wells) {
      WellSpec& ws = cs.wells[w];
      if (!(ws.end_caps == EndCaps::Hemisphere && ws.end_caps_fallback)) continue;
      ws.end_caps = EndCaps::Flat;
      flat_because[w] = why;
      out.blocks[w] = make_gabriel_well_block(cs, w);
      any = true;
    }
    if (any)
      enlargements.erase(std::remove_if(enlargements.begin(), enlargements.end(),
                                        [&](const Enlargement& e) { return share_a_well(e.wells, wells); }),
                         enlargements.end());
    return any;
  };
  for (int round = 0;; ++round) {
    // Nodes first (reservoir lattice, then each block) so that the cavity can name them.
    builder = MeshBuilder{};
    res_nodes = add_reservoir_nodes(out.grid, builder);
    std::vector<std::vector<int32_t>> well_nodes;
    std::vector<int32_t> well_offset;
    for (const WellBlock& b : out.blocks) {
      well_offset.push_back(builder.n_nodes());
      well_nodes.push_back(add_well_block(b, builder));
    }
    coords.resize(builder.n_nodes());
    for (int32_t i = 0; i < builder.n_nodes(); ++i) coords[i] = builder.node(i);
    const int32_t base = builder.n_nodes();

    std::vector<int32_t> extra;
    for (const Enlargement& e : enlargements) extra.insert(extra.end(), e.cells.begin(), e.cells.end());
    std::sort(extra.begin(), extra.end());
    extra.erase(std::unique(extra.begin(), extra.end()), extra.end());
    try {
      out.cavities = build_cavities(cs, out.grid, out.blocks, res_nodes, well_nodes, coords, extra);
    } catch (const InputError& e) {
      // Without enlargements the cavity is the input's (dilation, wells too close): exit 2.
      if (enlargements.empty()) throw;
      // Else the latest enlargements ran into it (e.g. the reservoir boundary): those cavities
      // get flat ends where they may, or the transition's refusal stands (not the input's).
      // Which of them: those without which the cavities can be built (all, if none alone is).
      const int last = enlargements.back().round;
      std::vector<Enlargement> latest, culprits;
      for (const Enlargement& en : enlargements)
        if (en.round == last) latest.push_back(en);
      for (size_t i = 0; i < latest.size() && latest.size() > 1; ++i) {
        std::vector<int32_t> others;
        for (const Enlargement& en : enlargements)
          if (!(en.round == last && en.wells == latest[i].wells)) others.insert(others.end(), en.cells.begin(), en.cells.end());
        try {
          build_cavities(cs, out.grid, out.blocks, res_nodes, well_nodes, coords, others);
          culprits.push_back(latest[i]);
        } catch (const InputError&) {
        }
      }
      if (culprits.empty()) culprits = latest;
      for (const Enlargement& en : culprits) {
        const std::string why = en.reason + " (the cavity was enlarged for it: " + e.what() + ")";
        if (!flatten(en.wells, why))
          throw MeshingError("transition", en.wells,
                             "transition of the cavity of " + well_list(cs, en.wells) + ": " + why +
                                 caps_hint(cs, en.wells));
      }
      continue;
    }
    const int nk = static_cast<int>(out.cavities.cavities.size());
    for (int k = 0; k < nk; ++k) {
      const auto problems = check_cavity_manifold(out.cavities.cavities[k], coords);
      if (!problems.empty())
        throw MeshingError("cavity", out.cavities.cavities[k].wells,
                           "cavity " + std::to_string(k) + " of " + well_list(cs, out.cavities.cavities[k].wells) +
                               ": boundary is not a closed 2-manifold: " + problems[0]);
    }
    if (!opts.build_transition) break;

    // Transitions (optimised) of the cavities not met before, concurrently, at most opts.threads
    // at once (0: every core); each result lands in its cavity's slot, so the output does not
    // depend on scheduling or on opts.threads. The others are reused.
    TransitionOptions topts;
    topts.optimize = opts.optimize && cs.transition.optimize;
    topts.g_remove = cs.transition.gamma[1];
    topts.g_expand = cs.transition.gamma[2];
    topts.written_origin = opts.written_origin;
    topts.frame = opts.frame;
    topts.frame_written_origin = opts.frame_written_origin;
    std::vector<CachedTransition> keys(nk);
    std::vector<std::optional<TransitionOutcome>> outcomes(nk);
    std::vector<int> to_build;
    for (int k = 0; k < nk; ++k) {
      const Cavity& cav = out.cavities.cavities[k];
      CachedTransition& key = keys[k];
      key.wells = cav.wells;
      for (int w : cav.wells) key.caps.push_back(cs.wells[w].end_caps);
      key.deactivated = cav.deactivated_cells;
      key.faces = cav.faces.size();
      key.well_offset = well_offset;
      for (CachedTransition& c : cache)
        if (!c.wells.empty() && c.wells == key.wells && c.caps == key.caps && c.deactivated == key.deactivated &&
            c.faces == key.faces) {
          renumber(c.cells, static_cast<int32_t>(res_nodes.size()), c.well_offset, well_offset, base);
          outcomes[k] = TransitionOutcome{std::move(c.cells), std::nullopt};
          c.wells.clear();  // used
          break;
        }
      if (!outcomes[k]) {
        ++out.transition_builds;
        to_build.push_back(k);
      }
    }
    build_transitions(to_build, out.cavities.cavities, coords, out.grid, out.blocks, base, topts, opts.threads, outcomes);
    if (auto all = all_transitions(outcomes)) {
      transitions = std::move(*all);
      break;
    }
    cache.clear();
    for (int k = 0; k < nk; ++k)
      if (outcomes[k]->ok()) {
        keys[k].cells = std::move(outcomes[k]->cells);
        cache.push_back(std::move(keys[k]));
      }
    for (int k = 0; k < nk; ++k) {
      if (outcomes[k]->ok()) continue;
      const TransitionRefusal& r = *outcomes[k]->refusal;
      const std::vector<int>& wells = out.cavities.cavities[k].wells;
      int done = 0;
      for (const Enlargement& e : enlargements) done += share_a_well(e.wells, wells);
      if (!r.cells_to_deactivate.empty() && done < kMaxEnlargements) {
        enlargements.push_back({wells, r.cells_to_deactivate, r.reason, round});
        continue;
      }
      if (flatten(wells, r.reason + (done > 0 ? " (after " + std::to_string(done) + " cavity enlargements)" : "")))
        continue;
      throw MeshingError("transition", wells,
                         "transition of the cavity of " + well_list(cs, wells) + ": " + r.reason +
                             (done > 0 ? " (after " + std::to_string(done) + " cavity enlargements)" : std::string()) +
                             caps_hint(cs, wells));
    }
  }
  for (int w = 0; w < nw; ++w)
    if (!flat_because[w].empty())
      out.notes.push_back("wells[" + std::to_string(w) + "]: closed with flat ends (end_caps: auto): the hemispherical "
                          "end caps could not be meshed: " + flat_because[w]);
  for (const WellBlock& b : out.blocks)
    for (const std::string& n : b.notes) out.notes.push_back(n);
  for (const Enlargement& e : enlargements)
    out.notes.push_back("cavity: " + std::to_string(e.cells.size()) + " reservoir cells deactivated so that the " +
                        "transition mesh of " + well_list(cs, e.wells) + " can be built (" + e.reason + ")");
  for (const std::string& n : out.cavities.notes) out.notes.push_back(n);
  out.cavity_node_coords = coords;
  timer.mark(opts.build_transition ? "cavities_and_transition" : "cavities");

  {
    Progress progress("reservoir cells");
    add_reservoir_cells(out.grid, cs.reservoir, res_nodes, out.cavities.reservoir_active, builder,
                        transition_capacity(transitions));
  }
  timer.mark("reservoir_cells");

  std::optional<Progress> assembly_progress(std::in_place, "assembly + geometry");
  // Assemble the transition cells; rock: the reservoir cell around each site.
  const TransitionCellMaps maps = add_transition_cells(
      transitions,
      [&](CellAttributes& at) {
        assign_reservoir_rock(cs.reservoir, reservoir_cell_at(cs.reservoir, at.fv_center), at);
      },
      builder, out.transition_reports);
  out.mesh = builder.finish(&out.build_report);
  fill_cell_maps(out, maps);
  round_to_written_frame(out.mesh, opts.written_origin);
  out.geometry = compute_geometry(out.mesh);
  assembly_progress.reset();
  timer.mark("assembly_geometry");
  std::vector<int> all_wells(nw);
  for (int w = 0; w < nw; ++w) all_wells[w] = w;
  if (opts.build_transition && !out.build_report.ok)
    throw MeshingError("assembly", all_wells, "assembly: the hybrid mesh is not conforming: " +
                             (out.build_report.problems.empty() ? std::string("?") : out.build_report.problems[0]) +
                             " (" + std::to_string(out.build_report.unmatched_faces) + " unmatched, " +
                             std::to_string(out.build_report.misoriented_faces) + " misoriented, " +
                             std::to_string(out.build_report.overused_faces) + " overused faces)");
  close_unperforated_wellbore(out.mesh, out.geometry, cs);
  if (!opts.build_transition) return out;

  std::optional<Progress> quality_progress(std::in_place, "transition quality before/after");
  summarize_transitions(out, transitions, coords);
  quality_progress.reset();
  timer.mark("transition_quality");
  std::vector<std::vector<int>> cavity_wells;
  for (const Cavity& c : out.cavities.cavities) cavity_wells.push_back(c.wells);
  out.mesh.reservoir_cells_are_model = cs.reservoir.corner_point != nullptr;
  out.self_check = self_check(out.mesh, out.geometry, out.build_report, out.cell_cavity, cavity_wells, cs);
  timer.mark("self_check");
  if (!out.self_check.ok())
    throw MeshingError("self-check", out.self_check.wells,
                       out.self_check.message + (out.optimized ? " (after optimisation)" : " (no optimisation)"));
  return out;
}

}  // namespace hm
