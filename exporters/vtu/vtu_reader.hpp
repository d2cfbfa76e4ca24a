// VTK XML UnstructuredGrid (.vtu) reader -> PolyMesh, rebuilt with the MeshBuilder.
// Accepts polyhedra (42) and tetra (10), voxel (11), hexahedron (12), wedge (13), pyramid (14);
// data formats ascii, binary (base64, UInt32 or UInt64 header), appended raw and appended
// base64, in either byte order. zlib-compressed files are refused with a clear error.
// Never crashes or hangs on a malformed file: every count, id and offset is bounds-checked
// and a failure comes back as ok = false with a one-line message. docs/output-formats.md.
#pragma once
#include <string>
#include <vector>

#include "exporters/vtu/vtu_writer.hpp"
#include "meshgen/core/mesh_builder.hpp"

namespace hm {

struct ReadResult {
  bool ok = false;
  std::string error;        ///< one line, set when !ok
  PolyMesh mesh;            ///< valid when ok (the builder's problems are in `build`)
  BuildReport build;        ///< the builder's report: conformity problems found while assembling
  bool has_region = false;     ///< `region` was present (else every cell is kReservoir)
  bool has_fv_center = false;  ///< `fv_center` was present (else the cell centroid is used)
  bool has_face_patch = false; ///< field data `face_patch` was present and used
  int flipped_faces = 0;       ///< faces re-oriented to point out of their cell
  int unorientable_cells = 0;  ///< cells whose faces admit no consistent orientation
  /// Every cell data array of the file, as Float64 values (cell order = mesh cell order).
  std::vector<VtuCellArray> cell_arrays;
  std::vector<std::string> warnings;

  const VtuCellArray* find(const std::string& name) const {
    for (const VtuCellArray& a : cell_arrays)
      if (a.name == name) return &a;
    return nullptr;
  }
};

/// Reads a .vtu file. Never throws for bad content.
ReadResult read_vtu(const std::string& path);
/// Same, from the file's bytes (tests).
ReadResult read_vtu_buffer(const std::string& bytes);

/// Reorients the faces of one closed cell so that they agree along shared edges and
/// point outward (positive signed volume). Returns the number of faces reversed; sets
/// *consistent to false when no consistent orientation exists (non-manifold or Moebius-like).
int orient_cell_faces(std::vector<std::vector<int32_t>>& faces, const std::vector<Vec3>& points, bool* consistent);

}  // namespace hm
