// The job for a true corner-point model (reservoir.grdecl that is not a box grid): the model's
// active cells as the mesh's reservoir cells (meshgen/grids/corner_point_grid.hpp), checked like
// every mesh. Near-well meshing in such a model is not built yet: a case with wells is refused.
#include <chrono>
#include <string>

#include "hybrid_mesh.hpp"
#include "meshgen/grids/corner_point_grid.hpp"

namespace hm {

HybridMesh build_corner_point_mesh(const CaseSpec& cs, const PipelineOptions& opts) {
  const CornerPointModel& model = *cs.reservoir.corner_point;
  if (!cs.wells.empty())
    throw InputError("wells: " + cs.reservoir.grdecl +
                     " is a corner-point model (sloping layers, inclined pillars, faults or inactive cells): its cells "
                     "are meshed, but wells in a corner-point model are not meshed yet (docs/case-format.md, grdecl); "
                     "give the case without wells, or a model whose cells are axis-aligned boxes");
  HybridMesh out;
  auto last = std::chrono::steady_clock::now();
  const auto stage = [&](const std::string& s) {
    const auto now = std::chrono::steady_clock::now();
    out.timings_s.push_back({s, std::chrono::duration<double>(now - last).count()});
    last = now;
    if (opts.on_stage) opts.on_stage(s);
  };
  out.grid = make_reservoir_grid(cs.reservoir);  // index arithmetic only (nx, ny, nz)
  MeshBuilder builder;
  const CornerPointCells cells =
      add_corner_point_cells(model, cs.reservoir, std::vector<char>(model.actnum.size(), 1), builder);
  out.mesh = builder.finish(&out.build_report);
  stage("reservoir_cells");
  const int nc = out.mesh.n_cells();
  out.cell_cavity.assign(nc, -1);
  out.cell_h_ref.assign(nc, 0.0);
  out.reservoir_cell_of.assign(nc, -1);
  for (int c = 0; c < nc; ++c) {
    const auto& ijk = out.mesh.cell_ijk[c];
    out.reservoir_cell_of[c] = out.grid.cell_index(ijk[0], ijk[1], ijk[2]);
  }
  out.geometry = compute_geometry(out.mesh);
  stage("assembly_geometry");
  if (cells.zero_volume_cells > 0)
    out.notes.push_back("reservoir: " + std::to_string(cells.zero_volume_cells) +
                        " active cells of zero thickness on all their pillars are not meshed (OPM Flow drops them: pore "
                        "volume 0)");
  out.notes.push_back("reservoir: corner-point model meshed as its " + std::to_string(nc) + " cells (" +
                      std::to_string(cells.fault_faces) + " fault faces, " + std::to_string(cells.crossing_nodes) +
                      " edge crossings on faults)");
  if (!out.build_report.ok)
    throw MeshingError("assembly", {},
                       "assembly: the corner-point cells do not conform: " +
                           (out.build_report.problems.empty() ? std::string("?") : out.build_report.problems[0]));
  if (!opts.build_transition) return out;
  out.self_check = self_check(out.mesh, out.geometry, out.build_report, out.cell_cavity, {}, cs);
  stage("self_check");
  if (!out.self_check.ok()) throw MeshingError("self-check", {}, out.self_check.message);
  return out;
}

}  // namespace hm
