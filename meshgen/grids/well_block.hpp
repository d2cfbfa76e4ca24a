// Structured radial grid around one well trajectory (paper sections 2, 5.1).
//
// Layout: layers l = 0..L-1 are cross-sections perpendicular to the meshed axis (a bend
// is meshed as mirror wedges on a fillet arc, see well_block.cpp); each layer has rings+1
// node polygons (radii r_0 = radius .. r_rings = drainage_radius, geometric
// progression), each polygon `sectors` nodes at angles 2*pi*s/sectors in the
// rotation-minimising frame carried along the trajectory. Cell (ring, sector, segment)
// lies between polygons ring and ring+1, angles s and s+1, layers segment and segment+1.
// The wellbore r < radius is a hole: ring-0 inner faces are boundary faces (wellbore patch).
// The two extremities are closed as documented in docs/architecture.md (end caps).
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "meshgen/case/case.hpp"
#include "meshgen/core/mesh_builder.hpp"

namespace hm {

/// The focal line of a bend: the line through the fillet arc's centre along the bend's rotation
/// axis. Every wedge's cross-section planes contain it, so the dual lines of the wedge polygons on
/// the inside of the bend converge on it (docs/transition.md, "Bends").
struct BendAxis {
  Vec3 center;               ///< the fillet arc's centre
  Vec3 axis;                 ///< unit rotation axis of the bend
  double fillet_radius = 0;  ///< arc radius of the meshed axis (> the block's outer radius)
};

/// A well block as a stand-alone piece of mesh with LOCAL node ids 0..nodes.size()-1.
struct WellBlock {
  int well = -1;                   ///< index of the well in the case
  int rings = 0, sectors = 0, layers = 0;  ///< layers = segments + 1
  std::vector<double> radii;       ///< rings + 1 polygon circumradii, radii[0] = r_w
  std::vector<Vec3> nodes;         ///< local node coordinates
  std::vector<Vec3> layer_center;  ///< layers: axis point of each cross-section (the meshed axis polyline)
  std::vector<int32_t> layer_bend; ///< layers: trajectory point of the bend whose wedges it bounds, or -1
  std::vector<BendAxis> bend_axes; ///< one per bend (collinear points excluded)
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
  /// Both ends closed by hemispherical caps (case end_caps: hemisphere): their cells follow
  /// the cylinder's, their nodes follow the layers' (start cap first), and the outer surface
  /// is the cylinder's side plus the caps' outer shells (no end faces, no wellbore polygons).
  bool hemisphere_caps = false;
  /// The meshed part of the trajectory (meshed_trajectory.hpp): the user's, clipped to the box.
  std::vector<Vec3> trajectory;
  /// Per end (start, end): the block ends IN a boundary plane (a trajectory crossing it at
  /// right angles). Its end annulus faces are then outer-boundary faces (kOuterBoundary) and no
  /// surface polygon: neither end annulus nor wellbore cap; boundary_axis / boundary_value
  /// name the plane (axis -1 otherwise).
  std::array<bool, 2> boundary_end{false, false};
  std::array<int, 2> boundary_axis{-1, -1};
  std::array<double, 2> boundary_value{0, 0};
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

/// The wellbore axis as meshed: the trajectory's end points and the cross-section centres of
/// the bend wedges (it cuts each bend's corner along chords of the fillet arc).
std::vector<Vec3> meshed_axis(const WellBlock& block);

/// Adds the block's nodes and cells to the builder; returns the builder id of each local node.
std::vector<int32_t> add_well_block(const WellBlock& block, MeshBuilder& builder);
/// The two halves of add_well_block: the nodes (their builder ids), then the cells on those ids.
std::vector<int32_t> add_well_block_nodes(const WellBlock& block, MeshBuilder& builder);
void add_well_block_cells(const WellBlock& block, const std::vector<int32_t>& ids, MeshBuilder& builder);

/// L* such that the block's volume is (outer - inner polygon area) x L* and the wellbore
/// hole's is (inner polygon area) x L*: the trajectory length, less 2 t per bend, plus
/// 2 delta cos^2(a / 2) per wedge (closed form of the mirror wedges, well_block.cpp). The wedge
/// counts depend on the sectors (bends' orthogonality, well_block.cpp).
double well_block_prism_length(const CaseSpec& cs, int w, int sectors);

/// Volume of a hemispherical cap's polyhedral half-ball of the given radius (the region inside
/// its shell faces at that radius and the end cross-section), from the cap's node positions.
double hemisphere_cap_volume(double radius, int sectors);

/// Exact volume of the block: (area of the outer polygon - area of the inner polygon) x L*,
/// plus with hemispherical caps twice (cap volume at R - cap volume at r_w).
double exact_well_block_volume(const CaseSpec& cs, int w, int sectors);

/// Exact volume of the wellbore hole the block leaves: inner polygon area x L*, plus twice
/// the cap volume at r_w with hemispherical caps.
double exact_wellbore_hole_volume(const CaseSpec& cs, int w, int sectors);

}  // namespace hm
