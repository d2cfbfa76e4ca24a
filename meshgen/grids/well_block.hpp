// Structured radial grid around one well trajectory (paper sections 2, 5.1).
//
// Layout: layers l = 0..L-1 are cross-sections along the trajectory (at a bend the
// cross-section lies in the bisector plane of the two legs); each layer has rings+1
// node polygons (radii r_0 = radius .. r_rings = drainage_radius, geometric
// progression), each polygon `sectors` nodes at angles 2*pi*s/sectors in the
// rotation-minimising frame carried along the trajectory. Cell (ring, sector, segment)
// lies between polygons ring and ring+1, angles s and s+1, layers segment and segment+1.
// The wellbore r < radius is a hole: ring-0 inner faces are boundary faces (wellbore patch).
// The two extremities are closed as documented in docs/architecture.md (end caps).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "meshgen/case/case.hpp"
#include "meshgen/core/mesh_builder.hpp"

namespace hm {

/// A well block as a stand-alone piece of mesh with LOCAL node ids 0..nodes.size()-1.
struct WellBlock {
  int well = -1;                   ///< index of the well in the case
  int rings = 0, sectors = 0, layers = 0;  ///< layers = segments + 1
  std::vector<double> radii;       ///< rings + 1 polygon circumradii, radii[0] = r_w
  std::vector<Vec3> nodes;         ///< local node coordinates
  std::vector<Vec3> layer_center;  ///< layers: axis point of each cross-section
  /// Cells: faces with local node ids, outward oriented; patch = wellbore_patch(well) for
  /// wellbore faces, kInteriorFace for everything else (outer faces are claimed by the
  /// transition mesh).
  std::vector<std::vector<CellFace>> cell_faces;
  std::vector<CellAttributes> cell_attrs;  ///< region kWell, fv_center on the radial line, radial info
  /// Outer surface of the block (what the cavity sees): polygons with local node ids,
  /// oriented with the normal pointing OUT of the block, the local cell each belongs to
  /// (-1 for an end-cap polygon over the wellbore, whose patch is wellbore_patch(well)).
  std::vector<std::vector<int32_t>> surface_faces;
  std::vector<int32_t> surface_cell;
  std::vector<int32_t> surface_patch;
  int sectors_requested = 0;       ///< as in the case file
  std::vector<std::string> notes;  ///< what was changed to make it valid (e.g. sectors raised)
};

/// Builds the block for case well `w` with the given number of sectors (no Gabriel loop).
/// Throws InputError naming wells[w] when the trajectory cannot carry the block
/// (e.g. a leg too short for its bend with this drainage radius).
WellBlock make_well_block(const CaseSpec& cs, int w, int sectors);

/// Gabriel condition on the block's outer surface (paper 5.1): no surface edge's
/// diametral sphere contains another surface vertex. Returns the number of violations.
int count_gabriel_violations(const WellBlock& block);

/// make_well_block + raise sectors until the outer surface is Gabriel (notes say so).
WellBlock make_gabriel_well_block(const CaseSpec& cs, int w);

/// Adds the block's nodes and cells to the builder; returns the builder id of each local node.
std::vector<int32_t> add_well_block(const WellBlock& block, MeshBuilder& builder);

/// Exact volume of the block: per leg, (area of the outer polygon - area of the inner
/// polygon) x leg length along the axis (legs are cut by bisector planes at bends).
double exact_well_block_volume(const CaseSpec& cs, int w, int sectors);

}  // namespace hm
