// The transition mesh of one cavity: a 3D power diagram (paper 5.2-5.7), made
// conforming with the constrained polygons. This header is CGAL-free; CGAL lives in
// the .cpp files of this folder only.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "meshgen/cavity/cavity.hpp"
#include "meshgen/core/mesh_builder.hpp"

namespace hm {

struct TransitionReport {
  int internal_sites = 0, external_sites = 0;
  int site_corrections = 0;     ///< paper 5.5: number of corrected site pairs (all iterations)
  int correction_iterations = 0;
  int hidden_sites = 0;         ///< internal sites with an empty power cell (reported, handled)
  int snapped_vertices = 0;     ///< power vertices identified with constrained vertices (5.7)
  int removed_faces = 0;        ///< faces degenerated to < 3 nodes by conformity
  std::vector<std::string> notes;
};

/// Transition cells of one cavity, ready for the builder.
struct TransitionCells {
  /// New (free) nodes; their global ids are base_node_id + index.
  std::vector<Vec3> new_nodes;
  int32_t base_node_id = 0;
  /// Cells as outward-oriented faces over GLOBAL node ids (constrained vertices keep the
  /// ids of the reservoir/well grids). Faces on a wellbore end cap carry its patch.
  std::vector<std::vector<CellFace>> cells;
  std::vector<Vec3> sites;        ///< FV centre of each cell (its site)
  std::vector<double> weights;    ///< power weight (radius) of each cell's site
  std::vector<double> h_ref;      ///< mean edge length of the cell's constrained polygons (Q_S's h)
  TransitionReport report;
};

/// Builds the transition mesh of one cavity. `node_coords` holds the coordinates of all
/// global node ids (at least every cavity vertex). Throws std::runtime_error with a clear
/// message if the site correction does not converge.
TransitionCells build_transition(const Cavity& cavity, const std::vector<Vec3>& node_coords,
                                 const ReservoirGrid& grid, const std::vector<WellBlock>& blocks,
                                 int32_t base_node_id);

}  // namespace hm
