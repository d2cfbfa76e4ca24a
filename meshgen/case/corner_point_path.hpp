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
/// Once the model is refined near the wells its surface faces there are smaller than R, and the gap
/// can follow them (surface_gap): at least this many drainage radii (the end cross-section's rim is
/// sampled at 16 points; the block's faces between them must keep clear too).
constexpr double kSurfaceGapMin = 0.25;
/// surface_gap keeps the end cross-section this many times half the longest edge of the surface's
/// triangles near it away from the surface: outside their diametral spheres with a margin.
constexpr double kSurfaceGapMargin = 1.25;

/// Relative size (of the extent of the region tested) of the shift that moves a point off the faces it
/// lies on before the inside test: far above the rounding of field coordinates (1e-9 m at 1e7 m), far
/// below any cell. Relative to the extent, not to the coordinates, so that a model at UTM values and the
/// same model at the origin clip their wells at the same places.
constexpr double kFaceNudge = 1e-8;

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
  // The cells by the buckets of a uniform grid their boxes overlap (a query tests one bucket's cells).
  std::array<int, 3> bucket_index(Vec3 p) const;
  std::vector<Cell> cells_;
  Vec3 origin_, bucket_size_{1, 1, 1};
  std::array<int, 3> buckets_{0, 0, 0};
  std::vector<int32_t> bucket_begin_, bucket_cells_;  // CSR over buckets (x fastest)
  Vec3 nudge_;
};

/// The gap (m) the end cross-section of well ws's block (drainage radius R) needs from the model's
/// surface near `at` (a crossing of the surface, grid frame): kSurfaceGapMargin x the larger of half
/// the longest edge (sides and diagonals) of the surface faces of active cells within R +
/// kSurfaceGap R of `at` and half the diagonal of the block's outer end-face polygon (outer ring,
/// ws.sectors: the diametral spheres of both kinds must stay clear of the other's nodes), clamped to
/// [kSurfaceGapMin R, kSurfaceGap R]. A surface face is a face whose logical neighbour is outside
/// the grid or inactive.
double surface_gap(const CornerPointModel& m, Vec3 at, const WellSpec& ws);

/// The least distance (m) from the block's outer surface (drainage_radius around the meshed path
/// ws.trajectory, grid frame) to a node of the model's surface within 2 drainage radii of the path:
/// the corners of the faces of meshed cells (active, thicker than zero somewhere) whose neighbour
/// across is outside the grid, inactive or, for a top or bottom face, past layers of zero thickness
/// the edge of the model. The diametral spheres of the block's outer faces must clear those nodes
/// (paper 5.1), since no cell behind them can be deactivated. +infinity when there are none.
double surface_clearance(const CornerPointModel& m, const WellSpec& ws);

/// Sectors and segment length of a block whose outer faces (a chord of 2 R sin(pi / sectors) by a
/// segment) keep their diametral spheres off the surface's nodes `clearance` m beyond the block
/// (surface_clearance). ws's own values when their spheres cannot reach that far (a circumcentre
/// R cos(pi / sectors) from the axis plus the sphere's radius <= R + clearance); else the spheres made
/// kSurfaceGapMargin times smaller than the clearance: the sectors raised first (at most to 4 x
/// ws.sectors) until the chord is at most sqrt(2) of the radius allowed, then the segment shortened;
/// `fits` is false when even that is not enough (`sectors` then the most tried), or when the clearance
/// is not positive (ws's values).
struct OuterFaceFit {
  int sectors = 0;
  double segment_length = 0;
  bool fits = false;
};
OuterFaceFit fit_outer_faces(const WellSpec& ws, double clearance);

/// How clip_path_to_model sizes the gap: kSurfaceGap x R; kSurfaceGapMin x R (before the model is
/// refined near the wells: the refinement follows the path so clipped, the longest a block can get);
/// or surface_gap at each crossing (in the model the wells are meshed in).
enum class SurfaceGapRule { DrainageRadius, Least, SurfaceFaces };

/// A path clipped to a model: its points and measured depths, and per end (0 start, 1 end) how far
/// (m, along the path) the meshed end lies from the user's (0: the user's end, inside the model).
struct ClippedPath {
  std::vector<Vec3> points;
  std::vector<double> md;
  std::array<double, 2> cut{0, 0};
  std::array<double, 2> gap{0, 0};  ///< per clipped end, the gap (m) its end cross-section keeps
  std::array<bool, 2> crosses{false, false};  ///< per end: the path crosses the surface there (else ends inside)
  bool clipped() const { return cut[0] > 0 || cut[1] > 0; }
};

/// The part of `ws`'s path (grid frame) inside the model's active cells, each end that crosses the
/// model's surface, or ends inside it too near it, moved inward (by drainage_radius / 16 steps) until
/// the block's end cross-section (radius drainage_radius) keeps the gap of `rule` from the surface
/// (sampled: its centre and 16 rim points, each in 26 directions). Throws InputError naming `key`
/// when no part is inside, when the path leaves the model and comes back, or when too little of it
/// is left.
ClippedPath clip_path_to_model(const CornerPointModel& m, const WellSpec& ws, const std::string& key,
                               SurfaceGapRule rule = SurfaceGapRule::DrainageRadius);

}  // namespace hm
