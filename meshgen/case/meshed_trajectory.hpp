// The part of a well trajectory that is meshed: the trajectory clipped to the reservoir box
// (docs/case-format.md, "Wells through the reservoir boundary"). A trajectory may start above
// the top, end below the bottom or leave through a side; only its part inside the box carries
// a radial block.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "meshgen/case/case.hpp"

namespace hm {

/// How the radial block ends at one end of the meshed trajectory.
enum class WellEndKind {
  Inside,     ///< the trajectory ends inside the box: flat end or hemispherical cap
  Boundary,   ///< the trajectory crosses a boundary plane at right angles: the block ends IN the
              ///< plane, its end annulus faces are outer-boundary faces (no flow), no cap
  Retracted,  ///< an oblique crossing: the block ends (flat) where its end cross-section keeps
              ///< kRetractGap x drainage_radius from the plane; the transition fills the rest
};

/// Gap a radial block keeps from a boundary plane it does not end on, in drainage radii: the
/// transition mesh between the block and the plane sees the block's mirror image beyond the
/// plane (docs/transition.md, "Outer-boundary planes"); a thinner gap leaves cells too thin
/// for the site correction (measured: a horizontal well in a reservoir 2.5 R thick meshes).
constexpr double kBoundaryGap = 0.25;
/// Gap the end cross-section of a block keeps from the plane an oblique trajectory crosses
/// (Retracted end), in drainage radii (measured: 0.2 left 30-degree crossings failing fvcheck,
/// 0.5 passes).
constexpr double kRetractGap = 0.5;
/// Smallest fraction of the requested drainage radius a block squeezed between two opposite
/// boundary planes is lowered to (MeshedTrajectory::drainage_radius); below it the case is refused.
constexpr double kMinFittedRadius = 0.5;

struct MeshedTrajectory {
  std::vector<Vec3> points;  ///< >= 2 points, consecutive points distinct
  std::array<WellEndKind, 2> ends{WellEndKind::Inside, WellEndKind::Inside};
  std::array<int, 2> plane_axis{-1, -1};    ///< Boundary / Retracted: axis of the crossed plane (0 x, 1 y, 2 z)
  std::array<double, 2> plane_value{0, 0};  ///< and its coordinate
  std::array<bool, 2> plane_upper{false, false};  ///< the plane is the box's max side on that axis
  std::array<double, 2> retraction{0, 0};   ///< Retracted: distance (m) from the crossing to the block's end
  /// Drainage radius of the block: the well's, or lower where the block is squeezed between the two
  /// planes of one axis (a horizontal well in a reservoir thinner than 2 (1 + kBoundaryGap) R):
  /// the largest that keeps the gap from both, at least kMinFittedRadius x the well's.
  double drainage_radius = 0;
  /// Hemispherical caps at both ends keep the gap from every plane (false when clipped).
  bool caps_fit = false;
  bool clipped() const { return ends[0] != WellEndKind::Inside || ends[1] != WellEndKind::Inside; }
};

/// Clips the well's trajectory to the reservoir box and checks that the radial block fits:
/// one connected part inside, crossings through one plane at a time, a block that keeps
/// kBoundaryGap x drainage_radius from every plane it does not end on (hemispherical caps
/// included). Throws InputError "<key>.trajectory: reason" (or "<key>.end_caps: ..." for
/// explicit hemispherical caps on a well that crosses the boundary). With check_fit false only the
/// clipping is done (the mesher's own use on a validated case; tests build blocks in any box).
MeshedTrajectory meshed_trajectory(const ReservoirSpec& reservoir, const WellSpec& well, const std::string& key,
                                   bool check_fit = true);

/// The well as the mesher builds it: trajectory = the meshed part; end caps flat when the
/// trajectory crosses the boundary or the caps would come closer to it than the gap
/// (end_caps: auto; explicit hemisphere caps are refused there by meshed_trajectory).
WellSpec meshed_well_spec(const CaseSpec& cs, int w);

/// The angle (degrees) between two leg directions d1, d2 (not necessarily unit).
double bend_degrees(Vec3 d1, Vec3 d2);

/// Throws InputError "<key>.trajectory: bend of B degrees at point k exceeds the L-degree limit"
/// for the first bend of the polyline above limit_deg (kMaxBendDegrees for a case, case_limits.hpp).
void check_bend_limit(const std::vector<Vec3>& points, const std::string& key, double limit_deg);

/// "the reservoir top (z = 1000)" etc.: a boundary plane in words.
std::string boundary_plane_name(int axis, bool upper, double value);

}  // namespace hm
