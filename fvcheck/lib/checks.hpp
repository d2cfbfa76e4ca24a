// Finite-volume checks of a PolyMesh (paper section 2): convexity, conformity, closure,
// positive volumes, dual orthogonality, auto-centering, face planarity.
// Every check returns data (counts, worst value, worst ids, per-entity values); none
// prints or throws. Definitions and tolerances are documented in docs/fvcheck.md.
//
// Precondition of every check: check_csr_invariants(mesh).ok (meshgen/core/mesh_builder.hpp)
// and geo == compute_geometry(mesh). run_fvcheck (report.hpp) enforces this.
#pragma once
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "meshgen/core/geometry.hpp"
#include "meshgen/core/mesh_builder.hpp"
#include "meshgen/core/polymesh.hpp"

namespace hm {

/// Thresholds and tolerances (docs/fvcheck.md explains each choice).
struct CheckOptions {
  /// Geometric tolerance relative to the local length scale (cell or face bounding-box
  /// diagonal): convexity, auto-centering, hanging nodes, face self-intersection.
  double rel_tol = 1e-9;
  /// Closure: |sum of outward area vectors| / sum of face areas must not exceed this.
  double closure_tol = 1e-9;
  /// Volume: a cell's volume must exceed volume_rel_tol * L_c^3 (L_c: bounding-box diagonal).
  double volume_rel_tol = 1e-12;
  /// Orthogonality: a face violates when Q_O(F) < this (degrees; paper eq. 8).
  double min_orthogonality_deg = 45.0;
  /// Planarity: a face violates when Q_P(F) > this (degrees; paper eq. 10).
  double max_planarity_deg = 15.0;
};

/// What the ids and per-entity values of a CheckResult refer to.
enum class IdKind { Cell, Face };

struct CheckResult {
  std::string name;                 ///< "convexity", "conformity", ... (JSON key)
  IdKind id_kind = IdKind::Cell;
  bool skipped = false;             ///< not run (the mesh structure is invalid)
  int64_t violations = 0;           ///< number of violating cells (or faces, see id_kind)
  double worst = 0;                 ///< worst measured value (meaning per check, docs/fvcheck.md)
  std::vector<int32_t> worst_ids;   ///< up to 10 ids with the worst values, worst first
  std::vector<double> values;       ///< one measured value per cell or per face (may be empty)
  std::vector<char> failing;        ///< per cell or face as values: 1 where it violates (empty: not per item)
  std::vector<std::pair<std::string, int64_t>> counts;                ///< named sub-counts
  std::vector<std::pair<std::string, std::vector<int32_t>>> id_lists;  ///< named example ids (<= 10 each)
  std::vector<std::pair<std::string, double>> measures;                ///< named extra values (thresholds, ...)
  bool ok() const { return !skipped && violations == 0; }
};

/// Per-cell length scale L_c (bounding-box diagonal of the cell's nodes) and the absolute
/// tolerance tol_c = max(rel_tol * L_c, 64 * DBL_EPSILON * max |coordinate| of the cell).
struct CellScales {
  std::vector<double> length;  ///< n_cells
  std::vector<double> tol;     ///< n_cells
};
CellScales compute_cell_scales(const PolyMesh& mesh, double rel_tol);

/// Distinct node ids of cell c, sorted ascending.
std::vector<int32_t> cell_node_ids(const PolyMesh& mesh, int c);
/// The same into *ids (reuses its storage).
void cell_node_ids_into(const PolyMesh& mesh, int c, std::vector<int32_t>* ids);

/// Convexity: every node of a cell not on face F lies on the inner side of F's plane
/// (through the face centroid, normal = outward area vector) within tol_c, and every face
/// polygon, projected on its own plane, is simple and has no reflex vertex.
/// values[c] = max outside distance of a node / L_c (<= 0 for a strictly convex cell; 1 for a
/// degenerate face). worst = max of values.
CheckResult check_convexity(const PolyMesh& mesh, const MeshGeometry& geo, const CheckOptions& opt = {});

/// Conformity (ids are cells): unmatched interior faces, duplicate faces (two face records
/// over the same node set), cells whose surface is not a closed consistently oriented
/// 2-manifold (every edge of the cell used by exactly two of its faces, in opposite
/// directions), hanging nodes (a node lying on a face it is not a vertex of), and the
/// builder's problems if a report is given. values[c] = number of problems at cell c.
CheckResult check_conformity(const PolyMesh& mesh, const MeshGeometry& geo, const CheckOptions& opt = {},
                             const BuildReport* build = nullptr);

/// Closure: values[c] = |sum of outward area vectors| / sum of face areas.
CheckResult check_closure(const PolyMesh& mesh, const MeshGeometry& geo, const CheckOptions& opt = {});

/// Positive volume: values[c] = volume / L_c^3; violation when <= volume_rel_tol.
/// worst = smallest value; measure "min_volume" = smallest volume (m^3).
CheckResult check_volume(const PolyMesh& mesh, const MeshGeometry& geo, const CheckOptions& opt = {});
/// The same with the cell scales given (== compute_cell_scales(mesh, opt.rel_tol)).
CheckResult check_volume(const PolyMesh& mesh, const MeshGeometry& geo, const CheckOptions& opt,
                         const CellScales& scales);

/// Dual orthogonality per face (paper eq. 8, FV centres; boundary faces use the FV centre
/// and the face centroid). values[f] = Q_O(F) in degrees; violation when < min_orthogonality_deg.
/// worst = min Q_O. A mesh built in a permeability frame (metric_scale != 1, docs/anisotropy.md)
/// is measured in the metric of the K it was built for: values[f] = 90 -
/// face_frame_nonorthogonality (measure k_metric = 1); each cell's own K, where its anisotropy
/// differs, is the report's K-non-orthogonality (face_k_nonorthogonality).
CheckResult check_orthogonality(const PolyMesh& mesh, const MeshGeometry& geo, const CheckOptions& opt = {});

/// Auto-centering: the FV centre lies strictly on the inner side of every face plane.
/// values[c] = max over faces of the signed distance of the centre to the face plane / L_c
/// (< 0 inside); violation when > -tol_c / L_c. worst = max of values.
CheckResult check_auto_centering(const PolyMesh& mesh, const MeshGeometry& geo, const CheckOptions& opt = {});
/// The same with the cell scales given (== compute_cell_scales(mesh, opt.rel_tol)).
CheckResult check_auto_centering(const PolyMesh& mesh, const MeshGeometry& geo, const CheckOptions& opt,
                                 const CellScales& scales);

/// Planarity per face (paper eq. 10). values[f] = Q_P(F) in degrees; violation when
/// > max_planarity_deg. worst = max Q_P.
CheckResult check_planarity(const PolyMesh& mesh, const MeshGeometry& geo, const CheckOptions& opt = {});

/// The shape checks: convexity, orthogonality, auto-centering, planarity, in that order. On a mesh
/// whose reservoir cells are a corner-point model's (PolyMesh::reservoir_cells_are_model: the user's
/// cells, in general neither convex nor orthogonal) they judge only the other cells, as a mesh of
/// their own (cells_as_mesh: their faces toward model cells are boundary faces, measured to their
/// flux points); ids are then cells of `mesh` (id_kind Cell; a face's owner) and values are empty.
/// scales: compute_cell_scales(mesh, opt.rel_tol), or null to compute. *exempt_cells (if given)
/// receives the number of cells not judged.
std::vector<CheckResult> check_shapes(const PolyMesh& mesh, const MeshGeometry& geo, const CheckOptions& opt,
                                      const CellScales* scales = nullptr, int64_t* exempt_cells = nullptr);
/// Simple-polygon test of one face (projected on its own plane): returns 0 if simple and
/// without reflex vertex, 1 if it has a reflex vertex, 2 if edges intersect, 3 if degenerate.
int face_polygon_defect(const std::vector<Vec3>& nodes, const int32_t* begin, const int32_t* end,
                        double rel_tol);

}  // namespace hm
