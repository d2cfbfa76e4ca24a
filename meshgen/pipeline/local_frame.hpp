// The local frame the mesher works in (docs/architecture.md, "Local frame"). Field models sit at
// UTM coordinates (1e5-1e7 m) where a double resolves 1e-10-1e-9 m, the size of the tolerances of
// the transition and of fvcheck on 0.1 m wellbore cells. The case is moved so that the reservoir's
// min corner in plan (x[0], y[0]) is the origin right after it is read; every stage meshes in local coordinates, and
// the origin is added back only when a file is written.
#pragma once
#include "meshgen/case/case.hpp"
#include "meshgen/core/polymesh.hpp"

namespace hm {

/// The reservoir's min corner in plan, (x[0], y[0], 0): depth is not moved.
Vec3 case_origin(const CaseSpec& cs);

/// cs with every coordinate (reservoir axes, trajectory points) plus `shift`.
CaseSpec translated_case(const CaseSpec& cs, Vec3 shift);

/// Moves every position of the mesh by `shift`: nodes, FV centres, end-cap centres. Everything
/// else in a PolyMesh (topology, permeability, radii, lengths) does not depend on the frame.
void translate_mesh(PolyMesh& mesh, Vec3 shift);

}  // namespace hm
