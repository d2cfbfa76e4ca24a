// OpenFOAM case export of a PolyMesh (docs/export-openfoam.md): constant/polyMesh/{points, faces,
// owner, neighbour, boundary} plus a minimal system/{controlDict, fvSchemes, fvSolution}, such that
// checkMesh accepts it. OpenFOAM's ordering rules are applied here, not assumed of the mesh:
// internal faces first in upper-triangular order (by owner, then neighbour, owner < neighbour,
// a face flipped when needed so that its normal points out of the owner), then the boundary
// faces grouped by patch: `outer` (kOuterBoundary), then `wellbore_<NAME>` per well.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "exporters/vtu/vtu_writer.hpp"  // WriteStatus (shared by the exporters)
#include "meshgen/core/polymesh.hpp"

namespace hm {

struct OpenFoamOptions {
  /// false: ASCII; true: binary lists (faceCompactList faces), 5-10x smaller and faster to read.
  bool binary = false;
  /// Well names, one per well of the case: patch wellbore_patch(w) is written as wellbore_<NAME>.
  /// Wells without a name here are called wellbore_<w> (0-based).
  std::vector<std::string> well_names;
  /// Number of wells: every wellbore patch 0..n_wells-1 is written even if empty (-1: as many
  /// as well_names, or as the highest wellbore patch found in the mesh).
  int n_wells = -1;
};

struct OpenFoamPatch {
  std::string name;
  int32_t code = 0;        ///< face_patch code of the mesh
  int32_t start_face = 0;  ///< first face in the OpenFOAM face order
  int32_t n_faces = 0;
};

struct OpenFoamInfo {
  std::vector<std::string> files;
  int32_t n_internal_faces = 0;
  std::vector<OpenFoamPatch> patches;
  /// OpenFOAM face order: foam face i is mesh face face_order[i] (flipped if face_flipped[i]).
  std::vector<int32_t> face_order;
  std::vector<char> face_flipped;
};

/// Computes the OpenFOAM face order and patches (no I/O). False with `error` set if the mesh has
/// faces that are neither interior nor on a known patch.
bool make_openfoam_order(const PolyMesh& mesh, const OpenFoamOptions& options, OpenFoamInfo* info, std::string* error);

/// Writes the case into `dir` (created if needed). All files are written under temporary names
/// and renamed at the end (constant/polyMesh/owner last), so a failure leaves no complete-looking
/// case. Never throws for I/O problems.
WriteStatus write_openfoam_case(const std::string& dir, const PolyMesh& mesh, const OpenFoamOptions& options = {},
                                OpenFoamInfo* info = nullptr);

}  // namespace hm
