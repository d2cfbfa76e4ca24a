// The positions of a PolyMesh as a whole: moved to another frame, or rounded as the files that
// hold them in another frame give them back (docs/architecture.md, "Local frame").
#pragma once

#include "meshgen/core/polymesh.hpp"
#include "meshgen/core/vec3.hpp"

namespace hm {

/// Rounds every position that translate_mesh moves to (p + origin) - origin: the position the
/// written file's coordinates give back in the local frame. Field models' small faces do not all
/// survive that rounding (a sliver face's plane tilts), so the self-check must see it. The files'
/// coordinates are unchanged by it where p + origin - origin is exact (Sterbenz), as at UTM values.
void round_to_written_frame(PolyMesh& mesh, Vec3 origin);

/// (p + origin) - origin for one position (round_to_written_frame's rounding).
inline Vec3 as_written(Vec3 p, Vec3 origin) { return (p + origin) - origin; }

/// The least x and y of the mesh's nodes, z = 0: a mesh read from a file is checked after moving by
/// minus this (fvcheck, solver_demo --mesh), as meshgen meshes field models in a local frame
/// (docs/architecture.md, "Local frame"): at UTM values the file's own coordinates resolve only
/// 1e-10 to 1e-9 m, the size of the checks' tolerances on the smallest cells. The subtraction is
/// exact where the values are within a factor 2 of the origin (Sterbenz), as across a field.
Vec3 plan_origin(const PolyMesh& mesh);

/// Moves every position of the mesh by `shift`: nodes, FV centres, end-cap centres. Everything
/// else in a PolyMesh (topology, permeability, radii, lengths) does not depend on the frame.
void translate_mesh(PolyMesh& mesh, Vec3 shift);

}  // namespace hm
