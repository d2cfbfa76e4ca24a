// Geometry of a PolyMesh, computed in its own pass. Valid for non-planar faces:
// a face is the fan of triangles (g, a_i, a_{i+1}) around the mean g of its nodes,
// so that the closed surface of every cell stays closed and volumes stay additive.
#pragma once
#include <vector>

#include "polymesh.hpp"

namespace hm {

struct MeshGeometry {
  std::vector<Vec3> face_area;      ///< n_faces: area vector (|.| = area), oriented owner -> neighbour
  std::vector<Vec3> face_centroid;  ///< n_faces: area-weighted centroid of the triangle fan
  std::vector<double> cell_volume;  ///< n_cells: signed volume (> 0 for a well-oriented cell)
  std::vector<Vec3> cell_centroid;  ///< n_cells: volume centroid (differs from the FV centre)
};

/// Area vector and centroid of the polygon with the given node ids (fan around the node mean).
void polygon_area_centroid(const std::vector<Vec3>& nodes, const int32_t* begin, const int32_t* end,
                           Vec3* area, Vec3* centroid);

MeshGeometry compute_geometry(const PolyMesh& mesh);

/// Sum of outward face area vectors of cell c (zero for a closed cell).
Vec3 cell_area_sum(const PolyMesh& mesh, const MeshGeometry& geo, int c);

/// Total signed volume of all cells.
double total_volume(const MeshGeometry& geo);

/// Solid angle of triangle (a, b, c) seen from the origin, signed by its orientation (Van Oosterom
/// and Strackee): summed over a closed surface, 4 pi times its winding number about the origin.
double triangle_solid_angle(Vec3 a, Vec3 b, Vec3 c);

}  // namespace hm
