// Cavities between the reservoir grid and the well blocks (paper 5.1).
// A cavity is a set of deactivated reservoir cells (reservoir cells meeting a dilated
// well block) minus the well blocks inside; its boundary is a closed surface of
// constrained polygons: reservoir faces between an active and a deactivated cell, and
// the outer faces of the well blocks. Wells whose deactivated regions touch share one
// cavity.
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "meshgen/case/case.hpp"
#include "meshgen/grids/reservoir_grid.hpp"
#include "meshgen/grids/well_block.hpp"

namespace hm {

enum class FaceSide : int32_t { Reservoir = 0, Well = 1 };

/// One constrained polygon of a cavity boundary. Node ids are GLOBAL builder ids.
struct ConstrainedFace {
  std::vector<int32_t> nodes;  ///< oriented so that the right-hand normal points INTO the cavity
  FaceSide side = FaceSide::Reservoir;
  /// Reservoir side: the active reservoir cell outside (linear reservoir index) and the
  /// deactivated cell inside. Well side: outside_cell = the local cell of the well block
  /// (-1 for an end-cap polygon over the wellbore), inside_cell = -1.
  int32_t outside_cell = -1;
  int32_t inside_cell = -1;
  int32_t well = -1;            ///< well side: which well
  int32_t patch = kInteriorFace;  ///< kInteriorFace, or wellbore_patch(w) for an end cap (boundary face)
};

/// A plane of the reservoir's outer boundary that a cavity touches (docs/transition.md,
/// "Outer-boundary planes"): x[axis] = value. The cavity surface is open there: its part of
/// the plane is no constrained polygon; the transition mesh sees the mirror image of the
/// cavity through the plane, and its faces in the plane are outer-boundary faces.
struct MirrorPlane {
  int axis = 2;
  double value = 0;
  bool operator==(const MirrorPlane& o) const { return axis == o.axis && value == o.value; }
};

/// p reflected through the plane (exact for points on it: 2 v - v = v).
inline Vec3 reflect(Vec3 p, const MirrorPlane& m) {
  p[m.axis] = 2.0 * m.value - p[m.axis];
  return p;
}

struct Cavity {
  std::vector<int> wells;                 ///< wells whose blocks lie in this cavity
  std::vector<int32_t> deactivated_cells; ///< reservoir linear cell indices, sorted
  std::vector<ConstrainedFace> faces;     ///< the closed boundary surface
  std::vector<int32_t> vertices;          ///< distinct global node ids of `faces`, sorted
  double dilation_used = 0;               ///< largest local dilation used
  std::vector<MirrorPlane> mirrors;       ///< outer-boundary planes the cavity touches (sorted by axis, value)
  /// The deactivated cells are axis-aligned boxes (a rectilinear reservoir): the transition may
  /// use box sites (a cell's centre, its sphere through the 8 corners). False in a corner-point
  /// model (docs/corner-point.md): every reservoir polygon is a triangle with its own site and
  /// its mirror.
  bool cells_are_boxes = true;
  /// When set, the deactivated cell of this cavity holding x (-1 if none); else the transition
  /// locates x in the rectilinear grid.
  std::function<int(Vec3)> locate_cell;
};

struct CavitySet {
  std::vector<Cavity> cavities;
  std::vector<char> reservoir_active;  ///< per reservoir cell: 1 active, 0 deactivated
  std::vector<std::string> notes;      ///< local dilation changes, Gabriel repairs
  int gabriel_violations_remaining = 0;
};

/// Decides the deactivated cells (dilation, then the local enlargement that makes the
/// cavity Gabriel across its reservoir and well sides), groups them into cavities with
/// Boost.Graph connected components, and extracts each boundary. `reservoir_node_ids`
/// and `well_node_ids[w]` map lattice/local node indices to builder ids.
/// `extra_deactivated` (reservoir linear indices) are deactivated too: the cells a
/// transition mesh asked to move out of its way (TransitionError::cells_to_deactivate).
/// A cavity may reach the reservoir's outer boundary: its deactivated cells' faces on the box
/// are no constrained polygons; the planes are listed in Cavity::mirrors.
/// Throws InputError when two well blocks are too close for a Gabriel cavity.
CavitySet build_cavities(const CaseSpec& cs, const ReservoirGrid& grid, const std::vector<WellBlock>& blocks,
                         const std::vector<int32_t>& reservoir_node_ids,
                         const std::vector<std::vector<int32_t>>& well_node_ids,
                         const std::vector<Vec3>& node_coords,
                         const std::vector<int32_t>& extra_deactivated = {});

/// Distance from the axis-aligned box [lo, hi] to a polyline.
double box_polyline_distance(Vec3 lo, Vec3 hi, const std::vector<Vec3>& line);
/// box_polyline_distance(lo, hi, line) <= reach, without the distance to the segments that are
/// farther than reach along one axis (most of a model's cells).
bool box_polyline_within(Vec3 lo, Vec3 hi, const std::vector<Vec3>& line, double reach);

/// Makes the boundary of the deactivated set (active[c] == 0) a 2-manifold in the grid's index
/// space: around every lattice node the deactivated and the active cells of its 2x2x2
/// neighbourhood must each be face-connected, else all of them are deactivated. Returns cells added.
int regularize_deactivated(const ReservoirGrid& grid, std::vector<char>& active);

/// The well side of the cavities' Gabriel test: the blocks' outer polygons (builder ids), their
/// distinct vertices (sorted) and distinct edges (sorted, a < b).
struct WellSurfaces {
  std::vector<int32_t> vertices;
  std::vector<std::array<int32_t, 2>> edges;
  std::vector<std::vector<int32_t>> polygons;
};
WellSurfaces well_surfaces(const std::vector<WellBlock>& blocks, const std::vector<std::vector<int32_t>>& well_node_ids);

/// Appends the outer polygons of the cavity's wells' blocks to its faces (FaceSide::Well) and sets
/// its vertices (the distinct nodes of all its faces, sorted).
void add_well_polygons(Cavity& cav, const std::vector<WellBlock>& blocks,
                       const std::vector<std::vector<int32_t>>& well_node_ids);

/// Closed 2-manifold check of a cavity boundary (OpenMesh): every edge in exactly two
/// faces with opposite directions, every vertex's fan a single disk; edges lying in one of
/// the cavity's mirror planes may have one face (the surface is open there). Returns problems.
std::vector<std::string> check_cavity_manifold(const Cavity& cavity, const std::vector<Vec3>& node_coords);

/// Writes the boundary surface of a cavity as an .obj with every coordinate as the shortest
/// decimal that reads back as the same double, node_coords[v] + origin (the case's frame when the
/// mesh was built in a local one); returns false on I/O failure.
bool write_cavity_surface(const Cavity& cavity, const std::vector<Vec3>& node_coords, const std::string& path,
                          Vec3 origin = {});

}  // namespace hm
