// Straightened pillars near wells (docs/corner-point.md, "Straightened pillars"). Where a model's
// pillars lean obliquely to its grid axes, its cells are sheared parallelepipeds whose faces meet
// at sharp angles in two directions, and a cavity made of them has walls whose constrained
// triangles are not Delaunay admissible (measured there). Near a well the pillars of the refined
// model are turned toward the vertical about the well's depth, fully within the cavity's reach
// and blending back to the model's own pillars further out; every corner keeps its layer's surface
// (the depth where the turned pillar meets the model's top or bottom surface of that layer), and
// each cell takes the rock of the model cell its centre lies in. The layers' surfaces and the
// region's outer boundary are the model's; the cells between are a re-gridding of them.
#pragma once
#include <string>
#include <vector>

#include "grdecl.hpp"
#include "meshgen/core/vec3.hpp"

namespace hm {

/// A well asking for upright cells: its path (grid frame) and the plan distance from it within
/// which the pillars are made vertical.
struct StraightenRequest {
  std::vector<Vec3> path;
  double reach = 0;
  /// Turn wherever the pillars within reach lean more than kUprightMinLean, obliquely or not
  /// (`upright_pillars: on`); else only where they lean obliquely (kStraightenWallAngleBelow).
  bool any_lean = false;
};

/// With any_lean: pillars leaning less than this (degrees) are left as they are.
constexpr double kUprightMinLean = 1.0;

/// Beyond `reach` a pillar's lean falls back to the model's over a distance that keeps two
/// neighbouring pillars, turned by different amounts, from moving toward or away from each other by
/// more than this fraction of their distance anywhere in the region's depth range (measured:
/// docs/corner-point.md, "Upright pillars near wells").
constexpr double kStraightenShearPerWidth = 0.75;
/// Pillars are turned where a column's i-wall and j-wall (the planes through a pillar and its next
/// pillar along j, resp. i) meet at less than this angle (degrees) near the well: 90 for vertical
/// pillars and for pillars leaning along a grid axis, which mesh as they are up to 56 degrees of lean.
/// Measured on Reek and generated models (docs/corner-point.md, "Upright pillars near wells"):
/// 74 degrees (WI_1) and below are refused with the model's pillars and mesh turned; 77.6 (OP_3) and
/// 78 mesh as they are, and OP_3 turned fails the self-check by one face.
constexpr double kStraightenWallAngleBelow = 76.0;

/// Per request: whether its pillars were turned, and why not.
struct StraightenOutcome {
  bool straightened = false;
  double max_lean_deg = 0;    ///< the model's, among the pillars within reach
  double wall_angle_deg = 90; ///< the sharpest i-wall / j-wall angle there (kStraightenWallAngleBelow)
  int pillars = 0;          ///< pillars turned
  double blend = 0;         ///< metres over which the lean returns to the model's
  std::string refused;      ///< why not (empty when straightened or not needed)
};

/// The model with its pillars near each request turned upright (see above); `outcomes` gets one
/// entry per request. A request is refused (nothing changed for it) where its region holds a fault
/// (ZCORN not continuous across a column edge), an x or y transmissibility multiplier, or reaches the
/// model's side; requests whose regions overlap are refused together.
CornerPointModel straightened_model(const CornerPointModel& m, const std::vector<StraightenRequest>& requests,
                                    std::vector<StraightenOutcome>* outcomes);

}  // namespace hm
