// Optimisation of one cavity's transition mesh by moving its sites (docs/optimization.md).
// CGAL-free: every trial is a rebuild of the exact power diagram (build_power_cells), so the
// output stays a power diagram: planar faces, internal faces orthogonal to their site
// segments, the constrained polygons untouched.
//
// A short edge (u, v) of a power diagram joins the power centres of two tetrahedra of the
// regular triangulation that share a triangle ABC: u of ABCE, v of ABCD. Both lie on the line
// of equal power to A, B and C, and v moves along it when D moves. Placing v at a chosen point
// x of that line needs pow(x, D) = pow(x, A), one equation in D's parameter:
//  - a polygon site O + t n whose weight passes through its polygon's nodes X_i has
//    pow(x) = |x - O|^2 - R2 - 2 t n.(x - Xbar) (R2 = mean |O - X_i|^2): linear in t;
//  - its reflection O - t n: pow(x) = |x - O|^2 - R2 + 2 t n.(x - 2 O + Xbar);
//  - a free site of weight 0: moved radially about x to distance sqrt(pow(x, A)).
// x = u makes the five sites co-spherical: the edge vanishes (removal); x beyond v lengthens it
// (expansion). Boxes (reservoir cell centres) never move.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <utility>

#include "fvcheck/lib/checks.hpp"
#include "meshgen/core/fv_quality.hpp"
#include "meshgen/core/geometry.hpp"
#include "meshgen/core/mesh_positions.hpp"
#include "transition_internal.hpp"

namespace hm::transition_detail {

namespace {

// A power edge shorter than this fraction of its cells' reference length joins vertices that
// are distinct only because nearly co-spherical sites (a grid uniform to rounding) are not
// exactly so: the faces beside it are slivers whose plane the written coordinates cannot
// carry (docs/transition.md, "Sliver edges").
constexpr double kSliverEdge = 1e-5;

struct SiteState {
  Vec3 p;
  double w2 = 0, t = 0;
};

// One proposed site move: the site that moves (for a reflection, its internal partner) and
// the cells whose geometry it changes (its own and those sharing a node with it).
struct Move {
  int site = -1;
  SiteState before, after;
  std::vector<int> region;  // cells
  bool removal = false;
  MoveKind kind = MoveKind::ShortEdge;
  // The edge (power-sphere site quadruples of its ends; a constrained node as {-1,-1,-1,id})
  // and the site tried on it: a move refused once is not tried again.
  std::array<int, 9> tag{};
};

double power_of(const Site& s, Vec3 x) { return norm2(x - s.p) - s.w2; }

Vec3 mean_of(const std::vector<int32_t>& nodes, const std::vector<Vec3>& coords) {
  Vec3 m;
  for (int32_t v : nodes) m += coords[v];
  return m / static_cast<double>(nodes.size());
}

double mean_sq_distance(Vec3 p, const std::vector<int32_t>& nodes, const std::vector<Vec3>& coords) {
  double s = 0;
  for (int32_t v : nodes) s += norm2(coords[v] - p);
  return s / static_cast<double>(nodes.size());
}

// The live sites by their x at a round's start, for centred(): a site moved since then (a kept move)
// is within the drift of its entry, so a window of the sorted list widened by the drift holds every
// site near a point. Radii (sqrt w2) and clearances are bounded by their largest values so far.
class SiteSlab {
 public:
  void reset(const SiteSet& set) {
    by_x_.clear();
    start_x_.assign(set.sites.size(), 0.0);
    drift_ = max_radius_ = max_clearance_ = 0;
    for (size_t j = 0; j < set.sites.size(); ++j) {
      const Site& b = set.sites[j];
      if (!b.alive || b.kind == SiteKind::Guard) continue;
      by_x_.push_back({b.p.x, static_cast<int>(j)});
      start_x_[j] = b.p.x;
      max_radius_ = std::max(max_radius_, std::sqrt(b.w2));
      max_clearance_ = std::max(max_clearance_, b.clearance);
    }
    std::sort(by_x_.begin(), by_x_.end());
  }
  // Site j now where it is in `set` (a kept move or its undoing).
  void moved(const SiteSet& set, int j) {
    const Site& b = set.sites[j];
    drift_ = std::max(drift_, std::abs(b.p.x - start_x_[j]));
    max_radius_ = std::max(max_radius_, std::sqrt(b.w2));
  }
  // Calls f(j) for every live site j whose x may be within `reach` of x (and some beyond).
  template <class F>
  bool all_of_near(double x, double reach, F f) const {
    const double w = reach + drift_ + 1e-9 * (reach + std::abs(x));  // |x_j - x| <= distance, to rounding
    auto it = std::lower_bound(by_x_.begin(), by_x_.end(), std::make_pair(x - w, std::numeric_limits<int>::min()));
    for (; it != by_x_.end() && it->first <= x + w; ++it)
      if (!f(it->second)) return false;
    return true;
  }
  double max_radius() const { return max_radius_; }
  double max_clearance() const { return max_clearance_; }

 private:
  std::vector<std::pair<double, int>> by_x_;
  std::vector<double> start_x_;
  double drift_ = 0, max_radius_ = 0, max_clearance_ = 0;
};

// Condition (6) of paper 5.5.1 for sites a and b: where two spheres overlap, the radical plane must
// not pass beyond the smaller-weight (internal) site. A free site also keeps its clearance from every
// other sphere, and every sphere from it.
bool centred_pair(const Site& a, const Site& b) {
  const double d2 = norm2(a.p - b.p);
  if (a.kind == SiteKind::Free && b.kind != SiteKind::Free && std::sqrt(d2) < std::sqrt(b.w2) + a.clearance) return false;
  if (b.kind == SiteKind::Free && a.kind != SiteKind::Free && std::sqrt(d2) < std::sqrt(a.w2) + b.clearance) return false;
  if (d2 > std::max(a.w2, b.w2)) return true;
  const Site& small = a.w2 > b.w2 ? b : a;
  return !(small.internal() && std::abs(a.w2 - b.w2) > d2);
}

// Condition (6) for site s (a trial position) against every other live site. Only sites within
// max(radii) + max(clearances) of s can break it: those of the slab's window, where every site but
// s and the mirror that moves with it stands as the slab knows; that mirror is checked by itself.
bool centred(const SiteSet& set, int s, const SiteSlab& slab) {
  const Site& a = set.sites[s];
  const int mirror = a.kind == SiteKind::InternalPolygon ? set.external_of[a.polygon] : -1;
  if (mirror >= 0 && set.sites[mirror].alive && set.sites[mirror].kind != SiteKind::Guard &&
      !centred_pair(a, set.sites[mirror]))
    return false;
  const double reach = std::max(std::sqrt(a.w2), slab.max_radius()) + std::max(a.clearance, slab.max_clearance());
  return slab.all_of_near(a.p.x, reach, [&](int j) {
    const Site& b = set.sites[j];
    return j == s || j == mirror || !b.alive || b.kind == SiteKind::Guard || centred_pair(a, b);
  });
}

// Per cell: its faces shared with another transition cell whose OpenFOAM skewness exceeds
// checkMesh's limit (exact on the submesh: both cell centroids are there).
// Also (max_skew) the largest such skewness per cell, 0 if none is above the limit.
std::vector<int> skewed_faces_of_cells(const PolyMesh& sub, std::vector<int>* skewed_faces = nullptr,
                                       std::vector<double>* max_skew = nullptr) {
  const std::vector<double> sk = openfoam_face_skewness(sub);
  std::vector<int> per_cell(sub.n_cells(), 0);
  if (max_skew) max_skew->assign(sub.n_cells(), 0.0);
  std::vector<std::pair<double, int>> worst;
  for (int f = 0; f < sub.n_faces(); ++f)
    if (sub.face_neighbour[f] >= 0 && sk[f] > kOpenFoamSkewnessLimit) {
      ++per_cell[sub.face_owner[f]], ++per_cell[sub.face_neighbour[f]];
      if (max_skew)
        for (int c : {sub.face_owner[f], sub.face_neighbour[f]}) (*max_skew)[c] = std::max((*max_skew)[c], sk[f]);
      worst.push_back({-sk[f], f});
    }
  std::sort(worst.begin(), worst.end());
  if (skewed_faces) {
    skewed_faces->clear();
    for (const auto& w : worst) skewed_faces->push_back(w.second);
  }
  return per_cell;
}

// The transition cells of a diagram's submesh that fail a shape check the self-check applies to
// the written mesh (meshgen/pipeline/self_check.cpp, fvcheck's checks at their defaults):
// convexity, the FV centre (the site) inside, orthogonality of the faces between two transition
// cells and of the faces on well polygons (toward the well cell's FV centre, which the submesh
// does not hold: shape_failures is given it), planarity of every face.
struct ShapeFailures {
  std::vector<char> cell;
  int64_t count = 0;  ///< failing cells
};

// Marks both cells of each face the submesh's conformity check flags (a node on a face it is not a
// corner of, a face shared by more than two cells, an open cell).
void mark_nonconforming(const PolyMesh& sub, ShapeFailures& f) {
  const CheckResult r = check_conformity(sub, compute_geometry(sub), CheckOptions{});
  for (int c = 0; c < sub.n_cells(); ++c) f.cell[c] |= r.values[c] > 0;
  f.count = std::count(f.cell.begin(), f.cell.end(), 1);
}

// Marks each cell of the submesh with an edge shorter than kSliverEdge x its h_ref.
void mark_sliver_edges(const PolyMesh& sub, const std::vector<double>& h_ref, ShapeFailures& f) {
  for (int c = 0; c < sub.n_cells(); ++c)
    for (const int32_t* fp = sub.cell_begin(c); fp != sub.cell_end(c) && !f.cell[c]; ++fp) {
      const int k = sub.face_size(*fp);
      const int32_t* v = sub.face_begin(*fp);
      for (int i = 0; i < k; ++i)
        if (norm(sub.nodes[v[i]] - sub.nodes[v[(i + 1) % k]]) < kSliverEdge * h_ref[c]) f.cell[c] = 1;
    }
  f.count = std::count(f.cell.begin(), f.cell.end(), 1);
}

// Marks the cells of a submesh that fail convexity or the FV centre inside, and both cells of each
// face that fails planarity (fvcheck's checks at their defaults): the shape checks whose verdict a
// permeability frame's map can change (angles, relative tolerances; written_frame_failures).
void mark_affine_shape_failures(const PolyMesh& sub, const MeshGeometry& geo, std::vector<char>& cell) {
  const CheckOptions opt;
  for (const CheckResult& r : {check_convexity(sub, geo, opt), check_auto_centering(sub, geo, opt)})
    for (int c = 0; c < sub.n_cells(); ++c) cell[c] |= r.failing[c];
  const CheckResult planarity = check_planarity(sub, geo, opt);
  for (int f = 0; f < sub.n_faces(); ++f)
    if (planarity.failing[f]) {
      cell[sub.face_owner[f]] = 1;
      if (sub.face_neighbour[f] >= 0) cell[sub.face_neighbour[f]] = 1;
    }
}

// Whether every node of the submesh's face f lies in one of the outer-boundary planes (the
// extraction puts the free vertices of those faces in the plane exactly).
bool in_outer_plane(const PolyMesh& sub, int f, const std::vector<MirrorPlane>& planes) {
  for (const MirrorPlane& m : planes) {
    bool all = true;
    for (const int32_t* v = sub.face_begin(f); v != sub.face_end(f) && all; ++v) all = sub.nodes[*v][m.axis] == m.value;
    if (all) return true;
  }
  return false;
}

// A boundary face of the submesh is a cavity polygon or lies in an outer-boundary plane. Where
// the FV centre beyond a polygon is known (outside_centres, a well cell's), its Q_O is checked
// too, as fvcheck measures it on the written mesh: from the transition cell's site to that
// centre; a face in an outer-boundary plane is checked as fvcheck checks a boundary face (to its
// boundary flux point).
ShapeFailures shape_failures(const PolyMesh& sub, const std::vector<int32_t>& global, const TransitionCells& t,
                             const Cavity& cavity, const std::vector<Vec3>& outside_centres,
                             const std::vector<MirrorPlane>& planes) {
  ShapeFailures out;
  out.cell.assign(sub.n_cells(), 0);
  const MeshGeometry geo = compute_geometry(sub);
  const CheckOptions opt;
  for (int f = 0; f < sub.n_faces() && !planes.empty(); ++f)
    if (sub.face_neighbour[f] < 0 && in_outer_plane(sub, f, planes) &&
        face_orthogonality_of(sub, geo, f, boundary_flux_point(sub, geo, f)) < opt.min_orthogonality_deg)
      out.cell[sub.face_owner[f]] = 1;
  if (!outside_centres.empty()) {
    const std::vector<int32_t> polygon = submesh_face_polygons(
        sub, global, t, cavity, [&](int32_t q) { return std::isfinite(outside_centres[q].x); });
    for (int f = 0; f < sub.n_faces(); ++f)
      if (polygon[f] >= 0 &&
          face_orthogonality_of(sub, geo, f, outside_centres[polygon[f]]) < opt.min_orthogonality_deg)
        out.cell[sub.face_owner[f]] = 1;
  }
  mark_affine_shape_failures(sub, geo, out.cell);
  const std::vector<double> qo = face_orthogonality(sub, geo);
  for (int f = 0; f < sub.n_faces(); ++f)
    if (sub.face_neighbour[f] >= 0 && qo[f] < opt.min_orthogonality_deg)
      out.cell[sub.face_owner[f]] = 1, out.cell[sub.face_neighbour[f]] = 1;
  out.count = std::count(out.cell.begin(), out.cell.end(), 1);
  return out;
}

// A submesh built in permeability frame f at physical positions.
PolyMesh physical_submesh(PolyMesh sub, const PermeabilityFrame& f) {
  for (Vec3& p : sub.nodes) p = to_physical(f, p);
  for (Vec3& p : sub.cell_fv_center) p = to_physical(f, p);
  return sub;
}

// The cells of a submesh built in permeability frame f (not the identity) that fail convexity, the
// FV centre inside or planarity once moved back to physical positions (to_physical) and rounded as
// written about `origin`, where fvcheck judges them; orthogonality, which the K metric keeps, is
// judged in the frame (shape_failures).
std::vector<char> written_frame_failures(PolyMesh sub, const PermeabilityFrame& f, Vec3 origin) {
  sub = physical_submesh(std::move(sub), f);
  round_to_written_frame(sub, origin);
  std::vector<char> cell(sub.n_cells(), 0);
  mark_affine_shape_failures(sub, compute_geometry(sub), cell);
  return cell;
}

// Node -> cells (CSR, cells ascending) and edge -> cells ((a, b, cell) with a < b, sorted) over a
// submesh's node ids: built per node in cell order, so only each node's short list is sorted.
struct Incidence {
  std::vector<int> node_ptr, node_cells;
  std::vector<std::array<int32_t, 3>> edge_cell;
};
Incidence incidence_of(const PolyMesh& sub) {
  const int nc = sub.n_cells(), nn = sub.n_nodes();
  Incidence inc;
  std::vector<int> count(nn + 1, 0), last_cell(nn, -1), edge_count(nn + 1, 0);
  auto for_each_corner = [&](auto&& visit) {  // (cell, node, next node of the face)
    for (int c = 0; c < nc; ++c)
      for (const int32_t* f = sub.cell_begin(c); f != sub.cell_end(c); ++f) {
        const int k = sub.face_size(*f);
        const int32_t* v = sub.face_begin(*f);
        for (int i = 0; i < k; ++i) visit(c, v[i], v[(i + 1) % k]);
      }
  };
  for_each_corner([&](int c, int32_t a, int32_t b) {
    if (last_cell[a] != c) last_cell[a] = c, ++count[a + 1];
    ++edge_count[std::min(a, b) + 1];
  });
  for (int v = 0; v < nn; ++v) count[v + 1] += count[v], edge_count[v + 1] += edge_count[v];
  inc.node_ptr = count;
  inc.node_cells.resize(count[nn]);
  std::vector<std::pair<int32_t, int32_t>> edges(edge_count[nn]);  // per smaller node: (larger node, cell)
  std::fill(last_cell.begin(), last_cell.end(), -1);
  for_each_corner([&](int c, int32_t a, int32_t b) {
    if (last_cell[a] != c) last_cell[a] = c, inc.node_cells[count[a]++] = c;
    edges[edge_count[std::min(a, b)]++] = {std::max(a, b), c};
  });
  inc.edge_cell.reserve(edges.size());
  for (int a = 0, first = 0; a < nn; ++a) {
    const int last = edge_count[a];  // filled: now the end of node a's range
    std::sort(edges.begin() + first, edges.begin() + last);
    for (int i = first; i < last; ++i)
      if (i == first || edges[i] != edges[i - 1]) inc.edge_cell.push_back({a, edges[i].first, edges[i].second});
    first = last;
  }
  return inc;
}

// The moved sites whose cells share a node, in `before` or in `after` (two diagrams of the same
// sites: cell c is the same site's in both), with a cell flagged in `cells`. Sets *unattributed when
// a flagged cell has no such neighbour.
std::vector<char> moved_sites_sharing_a_node(const std::vector<char>& cells, const PolyMesh& before, const PolyMesh& after,
                                             const std::vector<int>& cell_site, const std::vector<char>& moved,
                                             bool* unattributed) {
  std::vector<char> blamed(moved.size(), 0), found(cells.size(), 0);
  *unattributed = false;
  if (std::find(cells.begin(), cells.end(), 1) == cells.end()) return blamed;
  for (const PolyMesh* m : {&before, &after}) {
    const Incidence inc = incidence_of(*m);
    for (size_t c = 0; c < cells.size(); ++c) {
      if (!cells[c]) continue;
      for (const int32_t* f = m->cell_begin(static_cast<int>(c)); f != m->cell_end(static_cast<int>(c)); ++f)
        for (const int32_t* v = m->face_begin(*f); v != m->face_end(*f); ++v)
          for (int k = inc.node_ptr[*v]; k < inc.node_ptr[*v + 1]; ++k) {
            const int site = cell_site[inc.node_cells[k]];
            if (moved[site]) blamed[site] = 1, found[c] = 1;
          }
    }
  }
  for (size_t c = 0; c < cells.size(); ++c) *unattributed = *unattributed || (cells[c] && !found[c]);
  return blamed;
}

// Appends cell c and its face neighbours to the sorted set `cells`.
void add_cell_and_neighbours(const PolyMesh& sub, int c, std::vector<int>& cells) {
  cells.push_back(c);
  for (const int32_t* f = sub.cell_begin(c); f != sub.cell_end(c); ++f) {
    const int o = sub.face_owner[*f], n = sub.face_neighbour[*f];
    if (n >= 0) cells.push_back(o == c ? n : o);
  }
  std::sort(cells.begin(), cells.end());
  cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
}

// What a SiteOptimizer's rounds propose: every kind of move (optimize_sites), removals of sliver
// edges alone (remove_sliver_edges), steps against checkMesh's skewness alone (reduce_skewness), or
// repairs of cells failing a shape check alone (repair_failing_cells).
enum class Pass { Optimize, Slivers, Skewness, Repairs };

const BoundaryImages kNoImages{};  // the optimiser and the sliver pass: cavities without boundary planes

class SiteOptimizer {
 public:
  SiteOptimizer(SiteSet& set, const Cavity& cavity, const std::vector<Vec3>& coords,
                const std::vector<PolygonFrame>& frames, const std::vector<double>& h_ref,
                const TransitionOptions& opt, const std::vector<Vec3>& outside_centres, const BoundaryImages& images,
                Pass pass = Pass::Optimize)
      : set_(set), cavity_(cavity), coords_(coords), frames_(frames), h_ref_(h_ref), opt_(opt),
        outside_centres_(outside_centres), images_(images), pass_(pass) {
    for (const MirrorPlane& m : images_.planes)
      for (const Site& s : set_.sites) side_.push_back(plane_side(s.p, m));
    // Repairs judge the cells as written (TransitionOptions::written_origin): the well cells'
    // centres beyond their faces too.
    if (judges_as_written())
      for (Vec3& c : outside_centres_)
        if (std::isfinite(c.x)) c = as_written(c, opt_.written_origin);
  }

  // One round on `out` (a valid diagram of set_): true if some move was kept.
  // skew_only: only steps against skewed faces and repairs. Sets skewed_left() to the count on
  // entry, proposed_last() to the moves proposed.
  bool round(TransitionCells& out, SiteOptimizeReport& rep, bool skew_only);
  int skewed_left() const { return skewed_left_; }
  double worst_skew_left() const { return worst_skew_left_; }  // the worst of them (0 if none)
  int proposed_last() const { return proposed_last_; }
  // Cells of the diagram a round left that fail a shape check (-1 before the first round).
  int64_t failing_now() const { return next_ ? next_->failing.count : -1; }
  // Faces above checkMesh's limit in the diagram a round left (-1 before the first round).
  int64_t skewed_now() const { return next_ ? static_cast<int64_t>(next_->skewed_faces.size()) : -1; }
  // Lets the moves against skewness refused so far be tried again: each was judged on the diagram of
  // its round, and the moves kept since have reshaped the cells around many of them. Returns how many.
  int forget_refused_skew_moves() {
    int n = 0;
    for (auto it = refused_.begin(); it != refused_.end();)
      if (it->second == MoveKind::SkewStep) it = refused_.erase(it), ++n;
      else ++it;
    return n;
  }

 private:
  Vec3 node(const TransitionCells& t, int32_t v) const {
    return v >= t.base_node_id ? t.new_nodes[v - t.base_node_id] : coords_[v];
  }
  bool rebuild(TransitionCells& fresh, int32_t base);
  // The repairs judge the cells where the self-check does. The skewness pass judges them in the
  // local frame: at the written positions its decisions would depend on where the model sits.
  bool judges_as_written() const { return pass_ == Pass::Repairs; }
  // A diagram's submesh (local node ids, `global` mapping them back), Q_S per cell, skewed
  // faces (worst first), their count and the worst skewness per cell.
  struct Measured {
    PolyMesh sub;
    std::vector<int32_t> global;
    std::vector<double> qs, max_skew;
    std::vector<int> skewed, skewed_faces;
    ShapeFailures failing;
  };
  Measured measure(const TransitionCells& t) const {
    Measured m;
    m.sub = transition_submesh(t, coords_, &m.global);
    if (judges_as_written()) round_to_written_frame(m.sub, opt_.written_origin);
    m.qs = cell_shape_quality(m.sub, h_ref_);
    // checkMesh measures skewness where the mesh is written: a permeability frame's at physical positions.
    if (opt_.frame.identity()) m.skewed = skewed_faces_of_cells(m.sub, &m.skewed_faces, &m.max_skew);
    else m.skewed = skewed_faces_of_cells(physical_submesh(m.sub, opt_.frame), &m.skewed_faces, &m.max_skew);
    m.failing = shape_failures(m.sub, m.global, t, cavity_, outside_centres_, images_.planes);
    // Its removals can put a free vertex on a face it is not a corner of (seed 3348), or leave an
    // edge of a sliver's size (seed 2380).
    if (pass_ == Pass::Skewness) {
      mark_nonconforming(m.sub, m.failing);
      mark_sliver_edges(m.sub, h_ref_, m.failing);
    }
    if (judges_as_written() && !opt_.frame.identity()) {
      const std::vector<char> written = written_frame_failures(m.sub, opt_.frame, opt_.frame_written_origin);
      for (size_t c = 0; c < written.size(); ++c) m.failing.cell[c] |= written[c];
      m.failing.count = std::count(m.failing.cell.begin(), m.failing.cell.end(), 1);
    }
    return m;
  }
  // A round's moves on the diagram `out` measured as `now`, in the pass's order of priority, at most
  // one in a region and none refused before; their sites are moved.
  std::vector<Move> propose(const TransitionCells& out, const Measured& now, const std::vector<int>& cell_of_site,
                            bool skew_only);
  // The moves (their regions in both diagrams) kept by what they did from `now` to `after`, the
  // diagram `fresh` rebuilt with them (move_is_kept); the others' sites restored, their tags refused.
  std::vector<Move> judge(const std::vector<Move>& moves, const TransitionCells& out, const Measured& now,
                          const TransitionCells& fresh, const Measured& after);
  // The cells of `after` (a diagram of the same sites, so the same cell per site) that fail a
  // shape check while the same site's cell in `before` did not.
  static std::vector<char> new_failures(const TransitionCells& t_before, const Measured& before,
                                        const TransitionCells& t_after, const Measured& after) {
    std::vector<char> bad_site;
    for (size_t c = 0; c < t_before.cell_site.size(); ++c)
      if (before.failing.cell[c]) {
        if (bad_site.size() <= static_cast<size_t>(t_before.cell_site[c])) bad_site.resize(t_before.cell_site[c] + 1, 0);
        bad_site[t_before.cell_site[c]] = 1;
      }
    std::vector<char> out(after.failing.cell.size(), 0);
    for (size_t c = 0; c < out.size(); ++c) {
      const size_t site = static_cast<size_t>(t_after.cell_site[c]);
      out[c] = after.failing.cell[c] && !(site < bad_site.size() && bad_site[site]);
    }
    return out;
  }
  static std::array<int, 4> key_of(const TransitionCells& t, int32_t v) {
    return v >= t.base_node_id ? t.new_node_sites[v - t.base_node_id] : std::array<int, 4>{-1, -1, -1, v};
  }
  // The site that moves when site s does: a polygon's internal site for its mirror.
  int mover_of(int s) const {
    const Site& site = set_.sites[s];
    if (site.kind == SiteKind::ExternalMirror && site.polygon >= 0) return set_.internal_of[site.polygon];
    return s;
  }
  // The movable sites of a removal's two power spheres (its tag's two quadruples); an image
  // through an outer-boundary plane stands for its site.
  std::vector<int> sphere_movers(const std::array<int, 9>& tag) const {
    std::vector<int> out;
    const int ns = static_cast<int>(set_.sites.size());
    for (int k = 0; k < 8; ++k) {
      if (tag[k / 4 * 4] < 0) continue;  // {-1, -1, -1, node}: a constrained node, no sphere
      int s = tag[k];
      const int images = static_cast<int>(image_origin_.size()) * static_cast<int>(images_.planes.size());
      if (s >= ns) s = s - ns < images ? image_origin_[(s - ns) % image_origin_.size()] : -1;
      if (s >= 0 && mover_of(s) >= 0) out.push_back(mover_of(s));
    }
    return out;
  }
  void number_images() { image_origin_ = images_.empty() ? std::vector<int>{} : imaged_sites(set_); }
  SiteState state(int s) const { return {set_.sites[s].p, set_.sites[s].w2, set_.sites[s].t}; }
  void restore(int s, const SiteState& st) {
    Site& site = set_.sites[s];
    if (site.kind == SiteKind::InternalPolygon) place_polygon_site(set_, s, st.t, cavity_, coords_, frames_);
    else site.p = st.p, site.w2 = st.w2;
    track(s);
  }
  // The slab follows site s, and the mirror that moves with a polygon site.
  void track(int s) {
    slab_.moved(set_, s);
    const Site& site = set_.sites[s];
    if (site.kind == SiteKind::InternalPolygon && set_.external_of[site.polygon] >= 0)
      slab_.moved(set_, set_.external_of[site.polygon]);
  }
  // The move of site d (or of its partner) that puts the power vertex it shares with
  // reference site a at x; false if it leaves the admissible range widened by `range_slack`
  // on either side. Changes nothing.
  bool trial_move(int d, int a, Vec3 x, double max_shift, double range_slack, Move* m);
  // A step of site s: a polygon site toward (or away from) its polygon by the correction's
  // factor 0.95 (size 2: 0.8), a free site toward (or away from) `other` by a tenth (a fifth)
  // of their distance. Small steps first: sites left by the correction at the edge of
  // condition (6) only allow those.
  // `level` > 0: a streak's step (SkewStreak), the polygon factor raised to the power 2^level, the
  // free site's fraction times 2^level (at most 0.4).
  bool trial_step(int s, int other, bool away, int size, Move* m, int level = 0);
  // That step as a move against skewness, tagged {-2, s, tag_other, k, level}; none (site -1) if that
  // tag was refused before or the step leaves condition (6).
  Move skew_step(int s, int other, int tag_other, int k, bool away, int size, int level) {
    Move m;
    m.tag = {-2, s, tag_other, k, level, 0, 0, 0, 0};
    m.kind = MoveKind::SkewStep;
    if (refused(m.tag) || !trial_step(s, other, away, size, &m, level)) return Move{};
    return m;
  }

  SiteSet& set_;
  const Cavity& cavity_;
  const std::vector<Vec3>& coords_;
  const std::vector<PolygonFrame>& frames_;
  const std::vector<double>& h_ref_;
  const TransitionOptions& opt_;
  std::vector<Vec3> outside_centres_;  // a copy: the repairs round them (as written)
  const BoundaryImages& images_;
  std::vector<int> image_origin_;  // imaged_sites: the site of image ns + k * size + i is [i]
  std::vector<int> side_;  // [plane * sites + site]: the side of each outer-boundary plane a site starts on
  static int plane_side(Vec3 p, const MirrorPlane& m) { return p[m.axis] < m.value ? -1 : p[m.axis] > m.value ? 1 : 0; }
  // Every site on the side of each outer-boundary plane it started on: its image stays beyond it.
  bool sites_keep_their_sides() const {
    const size_t n = set_.sites.size();
    for (size_t k = 0; k < images_.planes.size(); ++k)
      for (size_t s = 0; s < n; ++s)
        if (set_.sites[s].alive && plane_side(set_.sites[s].p, images_.planes[k]) != side_[k * n + s]) return false;
    return true;
  }
  // Moves refused (by tag, with their kind): not tried again, unless the rounds against skewness stall
  // (forget_refused_skew_moves).
  std::map<std::array<int, 9>, MoveKind> refused_;
  bool refused(const std::array<int, 9>& tag) const { return refused_.count(tag) > 0; }
  void refuse(const Move& m) { refused_.emplace(m.tag, m.kind); }
  SiteSlab slab_;  // the sites by x, for centred(): reset at each round's start
  PowerDiagram diagram_;  // the cavity's regular triangulation, kept across rounds and rebuilds
  // A site's run of kept steps against skewed faces (its own face's or a neighbour's; the same other
  // site, direction and size): each one kept doubles the next step's exponent, up to kMaxStreak; a
  // refused one ends the run (docs/optimization.md, "Streaks").
  struct SkewStreak {
    int other = -1, k = 0, level = 0;
  };
  static constexpr int kMaxStreak = 4;
  std::vector<SkewStreak> streak_;
  SkewStreak streak_of(int s) const { return static_cast<size_t>(s) < streak_.size() ? streak_[s] : SkewStreak{}; }
  void record_streak(const Move& m, bool kept) {
    if (m.kind != MoveKind::SkewStep || m.tag[0] != -2) return;  // steps, not removals
    if (streak_.size() <= static_cast<size_t>(m.site)) streak_.resize(m.site + 1);
    streak_[m.site] = kept ? SkewStreak{m.tag[2], m.tag[3], std::min(m.tag[4] + 1, kMaxStreak)} : SkewStreak{};
  }
  int skewed_left_ = 0;
  double worst_skew_left_ = 0;
  int proposed_last_ = 0;
  // Pass::Slivers: only removals of sliver edges (below kSliverEdge h), kept unless a cell newly
  // fails a shape check: the pass run on a diagram that is not optimised (remove_sliver_edges).
  Pass pass_ = Pass::Optimize;
  std::optional<Measured> next_;  // the measurement of the diagram the last round left in `out`
};

bool SiteOptimizer::rebuild(TransitionCells& fresh, int32_t base) {
  fresh = TransitionCells{};
  fresh.base_node_id = base;
  if (!sites_keep_their_sides()) return false;
  if (!diagram_.cells(set_, cavity_, coords_, frames_, fresh, images_).empty()) return false;
  const TransitionReport& r = fresh.report;
  if (r.unmatched_external_faces > 0 || r.missing_polygons > 0) return false;
  for (const auto& cell : fresh.cells)
    if (cell.size() < 4) return false;
  return tip_sites_in_bad_cells(set_, fresh).empty();
}

bool SiteOptimizer::trial_move(int d, int a, Vec3 x, double max_shift, double range_slack, Move* m) {
  const Site& ds = set_.sites[d];
  const double target = power_of(set_.sites[a], x);
  int mover = d;
  if (ds.kind == SiteKind::InternalPolygon || ds.kind == SiteKind::ExternalMirror) {
    const int q = ds.polygon;
    mover = set_.internal_of[q];
    if (mover < 0 || set_.sites[mover].kind != SiteKind::InternalPolygon) return false;
    const Vec3 o = frames_[q].center, n = frames_[q].normal;
    const Vec3 xbar = mean_of(cavity_.faces[q].nodes, coords_);
    const double r2 = mean_sq_distance(o, cavity_.faces[q].nodes, coords_);
    const double slope = ds.kind == SiteKind::InternalPolygon ? -2.0 * dot(n, x - xbar) : 2.0 * dot(n, x - 2.0 * o + xbar);
    if (!(std::abs(slope) > 0)) return false;
    const double t = (target - norm2(x - o) + r2) / slope;
    if (!(t >= min_t(frames_, q) - range_slack && t <= max_t(set_, q, frames_) + range_slack)) return false;
    if (std::abs(t - set_.sites[mover].t) > max_shift) return false;
    m->site = mover;
    m->before = state(mover);
    place_polygon_site(set_, mover, t, cavity_, coords_, frames_);
  } else if (ds.kind == SiteKind::Free) {
    if (!(target > 0)) return false;
    const Vec3 away = ds.p - x;
    const double len = norm(away);
    if (!(len > 0)) return false;
    const Vec3 p = x + (std::sqrt(target) / len) * away;
    if (norm(p - ds.p) > max_shift) return false;
    m->site = d;
    m->before = state(d);
    set_.sites[d].p = p;
  } else {
    return false;
  }
  const bool ok = centred(set_, mover, slab_);
  m->after = state(mover);
  restore(mover, m->before);
  return ok;
}

bool SiteOptimizer::trial_step(int s, int other, bool away, int size, Move* m, int level) {
  const Site& site = set_.sites[s];
  m->site = s;
  m->before = state(s);
  if (site.kind == SiteKind::InternalPolygon) {
    const int q = site.polygon;
    const double kStep = std::pow(size == 1 ? 0.95 : 0.8, 1 << level);
    const double t = away ? std::min(site.t / kStep, max_t(set_, q, frames_)) : std::max(site.t * kStep, min_t(frames_, q));
    if (!(std::abs(t - site.t) > 1e-3 * site.t)) return false;
    place_polygon_site(set_, s, t, cavity_, coords_, frames_);
  } else if (site.kind == SiteKind::Free) {
    const Vec3 d = site.p - set_.sites[other].p;
    set_.sites[s].p = site.p + (away ? 0.1 : -0.1) * std::min(size * (1 << level), 4) * d;
  } else {
    return false;
  }
  const bool ok = centred(set_, s, slab_);
  m->after = state(s);
  restore(s, m->before);
  return ok;
}

std::vector<Move> SiteOptimizer::propose(const TransitionCells& out, const Measured& now,
                                         const std::vector<int>& cell_of_site, bool skew_only) {
  const std::vector<int32_t>& global = now.global;
  const PolyMesh& sub = now.sub;
  const std::vector<int>& skewed_faces = now.skewed_faces;
  const std::vector<int>& skewed = now.skewed;
  const int nc = sub.n_cells();
  const Incidence inc = incidence_of(sub);
  const std::vector<std::array<int32_t, 3>>& edge_cell = inc.edge_cell;
  auto cells_of_node = [&](int32_t v) {
    return std::vector<int>(inc.node_cells.begin() + inc.node_ptr[v], inc.node_cells.begin() + inc.node_ptr[v + 1]);
  };
  const int ns = static_cast<int>(set_.sites.size());
  // The cells whose geometry a move of `site` changes: its own and its face neighbours.
  auto region_of = [&](int site) {
    std::vector<int> r;
    if (cell_of_site[site] >= 0) add_cell_and_neighbours(sub, cell_of_site[site], r);
    return r;
  };

  // Candidate edges: shorter than G3 h (h: the largest reference length of the cells around),
  // with a free end; shortest relative length first, ties by node ids. In the rounds against
  // skewness (skew_only): short edges between free vertices of a cell with a skewed face, whose tiny
  // faces are what checkMesh finds skewed.
  struct Candidate {
    double rel, len, h;
    int32_t a, b;
    size_t first, last;  // range in edge_cell
    bool for_skew;
  };
  std::vector<Candidate> cand;
  for (size_t i = 0; i < edge_cell.size();) {
    size_t j = i;
    double h = 0;
    while (j < edge_cell.size() && edge_cell[j][0] == edge_cell[i][0] && edge_cell[j][1] == edge_cell[i][1])
      h = std::max(h, h_ref_[edge_cell[j][2]]), ++j;
    const int32_t a = edge_cell[i][0], b = edge_cell[i][1];
    const bool free_end = global[a] >= out.base_node_id || global[b] >= out.base_node_id;
    const bool both_free = global[a] >= out.base_node_id && global[b] >= out.base_node_id;
    const double len = norm(sub.nodes[a] - sub.nodes[b]);
    bool of_failing_cell = false, of_skewed_cell = false;
    for (size_t k = i; k < j; ++k) {
      of_failing_cell = of_failing_cell || now.failing.cell[edge_cell[k][2]];
      of_skewed_cell = of_skewed_cell || skewed[edge_cell[k][2]] > 0;
    }
    const bool short_between_free = both_free && len < opt_.g_remove * h;
    bool wanted = false, for_skew = false;
    switch (pass_) {
      case Pass::Optimize:
        for_skew = skew_only;
        wanted = skew_only ? short_between_free && of_skewed_cell : free_end && len < opt_.g_expand * h;
        break;
      case Pass::Skewness: for_skew = true, wanted = short_between_free && of_skewed_cell; break;
      case Pass::Slivers: wanted = both_free && len < kSliverEdge * h; break;
      // A failing cell's short edge between two free vertices (nearly co-spherical sites) is removed.
      case Pass::Repairs: wanted = short_between_free && of_failing_cell; break;
    }
    if (wanted && h > 0) cand.push_back({len / h, len, h, a, b, i, j, for_skew});
    i = j;
  }
  std::sort(cand.begin(), cand.end(), [&](const Candidate& x, const Candidate& y) {
    return x.rel != y.rel ? x.rel < y.rel : std::make_pair(global[x.a], global[x.b]) < std::make_pair(global[y.a], global[y.b]);
  });

  std::vector<char> locked(ns, 0), moved(ns, 0);
  std::vector<Move> moves;
  auto admit = [&](Move& m) {
    m.region = region_of(m.site);
    for (int c : m.region)
      if (moved[out.cell_site[c]]) return;
    // A removal solves for its edge's two power spheres as they are: none of their sites may
    // move in the same round (else the edge comes back: docs/optimization.md, "Removals that undid
    // each other").
    const std::vector<int> spheres = m.removal ? sphere_movers(m.tag) : std::vector<int>{};
    for (int s : spheres)
      if (moved[s]) return;
    restore(m.site, m.after);
    moved[m.site] = 1;
    for (int c : m.region) locked[out.cell_site[c]] = 1;
    for (int s : spheres) locked[s] = 1;
    locked[m.site] = 1;
    moves.push_back(m);
  };
  // Skewed faces first, worst first: one of their two sites moves a step (toward or away from
  // its polygon, or from the other site), kept if the cells around have fewer skewed faces.
  std::vector<int> unstepped;  // skewed faces whose own sites have no step left
  for (int f : skewed_faces) {
    if (pass_ != Pass::Optimize && pass_ != Pass::Skewness) break;
    const int s1 = out.cell_site[sub.face_owner[f]], s2 = out.cell_site[sub.face_neighbour[f]];
    if (moved[s1] || moved[s2] || locked[s1] || locked[s2]) continue;
    Move best;
    // A site on a streak against this face first: its last kept step, with the exponent doubled.
    for (int s : {s1, s2}) {
      const int other = s == s1 ? s2 : s1;
      const SkewStreak st = streak_of(s);
      if (best.site >= 0 || st.level == 0 || st.k >= 8 || st.other != other) continue;
      best = skew_step(s, other, other, st.k, st.k % 2 == 1, st.k < 4 ? 1 : 2, st.level);
    }
    // Small steps of either site in either direction first, then larger ones.
    for (int k = 0; k < 8 && best.site < 0; ++k) {
      const int s = k % 4 < 2 ? s1 : s2, other = k % 4 < 2 ? s2 : s1;
      best = skew_step(s, other, other, k, k % 2 == 1, k < 4 ? 1 : 2, 0);
    }
    if (best.site >= 0) admit(best);
    else unstepped.push_back(f);
  }
  for (const Candidate& e : cand) {
    std::vector<int> around;  // sites of the cells around the edge
    for (size_t k = e.first; k < e.last; ++k) around.push_back(out.cell_site[edge_cell[k][2]]);
    bool busy = false;
    for (int s : around) busy = busy || moved[s];
    if (busy) continue;
    Move best;
    double best_shift = std::numeric_limits<double>::infinity();
    for (int end = 0; end < 2; ++end) {
      const int32_t v = end ? e.a : e.b, u = end ? e.b : e.a;
      if (global[v] < out.base_node_id) continue;
      const bool removal = (pass_ == Pass::Slivers || e.rel < opt_.g_remove) && global[u] >= out.base_node_id;
      const Vec3 pv = sub.nodes[v], pu = sub.nodes[u];
      const Vec3 x = removal ? pu : pv + ((opt_.g_expand * e.h - e.len) / e.len) * (pv - pu);
      // Sites of v not around the edge: those of its cells and of its power sphere.
      std::vector<int> ds;
      for (int c : cells_of_node(v)) ds.push_back(out.cell_site[c]);
      for (int s : out.new_node_sites[global[v] - out.base_node_id])
        if (s < ns) ds.push_back(s);
      std::sort(ds.begin(), ds.end());
      ds.erase(std::unique(ds.begin(), ds.end()), ds.end());
      for (int d : ds) {
        if (std::find(around.begin(), around.end(), d) != around.end()) continue;
        Move m;
        const std::array<int, 4> ku = key_of(out, global[u]), kv = key_of(out, global[v]);
        m.tag = {ku[0], ku[1], ku[2], ku[3], kv[0], kv[1], kv[2], kv[3], d};
        if (refused(m.tag)) continue;
        // A sliver's sites may sit at a bound of their range (an end face's height cap): the
        // co-spherical position is then beyond it by rounding, the size of the edge itself.
        const double range_slack = pass_ == Pass::Slivers ? kSliverEdge * e.h : 0.0;
        if (!trial_move(d, around.front(), x, opt_.max_shift * e.h, range_slack, &m) || locked[m.site]) continue;
        const double shift = norm(m.after.p - m.before.p);
        m.removal = removal;
        if (pass_ == Pass::Slivers) m.kind = MoveKind::SliverRemoval;
        if (pass_ == Pass::Repairs) m.kind = MoveKind::Repair;
        if (e.for_skew) m.kind = MoveKind::SkewStep;
        if (shift < best_shift) best = m, best_shift = shift;
      }
    }
    if (best.site >= 0) admit(best);
  }
  // Skewed faces whose own sites have no step left, last (their moves lock the most cells): a step of
  // a face neighbour of either cell, which moves the two cells' centroids.
  for (int f : unstepped) {
    if (!skew_only && pass_ != Pass::Skewness) break;
    const int s1 = out.cell_site[sub.face_owner[f]], s2 = out.cell_site[sub.face_neighbour[f]];
    if (moved[s1] || moved[s2] || locked[s1] || locked[s2]) continue;
    // A neighbour on a streak against this face first (its last kept step, the exponent doubled),
    // then the neighbours' small steps, then their larger ones.
    auto neighbour_step = [&](int mover, int s, bool streak) {
      const bool polygon = set_.sites[mover].kind == SiteKind::InternalPolygon;
      const int other = polygon ? -1 : s;
      const SkewStreak st = streak_of(mover);
      const int first = streak ? st.k - 8 : 0, last = streak ? first + 1 : 4;
      if (streak && !(st.level > 0 && st.k >= 8 && st.other == other)) return Move{};
      for (int k = first; k < last; ++k) {
        const Move m = skew_step(mover, s, other, 8 + k, k % 2 == 1, k < 2 ? 1 : 2, streak ? st.level : 0);
        if (m.site >= 0) return m;
      }
      return Move{};
    };
    Move best;
    for (int streak = 1; streak >= 0 && best.site < 0; --streak)
      for (int s : {s1, s2}) {
        for (int n : region_of(s)) {
          const int mover = out.cell_site[n];
          if (mover == s1 || mover == s2 || moved[mover] || locked[mover]) continue;
          best = neighbour_step(mover, s, streak == 1);
          if (best.site >= 0) break;
        }
        if (best.site >= 0) break;
      }
    if (best.site >= 0) admit(best);
  }
  // Cells failing a shape check that no move above touches: a step of the cell's site or of a face
  // neighbour's (toward or away from the other, a polygon site along its range), kept only if fewer
  // cells around fail. Each round tries the first option not refused before, so later rounds try the
  // next ones. Last, as the moves above mend most failing cells of a raw diagram in passing.
  for (int c = 0; c < nc && pass_ != Pass::Slivers && pass_ != Pass::Skewness; ++c) {
    const int s = out.cell_site[c];
    if (!now.failing.cell[c] || locked[s]) continue;
    Move best;
    for (int size = 1; size <= 2 && best.site < 0; ++size)
      for (int n : region_of(s)) {
        const int other = out.cell_site[n];
        if (other == s) continue;
        for (int k = 0; k < 4 && best.site < 0; ++k) {
          const int mover = k < 2 ? s : other, from = k < 2 ? other : s;
          const bool away = k % 2 == 1;
          if (moved[mover] || locked[mover]) continue;
          Move m;
          m.kind = MoveKind::Repair;
          const bool polygon = set_.sites[mover].kind == SiteKind::InternalPolygon;
          m.tag = {-3, mover, polygon ? -1 : from, away, size, 0, 0, 0, 0};
          if (!refused(m.tag) && trial_step(mover, from, away, size, &m)) best = m;
        }
        if (best.site >= 0) break;
      }
    if (best.site >= 0) admit(best);
  }
  return moves;
}

std::vector<Move> SiteOptimizer::judge(const std::vector<Move>& moves, const TransitionCells& out, const Measured& now,
                                       const TransitionCells& fresh, const Measured& after) {
  const int nc = now.sub.n_cells();
  const int ns = static_cast<int>(set_.sites.size());
  const std::vector<double>& qs = now.qs;
  const std::vector<double>& max_skew = now.max_skew;
  const std::vector<int>& skewed = now.skewed;
  const std::vector<double>& qs2 = after.qs;
  const std::vector<int>& skewed2 = after.skewed;
  const std::vector<double>& max_skew2 = after.max_skew;
  const std::vector<char>& failing2 = after.failing.cell;
  // No move may make a cell fail a shape check of the self-check (shape_failures): one whose
  // region holds a newly failing cell is refused. A newly failing cell in no move's region changed
  // through a power vertex it shares with a moved site's cell: the moves whose cells share a node
  // with it are refused, and all of them only when no moved site's cell does.
  const std::vector<char> worse = new_failures(out, now, fresh, after);
  std::vector<char> applied(ns, 0);  // the moves in this rebuild (the halving may have undone some)
  for (const Move& m : moves) applied[m.site] = 1;
  // The moved sites to blame for the flagged cells outside every move's region.
  auto blame_strays = [&](std::vector<char> cells, bool* unattributed) {
    for (const Move& m : moves)
      for (int c : m.region) cells[c] = 0;
    return moved_sites_sharing_a_node(cells, now.sub, after.sub, out.cell_site, applied, unattributed);
  };
  bool unattributed = false;
  const std::vector<char> blamed = blame_strays(worse, &unattributed);
  // Likewise a cell with more faces above checkMesh's limit in no move's region: a step against
  // skewness is refused when its site's cell shares a node with one.
  std::vector<char> more_skewed(nc, 0);
  for (int c = 0; c < nc; ++c) more_skewed[c] = skewed2[c] > skewed[c];
  bool skew_unattributed = false;
  const std::vector<char> skew_blamed = blame_strays(std::move(more_skewed), &skew_unattributed);
  std::vector<Move> kept;
  for (const Move& m : moves) {
    MoveEffect e;
    e.newly_failing = unattributed || blamed[m.site];
    if (m.kind == MoveKind::SkewStep) e.newly_failing = e.newly_failing || skew_unattributed || skew_blamed[m.site];
    for (int c : m.region) {
      e.newly_failing = e.newly_failing || worse[c];
      e.q_s_before += qs[c], e.q_s_after += qs2[c], e.skewed_before += skewed[c], e.skewed_after += skewed2[c];
      e.worst_skew_before = std::max(e.worst_skew_before, max_skew[c]);
      e.worst_skew_after = std::max(e.worst_skew_after, max_skew2[c]);
      e.failing_before += now.failing.cell[c], e.failing_after += failing2[c];
    }
    const bool keep = move_is_kept(e, m.kind);
    record_streak(m, keep);
    if (keep) kept.push_back(m);
    else restore(m.site, m.before), refuse(m);
  }
  return kept;
}

bool SiteOptimizer::round(TransitionCells& out, SiteOptimizeReport& rep, bool skew_only) {
  slab_.reset(set_);
  number_images();
  // The diagram's measurement: the one the previous round took of the diagram it left, if any.
  Measured now = next_ ? std::move(*next_) : measure(out);
  next_.reset();
  // `out` unchanged on return: its measurement serves the next round.
  auto unchanged = [&] {
    next_ = std::move(now);
    return false;
  };
  skewed_left_ = static_cast<int>(now.skewed_faces.size());
  worst_skew_left_ = now.max_skew.empty() ? 0.0 : *std::max_element(now.max_skew.begin(), now.max_skew.end());
  std::vector<int> cell_of_site(set_.sites.size(), -1);
  for (int c = 0; c < now.sub.n_cells(); ++c) cell_of_site[out.cell_site[c]] = c;
  std::vector<Move> moves = propose(out, now, cell_of_site, skew_only);
  rep.proposed += static_cast<int>(moves.size());
  proposed_last_ = static_cast<int>(moves.size());
  if (moves.empty()) return unchanged();

  // Rebuild with the moves; an invalid diagram keeps the first half of them, down to none.
  TransitionCells fresh;
  size_t keep = moves.size();
  diagram_.save();  // the diagram of `out`: the rebuild with the kept moves alone starts from it
  while (!rebuild(fresh, out.base_node_id)) {
    const size_t half = keep / 2;
    for (size_t i = half; i < keep; ++i) restore(moves[i].site, moves[i].before);
    if (keep == 1) refuse(moves[0]);
    rep.invalid += static_cast<int>(keep - half);
    keep = half;
    if (keep == 0) {
      moves.clear();
      return unchanged();
    }
  }
  moves.resize(keep);
  // Keep a move by what it did to the cells around it (move_is_kept), its neighbours before and
  // after the move (a diagram of the same sites: cell c is the same site's in both).
  Measured after = measure(fresh);
  for (Move& m : moves)
    if (cell_of_site[m.site] >= 0) add_cell_and_neighbours(after.sub, cell_of_site[m.site], m.region);
  const std::vector<Move> kept = judge(moves, out, now, fresh, after);
  rep.refused += static_cast<int>(moves.size() - kept.size());
  if (kept.empty()) {
    return unchanged();
  }
  if (kept.size() < moves.size()) {
    // Rebuilt with the kept moves alone: valid, and no cell failing that did not before.
    bool ok = rebuild(fresh, out.base_node_id);
    if (ok) {
      after = measure(fresh);
      const std::vector<char> worse_kept = new_failures(out, now, fresh, after);
      ok = std::find(worse_kept.begin(), worse_kept.end(), 1) == worse_kept.end();
    }
    if (!ok) {
      for (const Move& m : kept) restore(m.site, m.before);
      rep.invalid += static_cast<int>(kept.size());
      return unchanged();
    }
  }
  rep.kept += static_cast<int>(kept.size());
  out = std::move(fresh);
  next_ = std::move(after);
  return true;
}

}  // namespace

bool move_is_kept(const MoveEffect& e, MoveKind kind) {
  if (e.newly_failing) return false;
  if (kind == MoveKind::SliverRemoval) return e.skewed_after <= e.skewed_before;  // checkMesh fails above its skewness limit
  if (e.failing_after < e.failing_before) return true;
  if (kind == MoveKind::Repair) return false;
  if (kind == MoveKind::SkewStep)
    return e.skewed_after < e.skewed_before ||
           (e.skewed_after == e.skewed_before && e.worst_skew_after < e.worst_skew_before);
  return e.skewed_after <= e.skewed_before && e.q_s_after > e.q_s_before + 1e-12;
}

// Rounds against checkMesh's skewness, with and without optimisation: a round keeps about one step per
// skewed face, and some faces need a dozen or more (docs/optimization.md, "Steps of a skewed face's
// neighbours"). After kSkewRounds, more while they make progress (SkewRoundBudget).
constexpr int kSkewRounds = 24;
constexpr int kSliverRounds = 4;
constexpr int kRepairRounds = 16;

namespace {
// The rounds against skewness: kSkewRounds, then up to kMaxSkewRounds as long as the faces above
// checkMesh's limit reached a new low (fewer of them, or the same count with a lower worst) within
// the last kSkewPatience rounds: faces a little above the limit that neighbours' steps lower by
// hundredths a round (docs/optimization.md, "More rounds while they make progress"). When they stall
// (no new low within the patience, or a round with nothing left to propose) with faces still above
// the limit, up to kSkewRetries second chances: the refused moves against skewness may be tried again
// (docs/optimization.md, "A second chance after a stall"). A case left with no face above
// kOpenFoamSkewnessLimit never stalls with faces left, so it meshes as without the second chances.
constexpr int kMaxSkewRounds = 64;
constexpr int kSkewPatience = 8;
constexpr int kSkewRetries = 2;
class SkewRoundBudget {
 public:
  // Whether another round may run after `rounds` rounds of `o`; the state the last of them started
  // from (SiteOptimizer::skewed_left, worst_skew_left) counts toward the progress.
  bool more(int rounds, SiteOptimizer& o) {
    const int faces = o.skewed_left();
    const double worst = o.worst_skew_left();
    if (rounds > 0 && (faces < faces_ || (faces == faces_ && worst < worst_)))
      faces_ = faces, worst_ = worst, last_low_ = rounds;
    if (rounds < kSkewRounds || (rounds < kMaxSkewRounds && rounds - last_low_ <= kSkewPatience)) return true;
    return second_chance(rounds, o);
  }
  // After `rounds` rounds the rounds stalled: whether they go on, with the refused moves forgotten.
  bool second_chance(int rounds, SiteOptimizer& o) {
    if (rounds >= kMaxSkewRounds || retries_ == kSkewRetries || o.skewed_now() <= 0) return false;
    if (o.forget_refused_skew_moves() == 0) return false;
    ++retries_;
    last_low_ = rounds;
    return true;
  }

 private:
  int faces_ = std::numeric_limits<int>::max();
  double worst_ = std::numeric_limits<double>::infinity();
  int last_low_ = 0;
  int retries_ = 0;
};

// An edge between two free vertices shorter than kSliverEdge x the h_ref of a cell it bounds.
bool has_sliver_edge(const TransitionCells& t) {
  auto at = [&](int32_t v) { return t.new_nodes[v - t.base_node_id]; };
  for (size_t c = 0; c < t.cells.size(); ++c)
    for (const CellFace& f : t.cells[c])
      for (size_t k = 0; k < f.nodes.size(); ++k) {
        const int32_t a = f.nodes[k], b = f.nodes[(k + 1) % f.nodes.size()];
        if (a >= t.base_node_id && b >= t.base_node_id && norm(at(a) - at(b)) < kSliverEdge * t.h_ref[c]) return true;
      }
  return false;
}
}  // namespace

namespace {
// The passes other than skewness's stop when a round has nothing left to propose.
bool no_second_chance(int, const SiteOptimizer&) { return false; }

// Rounds of one pass without optimisation on `out` while more(rounds done, optimizer), until
// done(optimizer) after a round or a round proposes nothing and stalled(rounds done, optimizer) gives
// no second chance: a round whose moves were all refused has tagged them, and the next tries each
// one's next option. The first round measures the diagram. Returns the moves kept.
template <class More, class Done, class Stalled>
int run_pass(Pass pass, More more, Done done, Stalled stalled, SiteSet& set, const Cavity& cavity,
             const std::vector<Vec3>& coords, const std::vector<PolygonFrame>& frames, const TransitionOptions& opt,
             const std::vector<Vec3>& outside_centres, const BoundaryImages& images, TransitionCells& out) {
  SiteOptimizeReport rep;
  const std::vector<double> h_ref = out.h_ref;
  SiteOptimizer optimizer(set, cavity, coords, frames, h_ref, opt, outside_centres, images, pass);
  while (more(rep.rounds, optimizer)) {
    ++rep.rounds;
    if (!optimizer.round(out, rep, pass != Pass::Slivers) && optimizer.proposed_last() == 0 &&
        !stalled(rep.rounds, optimizer))
      break;
    if (done(optimizer)) break;
  }
  out.h_ref = h_ref;
  return rep.kept;
}
}  // namespace

int remove_sliver_edges(SiteSet& set, const Cavity& cavity, const std::vector<Vec3>& coords,
                        const std::vector<PolygonFrame>& frames, const TransitionOptions& opt,
                        const std::vector<Vec3>& outside_centres, TransitionCells& out) {
  if (!has_sliver_edge(out)) return 0;  // the common case: no submesh to measure
  return run_pass(Pass::Slivers, [](int rounds, const SiteOptimizer&) { return rounds < kSliverRounds; },
                  [](const SiteOptimizer&) { return false; }, no_second_chance, set, cavity, coords, frames, opt,
                  outside_centres, kNoImages, out);
}

int reduce_skewness(SiteSet& set, const Cavity& cavity, const std::vector<Vec3>& coords,
                    const std::vector<PolygonFrame>& frames, const TransitionOptions& opt,
                    const std::vector<Vec3>& outside_centres, const BoundaryImages& images,
                    TransitionCells& out) {
  SkewRoundBudget budget;
  return run_pass(
      Pass::Skewness, [&](int rounds, SiteOptimizer& o) { return budget.more(rounds, o); },
      [](const SiteOptimizer& o) { return o.skewed_left() == 0; },
      [&](int rounds, SiteOptimizer& o) { return budget.second_chance(rounds, o); }, set, cavity, coords, frames, opt,
      outside_centres, images, out);
}

int repair_failing_cells(SiteSet& set, const Cavity& cavity, const std::vector<Vec3>& coords,
                         const std::vector<PolygonFrame>& frames, const TransitionOptions& opt,
                         const std::vector<Vec3>& outside_centres, const BoundaryImages& images,
                         TransitionCells& out) {
  // It proposes nothing when no cell fails, the common case.
  return run_pass(Pass::Repairs, [](int rounds, const SiteOptimizer&) { return rounds < kRepairRounds; },
                  [](const SiteOptimizer& o) { return o.failing_now() == 0; }, no_second_chance, set, cavity, coords,
                  frames, opt, outside_centres, images, out);
}

SiteOptimizeReport optimize_sites(SiteSet& set, const Cavity& cavity, const std::vector<Vec3>& coords,
                                  const std::vector<PolygonFrame>& frames, const TransitionOptions& opt,
                                  const std::vector<Vec3>& outside_centres, TransitionCells& out) {
  SiteOptimizeReport rep;
  const std::vector<double> h_ref = out.h_ref;  // the raw diagram's: the same reference before and after
  SiteOptimizer optimizer(set, cavity, coords, frames, h_ref, opt, outside_centres, kNoImages);
  while (rep.rounds < opt.max_rounds) {
    ++rep.rounds;
    if (!optimizer.round(out, rep, false)) break;
  }
  // Faces above checkMesh's skewness limit left: a few more rounds against them alone.
  SkewRoundBudget budget;
  for (int extra = 0; budget.more(extra, optimizer); ++extra) {
    ++rep.rounds;
    // A round whose steps were all refused has tagged them: the next tries each face's next step.
    if (!optimizer.round(out, rep, true) && optimizer.proposed_last() == 0 && !budget.second_chance(extra + 1, optimizer))
      break;
    if (optimizer.skewed_left() == 0) break;
  }
  // Cells failing a shape check left: rounds of repairs while untried options remain.
  for (int extra = 0; extra < kRepairRounds && optimizer.failing_now() != 0; ++extra) {
    ++rep.rounds;
    if (!optimizer.round(out, rep, true) && optimizer.proposed_last() == 0) break;
  }
  out.h_ref = h_ref;
  return rep;
}

std::vector<Vec3> well_polygon_centres(const Cavity& cavity, const std::vector<WellBlock>& blocks) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<Vec3> out(cavity.faces.size(), Vec3{nan, nan, nan});
  for (size_t q = 0; q < cavity.faces.size(); ++q) {
    const ConstrainedFace& face = cavity.faces[q];
    if (face.side != FaceSide::Well || face.outside_cell < 0) continue;
    for (const WellBlock& b : blocks)
      if (b.well == face.well && static_cast<size_t>(face.outside_cell) < b.cell_attrs.size())
        out[q] = b.cell_attrs[face.outside_cell].fv_center;
  }
  return out;
}

}  // namespace hm::transition_detail
