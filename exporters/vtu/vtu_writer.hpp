// VTK XML UnstructuredGrid (.vtu) writer: hexahedra as VTK_HEXAHEDRON (12), triangular prisms as
// VTK_WEDGE (13), every other cell as VTK_POLYHEDRON (42), binary appended raw data with UInt64 headers. Layout in docs/output-formats.md.
#pragma once
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "meshgen/core/geometry.hpp"
#include "meshgen/core/polymesh.hpp"

namespace hm {

/// A cell data array: n_cells * components values, tuple-major (cell 0's components first).
struct VtuCellArray {
  std::string name;
  int components = 1;
  bool integer = false;         ///< true: `ints` written as Int32; false: `values` written as Float64
  std::vector<double> values;   ///< used when !integer
  std::vector<int32_t> ints;    ///< used when integer

  static VtuCellArray real(std::string name, int components, std::vector<double> values) {
    VtuCellArray a;
    a.name = std::move(name);
    a.components = components;
    a.values = std::move(values);
    return a;
  }
  static VtuCellArray int32(std::string name, int components, std::vector<int32_t> ints) {
    VtuCellArray a;
    a.name = std::move(name);
    a.components = components;
    a.integer = true;
    a.ints = std::move(ints);
    return a;
  }
  size_t size() const { return integer ? ints.size() : values.size(); }
};

/// Outcome of a writer: ok, or a one-line reason.
struct WriteStatus {
  bool ok = true;
  std::string message;
};

/// Writes the mesh with its own per-cell data (mesh_cell_arrays, vtu_mesh_arrays.hpp: region,
/// fv_center, ijk, rock, radial structure) and `extra`, plus field data `face_patch` (boundary
/// patch of every face of every cell, in the order a reader sees the faces: the `faces` stream of
/// a polyhedron, vtkHexahedron's or vtkWedge's face order; -1 for interior faces). Writes `path + ".tmp"` then renames it, so a
/// failed write never leaves a complete-looking file. Never throws for I/O problems.
WriteStatus write_vtu(const std::string& path, const PolyMesh& mesh, const std::vector<VtuCellArray>& extra = {});

/// The cell arrays meshgen's mesh.vtu carries beside the mesh's own data: `cavity` (cell_cavity),
/// `volume`, `h_ref` (Q_S's reference length) and the quality criteria `Q_S`, `Q_O`, `Q_P`
/// (meshgen/core/fv_quality.hpp). One list for every writer of a mesh file (meshgen, Python).
std::vector<VtuCellArray> mesh_file_quality_arrays(const PolyMesh& mesh, const MeshGeometry& geo,
                                                   const std::vector<int32_t>& cell_cavity,
                                                   const std::vector<double>& cell_h_ref);

}  // namespace hm
