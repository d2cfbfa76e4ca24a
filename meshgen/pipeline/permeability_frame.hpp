// The permeability frame (case `metric: permeability`, docs/anisotropy.md). For a diagonal
// K = diag(kx, ky, kz) the job meshes in scaled coordinates x' = o + S^-1 (x - o), with
// S = diag(sqrt(kx/k0), sqrt(ky/k0), sqrt(kz/k0)), k0 = cbrt(kx ky kz) (det S = 1: volumes are
// preserved; K is isotropic, k0, in the scaled frame). A power diagram orthogonal there is
// K-orthogonal once mapped back (x = o + S (x' - o), affine: planar faces stay planar, convex
// cells convex). build_hybrid_mesh applies it, so meshgen, solver_demo, Python and the tests
// all get the same mesh.
#pragma once
#include "meshgen/case/case.hpp"
#include "meshgen/case/permeability_metric.hpp"
#include "meshgen/core/polymesh.hpp"

namespace hm {

/// Equivalent radius (a + b) / 2 of the scaled cross-section (normal to the scaled axis) of a
/// circular cylinder of radius r about the physical unit axis; for a vertical axis and
/// kz = sqrt(kx ky) this is Peaceman's anisotropic r_w' = r/2 [(ky/kx)^1/4 + (kx/ky)^1/4].
double equivalent_radius(Vec3 scale, Vec3 unit_axis, double r);

/// Radius in the scaled frame of a block whose physical image lies within distance R of its
/// physical axis in every direction: R / max(scale) (the physical block is an elliptic
/// cylinder inside the user's cylinder of radius R, so the case's checks against the box and
/// the other wells still hold).
double scaled_block_radius(Vec3 scale, double R);

/// Radius in the scaled frame of a block whose physical cross-section (an ellipse about the
/// physical unit axis) has the area pi R^2 of the user's circular block: R sqrt(a b), a, b the
/// semi-axes of the scaled image of the unit circle about the axis. >= scaled_block_radius;
/// equal to it for an axis along z with kx = ky (and for isotropic K). The physical block then
/// reaches beyond R in the direction of the largest s (docs/anisotropy.md, "Block radius R").
double area_block_radius(Vec3 scale, Vec3 unit_axis, double R);

/// The case as meshed in frame f: reservoir axes and trajectories scaled; per well, radius =
/// length-weighted mean over the legs of equivalent_radius; drainage_radius = for a case with one
/// well the length-weighted mean over the legs of area_block_radius when it exceeds the inscribed
/// radius by more than 1 % and that block fits the scaled box as the inscribed one does (no
/// refusal, not squeezed, the same ends and caps), else (and with several wells)
/// scaled_block_radius; segment_length times the scaled/physical trajectory length ratio,
/// trajectory_md the physical measured depths (perforations keep their meaning). The
/// rock (per cell or uniform) stays physical. Throws InputError when the scaled radius is not
/// below the scaled drainage radius.
/// A corner-point model is scaled with it (scaled_corner_point_model), and its wells keep the
/// inscribed radius (their paths were fitted to the model's surface with the physical block).
CaseSpec scaled_case(const CaseSpec& cs, const PermeabilityFrame& f);

/// A corner-point model as seen in frame f: its pillars (COORD) and depths (ZCORN) mapped, and PINCH's
/// thicknesses with the depths. A pillar point at a depth maps to the scaled pillar's point at the
/// scaled depth (the map is affine), so the cells are the scaled cells; rock, multipliers and
/// connections stay as they are.
std::shared_ptr<const CornerPointModel> scaled_corner_point_model(const CornerPointModel& m, const PermeabilityFrame& f);

/// Maps a position of the scaled frame back; a coordinate equal to a scaled reservoir node
/// coordinate gets the user's coordinate of that node exactly (the reservoir's planes stay the
/// user's planes, not x' * s off by ulps). A corner-point model's nodes are put back by
/// build_hybrid_mesh from the model itself.
struct FrameUnmapper {
  FrameUnmapper(const PermeabilityFrame& f, const ReservoirSpec& physical);
  Vec3 operator()(Vec3 x_scaled) const;
  PermeabilityFrame frame;
  const ReservoirSpec* physical;
  std::vector<double> scaled_axis[3];
};

/// Moves a mesh built in frame f to physical coordinates (nodes, FV centres, cap centres) and
/// records the frame in mesh.metric_scale. The radial data (radii, lengths) stay those of the
/// scaled frame, where the transmissibilities are computed (docs/mesh-layout.md).
void unscale_mesh(PolyMesh& mesh, const FrameUnmapper& unmap);

}  // namespace hm
