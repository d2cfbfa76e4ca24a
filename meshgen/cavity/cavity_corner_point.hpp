// Cavities in a corner-point model (docs/corner-point.md): the model cells meeting a dilated
// well block are deactivated (and grown for the Gabriel condition, as in cavity.hpp); the
// boundary is made of the model faces between an active and a deactivated cell (fault
// overlaps included), each as its constrained triangles (cavity_triangles), which the
// active cell gets as its faces too: no new node, exact conformity; and the deactivated cells'
// faces on the model's outer surface, as triangles over their own nodes (outer-boundary faces).
#pragma once
#include <memory>
#include <vector>

#include "cavity.hpp"
#include "meshgen/grids/corner_point_grid.hpp"

namespace hm {

/// Which model cell holds a point, among a set of meshed model cells: inside the closed surface of
/// the cell's triangulated faces (winding number from solid angles). The first such cell in the
/// order of `among`; only the cells whose bounding box holds the point are tried (a uniform grid
/// of buckets over the boxes), so a query costs a few cells, not all of them.
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
  bool holds(const Cell& c, Vec3 x) const;
  void index_buckets();
  size_t bucket_of(Vec3 x) const;
  int bucket_index(int axis, double v) const;  // clamped to the grid
  size_t bucket_id(int x, int y, int z) const;
  template <class F>
  void for_each_bucket_of(const Cell& c, F&& f) const;  // f(bucket) for each bucket c's box meets
  std::vector<Cell> cells_;
  // Buckets: a grid of dims_ cells of size step_ from origin_; bucket b holds the indices into cells_
  // (ascending) of the cells whose box meets it: bucket_cells_[bucket_ptr_[b] .. bucket_ptr_[b + 1]).
  Vec3 origin_, step_{1, 1, 1};
  std::array<int, 3> dims_{1, 1, 1};
  std::vector<int32_t> bucket_ptr_, bucket_cells_;
};

/// Makes the boundary of the deactivated meshed cells (active[c] == 0) a 2-manifold where the model's
/// index space misleads regularize_deactivated (a zero-thickness cell between two cells of a column,
/// layers split at fault steps, faults): at every edge of the boundary's triangles used by more than two
/// of them, and every vertex whose triangles make more than one fan, the active cells behind those
/// triangles are deactivated, until none is left. Returns the cells added.
int regularize_cavity_surface(const CornerPointCellFaces& cells, std::vector<char>& active,
                              const std::vector<Vec3>& node_coords);

/// The cavities of the wells in a corner-point model: `cells` (corner_point_cell_faces) with
/// its nodes in `node_coords`, `well_node_ids[w]` the builder ids of block w's nodes. Every
/// cavity has cells_are_boxes = false, no mirror plane, and a locate_cell over its cells.
/// `extra_deactivated` are deactivated too (a transition's request). A cavity may reach the
/// model's outer surface (top, bottom, sides, an inactive or zero-thickness cell): the deactivated
/// cells' faces there are constrained triangles too (outside_cell -1, patch kOuterBoundary: the
/// transition's faces on them are outer-boundary faces; docs/corner-point.md). Throws InputError
/// when a cavity cannot be made Gabriel, in particular where the surface itself is too close to a
/// well (no cell behind it to deactivate; the message names the cell and the well).
CavitySet build_corner_point_cavities(const CaseSpec& cs, const CornerPointModel& model,
                                      const CornerPointCellFaces& cells, const std::vector<WellBlock>& blocks,
                                      const std::vector<std::vector<int32_t>>& well_node_ids,
                                      const std::vector<Vec3>& node_coords,
                                      const std::vector<int32_t>& extra_deactivated = {});

}  // namespace hm
