// The transition cells of the cavities put into the mesh builder, and the per-cell maps of the
// finished mesh (cavity, Q_S's h, reservoir cell): one implementation for the rectilinear and the
// corner-point jobs.
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include "hybrid_mesh.hpp"

namespace hm {

/// Per transition cell, in the order added: its cavity and its Q_S reference length.
struct TransitionCellMaps {
  std::vector<int32_t> cavity;
  std::vector<double> h_ref;
};

/// Adds every cavity's new nodes (renumbered cavity by cavity from the builder's next id) and cells
/// (region kTransition, FV centre = site, rock from `set_rock`), and appends each cavity's report.
TransitionCellMaps add_transition_cells(const std::vector<TransitionCells>& transitions,
                                        const std::function<void(CellAttributes&)>& set_rock, MeshBuilder& builder,
                                        std::vector<TransitionReport>& reports);

/// out.cell_cavity, out.cell_h_ref (transition cells, from `maps` in cell order) and
/// out.reservoir_cell_of (reservoir cells, from their ijk) over out.mesh.
void fill_cell_maps(HybridMesh& out, const TransitionCellMaps& maps);

/// out.optimized, out.transition_before/after (each cavity's cells on their own, its polygons
/// their boundary faces: only the transition cells are measured) and out.optimize_report (summed,
/// rounds: the largest) from the cavities' transitions; `coords`: the cavities' node coordinates.
void summarize_transitions(HybridMesh& out, const std::vector<TransitionCells>& transitions,
                           const std::vector<Vec3>& coords);

}  // namespace hm
