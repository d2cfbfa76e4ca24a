// The two-point constants and OPM's corner-point half-transmissibility, shared by the transmissibility
// module (fvcheck/lib/transmissibility.hpp) and the mesher's connections across cells OPM Flow removes
// (MINPV, meshgen/pipeline). Formulas and units: docs/transmissibility.md.
#pragma once
#include <cmath>

#include "vec3.hpp"

namespace hm {

/// Eclipse METRIC Darcy constant CDARCY: k [mD] * length [m] -> transmissibility [cP.rm3/day/bar]
/// (1 mD = 9.869233e-16 m2, 1 cP = 1e-3 Pa.s, 1 day = 86400 s, 1 bar = 1e5 Pa; E300 value).
constexpr double kDarcyMetric = 0.00852702;

/// OPM's corner-point half (its EclTransmissibility): the permeability of the face's axis times
/// |A . c| / |c|^2, A the face's area vector, c from the cell's centre to the face's centre;
/// `axis` 0, 1, 2 for an I, J, K face.
inline double opm_half_transmissibility(Vec3 area, Vec3 perm, Vec3 c, int axis) {
  const double k = axis == 0 ? perm.x : axis == 1 ? perm.y : perm.z;
  return k * std::abs(dot(area, c)) / norm2(c);
}

}  // namespace hm
