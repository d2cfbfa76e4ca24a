// The cell arrays that make a .vtu lossless for HybridMesh: every per-cell field of PolyMesh
// (region, FV centre, ijk, rock, the radial structure of well cells), so that a mesh read back
// gives the same transmissibilities as the one written (docs/output-formats.md lists them).
#pragma once
#include <string>
#include <vector>

#include "exporters/vtu/vtu_writer.hpp"

namespace hm {

/// The arrays written for every mesh, in file order: region, fv_center, ijk, permeability,
/// porosity, pore_volume_multiplier (only when the mesh carries one), radial_well, radial_ring, radial_sector, radial_segment, radial_band, radial_r_in,
/// radial_r_out, radial_r_center, radial_angle, radial_length, radial_cap_center, metric_scale.
std::vector<VtuCellArray> mesh_cell_arrays(const PolyMesh& mesh);

/// True for a name mesh_cell_arrays writes (a caller's extra array may not reuse it).
bool is_mesh_array_name(const std::string& name);

/// What restore_mesh_cell_arrays found.
struct RestoredArrays {
  std::string error;                 ///< "array: reason" when an array present is malformed
  std::vector<std::string> missing;  ///< names of mesh_cell_arrays absent from the file
  bool has(const std::string& name) const;
};

/// Copies the arrays read back from a file (one value per cell and component, cell order =
/// mesh cell order) into the mesh's per-cell fields. Absent arrays leave the fields as they are.
RestoredArrays restore_mesh_cell_arrays(const std::vector<VtuCellArray>& arrays, PolyMesh& mesh);

}  // namespace hm
