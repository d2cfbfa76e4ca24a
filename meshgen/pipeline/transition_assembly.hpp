// The transition cells of the cavities put into the mesh builder, and the per-cell maps of the
// finished mesh (cavity, Q_S's h, reservoir cell): one implementation for the rectilinear and the
// corner-point jobs.
#pragma once
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "hybrid_mesh.hpp"

namespace hm {

/// Per transition cell, in the order added: its cavity and its Q_S reference length.
struct TransitionCellMaps {
  std::vector<int32_t> cavity;
  std::vector<double> h_ref;
};

/// outcomes[k] = try_build_transition of cavity k for every k in `to_build`, concurrently (at most
/// `threads`, <= 0: every core), with a progress line; the outcomes do not depend on scheduling.
void build_transitions(const std::vector<int>& to_build, const std::vector<Cavity>& cavities,
                       const std::vector<Vec3>& coords, const ReservoirGrid& grid, const std::vector<WellBlock>& blocks,
                       int32_t base, const TransitionOptions& options, int threads,
                       std::vector<std::optional<TransitionOutcome>>& outcomes);

/// Every cavity's cells in cavity order (moved out of `outcomes`) when none was refused, else nothing.
std::optional<std::vector<TransitionCells>> all_transitions(std::vector<std::optional<TransitionOutcome>>& outcomes);

/// At most what add_transition_cells adds to a builder (a face shared by two cells counted twice).
BuilderCapacity transition_capacity(const std::vector<TransitionCells>& transitions);

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
/// out.transition_q_o_in_mesh from out.mesh and out.geometry (assembled before).
void summarize_transitions(HybridMesh& out, const std::vector<TransitionCells>& transitions,
                           const std::vector<Vec3>& coords);

}  // namespace hm
