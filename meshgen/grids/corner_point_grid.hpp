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

/// The faces of a model's cells before they are added (the nodes are), in flat arrays: per model
/// cell (natural order) its outward faces as add_corner_point_cells makes them, and per face the
/// model cell across it (-1: none, a boundary face). Cells with present[c] == 0 take no part (gaps).
/// Flat because a refined model has millions of cells: one heap vector per face cost 700 bytes per
/// cell (docs/performance.md, "Session 32").
struct CornerPointCellFaces {
  std::vector<int64_t> cell_start;  ///< n_cells + 1: cell c's faces are f in [cell_start[c], cell_start[c + 1])
  std::vector<int64_t> node_start;  ///< n_faces + 1: face f's nodes are nodes[node_start[f] .. node_start[f + 1])
  std::vector<int32_t> nodes;       ///< builder node ids, each face outward for its cell
  std::vector<int32_t> patch;       ///< n_faces: kInteriorFace or the boundary patch
  std::vector<int32_t> neighbour;   ///< n_faces: the model cell across, -1 none
  /// n_faces: the split group a face belongs to (a face fanned about its centre node), -1 none; and
  /// per group the cycle it fans (outward for its cell).
  std::vector<int32_t> group;
  std::vector<std::vector<int32_t>> groups;
  std::vector<char> meshed;  ///< per model cell: present, active and of non-zero thickness
  int64_t zero_volume_cells = 0, fault_faces = 0, crossing_nodes = 0;

  int64_t n_cells() const { return static_cast<int64_t>(cell_start.size()) - 1; }
  int64_t face_begin(int64_t c) const { return cell_start[c]; }
  int64_t face_end(int64_t c) const { return cell_start[c + 1]; }
  const int32_t* nodes_begin(int64_t f) const { return nodes.data() + node_start[f]; }
  const int32_t* nodes_end(int64_t f) const { return nodes.data() + node_start[f + 1]; }
  std::vector<int32_t> face_nodes(int64_t f) const { return {nodes_begin(f), nodes_end(f)}; }
  /// False for a triangle of a fanned face after the fan's first: the fan's cycle is taken once.
  bool first_of_its_group(int64_t c, int64_t f) const {
    for (int64_t e = face_begin(c); e < f && group[f] >= 0; ++e)
      if (group[e] == group[f]) return false;
    return true;
  }
  /// Face f's cycle, or its group's when it is one triangle of a fanned face.
  std::vector<int32_t> cycle(int64_t f) const { return group[f] >= 0 ? groups[group[f]] : face_nodes(f); }
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
