// Near-well refinement of a corner-point model's columns (docs/corner-point.md, "Near-well
// refinement"). A model whose columns are many times wider than a well's drainage radius (Reek's)
// gives cavity walls whose constrained triangles have diametral spheres far larger than the block,
// and the Gabriel repair grows the cavity through the whole model. Splitting the model's i-columns and j-rows near the wells brings the cells
// there to the block's scale, like an Eclipse CARFIN extended along whole rows so that the
// refined model is again a corner-point grid: new pillars interpolate the model's pillars,
// children's ZCORN interpolate their parent's, so faults stay on the model's pillars and every
// child keeps its parent's rock and multipliers.
#pragma once
#include <vector>

#include "grdecl.hpp"
#include "meshgen/core/vec3.hpp"

namespace hm {

/// Children per model column along i (size nx) and along j (size ny), each >= 1.
struct ColumnSplits {
  std::vector<int> i, j;
  /// Where the children of each slice end, as parameters across it: empty for children of equal
  /// widths, else one list per slice of i[p] + 1 (j[p] + 1) increasing values from exactly 0 to
  /// exactly 1.
  std::vector<std::vector<double>> i_bounds, j_bounds;
  bool refines() const;
  /// The refined model's cells (nz layers), known before it is built.
  double cells(int nz) const;
};

/// What a well asks of the columns around it: its path in the grid frame, the size its nearby
/// cells should have, and the distance from the path within which cells get that size.
struct RefinementRequest {
  std::vector<Vec3> path;
  double cell_size = 0;
  double reach = 0;
  /// Also no wider than kCellsPerLayerThickness x the thickness of the layer the path is in (auto).
  bool limit_by_layer = false;
  /// Also no wider than the layers split at fault steps within reach allow on the column's leaning
  /// pillars (kLeanSphereMargin; auto, where the pillars near the path are not turned upright).
  bool limit_by_lean = false;
  /// Children that grow away from the path across a slice; false: a slice this well asks for is
  /// split into equal children, as many as the largest ask on it needs where it is nearest.
  bool graded = true;
};

/// A column or row wider than this many target cell sizes is split (Gabriel repair handles the
/// narrower ones with a round or two: docs/corner-point.md, measured).
constexpr double kRefineWiderThan = 4.0;
/// Where another well's children cross a well's reach, that well's slices wider than this many target
/// sizes are split too (docs/corner-point.md, "Near-well refinement": two wells).
constexpr double kRefineBesideChildrenWiderThan = 1.0;
/// With limit_by_layer, near-well cells are at most this many layer thicknesses wide: where the
/// pillars are inclined the cells are sheared, and the constrained triangles of a sheared cavity
/// wall stay Delaunay admissible only if the cells are not much wider than thick (measured on
/// 3 m layers: docs/corner-point.md, "Near-well refinement").
constexpr double kCellsPerLayerThickness = 1.5;
/// In a model whose layers are split at fault steps, a child's thickness counts as at least this
/// fraction of its parent's for limit_by_layer (measured: docs/corner-point.md, "Fault steps").
constexpr double kStepChildSizing = 0.5;
/// With limit_by_lean, near-well cells are at most sqrt(2) h / (this x sin(2 lean)) wide, h the
/// thinnest child of a layer split at fault steps within reach of the path (kStepChildSizing sizes
/// them for limit_by_layer as thicker than they are) and lean the column's largest pillar lean (at most 45
/// degrees): a square cell face of half-diagonal R holds, in its triangles' diametral sphere, the
/// corner of the next layer h away along a pillar leaning toward it by lean when h < R sin(2 lean)
/// (docs/corner-point.md, "Thin layers on leaning pillars").
constexpr double kLeanSphereMargin = 1.25;
/// Beyond `reach` the target size grows by this much per metre of distance from the path, so
/// that neighbouring slices differ by a bounded ratio and refinement dies out within a few
/// model columns.
constexpr double kRefinementGrowth = 1.0;

/// How each model column and row is split: a slice (all columns of one i, or of one j) whose width
/// near a well's path exceeds kRefineWiderThan x cell_size is split into children of about the
/// target size where each lies: cell_size within reach of the path, growing by kRefinementGrowth
/// per metre beyond, so that a wide column holding a well has fine children near it and coarser
/// ones toward its sides (the target's smallest value over all wells and path points; children's
/// widths follow it by equidistribution). A slice asked for by a well that is not `graded` gets
/// equal children instead. Path points outside the model's columns in plan ask nothing.
ColumnSplits near_well_splits(const CornerPointModel& m, const std::vector<RefinementRequest>& wells);

/// The model with column i split into splits.i[i] and row j into splits.j[j] children, of equal
/// parametric width or at splits.i_bounds / j_bounds. New pillars interpolate the model's pillars bilinearly (top and bottom
/// points); a child's ZCORN interpolate its parent's 4 depths on the same side bilinearly, so a
/// child's corners on the model's pillars are its parent's (bit for bit). Rock, ACTNUM and the
/// z multipliers are the parent's; an x (y) multiplier stays on the children along the parent's
/// face it acts on, 1 inside the parent. `parent_cell` maps each cell to the model's cell.
CornerPointModel refined_model(const CornerPointModel& m, const ColumnSplits& splits);

}  // namespace hm
