#include "transition_assembly.hpp"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "meshgen/core/progress.hpp"

namespace hm {

void build_transitions(const std::vector<int>& to_build, const std::vector<Cavity>& cavities,
                       const std::vector<Vec3>& coords, const ReservoirGrid& grid, const std::vector<WellBlock>& blocks,
                       int32_t base, const TransitionOptions& options, int threads,
                       std::vector<std::optional<TransitionOutcome>>& outcomes) {
  Progress progress(options.optimize ? "transition meshes + optimisation (cavities)" : "transition meshes (cavities)",
                    static_cast<int64_t>(to_build.size()));
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(size_t(0), to_build.size(), [&](size_t i) {
      const int k = to_build[i];
      outcomes[k] = try_build_transition(cavities[k], coords, grid, blocks, base, options);
      progress.advance();
    });
  });
}

std::optional<std::vector<TransitionCells>> all_transitions(std::vector<std::optional<TransitionOutcome>>& outcomes) {
  for (const auto& o : outcomes)
    if (!o->ok()) return std::nullopt;
  std::vector<TransitionCells> cells;
  for (auto& o : outcomes) cells.push_back(std::move(o->cells));
  return cells;
}

BuilderCapacity transition_capacity(const std::vector<TransitionCells>& transitions) {
  BuilderCapacity c;
  for (const TransitionCells& t : transitions)
    for (const auto& cell : t.cells) {
      ++c.cells;
      c.faces += cell.size();
      for (const CellFace& f : cell) c.face_nodes += f.nodes.size();
    }
  return c;
}

TransitionCellMaps add_transition_cells(const std::vector<TransitionCells>& transitions,
                                        const std::function<void(CellAttributes&)>& set_rock, MeshBuilder& builder,
                                        std::vector<TransitionReport>& reports) {
  TransitionCellMaps maps;
  for (size_t k = 0; k < transitions.size(); ++k) {
    const TransitionCells& t = transitions[k];
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
      set_rock(at);
      builder.add_cell(faces, at);
      maps.cavity.push_back(static_cast<int32_t>(k));
      maps.h_ref.push_back(t.h_ref[c]);
    }
    reports.push_back(t.report);
  }
  return maps;
}

void fill_cell_maps(HybridMesh& out, const TransitionCellMaps& maps) {
  const int nc = out.mesh.n_cells();
  out.cell_cavity.assign(nc, -1);
  out.cell_h_ref.assign(nc, 0.0);
  out.reservoir_cell_of.assign(nc, -1);
  for (int c = 0, t = 0; c < nc; ++c) {
    const auto& ijk = out.mesh.cell_ijk[c];
    if (out.mesh.cell_region[c] == kReservoir) out.reservoir_cell_of[c] = out.grid.cell_index(ijk[0], ijk[1], ijk[2]);
    if (out.mesh.cell_region[c] == kTransition) {
      out.cell_cavity[c] = maps.cavity[t];
      out.cell_h_ref[c] = maps.h_ref[t];
      ++t;
    }
  }
}

}  // namespace hm

namespace hm {

void summarize_transitions(HybridMesh& out, const std::vector<TransitionCells>& transitions,
                           const std::vector<Vec3>& coords) {
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
  out.transition_q_o_in_mesh = transition_orthogonality_in_mesh(out.mesh, out.geometry);
}

}  // namespace hm
