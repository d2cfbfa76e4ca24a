// The cells of a corner-point model (COORD/ZCORN) as mesh cells: each active cell is the
// hexahedron of its 8 corners (faces possibly non-planar, corners possibly collapsed), faces
// between neighbours matched exactly, fault faces split into the overlaps of the two cells' faces
// on their pillar pair (docs/mesh-layout.md, "Corner-point reservoir cells").
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "meshgen/case/case.hpp"
#include "meshgen/case/grdecl.hpp"
#include "meshgen/core/mesh_builder.hpp"

namespace hm {

struct CornerPointCells {
  std::vector<int32_t> cell_id;  ///< mesh cell per model cell (natural order), -1 when not meshed
  int64_t zero_volume_cells = 0; ///< active cells of zero thickness on all 4 pillars (not meshed, as OPM drops PORV = 0)
  int64_t fault_faces = 0;       ///< interior faces between cells of two columns whose faces do not coincide
  int64_t crossing_nodes = 0;    ///< nodes where an edge of one side of a pillar pair crosses one of the other
};

/// The faces of a model's cells before they are added (the nodes are): per model cell (natural
/// order) its outward faces as add_corner_point_cells makes them, and per face the model cell
/// across it (-1: none, a boundary face). Cells with present[c] == 0 take no part (gaps).
struct CornerPointCellFaces {
  std::vector<std::vector<CellFace>> faces;
  std::vector<std::vector<int32_t>> neighbour;
  /// Per face: the split group it belongs to (a face fanned about its centre node), -1 none; and per
  /// group the cycle it fans (outward for its cell).
  std::vector<std::vector<int32_t>> group;
  std::vector<std::vector<int32_t>> groups;
  std::vector<char> meshed;  ///< per model cell: present, active and of non-zero thickness
  int64_t zero_volume_cells = 0, fault_faces = 0, crossing_nodes = 0;
};

/// Corner q (bit 0 +i, bit 1 +j, bit 2 +k) of model cell c as meshed: on its pillar at its ZCORN depth.
Vec3 model_cell_corner(const CornerPointModel& model, int c, int q);

/// Adds the nodes of the present cells to the builder (no cell) and returns their faces.
CornerPointCellFaces corner_point_cell_faces(const CornerPointModel& model, const std::vector<char>& present,
                                             MeshBuilder& builder, int32_t boundary_patch = kOuterBoundary);

/// A face cycle as triangles over its own nodes (no new node): ear clipping in the plane of its
/// Newell normal, the ear of the largest smallest angle first; deterministic, same orientation.
std::vector<std::array<int32_t, 3>> face_triangles(const std::vector<int32_t>& cycle, const std::vector<Vec3>& coords);

/// A constrained triangle of a cavity: on the face of an active cell toward deactivated cell `inside`.
struct CavityTriangle {
  std::vector<int32_t> nodes;  ///< outward for the active cell (into the cavity)
  int32_t inside = -1;
};

/// The faces of active model cell c toward cells with active == 0, as constrained triangles
/// (face_triangles of each face; a fanned face's cycle without its centre). The cavity and the
/// active cell use this one list, so they conform exactly.
std::vector<CavityTriangle> cavity_triangles(const CornerPointCellFaces& cells, int c, const std::vector<char>& active,
                                             const std::vector<Vec3>& coords);

/// Adds the meshed cells with active[c] != 0 (attributes as below); a face toward a meshed cell
/// that is not active (a cavity's) is added as its cavity_triangles, interior. `added_after`: what
/// the caller adds next (the transition cells), reserved with these cells (no regrowth of the arrays).
CornerPointCells add_corner_point_cells(const CornerPointModel& model, const CornerPointCellFaces& cells,
                                        const ReservoirSpec& rock, const std::vector<char>& active,
                                        MeshBuilder& builder, const BuilderCapacity& added_after = {});

/// Adds the nodes and the cells with active[c] != 0 of the model (region kReservoir, ijk, the rock of
/// `rock` (per cell), FV centre = the mean of the 8 corners). A face part toward no active cell
/// (inactive or absent neighbour, the model's outer surface, a gap between layers) gets patch
/// `boundary_patch`. The model must satisfy check_corner_point_geometry.
CornerPointCells add_corner_point_cells(const CornerPointModel& model, const ReservoirSpec& rock,
                                        const std::vector<char>& active, MeshBuilder& builder,
                                        int32_t boundary_patch = kOuterBoundary);

}  // namespace hm
