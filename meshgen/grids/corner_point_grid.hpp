// The cells of a corner-point model (COORD/ZCORN) as mesh cells: each active cell is the
// hexahedron of its 8 corners (faces possibly non-planar, corners possibly collapsed), faces
// between neighbours matched exactly, fault faces split into the overlaps of the two cells' faces
// on their pillar pair (docs/mesh-layout.md, "Corner-point reservoir cells").
#pragma once
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

/// Adds the nodes and the cells with active[c] != 0 of the model (region kReservoir, ijk, the rock of
/// `rock` (per cell), FV centre = the mean of the 8 corners). A face part toward no active cell
/// (inactive or absent neighbour, the model's outer surface, a gap between layers) gets patch
/// `boundary_patch`. The model must satisfy check_corner_point_geometry.
CornerPointCells add_corner_point_cells(const CornerPointModel& model, const ReservoirSpec& rock,
                                        const std::vector<char>& active, MeshBuilder& builder,
                                        int32_t boundary_patch = kOuterBoundary);

}  // namespace hm
