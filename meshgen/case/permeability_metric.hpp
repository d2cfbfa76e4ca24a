// The permeability frame's map (case `metric: permeability`, docs/anisotropy.md): for a diagonal
// K = diag(kx, ky, kz) the job meshes in scaled coordinates x' = o + S^-1 (x - o), with
// S = diag(sqrt(kx/k0), sqrt(ky/k0), sqrt(kz/k0)), k0 = cbrt(kx ky kz). Here, below the pipeline,
// because reading a case already needs it (near_well_layers.hpp); the scaled case and the mesh's
// way back are meshgen/pipeline/permeability_frame.hpp.
#pragma once
#include "meshgen/case/case.hpp"

namespace hm {

struct PermeabilityFrame {
  Vec3 scale{1, 1, 1};  ///< diagonal of S; product 1
  Vec3 origin;          ///< fixed point of the map: the reservoir's min corner
  Vec3 k{0, 0, 0};      ///< the K the frame is built for (mD; permeability_frame says how)
  bool identity() const { return scale == Vec3{1, 1, 1}; }
};

/// diag(S) for a diagonal K: (sqrt(kx/k0), sqrt(ky/k0), sqrt(kz/k0)), k0 = cbrt(kx ky kz);
/// exactly (1, 1, 1) when kx == ky == kz.
Vec3 frame_scale(Vec3 k);

/// The case's frame: identity for `metric: euclidean` or isotropic rock; else one frame per case
/// for K = kx (1, ky/kx, kz/kx): kx the geometric mean and the ratios the medians over the reservoir
/// cells the wells' trajectories pass through (sampled every segment_length / 4; in a corner-point
/// model the active cells whose centre lies within a drainage radius of a path), the whole grid when
/// there are no wells.
PermeabilityFrame permeability_frame(const CaseSpec& cs);

Vec3 to_scaled(const PermeabilityFrame& f, Vec3 x);
Vec3 to_physical(const PermeabilityFrame& f, Vec3 x_scaled);

}  // namespace hm
