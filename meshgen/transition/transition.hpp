// The transition mesh of one cavity: a 3D power diagram (paper 5.2-5.7), made
// conforming with the constrained polygons. This header is CGAL-free; CGAL lives in
// the .cpp files of this folder only.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "meshgen/cavity/cavity.hpp"
#include "meshgen/case/permeability_metric.hpp"
#include "meshgen/core/mesh_builder.hpp"

namespace hm {

/// Options of the site optimiser (docs/optimization.md), the transition's last stage.
struct TransitionOptions {
  bool optimize = false;    ///< move sites to remove and expand short edges, rebuilding the diagram
  double g_remove = 0.30;   ///< gamma G2: edges between free vertices below G2 h are removed
  double g_expand = 0.40;   ///< gamma G3: other edges with a free end below G3 h are expanded to it
  double max_shift = 0.5;   ///< a site moves at most this fraction of the edge's h per step
  int max_rounds = 8;       ///< rounds of simultaneous independent moves (each: one or two rebuilds)
  /// The offset the mesh's files hold it at (PipelineOptions::written_origin, 0: the frame it is
  /// built in): the repairs of cells that fail a shape check judge the cells at the positions those
  /// files give back (round_to_written_frame), so that what they repair stays repaired as written.
  Vec3 written_origin;
  /// The permeability frame the cavity is built in (identity: none) and the origin its physical,
  /// written positions are rounded to (PipelineOptions::frame): the repairs also judge convexity, the
  /// FV centres and planarity there, since the frame's map keeps neither angles nor the checks'
  /// relative tolerances (a face 1 degree off planar in a frame of kv/kh = 0.01 can be 18 as written).
  PermeabilityFrame frame;
  Vec3 frame_written_origin;
};

struct SiteOptimizeReport {
  int rounds = 0;    ///< rounds run
  int proposed = 0;  ///< independent site moves tried
  int kept = 0;      ///< moves kept (the Q_S of the cells they touch improved)
  int refused = 0;   ///< moves undone: no Q_S improvement
  int invalid = 0;   ///< moves undone: the rebuilt diagram was not a valid conforming mesh
};

struct TransitionReport {
  int internal_sites = 0, external_sites = 0;
  int site_corrections = 0;     ///< paper 5.5: number of corrected site pairs (all iterations)
  int correction_iterations = 0;
  int hidden_sites = 0;         ///< internal sites with an empty power cell (reported, handled)
  int snapped_vertices = 0;     ///< power vertices identified with constrained vertices (5.7)
  int removed_faces = 0;        ///< faces degenerated to < 3 nodes by conformity
  std::vector<std::string> notes;
  // ---- added by the transition module (docs/transition.md)
  int box_sites = 0;            ///< internal sites that are deactivated-cell centres (n > 1 rule)
  int free_sites = 0;           ///< internal sites of weight 0 graded around the well ends (no polygon)
  int dropped_tip_sites = 0;    ///< free sites dropped after sites moved or because their cell was unusable
  int split_boxes = 0;          ///< box sites replaced by per-polygon sites (sphere not empty / correction)
  int emptiness_fixes = 0;      ///< sites moved so that their sphere holds no other cavity vertex
  int hidden_repairs = 0;       ///< rebuilds after moving hidden internal sites
  int power_vertices = 0;       ///< distinct power vertices used by the cells (after exact merging)
  int merged_cells = 0;         ///< RT cells merged into another's power vertex (co-spherical sites)
  int exact_power_centers = 0;  ///< power vertices of nearly flat RT cells, computed exactly
  int coincident_vertices = 0;  ///< power vertices merged because they coincide numerically (< 1e-9 x size)
  int identified_vertices = 0;  ///< power vertices identified with a constrained vertex combinatorially
  int ambiguous_vertices = 0;   ///< of those, vertices whose sites shared an edge AB (nearest end taken)
  int free_vertices = 0;        ///< new nodes (transition-only vertices)
  int unmatched_external_faces = 0;  ///< external faces that are not exactly a constrained polygon (bug)
  int missing_polygons = 0;     ///< constrained polygons that are no face of any cell (bug)
  int faces = 0;                ///< distinct faces of the transition cells
  double max_identification_shift = 0;  ///< max distance power vertex -> identified constrained node (m)
  double max_snap_shift = 0;    ///< max distance power vertex -> snapped constrained node (m)
  double seconds_delaunay = 0, seconds_sites = 0, seconds_power = 0;  ///< wall time of the stages
  double seconds_optimize = 0;  ///< wall time of the site optimiser (0 when not run)
  SiteOptimizeReport optimization;
  int sliver_removals = 0;      ///< without optimisation: site moves that removed a sliver edge (docs/transition.md)
  int skew_steps = 0;           ///< without optimisation: site moves that left fewer faces above checkMesh's skewness limit
  int repairs = 0;              ///< without optimisation: site moves that mended cells failing a shape check
};

/// Transition cells of one cavity, ready for the builder.
struct TransitionCells {
  /// New (free) nodes; their global ids are base_node_id + index.
  std::vector<Vec3> new_nodes;
  int32_t base_node_id = 0;
  /// Cells as outward-oriented faces over GLOBAL node ids (constrained vertices keep the
  /// ids of the reservoir/well grids). Faces on a wellbore end cap carry its patch.
  std::vector<std::vector<CellFace>> cells;
  std::vector<Vec3> sites;        ///< FV centre of each cell (its site)
  std::vector<double> weights;    ///< power weight (radius) of each cell's site
  /// Q_S's h: mean edge length of the cell's constrained polygons; for a cell with none (a tip
  /// site's), the mean edge length of the cell's own faces.
  std::vector<double> h_ref;
  /// Per cell: the cavity face indices (constrained polygons) that are faces of this cell.
  std::vector<std::vector<int32_t>> cell_polygons;
  /// Per cell: its site's index in the cavity's site set (for the site optimiser).
  std::vector<int32_t> cell_site;
  /// Per new node: four of the sites whose power sphere it is the centre of (sorted; ids
  /// >= the site count are the far guard points).
  std::vector<std::array<int, 4>> new_node_sites;
  /// When optimised: the raw power diagram before the site optimiser (for before/after figures).
  std::shared_ptr<const TransitionCells> unoptimized;
  TransitionReport report;
};

/// Why the transition mesh of a cavity could not be built, as a value (docs/transition.md,
/// "Refusals"): some constrained polygon is not Delaunay admissible, the site correction
/// (5.5.3) does not converge (typically a large reservoir face close to a well), sites stay
/// hidden, or the diagram leaks. `cells_to_deactivate` are the active reservoir cells behind
/// the polygons involved: deactivating them moves that part of the cavity boundary away, after
/// which the caller may rebuild this cavity; empty when no reservoir cell is to blame.
struct TransitionRefusal {
  std::string reason;                        ///< "transition: ..." (one line)
  std::vector<int32_t> polygons;             ///< cavity face indices involved (sorted)
  std::vector<int32_t> cells_to_deactivate;  ///< reservoir linear cell indices (sorted, unique)
  std::vector<int32_t> wells;                ///< wells whose block polygons are involved (sorted, unique)
};

/// The transition of one cavity: its cells, or the refusal (then `cells` is empty).
struct TransitionOutcome {
  TransitionCells cells;
  std::optional<TransitionRefusal> refusal;
  bool ok() const { return !refusal; }
};

/// The stages' internal signal of a refusal (transition_sites.cpp, transition.cpp); meshed
/// callers get it as a TransitionRefusal from try_build_transition, tests may catch it from
/// build_transition.
class TransitionError : public std::runtime_error {
 public:
  TransitionError(const std::string& what, std::vector<int32_t> polygons_involved,
                  std::vector<int32_t> cells)
      : std::runtime_error(what), polygons(std::move(polygons_involved)), cells_to_deactivate(std::move(cells)) {}
  std::vector<int32_t> polygons;             ///< cavity face indices involved (sorted)
  std::vector<int32_t> cells_to_deactivate;  ///< reservoir linear cell indices (sorted, unique)
};

/// Builds the transition mesh of one cavity. `node_coords` holds the coordinates of all
/// global node ids (at least every cavity vertex). A cavity it cannot mesh is returned as a
/// refusal, never thrown.
TransitionOutcome try_build_transition(const Cavity& cavity, const std::vector<Vec3>& node_coords,
                                       const ReservoirGrid& grid, const std::vector<WellBlock>& blocks,
                                       int32_t base_node_id, const TransitionOptions& options = {});

/// try_build_transition for callers that want an exception: throws the refusal as a
/// TransitionError (a std::runtime_error) with its reason, polygons and cells.
TransitionCells build_transition(const Cavity& cavity, const std::vector<Vec3>& node_coords,
                                 const ReservoirGrid& grid, const std::vector<WellBlock>& blocks,
                                 int32_t base_node_id, const TransitionOptions& options = {});

/// The transition cells of one cavity as a PolyMesh of their own (cells in order; the cavity's
/// constrained polygons are its boundary faces). Node i of the result is global node
/// (*global_node)[i] (constrained ids, or base_node_id + k for new node k).
PolyMesh transition_submesh(const TransitionCells& cells, const std::vector<Vec3>& node_coords,
                            std::vector<int32_t>* global_node = nullptr);

/// The transition faces on the cavity's model polygons (FaceSide::Reservoir with a model cell
/// behind) whose Q_O is below `min_orthogonality_deg`, measured as fvcheck measures a face toward
/// a corner-point model cell: from the transition cell's site to the face's boundary flux point.
/// A power diagram puts a polygon's site over its circumcentre, which an obtuse triangle has
/// outside itself; near the plane the segment then leans. As a refusal naming those polygons and
/// the model cells behind them (deactivating them moves that wall away); nullopt when none fails.
std::optional<TransitionRefusal> model_wall_orthogonality_refusal(const TransitionCells& cells, const Cavity& cavity,
                                                                  const std::vector<Vec3>& node_coords,
                                                                  double min_orthogonality_deg);

/// Dual (Voronoi) edge parameters of each constrained polygon, found from the Delaunay
/// tetrahedra attached to it (paper 5.3): the internal Voronoi vertex is O + t_in n, the
/// external one O + t_out n (O circumcentre, n unit normal into the cavity; +-inf if none).
/// Exposed for tests (cross-check against a brute-force empty-sphere search).
struct PolygonDual {
  Vec3 center, normal;
  double radius = 0, t_in = 0, t_out = 0;
  int inner_tets = 0, outer_tets = 0;
};
std::vector<PolygonDual> polygon_duals(const Cavity& cavity, const std::vector<Vec3>& node_coords);

/// Constrained polygons whose internal Voronoi vertex is not inside the cavity (t_in <= 0:
/// a cavity vertex lies in the polygon's diametral sphere on the cavity side), or, for
/// polygons whose external site is a reflection (well side, outer boundary), whose
/// external Voronoi vertex is not outside (t_out >= 0). No site on the dual line can then
/// have an empty sphere, so build_transition refuses such a cavity; the caller enlarges it.
std::vector<int> non_admissible_polygons(const Cavity& cavity, const std::vector<Vec3>& node_coords);

}  // namespace hm
