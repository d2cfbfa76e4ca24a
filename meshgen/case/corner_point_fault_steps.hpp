// Layers split at fault steps near the wells (docs/corner-point.md, "Fault steps"). Across a fault
// whose throw is a fraction of a layer, the two sides' cells meet along faces that match only in
// part: the cavity's walls then carry nodes in the middle of their edges, and no triangulation of
// such a wall face keeps every polygon site in its own cell (measured: the site correction stalls,
// or the step's triangles are not Delaunay admissible). Splitting each layer there at the other
// side's layer boundaries makes the two sides meet face to face; as a corner-point grid again
// (whole layers split, each child a corner-point cell), so that the deck carries it as it is.
#pragma once
#include <string>
#include <vector>

#include "grdecl.hpp"
#include "meshgen/core/vec3.hpp"

namespace hm {

/// A step thinner than this fraction of the layer it cuts is left as it is: a child that thin would
/// be a sliver, and such a step is within the tolerance of the model's depths.
constexpr double kMinStepFraction = 0.05;
/// At most this many children per layer (a layer cut by more boundaries of the other side keeps the
/// first ones, from the top).
constexpr int kMaxStepChildren = 4;

/// A step counts within this many times a well's cavity reach, (dilation + 2) drainage radii, of its
/// path: the cavity may grow beyond its dilation (Gabriel rounds, enlargements).
constexpr double kFaultStepReach = 2.0;

/// Where a well asks for fault steps to be split: its path and the distance from it within which a
/// step counts.
struct FaultStepRequest {
  std::vector<Vec3> path;
  double reach = 0;
};

/// What split_layers_at_fault_steps did.
struct FaultStepSplit {
  std::vector<int> children;  ///< per layer of the input model, >= 1 (all 1: nothing to split)
  int64_t steps = 0;          ///< cell corners on a fault pillar within reach that asked for a split
  bool splits() const;
};

/// Children per layer: a layer is split where, within reach of a well, the corner of one of its
/// cells on a fault pillar (a pillar whose columns' depths differ) has a boundary of a cell across
/// the fault strictly inside it (beyond kMinStepFraction of its thickness from either end); into as
/// many children as the most such boundaries in one corner, plus one.
FaultStepSplit fault_step_children(const CornerPointModel& m, const std::vector<FaultStepRequest>& wells);

/// The model with layer k split into split.children[k] children. On each side of each fault pillar
/// the children end exactly at the other side's boundaries (the same ZCORN values) where the counts
/// agree; elsewhere a pillar takes the fractions of the nearest pillar that has them (breadth first
/// over the columns, so that cells sharing a pillar keep sharing their corners), equal children where
/// none is near. The parent's top and bottom stay bit for bit. Rock, ACTNUM and the x/y multipliers
/// are the parent's in every child; MULTZ acts on the bottom child's bottom, MULTZ- on the top
/// child's top. `parent_cell` maps each cell to the model's cell as read, `parent_layer` each layer.
CornerPointModel layers_split_at_fault_steps(const CornerPointModel& m, const FaultStepSplit& split);

}  // namespace hm
