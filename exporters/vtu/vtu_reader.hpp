// VTK XML UnstructuredGrid (.vtu) reader -> PolyMesh, rebuilt with the MeshBuilder.
// The XML and the data arrays are decoded by VTK's own vtkXMLDataParser, so every variant VTK
// writes is read: ascii, binary (inline base64), appended (raw or base64), UInt32 or UInt64
// headers, 32- or 64-bit ids, either byte order, compressors none / zlib / LZ4 / LZMA, several
// pieces. The cells are assembled here (VTK's vtkXMLUnstructuredGridReader crashes on a
// malformed polyhedron face stream).
// Accepts polyhedra (42) and tetra (10), voxel (11), hexahedron (12), wedge (13), pyramid (14).
// The reader reports what is in the file and repairs nothing: faces are taken with the
// orientation the file gives them (a reversed face is the checker's finding, not fixed here).
// Never crashes on a malformed file: every id and face stream is bounds-checked and a failure
// comes back as ok = false with a one-line message. docs/output-formats.md.
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
  bool has_radial = false;     ///< the radial_* arrays were present (exact radial transmissibilities)
  bool assembled_in_parallel = false;  ///< VtuAssembly::Parallel built the mesh (a regular file)
  std::vector<std::string> missing_mesh_arrays;  ///< mesh_cell_arrays names absent from the file
  /// Every cell data array of the file, as Float64 values (cell order = mesh cell order).
  std::vector<VtuCellArray> cell_arrays;
  std::vector<std::string> warnings;

  const VtuCellArray* find(const std::string& name) const {
    for (const VtuCellArray& a : cell_arrays)
      if (a.name == name) return &a;
    return nullptr;
  }
};

/// How the mesh is assembled from the file's cells. Parallel (the default): a file whose faces
/// are all regular is assembled on all cores, any other by MeshBuilder, which reports its
/// problems; the mesh is the same either way. Serial: always MeshBuilder (tests compare the two).
enum class VtuAssembly { Parallel, Serial };

/// Reads a .vtu file. Never throws for bad content.
ReadResult read_vtu(const std::string& path, VtuAssembly assembly = VtuAssembly::Parallel);
/// Same, from the file's bytes (tests, fuzzing).
ReadResult read_vtu_buffer(const std::string& bytes, VtuAssembly assembly = VtuAssembly::Parallel);

}  // namespace hm
