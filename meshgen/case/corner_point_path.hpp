// The part of a well's path that is meshed in a corner-point model (docs/corner-point.md, "Wells
// through the model's surface"). A path may start above the model (a survey from the wellhead), end
// below it or leave through a side or into inactive cells; the radial block is built around its part
// inside the model's active cells, ended flat where its end cross-section keeps a gap from the
// model's surface, and the transition fills the rest up to the surface.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "case.hpp"
#include "grdecl.hpp"

namespace hm {

/// Gap the end cross-section of a block keeps from the surface of the model's active cells where the
/// path crosses it, in drainage radii. The surface's constrained triangles cannot move away from the
/// block (no cell behind them to deactivate), so their diametral spheres must not reach it: a face
/// of a near-well cell about R wide (the refinement's target) has a circumradius of ~0.7 R.
constexpr double kSurfaceGap = 1.0;

/// Relative size (of the coordinates) of the shift that moves a point off the faces it lies on before
/// the inside test: far above rounding, far below any cell.
constexpr double kFaceNudge = 1e-12;

/// Whether points lie inside the active, non-degenerate cells of a model whose corner box meets the
/// box [lo, hi] (each cell the closed surface of its 6 faces cut into 2 triangles along a diagonal:
/// winding number). A point on a face counts as the point kFaceNudge above it (and aside).
class CornerPointInterior {
 public:
  CornerPointInterior(const CornerPointModel& m, Vec3 lo, Vec3 hi);
  bool contains(Vec3 p) const;

 private:
  struct Cell {
    Vec3 lo, hi;
    std::array<Vec3, 8> corners;
  };
  std::vector<Cell> cells_;
  Vec3 nudge_;
};

/// A path clipped to a model: its points and measured depths, and per end (0 start, 1 end) how far
/// (m, along the path) the meshed end lies from the user's (0: the user's end, inside the model).
struct ClippedPath {
  std::vector<Vec3> points;
  std::vector<double> md;
  std::array<double, 2> cut{0, 0};
  bool clipped() const { return cut[0] > 0 || cut[1] > 0; }
};

/// The part of `ws`'s path (grid frame) inside the model's active cells, each end that crosses the
/// model's surface moved inward (by drainage_radius / 16 steps) until the block's end cross-section
/// (radius drainage_radius) keeps kSurfaceGap x drainage_radius from the surface (sampled: its centre
/// and 16 rim points, each in 26 directions). Throws InputError naming `key` when no part is
/// inside, when the path leaves the model and comes back, or when too little of it is left.
ClippedPath clip_path_to_model(const CornerPointModel& m, const WellSpec& ws, const std::string& key);

}  // namespace hm
