// Layers split at fault steps near the wells (docs/corner-point.md, "Fault steps"). Across a fault
// whose throw is a fraction of a layer, the two sides' cells meet along faces that match only in
// part: the cavity's walls then carry nodes in the middle of their edges, and no triangulation of
// such a wall face keeps every polygon site in its own cell (measured: the site correction stalls,
// or the step's triangles are not Delaunay admissible). Splitting each layer near the wells at the other
// side's layer boundaries makes the two sides meet face to face there; the result is a corner-point
// grid again (the cells away from the wells keep their thickness in one child, the others of zero
// thickness), so that the deck carries it as it is.
#pragma once
#include <array>
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

/// At most this many children per layer in the permeability frame's split (frame_layer_children).
constexpr int kMaxFrameChildren = 16;

/// A step counts within this many times a well's cavity reach, (dilation + 2) drainage radii, of its
/// path: the cavity may grow beyond its dilation (Gabriel rounds, enlargements).
constexpr double kFaultStepReach = 1.0;

/// Where a well asks for fault steps to be split: its path and the distance from it within which a
/// step counts.
struct FaultStepRequest {
  std::vector<Vec3> path;
  double reach = 0;
};

/// A pillar whose columns' layers are offset against each other both ways (a fault's two sides there).
struct FaultPillar {
  int pillar = 0;  ///< I + (nx + 1) J
  /// Per column slot a (bit 0: the column's i is I, bit 1: its j is J): the depths of its active
  /// cells' tops and bottoms on the pillar, sorted, distinct; empty for a slot outside the model.
  std::array<std::vector<double>, 4> boundaries;
  std::array<std::array<bool, 4>, 4> offset{};  ///< offset[a][b]: slots a and b are offset both ways
};

/// What fault_step_children found.
struct FaultStepSplit {
  std::vector<int> children;  ///< per layer of the input model, >= 1 (all 1: nothing to split)
  /// Per cell of the input model: within reach of a well that asked for a split, or of a well that has
  /// such a cell within its own reach, and so on (its cells are split; the others keep their whole
  /// thickness in their first child, the rest of zero thickness).
  std::vector<char> near;
  int64_t steps = 0;          ///< cell corners on a fault pillar within reach that asked for a split
  std::vector<FaultPillar> fault_pillars;  ///< every such pillar of the model, by increasing pillar
  /// 0: the fault steps' split (fault_step_children). > 0: the permeability frame's
  /// (frame_layer_children): near the wells each interval between a pillar side's own and its offset
  /// sides' boundaries is split into equal children no thicker than this (m).
  double child_thickness = 0;
  bool splits() const;
};

/// What snap_thin_fault_steps moved.
struct SnappedSteps {
  int64_t corners = 0;  ///< cell corners moved (ZCORN values)
  double largest = 0;   ///< the largest move (m)
};

/// Steps too thin to split (kMinStepFraction): on a fault pillar within reach of a well, a layer
/// boundary of one side that lies less than kMinStepFraction of the thinner of the cells it separates
/// (on either side) from a boundary of the other side is moved onto it: every ZCORN value of the
/// columns offset against the lower column slot equal to it, so that the sides meet face to face
/// there. Such a step is within the tolerance of the model's depths, and left as it is it puts a
/// cavity vertex a few centimetres from the corner of a wall face, inside that face's diametral
/// sphere (not Delaunay admissible; docs/corner-point.md, "Fault steps"). Cells keep their ids; rock,
/// ACTNUM and multipliers are untouched; m.opm_volume is cleared when anything moves.
SnappedSteps snap_thin_fault_steps(CornerPointModel& m, const std::vector<FaultStepRequest>& wells);

/// Children per layer: a layer is split where, within reach of a well, the corner of one of its
/// cells on a fault pillar (a pillar whose columns' depths differ) has a boundary of a cell across
/// the fault strictly inside it (beyond kMinStepFraction of its thickness from either end); into as
/// many children as the most such boundaries in one corner, plus one.
FaultStepSplit fault_step_children(const CornerPointModel& m, const std::vector<FaultStepRequest>& wells);

/// Children for the permeability frame, which stretches the layers against the columns by s_x / s_z
/// (docs/anisotropy.md, "Corner-point models"): the active cells within reach of the wells are split
/// so that, scaled by `scale`, they are at most `aspect` times taller than the narrowest of them is
/// wide. At every pillar near a well the children end at the boundaries of the columns offset against
/// it (a fault's other side) and at its own, each interval between them in equal parts no thicker than
/// child_thickness: the two sides of a fault get the same depths and meet face to face. A layer with
/// fewer parts at a pillar than its children gets the rest of zero thickness at its bottom there.
/// Children all 1 when no near cell is taller than that; child_thickness grows (by 5/4) until no layer
/// needs more than kMaxFrameChildren.
FaultStepSplit frame_layer_children(const CornerPointModel& m, const std::vector<FaultStepRequest>& wells, Vec3 scale,
                                    double aspect);

/// The model with layer k split into split.children[k] children. Cells near the wells (split.near):
/// on each side of each fault pillar the children end exactly at the other side's boundaries (the same
/// ZCORN values); elsewhere a pillar takes the fractions of the nearest pillar that has them (breadth
/// first over the columns, so that cells sharing a pillar keep sharing their corners), equal children
/// where none is near (the frame's split instead cuts every near pillar side by its own intervals:
/// frame_layer_children). The other cells keep their whole thickness in their first child, the others
/// of zero thickness at its bottom (not meshed; the cells above and below connect as in the model as read,
/// `across_pinched_layers` counting layers as read). The parent's top and bottom stay bit for bit. Rock,
/// ACTNUM and the x/y multipliers are the parent's in every child; MULTZ acts on the bottom of the
/// children that end at the parent's bottom, MULTZ- on the top of the one that starts at its top.
/// `parent_cell` maps each cell to the model's cell as read, `parent_layer` each layer.
CornerPointModel layers_split_at_fault_steps(const CornerPointModel& m, const FaultStepSplit& split);

}  // namespace hm
