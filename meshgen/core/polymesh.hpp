// The one polyhedral mesh type of HybridMesh: a handful of flat arrays.
// Every field is documented with its size and invariant in docs/mesh-layout.md.
// Topology only (plus per-cell data); geometry lives in MeshGeometry (geometry.hpp).
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "vec3.hpp"

namespace hm {

/// Region code per cell (cell_region).
enum Region : int32_t { kReservoir = 0, kTransition = 1, kWell = 2 };

/// Patch code per face (face_patch).
constexpr int32_t kInteriorFace = -1;   ///< shared by two cells
constexpr int32_t kOuterBoundary = 0;   ///< on the reservoir box's outer boundary
constexpr int32_t kUnmatchedFace = -2;  ///< builder: a face expected interior that found no partner (a bug)
/// Wellbore of well w (0-based): the boundary faces r = r_w (and the capped ends) of that well.
inline constexpr int32_t wellbore_patch(int well) { return 1 + well; }
inline constexpr bool is_wellbore_patch(int32_t p) { return p >= 1; }
inline constexpr int well_of_patch(int32_t p) { return p - 1; }
/// Wellbore of well w outside its perforated intervals: a closed wall (no flow, no connection).
inline constexpr int32_t closed_wellbore_patch(int well) { return -3 - well; }
inline constexpr bool is_closed_wellbore_patch(int32_t p) { return p <= -3; }
inline constexpr int well_of_closed_patch(int32_t p) { return -3 - p; }

/// Structured description of a radial well cell; well < 0 for every other cell.
/// The exact radial half-transmissibility of ring faces needs these (docs/mesh-layout.md).
struct RadialCellInfo {
  int32_t well = -1;     ///< well index in the case file, -1 if not a radial cell
  int32_t ring = -1;     ///< 0 = next to the wellbore
  int32_t sector = -1;   ///< angular index
  int32_t segment = -1;  ///< index along the trajectory
  double r_in = 0, r_out = 0;  ///< radii of the inner and outer ring polygons (circumradii)
  double r_center = 0;         ///< radius of the FV centre: sqrt(r_in * r_out) (caps: / cos(beta_0))
  double angle = 0;            ///< sector angle (rad)
  double length = 0;           ///< cell length along the trajectory axis (m); 0 in an end cap
  /// Hemispherical end caps (docs/mesh-layout.md): latitude band 0 (at the end plane) ..
  /// bands-1 (at the pole), -1 for a cell of the cylindrical part. In a cap, r_in / r_out /
  /// r_center are distances from cap_center (the trajectory's end point; r_center is the
  /// cylinder's sqrt(r_in * r_out) / cos(beta_0), beta_0 band 0's centre latitude), segment is -1 for
  /// the cap before the first segment and `segments` for the one after the last.
  int32_t band = -1;
  Vec3 cap_center;
};

struct PolyMesh {
  // ---- nodes
  std::vector<Vec3> nodes;  ///< n_nodes coordinates (m; z = depth, positive down)

  // ---- faces (CSR face -> nodes)
  std::vector<int32_t> face_node_ptr{0};  ///< n_faces + 1, starts at 0, non-decreasing, >= 3 nodes per face
  std::vector<int32_t> face_nodes;        ///< face_node_ptr.back() node ids; a face's cycle is oriented so
                                          ///< that its right-hand normal points out of face_owner
  std::vector<int32_t> face_owner;        ///< n_faces, a valid cell id
  std::vector<int32_t> face_neighbour;    ///< n_faces, cell id or -1 on the boundary
  std::vector<int32_t> face_patch;        ///< n_faces, kInteriorFace iff face_neighbour >= 0, else a patch code
  /// n_faces or empty (every face 1): the transmissibility multiplier of a corner-point model's face
  /// (MULTX..MULTZ-, FAULTS/MULTFLT as OPM Flow applies them; docs/corner-point.md), finite and >= 0,
  /// 1 on boundary faces and on faces the model's multipliers do not reach.
  std::vector<double> face_trans_mult;

  // ---- cells (CSR cell -> faces)
  std::vector<int32_t> cell_face_ptr{0};  ///< n_cells + 1
  std::vector<int32_t> cell_faces;        ///< face ids; each face appears in exactly its owner's and neighbour's lists
  std::vector<int32_t> cell_region;       ///< n_cells, a Region code
  std::vector<Vec3> cell_fv_center;       ///< n_cells, the finite-volume centre (site), NOT the centroid
  std::vector<std::array<int32_t, 3>> cell_ijk;  ///< n_cells, (i,j,k) of reservoir cells, {-1,-1,-1} otherwise
  std::vector<Vec3> cell_perm;            ///< n_cells, diagonal permeability (kx, ky, kz) in mD
  std::vector<double> cell_porosity;      ///< n_cells, porosity in [0, 1]
  /// n_cells or empty (every cell 1): the pore-volume multiplier of a corner-point model's cell, OPM's
  /// pore volume over volume x PORO x NTG (MULTPV, PORV edits; docs/corner-point.md), finite and > 0.
  /// A cell's pore volume is its volume x cell_porosity x this.
  std::vector<double> cell_pore_volume_mult;
  std::vector<RadialCellInfo> cell_radial;  ///< n_cells, radial structure of well cells

  // ---- connections without a face
  /// A corner-point deck's NNC (docs/corner-point.md, "NNC and EDITNNC"): two cells that share no face
  /// and exchange flow through a given transmissibility. n_nncs pairs of distinct valid cell ids.
  std::vector<std::array<int32_t, 2>> nnc_cells;
  /// n_nncs: their transmissibilities in cP.rm3/day/bar (METRIC), as the deck gives them (OPM folds an
  /// EDITNNC of the pair in); finite and >= 0. They do not depend on the geometry or the frame.
  std::vector<double> nnc_trans;

  // ---- frame
  /// Diagonal of the permeability frame S the mesh was built in (case `metric: permeability`,
  /// docs/anisotropy.md), product 1; (1, 1, 1) for a Euclidean mesh. cell_radial's radii and
  /// lengths are those of the scaled frame x' = S^-1 x, where the transmissibilities are computed.
  Vec3 metric_scale{1, 1, 1};
  /// The reservoir cells (region kReservoir) are a user's corner-point model's cells as given: not
  /// ours, so the shape checks (convexity, orthogonality, auto-centering, planarity) judge only the
  /// other cells (fvcheck/lib/checks.hpp, check_shapes); fvcheck then checks the transmissibilities
  /// of deck_transmissibility_options, the ones solver_demo and the Eclipse deck use.
  bool reservoir_cells_are_model = false;

  int n_nodes() const { return static_cast<int>(nodes.size()); }
  int n_faces() const { return static_cast<int>(face_owner.size()); }
  int n_cells() const { return static_cast<int>(cell_region.size()); }
  int n_nncs() const { return static_cast<int>(nnc_cells.size()); }
  int face_size(int f) const { return face_node_ptr[f + 1] - face_node_ptr[f]; }
  const int32_t* face_begin(int f) const { return face_nodes.data() + face_node_ptr[f]; }
  const int32_t* face_end(int f) const { return face_nodes.data() + face_node_ptr[f + 1]; }
  const int32_t* cell_begin(int c) const { return cell_faces.data() + cell_face_ptr[c]; }
  const int32_t* cell_end(int c) const { return cell_faces.data() + cell_face_ptr[c + 1]; }
  /// +1 if cell c owns face f (outward normal), -1 if c is its neighbour.
  int face_sign(int f, int c) const { return face_owner[f] == c ? 1 : -1; }
  /// Cell c's pore-volume multiplier (1 when the mesh carries none).
  double pore_volume_mult(int c) const { return cell_pore_volume_mult.empty() ? 1.0 : cell_pore_volume_mult[c]; }
};

/// Per-cell attributes handed to the builder with each cell.
struct CellAttributes {
  int32_t region = kReservoir;
  Vec3 fv_center;
  std::array<int32_t, 3> ijk{-1, -1, -1};
  Vec3 perm{0, 0, 0};
  double porosity = 0;
  double pore_volume_mult = 1;
  RadialCellInfo radial;
};

/// Sorted, compacted statistics of CSR validity (see check_csr_invariants).
struct CsrReport {
  bool ok = true;
  std::vector<std::string> problems;  ///< first problems found, human readable (at most 20)
};

}  // namespace hm
