// The local frame the mesher works in (docs/architecture.md, "Local frame"). Field models sit at
// UTM coordinates (1e5-1e7 m) where a double resolves 1e-10-1e-9 m, the size of the tolerances of
// the transition and of fvcheck on 0.1 m wellbore cells. The case is moved so that the reservoir's
// min corner in plan (x[0], y[0]) is the origin right after it is read; every stage meshes in local coordinates, and
// the origin is added back only when a file is written.
#pragma once
#include "meshgen/case/case.hpp"
#include "meshgen/core/mesh_positions.hpp"  // round_to_written_frame, translate_mesh
#include "meshgen/core/polymesh.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"

namespace hm {

/// The reservoir's min corner in plan, (x[0], y[0], 0): depth is not moved.
Vec3 case_origin(const CaseSpec& cs);

/// cs with every coordinate (reservoir axes, trajectory points) plus `shift`. A zero shift shares
/// the corner-point model with cs instead of copying it.
CaseSpec translated_case(const CaseSpec& cs, Vec3 shift);

/// Plan coordinates in the local frame are multiples of this (2^-20 m, 0.95 micrometre): a case and
/// the same case moved by any shift then mesh from the same doubles. Moving a model to UTM rounds
/// its coordinates there (136.087 + 6780000 is not a double), so without it the local coordinates
/// differ by up to 5e-10 m, and power vertices where nearly co-spherical sites meet move by
/// centimetres for that (docs/architecture.md, "Local frame"). A power of two: the rounding is exact.
constexpr double kFrameQuantum = 0x1p-20;

/// v rounded to the nearest multiple of kFrameQuantum (ties to even).
double on_frame_grid(double v);

/// cs in its local frame: translated_case(cs, -case_origin(cs)) with every plan coordinate
/// (reservoir x and y, trajectory x and y, the corner-point model's COORD x and y) rounded to a
/// multiple of kFrameQuantum; depths are kept. Throws InputError where two values the case keeps
/// apart (grid nodes, consecutive trajectory points) fall on one multiple.
CaseSpec local_case(const CaseSpec& cs);

/// Whether moving the model's coordinates by `shift` and back gives each of them bit for bit:
/// (v + s) - s is v, the sign of a zero included, for every COORD and ZCORN value (the corners are
/// computed from them, so they come back bit for bit too). Field
/// coordinates within a factor 2 of the shift do (Sterbenz's lemma), as UTM models' are.
bool translation_round_trips(const CornerPointModel& m, Vec3 shift);

/// What meshgen does: meshes cs in its local frame (build_hybrid_mesh on local_case(cs)); the mesh
/// comes back in the local frame. A large corner-point model is held once, not twice, meanwhile:
/// when cs holds the only reference to it and the translation round-trips (so the deck still gets
/// the user's own numbers), cs's copy is released while meshing and made again from the local one
/// afterwards, with the user's own COORD. cs is as given on return, also when meshing throws.
HybridMesh build_hybrid_mesh_in_local_frame(CaseSpec& cs, const PipelineOptions& opts = {});

}  // namespace hm
