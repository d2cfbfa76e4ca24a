// Internal stages of the transition mesh (paper 5.2-5.7), shared by the .cpp files of
// this folder. CGAL-free: the two CGAL stages (Delaunay of the cavity vertices, power
// diagram of the sites) live in their own translation units and talk through these types.
#pragma once
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "meshgen/cavity/cavity.hpp"
#include "meshgen/core/vec3.hpp"
#include "transition.hpp"

namespace hm::transition_detail {

/// Per face of `sub` (transition_submesh of t, `global` its node ids): the cavity polygon the face is
/// (a boundary face over exactly that polygon's nodes), among the polygons `wanted` accepts; else -1.
std::vector<int32_t> submesh_face_polygons(const PolyMesh& sub, const std::vector<int32_t>& global,
                                           const TransitionCells& t, const Cavity& cavity,
                                           const std::function<bool(int32_t)>& wanted);

constexpr double kInf = std::numeric_limits<double>::infinity();

/// Frame of one constrained polygon: the line through its circumcentre O along its unit
/// normal n (into the cavity) carries its Voronoi (dual) edge, points O + t n.
struct PolygonFrame {
  Vec3 center;           ///< O: centre of the least-squares circle through the nodes, in the mean plane
  Vec3 normal;           ///< n: unit, pointing into the cavity
  double radius = 0;     ///< rho: circumradius (least squares)
  double circle_error = 0;  ///< max | |X - O| - rho | over the nodes (0 when co-circular)
  double mean_edge = 0;  ///< mean edge length
  /// Voronoi vertices of the polygon on its dual line (5.3): t of the barycentre of the
  /// circumcentres of the attached Delaunay tetrahedra inside (t_in > 0) and outside
  /// (t_out < 0) the cavity; +-kInf when none was found.
  double t_in = kInf, t_out = -kInf;
  int inner_tets = 0, outer_tets = 0, sliver_tets = 0;
};

/// Least-squares circle of a polygon (exact for co-circular planar polygons).
PolygonFrame fit_polygon(const std::vector<int32_t>& nodes, const std::vector<Vec3>& coords);

/// Stage 5.2-5.3 (CGAL Delaunay_triangulation_3): fills t_in/t_out and the tet counts of
/// every frame from the tetrahedra attached to each polygon. Notes polygons that are not
/// Delaunay faces.
void attach_voronoi_edges(const Cavity& cavity, const std::vector<Vec3>& coords,
                          std::vector<PolygonFrame>& frames, std::vector<std::string>& notes);

enum class SiteKind : int {
  InternalBox = 0,      ///< centre of a deactivated reservoir cell, weight = half diagonal (fixed)
  InternalPolygon = 1,  ///< on one polygon's dual line, O + t n (movable)
  ExternalBox = 2,      ///< centre of an active reservoir cell, weight = half diagonal (fixed)
  ExternalMirror = 3,   ///< reflection of the polygon's internal site through O (5.4.2)
  Guard = 4,            ///< far point of weight 0 that bounds every cell
  /// Weight 0, strictly inside the cavity beyond a well's end, owns no constrained polygon
  /// (grades the cells around the tip, docs/transition.md "Tip sites").
  Free = 5,
  /// The mirror image of a site through an outer-boundary plane of the cavity (power diagram
  /// only, docs/transition.md "Outer-boundary planes"): same weight, image constrained vertices.
  Image = 6,
};

struct Site {
  SiteKind kind = SiteKind::InternalBox;
  Vec3 p;
  double w2 = 0;          ///< squared weight (CGAL's weight)
  bool alive = true;      ///< false once replaced (a split box)
  bool unchecked = true;  ///< sphere not yet checked empty since its last move
  int reservoir_cell = -1;  ///< boxes: reservoir linear cell index
  int polygon = -1;       ///< InternalPolygon / ExternalMirror: its polygon
  double t = 0;           ///< InternalPolygon: parameter on the dual line
  double t_cap = kInf;    ///< InternalPolygon: largest t the correction may grow it to (end faces)
  double clearance = 0;   ///< Free: distance it keeps from every other site's sphere
  int image_of = -1;      ///< Image: the site it reflects
  int plane = -1;         ///< Image: index of the plane in Cavity::mirrors
  std::vector<int> polygons;       ///< constrained polygons of this site (cavity face indices)
  std::vector<int32_t> vertices;   ///< sorted distinct global node ids of those polygons
  bool internal() const {
    return kind == SiteKind::InternalBox || kind == SiteKind::InternalPolygon || kind == SiteKind::Free;
  }
};

/// The images of a cavity's vertices through its outer-boundary planes. A vertex on a plane is
/// its own image; the others get ids from `first_image` on (past the caller's coordinates).
struct BoundaryImages {
  std::vector<MirrorPlane> planes;
  std::vector<int32_t> vertices;            ///< the cavity's own vertices, sorted
  std::vector<std::vector<int32_t>> image;  ///< [plane][i]: id of the image of vertices[i]
  int32_t first_image = 0;
  bool empty() const { return planes.empty(); }
  /// Sorted image ids of the given (own, sorted) vertex ids through plane k.
  std::vector<int32_t> image_of(int k, const std::vector<int32_t>& ids) const;
};

/// Appends the images of the cavity vertices that are off its planes to `cavity.vertices` and
/// `coords` (ids coords.size(), ...): every stage that keeps spheres empty or builds the
/// Delaunay of the vertices then sees the mirrored cavity too.
BoundaryImages add_boundary_images(Cavity& cavity, std::vector<Vec3>& coords);

struct SiteSet {
  std::vector<Site> sites;
  std::vector<int> internal_of;  ///< per polygon: its internal site
  std::vector<int> external_of;  ///< per polygon: its external site
  int splits = 0;                ///< boxes replaced by per-polygon sites
  int emptiness_fixes = 0;       ///< sites moved because their sphere held a cavity vertex
};

/// The sites that get an image through each outer-boundary plane (every live site but the guards),
/// in the order of the images' ids: the power diagram numbers the image of imaged_sites[i] through
/// plane k as set.sites.size() + k * imaged_sites.size() + i.
std::vector<int> imaged_sites(const SiteSet& set);

/// Places the internal polygon site s at O + t n with the weight of its constrained vertices
/// (and re-derives its reflection, if its polygon has one).
void place_polygon_site(SiteSet& set, int s, double t, const Cavity& cavity, const std::vector<Vec3>& coords,
                        const std::vector<PolygonFrame>& frames);
/// Admissible range of polygon q's internal site parameter t: above min_t the site stays apart
/// from its reflection; below max_t its sphere (and its reflection's) stays empty of other
/// cavity vertices and within the site's own cap.
double min_t(const std::vector<PolygonFrame>& frames, int q);
double max_t(const SiteSet& set, int q, const std::vector<PolygonFrame>& frames);

/// Stage 5.4: one site per deactivated cell (box) or per polygon, plus external sites.
SiteSet make_sites(const Cavity& cavity, const std::vector<Vec3>& coords, const ReservoirGrid& grid,
                   const std::vector<PolygonFrame>& frames, std::vector<std::string>& notes);

/// Keeps every site's sphere free of other cavity vertices (a conformity condition:
/// every constrained vertex must be a power vertex). Returns the number of fixes.
int enforce_empty_spheres(SiteSet& set, const Cavity& cavity, const std::vector<Vec3>& coords,
                          const ReservoirGrid& grid, const std::vector<PolygonFrame>& frames);

/// Stage 5.5.3: auto-centering correction. Returns the number of corrected pairs over all
/// iterations, sets *iterations; throws TransitionError when it does not converge.
int correct_sites(SiteSet& set, const Cavity& cavity, const std::vector<Vec3>& coords,
                  const ReservoirGrid& grid, const std::vector<PolygonFrame>& frames, int max_iterations,
                  int* iterations);

/// Active reservoir cells behind the given polygons (reservoir side: the outside cell; well
/// side: the outside cells of the reservoir polygons that share a vertex lying in the
/// polygon's diametral sphere on the cavity side), sorted and unique.
std::vector<int32_t> cells_behind(const Cavity& cavity, const std::vector<Vec3>& coords,
                                  const std::vector<PolygonFrame>& frames, const std::vector<int32_t>& polygons);

/// Moves a movable site toward its polygon (alpha in (0,1)) or splits a fixed box site;
/// used by the correction and by the hidden-site repair.
void shrink_or_split(SiteSet& set, int site, double alpha, const Cavity& cavity,
                     const std::vector<Vec3>& coords, const ReservoirGrid& grid,
                     const std::vector<PolygonFrame>& frames);

/// One end of a well block: the plane of its end faces (through `center`, normal `axis`
/// pointing away from the block) and the block's ring radii.
struct WellEnd {
  int well = -1;
  Vec3 center, axis;
  std::vector<double> radii;
  double end_length = 0;  ///< axial length of the block's segment at this end
};

/// The two ends of every block of a well in the cavity (blocks[k].well identifies it).
std::vector<WellEnd> well_ends(const Cavity& cavity, const std::vector<WellBlock>& blocks);

/// Tip grading (docs/transition.md "Tip sites"). Places the internal sites of the polygons on
/// each well block's end faces half an end segment above their polygon (the mirror of the ring
/// cells' FV centres), within their empty-sphere range, and caps their later growth there.
/// Returns the number of sites placed.
int place_end_face_sites(SiteSet& set, const Cavity& cavity, const std::vector<Vec3>& coords,
                         const std::vector<WellBlock>& blocks, const std::vector<PolygonFrame>& frames);

/// Replaces the Free sites of `set` by a new set: sites of weight 0 on the focal line of every
/// bend (cap_sites_off_bend_axes) and on half-shells around each well end of the cavity (radii growing geometrically from r_w with half the ring
/// ratio of the block), kept only where they are strictly inside the cavity, clear of every
/// cavity vertex and outside every other site's sphere (so every site stays in its own power
/// cell and no free site takes a constrained face). Returns the number of free sites.
int place_tip_sites(SiteSet& set, const Cavity& cavity, const std::vector<Vec3>& coords, const ReservoirGrid& grid,
                    const std::vector<WellBlock>& blocks);

/// Bends (docs/transition.md, "Bends"): lowers (and caps) the internal sites of the well polygons
/// whose spheres reach the focal line of a bend of their block (BendAxis), so that the free sites
/// place_tip_sites puts on that line fit. Returns the number of sites lowered.
int cap_sites_off_bend_axes(SiteSet& set, const Cavity& cavity, const std::vector<Vec3>& coords,
                            const std::vector<WellBlock>& blocks, const std::vector<PolygonFrame>& frames);

/// Drops the Free sites that an other site's sphere (grown by the free site's clearance) now
/// reaches, after sites moved (hidden-site repair), also through the outer-boundary planes.
/// Returns the number dropped.
int drop_blocked_tip_sites(SiteSet& set, const std::vector<MirrorPlane>& planes = {});

/// Free sites whose cells came out of the power diagram unusable: a face whose node set is also
/// another face's (after vertex identification; the builder would see a face named by three
/// cells) or a cell with fewer than 4 faces. `out` holds one cell per live internal site, in
/// site order.
std::vector<int> tip_sites_in_bad_cells(const SiteSet& set, const TransitionCells& out);

/// Internal sites whose cells share a face node set with two other faces, or twice within the
/// cell (after vertex identification, near-degenerate quadruples of sites can collapse two power
/// faces onto the same nodes). The builder would reject the mesh; the driver moves them instead.
std::vector<int> sites_in_duplicate_faces(const SiteSet& set, const TransitionCells& out);

/// Stage 5.6-5.7 (CGAL Regular_triangulation_3): power cells of the internal sites,
/// power vertices identified combinatorially, external faces snapped to the constrained
/// polygons. Fills `out` (cells, new nodes, report counters). Returns the ids of internal
/// sites that are hidden (no cell); nothing is emitted then. With outer-boundary planes every
/// site's image joins the diagram; the face between a site and its own image lies in the plane
/// and is emitted as an outer-boundary face (kOuterBoundary).
std::vector<int> build_power_cells(const SiteSet& set, const Cavity& cavity, const std::vector<Vec3>& coords,
                                   const std::vector<PolygonFrame>& frames, TransitionCells& out,
                                   const BoundaryImages& images = {});

/// The pairs (i, j), i < j, of `points` at most eps apart, each once, in no particular order: the
/// power vertices that rounding split (extraction). Near-linear: buckets, not all pairs.
std::vector<std::pair<int, int>> coincident_pairs(const std::vector<Vec3>& points, double eps);

/// A cavity's regular triangulation kept across the optimiser's rounds (CGAL inside the
/// .cpp): each call brings it to the sites of `set` by removing and inserting again only the
/// sites whose point or weight changed since the last call (from scratch the first time, when
/// the live sites changed, or after a site was hidden), then extracts the cells as
/// build_power_cells does (no boundary images). RT cells that no move touched keep their power
/// centres and their comparisons with their neighbours. The same result as build_power_cells on
/// the same sites, bit for bit: the regular triangulation does not depend on the order of
/// insertions and removals (CGAL's symbolic perturbation), and a power vertex is computed from
/// its cell's points taken in the order of their site ids.
class PowerDiagram {
 public:
  PowerDiagram();
  ~PowerDiagram();
  PowerDiagram(const PowerDiagram&) = delete;
  PowerDiagram& operator=(const PowerDiagram&) = delete;
  /// With outer-boundary planes (`images`), every live site's image joins the triangulation, as in
  /// build_power_cells.
  std::vector<int> cells(const SiteSet& set, const Cavity& cavity, const std::vector<Vec3>& coords,
                         const std::vector<PolygonFrame>& frames, TransitionCells& out,
                         const BoundaryImages& images = {});
  int moved_last() const { return moved_; }  ///< sites moved incrementally by the last call
  /// Keeps a copy of the triangulation as it is: a later call starts from the copy when it is
  /// nearer the sites (fewer sites to move), as when a round's refused moves are undone.
  void save();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_, saved_;
  int moved_ = 0;
};

/// What one site move did to the cells of its region (its cell and their face neighbours), measured on
/// the diagram before and after the round's rebuild.
struct MoveEffect {
  bool newly_failing = false;  ///< a cell of the region, or one sharing a node with the moved site's cell, fails a shape check it passed
  double q_s_before = 0, q_s_after = 0;          ///< sum of Q_S over the region
  int skewed_before = 0, skewed_after = 0;       ///< faces above checkMesh's skewness limit
  double worst_skew_before = 0, worst_skew_after = 0;
  int failing_before = 0, failing_after = 0;     ///< cells failing a shape check of the self-check
};
/// Why a site moves: to remove or expand a short edge, a step against a skewed face, a step of a
/// failing cell's site or of a neighbour's (repair), the removal of a sliver edge (remove_sliver_edges).
enum class MoveKind { ShortEdge, SkewStep, Repair, SliverRemoval };
/// Whether a move is kept: never when it makes a cell fail a shape check; a sliver removal whenever
/// nothing fails and no face around it newly exceeds checkMesh's skewness limit (which fails the mesh
/// there); else when it leaves fewer cells around it failing one (mending the raw diagram's
/// failures is a gain in itself); a repair for nothing else; a step against skewness must lower the
/// count of skewed faces or their worst, a short-edge move must raise Q_S without adding a skewed face.
bool move_is_kept(const MoveEffect& e, MoveKind kind);

/// The site optimiser (transition_optimize.cpp): rounds of independent site moves that
/// remove or expand short edges, each followed by a rebuild of the exact diagram; `out` is a
/// valid diagram of `set` on entry and on exit. Q_S's h is the entry diagram's h_ref.
/// `outside_centres`: per cavity face, the FV centre of the cell beyond it (NaN where not known), so
/// that a move may not turn a polygon face below fvcheck's orthogonality bound
/// (well_polygon_centres). Cavities without outer-boundary planes only.
SiteOptimizeReport optimize_sites(SiteSet& set, const Cavity& cavity, const std::vector<Vec3>& coords,
                                  const std::vector<PolygonFrame>& frames, const TransitionOptions& options,
                                  const std::vector<Vec3>& outside_centres, TransitionCells& out);
/// Without optimisation: only the removal of sliver edges (kSliverEdge, transition_optimize.cpp),
/// each kept unless a cell newly fails a shape check of the self-check. Returns the moves kept.
/// Cavities without outer-boundary planes only.
int remove_sliver_edges(SiteSet& set, const Cavity& cavity, const std::vector<Vec3>& coords,
                        const std::vector<PolygonFrame>& frames, const TransitionOptions& opt,
                        const std::vector<Vec3>& outside_centres, TransitionCells& out);
/// Without optimisation, after remove_sliver_edges: up to 24 rounds of the optimiser's moves against
/// checkMesh's skewness (a step of a skewed face's site, the removal of a short edge between free
/// vertices of a cell with a skewed face), each kept when the cells around have fewer skewed faces
/// (or the same count, a lower worst) and none newly fails a shape check or conformity, judged in
/// the local frame; a cell with an edge shorter than kSliverEdge x h fails too (the pass runs after
/// remove_sliver_edges). Returns the moves kept. `images`: as for repair_failing_cells.
int reduce_skewness(SiteSet& set, const Cavity& cavity, const std::vector<Vec3>& coords,
                    const std::vector<PolygonFrame>& frames, const TransitionOptions& opt,
                    const std::vector<Vec3>& outside_centres, const BoundaryImages& images,
                    TransitionCells& out);
/// Without optimisation, after remove_sliver_edges: rounds of repairs of the cells failing a shape
/// check of the self-check, while some fail and untried moves remain: the removal of a failing cell's
/// edge between two free vertices shorter than G2 h (nearly co-spherical sites), or a step of its site
/// or of a face neighbour's; each kept only if fewer cells around fail and none newly fails. Returns
/// the moves kept. `images`: the cavity's outer-boundary planes (add_boundary_images): every rebuild
/// adds the sites' images, a move that takes a site across a plane is refused, and a face in a plane
/// is judged as fvcheck judges a boundary face.
int repair_failing_cells(SiteSet& set, const Cavity& cavity, const std::vector<Vec3>& coords,
                         const std::vector<PolygonFrame>& frames, const TransitionOptions& opt,
                         const std::vector<Vec3>& outside_centres, const BoundaryImages& images,
                         TransitionCells& out);
/// Per cavity face: the FV centre of the well cell beyond a well polygon; NaN for every other face.
std::vector<Vec3> well_polygon_centres(const Cavity& cavity, const std::vector<WellBlock>& blocks);

}  // namespace hm::transition_detail
