// Cavities in a corner-point model (docs/corner-point.md): the model cells meeting a dilated
// well block are deactivated (and grown for the Gabriel condition, as in cavity.hpp); the
// boundary is made of the model faces between an active and a deactivated cell (fault
// overlaps included), each as its constrained triangles (cavity_triangles), which the
// active cell gets as its faces too: no new node, exact conformity.
#pragma once
#include <memory>
#include <vector>

#include "cavity.hpp"
#include "meshgen/grids/corner_point_grid.hpp"

namespace hm {

/// Which model cell holds a point, among a set of meshed model cells: inside the closed surface of
/// the cell's triangulated faces (winding number from solid angles).
class CornerPointLocator {
 public:
  CornerPointLocator(const CornerPointModel& model, const CornerPointCellFaces& cells, const std::vector<int32_t>& among,
                     const std::vector<Vec3>& coords);
  /// The cell holding x (-1 if none of them does).
  int cell_at(Vec3 x) const;
  /// cell_at, or else the cell whose corner mean is nearest to x.
  int cell_at_or_nearest(Vec3 x) const;

 private:
  struct Cell {
    int id;
    Vec3 lo, hi, centre;
    std::vector<std::array<Vec3, 3>> triangles;
  };
  std::vector<Cell> cells_;
};

/// The cavities of the wells in a corner-point model: `cells` (corner_point_cell_faces) with
/// its nodes in `node_coords`, `well_node_ids[w]` the builder ids of block w's nodes. Every
/// cavity has cells_are_boxes = false, no mirror plane, and a locate_cell over its cells.
/// `extra_deactivated` are deactivated too (a transition's request). Throws InputError when a
/// cavity reaches the model's outer surface (top, bottom, sides, an inactive or zero-thickness
/// cell: no mirror plane there, docs/corner-point.md) or cannot be made Gabriel.
CavitySet build_corner_point_cavities(const CaseSpec& cs, const CornerPointModel& model,
                                      const CornerPointCellFaces& cells, const std::vector<WellBlock>& blocks,
                                      const std::vector<std::vector<int32_t>>& well_node_ids,
                                      const std::vector<Vec3>& node_coords,
                                      const std::vector<int32_t>& extra_deactivated = {});

}  // namespace hm
