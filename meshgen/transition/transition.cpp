// Driver of the transition mesh of one cavity (paper 5.2-5.7). CGAL-free: the two CGAL
// stages are in transition_delaunay.cpp and transition_power.cpp.
#include "transition.hpp"

#include <algorithm>
#include <chrono>
#include <map>
#include <sstream>
#include <stdexcept>

#include "meshgen/core/fv_quality.hpp"
#include "meshgen/core/geometry.hpp"
#include "transition_internal.hpp"

namespace hm {

using namespace transition_detail;

namespace {
constexpr int kMaxCorrectionIterations = 400;
constexpr int kMaxHiddenRepairs = 8;
constexpr double kHiddenShrink = 0.7;

std::vector<PolygonFrame> frames_of(const Cavity& cavity, const std::vector<Vec3>& coords,
                                    std::vector<std::string>& notes) {
  std::vector<PolygonFrame> frames;
  frames.reserve(cavity.faces.size());
  for (const ConstrainedFace& f : cavity.faces) frames.push_back(fit_polygon(f.nodes, coords));
  attach_voronoi_edges(cavity, coords, frames, notes);
  return frames;
}

// A polygon's external site is a reflection unless it faces an active reservoir box.
bool mirrored(const Cavity& cavity, const ConstrainedFace& f) {
  return !(cavity.cells_are_boxes && f.side == FaceSide::Reservoir && f.outside_cell >= 0);
}

std::vector<int> non_admissible(const Cavity& cavity, const std::vector<PolygonFrame>& frames) {
  std::vector<int> bad;
  for (size_t q = 0; q < frames.size(); ++q)
    if (!(frames[q].t_in > 0) || (mirrored(cavity, cavity.faces[q]) && !(frames[q].t_out < 0)))
      bad.push_back(static_cast<int>(q));
  return bad;
}
}  // namespace

namespace transition_detail {

std::vector<int32_t> BoundaryImages::image_of(int k, const std::vector<int32_t>& ids) const {
  std::vector<int32_t> out;
  out.reserve(ids.size());
  for (int32_t v : ids) {
    const auto it = std::lower_bound(vertices.begin(), vertices.end(), v);
    out.push_back(it != vertices.end() && *it == v ? image[k][it - vertices.begin()] : v);
  }
  std::sort(out.begin(), out.end());
  return out;
}

BoundaryImages add_boundary_images(Cavity& cavity, std::vector<Vec3>& coords) {
  BoundaryImages im;
  im.planes = cavity.mirrors;
  im.vertices = cavity.vertices;
  im.first_image = static_cast<int32_t>(coords.size());
  for (const MirrorPlane& m : im.planes) {
    std::vector<int32_t> ids(im.vertices.size());
    for (size_t i = 0; i < im.vertices.size(); ++i) {
      const Vec3 p = coords[im.vertices[i]];
      if (p[m.axis] == m.value) {
        ids[i] = im.vertices[i];
        continue;
      }
      ids[i] = static_cast<int32_t>(coords.size());
      coords.push_back(reflect(p, m));
      cavity.vertices.push_back(ids[i]);
    }
    im.image.push_back(std::move(ids));
  }
  return im;
}

}  // namespace transition_detail

std::vector<PolygonDual> polygon_duals(const Cavity& cavity, const std::vector<Vec3>& node_coords) {
  std::vector<std::string> notes;
  const std::vector<PolygonFrame> frames = frames_of(cavity, node_coords, notes);
  std::vector<PolygonDual> out;
  for (const PolygonFrame& f : frames)
    out.push_back({f.center, f.normal, f.radius, f.t_in, f.t_out, f.inner_tets, f.outer_tets});
  return out;
}

std::vector<int32_t> transition_detail::submesh_face_polygons(const PolyMesh& sub,
                                                              const std::vector<int32_t>& global,
                                                              const TransitionCells& t, const Cavity& cavity,
                                                              const std::function<bool(int32_t)>& wanted) {
  std::vector<int32_t> out(sub.n_faces(), -1);
  std::map<std::vector<int32_t>, int32_t> polygon_of;  // sorted global nodes -> cavity face
  for (const auto& polygons : t.cell_polygons)
    for (int32_t q : polygons) {
      if (!wanted(q)) continue;
      std::vector<int32_t> key = cavity.faces[q].nodes;
      std::sort(key.begin(), key.end());
      polygon_of[key] = q;
    }
  for (int f = 0; f < sub.n_faces() && !polygon_of.empty(); ++f) {
    if (sub.face_neighbour[f] >= 0) continue;
    std::vector<int32_t> key;
    for (const int32_t* v = sub.face_begin(f); v != sub.face_end(f); ++v) key.push_back(global[*v]);
    std::sort(key.begin(), key.end());
    if (const auto it = polygon_of.find(key); it != polygon_of.end()) out[f] = it->second;
  }
  return out;
}

std::vector<int> non_admissible_polygons(const Cavity& cavity, const std::vector<Vec3>& node_coords) {
  std::vector<std::string> notes;
  return non_admissible(cavity, frames_of(cavity, node_coords, notes));
}

namespace {

TransitionCells build_transition_with(const Cavity& cavity, const std::vector<Vec3>& node_coords,
                                      const ReservoirGrid& grid, const std::vector<WellBlock>& blocks,
                                      int32_t base_node_id, const BoundaryImages& images,
                                      const TransitionOptions& options) {
  TransitionReport report;
  using Clock = std::chrono::steady_clock;
  auto seconds = [](Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); };
  const Clock::time_point t0 = Clock::now();
  const std::vector<PolygonFrame> frames = frames_of(cavity, node_coords, report.notes);
  const Clock::time_point t1 = Clock::now();
  const std::vector<int> bad = non_admissible(cavity, frames);
  if (!bad.empty()) {
    const PolygonFrame& f = frames[bad.front()];
    std::ostringstream os;
    os << "transition: " << bad.size() << " constrained polygons are not Delaunay admissible (first: polygon "
       << bad.front() << ", t_in = " << f.t_in << ", t_out = " << f.t_out << ", radius " << f.radius
       << "): a cavity vertex lies in its diametral sphere; the cavity must be enlarged";
    std::vector<int32_t> polygons(bad.begin(), bad.end());
    std::vector<int32_t> cells = cells_behind(cavity, node_coords, frames, polygons);
    throw TransitionError(os.str(), std::move(polygons), std::move(cells));
  }
  SiteSet set = make_sites(cavity, node_coords, grid, frames, report.notes);
  place_end_face_sites(set, cavity, node_coords, blocks, frames);
  cap_sites_off_bend_axes(set, cavity, node_coords, blocks, frames);
  enforce_empty_spheres(set, cavity, node_coords, grid, frames);
  int iterations = 0;
  report.site_corrections = correct_sites(set, cavity, node_coords, grid, frames, kMaxCorrectionIterations, &iterations);
  report.correction_iterations = iterations;
  place_tip_sites(set, cavity, node_coords, grid, blocks);
  const Clock::time_point t2 = Clock::now();

  TransitionCells out;
  int tip_rounds = 0, hidden_rounds = 0;
  for (;;) {
    out = TransitionCells{};
    out.base_node_id = base_node_id;
    std::vector<int> hidden = build_power_cells(set, cavity, node_coords, frames, out, images);
    bool degenerate = false;
    if (hidden.empty()) {
      // Free sites are optional: one whose cell came out unusable (near-degenerate sites whose
      // power vertices were identified into a duplicate face) is dropped and the diagram rebuilt.
      const std::vector<int> bad_tips = tip_sites_in_bad_cells(set, out);
      if (!bad_tips.empty()) {
        for (int s : bad_tips) set.sites[s].alive = false;
        report.dropped_tip_sites += static_cast<int>(bad_tips.size());
        if (++tip_rounds > kMaxHiddenRepairs)  // cannot happen twice: no free site is left
          for (Site& s : set.sites)
            if (s.kind == SiteKind::Free) s.alive = false;
        continue;
      }
      // Polygon or box sites whose cells collapsed onto a duplicate face: moved like hidden ones.
      hidden = sites_in_duplicate_faces(set, out);
      if (hidden.empty()) break;
      degenerate = true;
    }
    for (int s : hidden) {
      std::ostringstream os;
      if (set.sites[s].kind == SiteKind::Free)
        os << "tip site " << s << " is hidden: dropped and rebuilt";
      else
        os << "site " << s << (set.sites[s].internal() ? " (internal" : " (external") << ", polygon "
           << set.sites[s].polygons.front() << (degenerate ? ") has a duplicate face" : ") is hidden")
           << ": moved toward its polygon and rebuilt";
      if (report.notes.size() < 50) report.notes.push_back(os.str());
      if (set.sites[s].kind == SiteKind::Free) {
        set.sites[s].alive = false;
        ++report.dropped_tip_sites;
      } else if (set.sites[s].internal() && !degenerate) {
        ++report.hidden_sites;
      }
    }
    if (hidden_rounds++ == kMaxHiddenRepairs) {
      std::ostringstream os;
      os << "transition: " << hidden.size() << " sites stay " << (degenerate ? "in duplicate faces" : "hidden")
         << " after " << kMaxHiddenRepairs << " repairs";
      std::vector<int32_t> polygons;
      for (int s : hidden) polygons.insert(polygons.end(), set.sites[s].polygons.begin(), set.sites[s].polygons.end());
      std::sort(polygons.begin(), polygons.end());
      polygons.erase(std::unique(polygons.begin(), polygons.end()), polygons.end());
      throw TransitionError(os.str(), std::move(polygons), {});
    }
    ++report.hidden_repairs;
    for (int s : hidden)
      if (set.sites[s].alive) shrink_or_split(set, s, kHiddenShrink, cavity, node_coords, grid, frames);
    enforce_empty_spheres(set, cavity, node_coords, grid, frames);
    // Free sites now inside a moved sphere go first, so that the correction never shrinks a
    // polygon or box site on account of an optional site; and again after it.
    report.dropped_tip_sites += drop_blocked_tip_sites(set, cavity.mirrors);
    report.site_corrections +=
        correct_sites(set, cavity, node_coords, grid, frames, kMaxCorrectionIterations, &iterations);
    report.correction_iterations += iterations;
    report.dropped_tip_sites += drop_blocked_tip_sites(set, cavity.mirrors);
  }
  const Clock::time_point t3 = Clock::now();
  SiteOptimizeReport optimization;
  int sliver_removals = 0;
  // A cavity that reaches a boundary plane is not optimised: in a strongly scaled permeability
  // frame the optimiser's removals there left micro-edges that the way back turned out of plane
  // (docs/optimization.md, "Cavities that reach the outer boundary"). Its failing cells are repaired,
  // with its sites' images in every rebuild.
  const bool optimize = options.optimize && images.empty();
  std::shared_ptr<const TransitionCells> raw;
  const std::vector<Vec3> outside = well_polygon_centres(cavity, blocks);
  if (optimize) {
    raw = std::make_shared<const TransitionCells>(out);
    optimization = optimize_sites(set, cavity, node_coords, frames, options, outside, out);
  }
  // The optimiser's removals need a Q_S gain: sliver edges it left are removed here too.
  int repairs = 0;
  // Not where the cavity reaches a boundary plane either (the same micro-edges).
  if (images.empty()) sliver_removals = remove_sliver_edges(set, cavity, node_coords, frames, options, outside, out);
  // The raw diagram's tiny faces between large cells fail checkMesh's skewness (docs/transition.md,
  // "checkMesh's skewness without optimisation"); the optimiser has rounds of its own against them.
  int skew_steps = 0;
  if (!optimize) skew_steps = reduce_skewness(set, cavity, node_coords, frames, options, outside, images, out);
  // optimize_sites ends with repair rounds of its own (steps, no removals).
  if (!optimize) repairs = repair_failing_cells(set, cavity, node_coords, frames, options, outside, images, out);
  if (raw) out.unoptimized = std::move(raw);
  // Merge the stage reports.
  TransitionReport& r = out.report;
  r.optimization = optimization;
  r.sliver_removals = sliver_removals;
  r.skew_steps = skew_steps;
  r.repairs = repairs;
  r.seconds_optimize = optimize ? seconds(t3, Clock::now()) : 0.0;
  r.seconds_delaunay = seconds(t0, t1);
  r.seconds_sites = seconds(t1, t2);
  r.seconds_power = seconds(t2, t3);
  r.site_corrections = report.site_corrections;
  r.correction_iterations = report.correction_iterations;
  r.hidden_sites = report.hidden_sites;
  r.hidden_repairs = report.hidden_repairs;
  r.dropped_tip_sites = report.dropped_tip_sites;
  r.notes.insert(r.notes.begin(), report.notes.begin(), report.notes.end());
  for (const Site& s : set.sites) {
    if (!s.alive) continue;
    if (s.internal()) ++r.internal_sites;
    else if (s.kind != SiteKind::Guard) ++r.external_sites;
    if (s.kind == SiteKind::InternalBox) ++r.box_sites;
    if (s.kind == SiteKind::Free) ++r.free_sites;
  }
  r.split_boxes = set.splits;
  r.emptiness_fixes = set.emptiness_fixes;
  if (r.free_sites > 0 || r.dropped_tip_sites > 0)
    r.notes.push_back(std::to_string(r.free_sites) + " free sites (weight 0) grade the cells beyond the well ends and fill the bends' focal lines" +
                      (r.dropped_tip_sites > 0 ? " (" + std::to_string(r.dropped_tip_sites) + " dropped)" : ""));
  return out;
}
// Outer-boundary planes: every stage sees the images of the cavity vertices too (empty
// spheres, Delaunay); the power diagram adds the images of the sites.
TransitionCells build_transition_or_throw(const Cavity& real_cavity, const std::vector<Vec3>& real_coords,
                                          const ReservoirGrid& grid, const std::vector<WellBlock>& blocks,
                                          int32_t base_node_id, const TransitionOptions& options) {
  if (real_cavity.mirrors.empty())
    return build_transition_with(real_cavity, real_coords, grid, blocks, base_node_id, {}, options);
  Cavity cavity = real_cavity;
  std::vector<Vec3> coords = real_coords;
  const BoundaryImages images = add_boundary_images(cavity, coords);
  return build_transition_with(cavity, coords, grid, blocks, base_node_id, images, options);
}

}  // namespace

TransitionOutcome try_build_transition(const Cavity& cavity, const std::vector<Vec3>& node_coords,
                                       const ReservoirGrid& grid, const std::vector<WellBlock>& blocks,
                                       int32_t base_node_id, const TransitionOptions& options) {
  TransitionOutcome out;
  TransitionRefusal refusal;
  try {
    out.cells = build_transition_or_throw(cavity, node_coords, grid, blocks, base_node_id, options);
    return out;
  } catch (const TransitionError& e) {  // the stages' refusals: admissibility, correction, hidden sites
    refusal = {e.what(), e.polygons, e.cells_to_deactivate, {}};
  } catch (const std::runtime_error& e) {  // the diagram leaked (transition_power.cpp)
    refusal.reason = e.what();
  }
  for (int32_t q : refusal.polygons)
    if (q >= 0 && q < static_cast<int32_t>(cavity.faces.size()) && cavity.faces[q].side == FaceSide::Well)
      refusal.wells.push_back(cavity.faces[q].well);
  std::sort(refusal.wells.begin(), refusal.wells.end());
  refusal.wells.erase(std::unique(refusal.wells.begin(), refusal.wells.end()), refusal.wells.end());
  out.refusal = std::move(refusal);
  return out;
}

TransitionCells build_transition(const Cavity& cavity, const std::vector<Vec3>& node_coords,
                                 const ReservoirGrid& grid, const std::vector<WellBlock>& blocks,
                                 int32_t base_node_id, const TransitionOptions& options) {
  TransitionOutcome o = try_build_transition(cavity, node_coords, grid, blocks, base_node_id, options);
  if (o.refusal) throw TransitionError(o.refusal->reason, o.refusal->polygons, o.refusal->cells_to_deactivate);
  return std::move(o.cells);
}

PolyMesh transition_submesh(const TransitionCells& t, const std::vector<Vec3>& node_coords,
                            std::vector<int32_t>* global_node) {
  // The nodes used, ascending: the constrained ones (below base_node_id), then the new ones used.
  std::vector<int32_t> used, new_local(t.new_nodes.size(), -1);
  for (const auto& cell : t.cells)
    for (const CellFace& f : cell)
      for (int32_t v : f.nodes)
        if (v >= t.base_node_id) new_local[v - t.base_node_id] = 0;
        else used.push_back(v);
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  const size_t n_constrained = used.size();
  for (size_t k = 0; k < new_local.size(); ++k)
    if (new_local[k] == 0) new_local[k] = static_cast<int32_t>(used.size()), used.push_back(t.base_node_id + static_cast<int32_t>(k));
  MeshBuilder builder;
  for (int32_t v : used) builder.add_node(v >= t.base_node_id ? t.new_nodes[v - t.base_node_id] : node_coords[v]);
  auto local = [&](int32_t v) {
    if (v >= t.base_node_id) return new_local[v - t.base_node_id];
    return static_cast<int32_t>(std::lower_bound(used.begin(), used.begin() + static_cast<long>(n_constrained), v) - used.begin());
  };
  for (size_t c = 0; c < t.cells.size(); ++c) {
    std::vector<CellFace> faces = t.cells[c];
    for (CellFace& f : faces) {
      for (int32_t& v : f.nodes) v = local(v);
      f.patch = kOuterBoundary;  // the cavity's polygons: the boundary of this mesh
    }
    CellAttributes at;
    at.region = kTransition;
    at.fv_center = t.sites[c];
    builder.add_cell(faces, at);
  }
  BuildReport report;  // every node is used, so none is renumbered
  PolyMesh mesh = builder.finish(&report);
  if (global_node) *global_node = std::move(used);
  return mesh;
}

std::optional<TransitionRefusal> model_wall_orthogonality_refusal(const TransitionCells& t, const Cavity& cavity,
                                                                  const std::vector<Vec3>& node_coords,
                                                                  double min_orthogonality_deg) {
  auto is_wall = [&](int32_t q) {
    return cavity.faces[q].side == FaceSide::Reservoir && cavity.faces[q].outside_cell >= 0;
  };
  bool any_wall = false;
  for (const auto& polygons : t.cell_polygons)
    for (int32_t q : polygons) any_wall = any_wall || is_wall(q);
  if (!any_wall) return std::nullopt;
  std::vector<int32_t> global;
  const PolyMesh sub = transition_submesh(t, node_coords, &global);
  const MeshGeometry geo = compute_geometry(sub);
  const std::vector<double> qo = face_orthogonality(sub, geo, BoundaryPoint::Flux);
  const std::vector<int32_t> wall = submesh_face_polygons(sub, global, t, cavity, is_wall);
  TransitionRefusal r;
  double worst = 90;
  for (int f = 0; f < sub.n_faces(); ++f) {
    if (wall[f] < 0 || !(qo[f] < min_orthogonality_deg)) continue;
    r.polygons.push_back(wall[f]);
    r.cells_to_deactivate.push_back(cavity.faces[wall[f]].outside_cell);
    worst = std::min(worst, qo[f]);
  }
  if (r.polygons.empty()) return std::nullopt;
  for (std::vector<int32_t>* v : {&r.polygons, &r.cells_to_deactivate}) {
    std::sort(v->begin(), v->end());
    v->erase(std::unique(v->begin(), v->end()), v->end());
  }
  std::ostringstream os;
  os << "transition: " << r.polygons.size() << " faces on model walls have Q_O below " << min_orthogonality_deg
     << " degrees at their boundary flux point (worst " << worst << ")";
  r.reason = os.str();
  return r;
}

}  // namespace hm
