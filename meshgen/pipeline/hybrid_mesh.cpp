#include "hybrid_mesh.hpp"

#include <algorithm>
#include <chrono>
#include <exception>
#include <set>
#include <stdexcept>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

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
  q.q_o = stats_of(cell_min_of_faces(mesh, face_orthogonality(mesh, geo)), is_transition);
  q.q_p = stats_of(cell_max_of_faces(mesh, face_planarity(mesh, geo)), is_transition);
  return q;
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
  explicit StageTimer(std::vector<std::pair<std::string, double>>* out) : out_(out) {}
  void mark(const std::string& stage) {
    const auto now = std::chrono::steady_clock::now();
    out_->push_back({stage, std::chrono::duration<double>(now - last_).count()});
    last_ = now;
  }

 private:
  std::vector<std::pair<std::string, double>>* out_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

}  // namespace

namespace {
HybridMesh build_hybrid_mesh_as_given(const CaseSpec& cs, const PipelineOptions& opts);
}  // namespace

// end_caps: auto. Hemispherical caps reach a drainage radius beyond the end points; next to much
// coarser reservoir cells the transition may not be buildable there (docs/transition.md, known
// limits). Wells that did not ask for caps explicitly are then closed with flat ends, and the
// notes say so; an error with flat ends too is the case's own and is reported as such.
HybridMesh build_hybrid_mesh(const CaseSpec& cs, const PipelineOptions& opts) {
  std::vector<int> fallback;
  for (int w = 0; w < static_cast<int>(cs.wells.size()); ++w)
    if (cs.wells[w].end_caps == EndCaps::Hemisphere && cs.wells[w].end_caps_fallback) fallback.push_back(w);
  if (fallback.empty()) return build_hybrid_mesh_as_given(cs, opts);
  std::string why;
  try {
    return build_hybrid_mesh_as_given(cs, opts);
  } catch (const std::exception& e) {  // InputError (cavity) or a transition failure
    why = e.what();
    why = why.substr(0, why.find("; with hemispherical end caps"));  // the hint is what happens next
  }
  CaseSpec flat = cs;
  for (int w : fallback) flat.wells[w].end_caps = EndCaps::Flat;
  HybridMesh out = build_hybrid_mesh_as_given(flat, opts);
  std::string wells;
  for (int w : fallback) wells += (wells.empty() ? "" : ", ") + ("wells[" + std::to_string(w) + "]");
  out.notes.insert(out.notes.begin(), wells + ": closed with flat ends (end_caps: auto): the hemispherical end caps "
                                      "could not be meshed: " + why);
  return out;
}

namespace {

HybridMesh build_hybrid_mesh_as_given(const CaseSpec& cs, const PipelineOptions& opts) {
  HybridMesh out;
  StageTimer timer(&out.timings_s);

  out.grid = make_reservoir_grid(cs.reservoir);
  for (int w = 0; w < static_cast<int>(cs.wells.size()); ++w) {
    out.blocks.push_back(make_gabriel_well_block(cs, w));
    for (const std::string& n : out.blocks.back().notes) out.notes.push_back(n);
  }
  timer.mark("well_blocks");

  // Nodes first (reservoir lattice, then each block) so that the cavity can name them.
  MeshBuilder builder;
  const std::vector<int32_t> res_nodes = add_reservoir_nodes(out.grid, builder);
  std::vector<std::vector<int32_t>> well_nodes;
  for (const WellBlock& b : out.blocks) {
    well_nodes.push_back(add_well_block(b, builder));
  }
  std::vector<Vec3> coords(builder.n_nodes());
  for (int32_t i = 0; i < builder.n_nodes(); ++i) coords[i] = builder.node(i);

  // Cavities, then their transition meshes. A transition may refuse a cavity part (a
  // polygon that is not Delaunay admissible, or sites whose correction does not converge:
  // typically a large reservoir face close to a well) and name the reservoir cells whose
  // deactivation moves that part away; the cavities are then rebuilt with those cells
  // deactivated (a local dilation), a bounded number of times.
  std::vector<int32_t> extra_deactivated;
  std::vector<TransitionCells> transitions;
  const int32_t base = builder.n_nodes();
  constexpr int kMaxRetries = 5;
  std::string enlarged_for;  // the transition error that made the last enlargement
  // Hemispherical caps reach a drainage radius beyond the end points: next to much coarser
  // reservoir cells the site correction can fail there (docs/transition.md, known limits).
  bool any_caps = false;
  for (const WellSpec& w : cs.wells) any_caps = any_caps || w.end_caps == EndCaps::Hemisphere;
  const std::string caps_hint =
      any_caps ? "; with hemispherical end caps next to coarse reservoir cells, refining the reservoir beyond the "
                 "well ends or wells[i].end_caps: flat may help (docs/case-format.md)"
               : "";
  for (int attempt = 0;; ++attempt) {
    try {
      out.cavities = build_cavities(cs, out.grid, out.blocks, res_nodes, well_nodes, coords, extra_deactivated);
    } catch (const InputError& e) {
      if (enlarged_for.empty()) throw;
      // The cavity was enlarged for the transition (below) and can no longer be built: say why.
      throw InputError(std::string(e.what()) + " (the cavity was enlarged because " + enlarged_for + ")" + caps_hint);
    }
    for (size_t k = 0; k < out.cavities.cavities.size(); ++k) {
      const auto problems = check_cavity_manifold(out.cavities.cavities[k], coords);
      if (!problems.empty())
        throw std::runtime_error("cavity " + std::to_string(k) + ": boundary is not a closed 2-manifold: " + problems[0]);
    }
    if (!opts.build_transition) break;
    // Cavities are independent, so they are built (and optimised) concurrently; results are
    // used in cavity order, so the output does not depend on scheduling or on opts.threads.
    TransitionOptions topts;
    topts.optimize = opts.optimize && cs.transition.optimize;
    topts.g_remove = cs.transition.gamma[1];
    topts.g_expand = cs.transition.gamma[2];
    // At most opts.threads at once (0: every core); each result lands in its cavity's slot.
    const size_t n_cav = out.cavities.cavities.size();
    std::vector<TransitionCells> built(n_cav);
    std::vector<std::exception_ptr> failed(n_cav);
    tbb::task_arena arena(opts.threads > 0 ? opts.threads : tbb::task_arena::automatic);
    arena.execute([&] {
      tbb::parallel_for(size_t(0), n_cav, [&](size_t k) {
        try {
          built[k] = build_transition(out.cavities.cavities[k], coords, out.grid, out.blocks, base, topts);
        } catch (...) {
          failed[k] = std::current_exception();
        }
      });
    });
    transitions.clear();
    std::vector<int32_t> more;
    std::string first_error;
    for (size_t k = 0; k < n_cav; ++k) {
      try {
        if (failed[k]) std::rethrow_exception(failed[k]);
        transitions.push_back(std::move(built[k]));
      } catch (const TransitionError& e) {
        if (first_error.empty()) first_error = e.what();
        more.insert(more.end(), e.cells_to_deactivate.begin(), e.cells_to_deactivate.end());
      }
    }
    if (first_error.empty()) break;
    if (more.empty() || attempt == kMaxRetries)
      throw std::runtime_error(first_error +
                               (attempt > 0 ? " (after " + std::to_string(attempt) + " cavity enlargements)"
                                            : std::string()) +
                               caps_hint);
    enlarged_for = first_error;
    extra_deactivated.insert(extra_deactivated.end(), more.begin(), more.end());
    std::sort(extra_deactivated.begin(), extra_deactivated.end());
    extra_deactivated.erase(std::unique(extra_deactivated.begin(), extra_deactivated.end()), extra_deactivated.end());
    out.notes.push_back("cavity: " + std::to_string(more.size()) +
                        " reservoir cells deactivated so that the transition mesh can be built (" + first_error + ")");
  }
  for (const std::string& n : out.cavities.notes) out.notes.push_back(n);
  out.cavity_node_coords = coords;
  timer.mark(opts.build_transition ? "cavities_and_transition" : "cavities");

  add_reservoir_cells(out.grid, cs.reservoir, res_nodes, out.cavities.reservoir_active, builder);
  timer.mark("reservoir_cells");

  // Assemble the transition cells; free nodes are renumbered cavity by cavity.
  std::vector<int32_t> cell_cavity_list;
  std::vector<double> h_ref_list;
  for (size_t k = 0; k < transitions.size(); ++k) {
    TransitionCells& t = transitions[k];
    const int32_t first = builder.n_nodes();
    for (const Vec3& p : t.new_nodes) builder.add_node(p);
    for (size_t c = 0; c < t.cells.size(); ++c) {
      std::vector<CellFace> faces = t.cells[c];
      for (CellFace& f : faces)
        for (int32_t& v : f.nodes)
          if (v >= t.base_node_id) v = v - t.base_node_id + first;
      CellAttributes at;
      at.region = kTransition;
      at.fv_center = t.sites[c];
      const int rock_cell = reservoir_cell_at(cs.reservoir, at.fv_center);  // the model cell around its site
      at.perm = reservoir_permeability(cs.reservoir, rock_cell);
      at.porosity = reservoir_porosity(cs.reservoir, rock_cell);
      builder.add_cell(faces, at);
      cell_cavity_list.push_back(static_cast<int32_t>(k));
      h_ref_list.push_back(t.h_ref[c]);
    }
    out.transition_reports.push_back(t.report);
  }

  out.mesh = builder.finish(&out.build_report);
  const int nc = out.mesh.n_cells();
  out.cell_cavity.assign(nc, -1);
  out.cell_h_ref.assign(nc, 0.0);
  out.reservoir_cell_of.assign(nc, -1);
  for (int c = 0, t = 0; c < nc; ++c) {
    if (out.mesh.cell_region[c] == kTransition) {
      out.cell_cavity[c] = cell_cavity_list[t];
      out.cell_h_ref[c] = h_ref_list[t];
      ++t;
    }
    const auto& ijk = out.mesh.cell_ijk[c];
    if (out.mesh.cell_region[c] == kReservoir) out.reservoir_cell_of[c] = out.grid.cell_index(ijk[0], ijk[1], ijk[2]);
  }
  out.geometry = compute_geometry(out.mesh);
  timer.mark("assembly_geometry");
  if (opts.build_transition && !out.build_report.ok)
    throw std::runtime_error("assembly: the hybrid mesh is not conforming: " +
                             (out.build_report.problems.empty() ? std::string("?") : out.build_report.problems[0]) +
                             " (" + std::to_string(out.build_report.unmatched_faces) + " unmatched, " +
                             std::to_string(out.build_report.misoriented_faces) + " misoriented, " +
                             std::to_string(out.build_report.overused_faces) + " overused faces)");
  if (!opts.build_transition) return out;

  // Before/after figures of the transition cells, each cavity's cells on their own (the
  // cavity's polygons are their boundary faces): only the transition cells are measured.
  auto quality_of = [&](const TransitionCells& t) {
    const PolyMesh sub = transition_submesh(t, coords);
    return transition_quality(sub, compute_geometry(sub), t.h_ref);
  };
  for (const TransitionCells& t : transitions) {
    out.optimized = out.optimized || t.unoptimized != nullptr;
    add_quality(out.transition_before, quality_of(t.unoptimized ? *t.unoptimized : t));
    if (t.unoptimized) add_quality(out.transition_after, quality_of(t));
    const SiteOptimizeReport& o = t.report.optimization;
    SiteOptimizeReport& a = out.optimize_report;
    a.rounds = std::max(a.rounds, o.rounds);
    a.proposed += o.proposed, a.kept += o.kept, a.refused += o.refused, a.invalid += o.invalid;
  }
  timer.mark("transition_quality");
  return out;
}

}  // namespace

}  // namespace hm
