#include "cavity_corner_point.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include "meshgen/core/geometry.hpp"
#include "meshgen/grids/gabriel.hpp"

namespace hm {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Axis-aligned box of a model cell's 8 corners (the cell lies inside the corners' convex hull).
void cell_box(const CornerPointModel& m, int c, Vec3& lo, Vec3& hi) {
  lo = hi = model_cell_corner(m, c, 0);
  for (int q = 1; q < 8; ++q) {
    const Vec3 p = model_cell_corner(m, c, q);
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
  }
}

std::string cell_name(const CornerPointModel& m, int c) {
  return "(" + std::to_string(c % m.nx + 1) + ", " + std::to_string((c / m.nx) % m.ny + 1) + ", " +
         std::to_string(c / (m.nx * m.ny) + 1) + ")";
}

// Solid angle of triangle t seen from x, signed by orientation.
double solid_angle(Vec3 x, const std::array<Vec3, 3>& t) { return triangle_solid_angle(t[0] - x, t[1] - x, t[2] - x); }

// One reservoir polygon of the current cavity boundary: a constrained triangle of the face of
// active cell `outside` toward deactivated cell `inside`; or (outside = -1) a triangle of a face
// of deactivated cell `inside` with no meshed cell across it (the model's outer surface, a gap).
struct ResTriangle {
  std::vector<int32_t> nodes;
  int32_t outside, inside;
};

// The faces of deactivated cell c with no meshed cell across them, as triangles over their own
// nodes oriented into the cavity: face_triangles of each face, a fanned face's cycle once and
// without its centre (as cavity_triangles cuts the faces toward active cells).
void add_surface_triangles(const CornerPointCellFaces& cells, int c, const std::vector<Vec3>& coords,
                           std::vector<ResTriangle>& out) {
  for (int64_t f = cells.face_begin(c); f < cells.face_end(c); ++f) {
    if (cells.neighbour[f] >= 0 || !cells.first_of_its_group(c, f)) continue;
    for (const auto& t : face_triangles(cells.cycle(f), coords))  // the cycle is outward for c
      out.push_back({{t[2], t[1], t[0]}, -1, static_cast<int32_t>(c)});
  }
}

// The cavity boundary's reservoir triangles: those of the active cells toward deactivated ones (in
// the cells' order), then those of the deactivated cells on the model's outer surface.
std::vector<ResTriangle> reservoir_triangles(const CornerPointCellFaces& cells, const std::vector<char>& active,
                                             const std::vector<Vec3>& coords) {
  std::vector<ResTriangle> out;
  for (int64_t c = 0; c < cells.n_cells(); ++c) {
    if (!cells.meshed[c] || !active[c]) continue;
    for (CavityTriangle& t : cavity_triangles(cells, static_cast<int>(c), active, coords))
      out.push_back({std::move(t.nodes), static_cast<int32_t>(c), t.inside});
  }
  for (int64_t c = 0; c < cells.n_cells(); ++c)
    if (cells.meshed[c] && !active[c]) add_surface_triangles(cells, static_cast<int>(c), coords, out);
  return out;
}

}  // namespace

int regularize_cavity_surface(const CornerPointCellFaces& cells, std::vector<char>& active,
                              const std::vector<Vec3>& coords) {
  int added = 0;
  for (;;) {
    const std::vector<ResTriangle> tris = reservoir_triangles(cells, active, coords);
    std::map<std::pair<int32_t, int32_t>, std::vector<int32_t>> edge_tris;
    for (size_t t = 0; t < tris.size(); ++t)
      for (size_t i = 0; i < 3; ++i) {
        const int32_t a = tris[t].nodes[i], b = tris[t].nodes[(i + 1) % 3];
        edge_tris[{std::min(a, b), std::max(a, b)}].push_back(static_cast<int32_t>(t));
      }
    std::set<int32_t> offending;  // triangles at a non-manifold edge or vertex
    for (const auto& [e, ts] : edge_tris)
      if (ts.size() > 2) offending.insert(ts.begin(), ts.end());
    // Fans around each vertex: its triangles joined across the edges they share through it.
    std::map<int32_t, std::vector<int32_t>> vertex_tris;
    for (size_t t = 0; t < tris.size(); ++t)
      for (int32_t v : tris[t].nodes) vertex_tris[v].push_back(static_cast<int32_t>(t));
    for (const auto& [v, ts] : vertex_tris) {
      std::vector<int32_t> fan(ts.size(), -1);
      std::vector<size_t> stack{0};
      fan[0] = 0;
      while (!stack.empty()) {
        const size_t u = stack.back();
        stack.pop_back();
        for (int32_t x : tris[ts[u]].nodes) {
          if (x == v) continue;
          for (int32_t t : edge_tris.at({std::min(v, x), std::max(v, x)})) {
            const size_t w = std::find(ts.begin(), ts.end(), t) - ts.begin();
            if (fan[w] < 0) fan[w] = 0, stack.push_back(w);
          }
        }
      }
      if (std::find(fan.begin(), fan.end(), -1) != fan.end()) offending.insert(ts.begin(), ts.end());
    }
    int grown = 0;
    for (int32_t t : offending)
      if (tris[t].outside >= 0 && active[tris[t].outside]) active[tris[t].outside] = 0, ++grown;
    if (grown == 0) return added;
    added += grown;
  }
}

CornerPointLocator::CornerPointLocator(const CornerPointModel& model, const CornerPointCellFaces& cells,
                                       const std::vector<int32_t>& among, const std::vector<Vec3>& coords) {
  for (int32_t c : among) {
    if (!cells.meshed[c]) continue;
    Cell cell;
    cell.id = c;
    cell_box(model, c, cell.lo, cell.hi);
    cell.centre = Vec3{0, 0, 0};
    for (int q = 0; q < 8; ++q) cell.centre += model_cell_corner(model, c, q) / 8.0;
    for (int64_t f = cells.face_begin(c); f < cells.face_end(c); ++f)
      for (const auto& t : face_triangles(cells.face_nodes(f), coords))
        cell.triangles.push_back({coords[t[0]], coords[t[1]], coords[t[2]]});
    cells_.push_back(std::move(cell));
  }
  index_buckets();
}

int CornerPointLocator::bucket_index(int axis, double v) const {
  return std::clamp(static_cast<int>(std::floor((v - origin_[axis]) / step_[axis])), 0, dims_[axis] - 1);
}

size_t CornerPointLocator::bucket_id(int x, int y, int z) const {
  return (static_cast<size_t>(z) * dims_[1] + y) * dims_[0] + x;
}

template <class F>
void CornerPointLocator::for_each_bucket_of(const Cell& c, F&& f) const {
  int lo[3], hi[3];
  for (int a = 0; a < 3; ++a) lo[a] = bucket_index(a, c.lo[a]), hi[a] = bucket_index(a, c.hi[a]);
  for (int z = lo[2]; z <= hi[2]; ++z)
    for (int y = lo[1]; y <= hi[1]; ++y)
      for (int x = lo[0]; x <= hi[0]; ++x) f(bucket_id(x, y, z));
}

// About one bucket per cell, cubes as far as the extent allows (a flat model gets few layers of them).
void CornerPointLocator::index_buckets() {
  constexpr int kMaxDim = 256;
  if (cells_.empty()) return;
  Vec3 lo = cells_[0].lo, hi = cells_[0].hi;
  for (const Cell& c : cells_)
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], c.lo[a]), hi[a] = std::max(hi[a], c.hi[a]);
  double volume = 1;
  for (int a = 0; a < 3; ++a) volume *= std::max(hi[a] - lo[a], 1e-300);
  const double side = std::cbrt(volume / static_cast<double>(cells_.size()));
  origin_ = lo;
  for (int a = 0; a < 3; ++a) {
    const double extent = hi[a] - lo[a];
    dims_[a] = std::isfinite(extent / side) ? std::clamp(static_cast<int>(std::ceil(extent / side)), 1, kMaxDim) : 1;
    step_[a] = extent > 0 ? extent / dims_[a] : 1.0;
  }
  const size_t nb = static_cast<size_t>(dims_[0]) * dims_[1] * dims_[2];
  bucket_ptr_.assign(nb + 1, 0);
  for (const Cell& c : cells_) for_each_bucket_of(c, [&](size_t b) { ++bucket_ptr_[b + 1]; });
  for (size_t b = 0; b < nb; ++b) bucket_ptr_[b + 1] += bucket_ptr_[b];
  bucket_cells_.resize(bucket_ptr_[nb]);
  std::vector<int32_t> fill(bucket_ptr_.begin(), bucket_ptr_.end() - 1);
  for (size_t k = 0; k < cells_.size(); ++k)  // ascending k: each bucket keeps the order of `among`
    for_each_bucket_of(cells_[k], [&](size_t b) { bucket_cells_[fill[b]++] = static_cast<int32_t>(k); });
}

size_t CornerPointLocator::bucket_of(Vec3 x) const {
  return bucket_id(bucket_index(0, x[0]), bucket_index(1, x[1]), bucket_index(2, x[2]));
}

bool CornerPointLocator::holds(const Cell& c, Vec3 x) const {
  for (int a = 0; a < 3; ++a)
    if (x[a] < c.lo[a] || x[a] > c.hi[a]) return false;
  double w = 0;
  for (const auto& t : c.triangles) w += solid_angle(x, t);
  return std::abs(w) > 2.0 * kPi;  // winding number 1 (4 pi), not 0
}

int CornerPointLocator::cell_at(Vec3 x) const {
  // A cell holding x has x in its box, so it is in x's bucket (a point outside every box, or not
  // finite, is held by none).
  if (cells_.empty() || !(std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z))) return -1;
  const size_t b = bucket_of(x);
  for (int32_t i = bucket_ptr_[b]; i < bucket_ptr_[b + 1]; ++i)
    if (holds(cells_[bucket_cells_[i]], x)) return cells_[bucket_cells_[i]].id;
  return -1;
}

int CornerPointLocator::cell_at_or_nearest(Vec3 x) const {
  const int c = cell_at(x);
  if (c >= 0) return c;
  int best = -1;
  double d2 = INFINITY;
  for (const Cell& cell : cells_)
    if (norm2(cell.centre - x) < d2) d2 = norm2(cell.centre - x), best = cell.id;
  return best;
}

CavitySet build_corner_point_cavities(const CaseSpec& cs, const CornerPointModel& model,
                                      const CornerPointCellFaces& cells, const std::vector<WellBlock>& blocks,
                                      const std::vector<std::vector<int32_t>>& well_node_ids,
                                      const std::vector<Vec3>& coords,
                                      const std::vector<int32_t>& extra_deactivated) {
  CavitySet out;
  const int nc = model.nx * model.ny * model.nz;
  out.reservoir_active.assign(nc, 1);
  std::vector<char>& active = out.reservoir_active;
  if (blocks.empty()) return out;
  std::vector<Vec3> lo(nc), hi(nc);
  for (int c = 0; c < nc; ++c)
    if (cells.meshed[c]) cell_box(model, c, lo[c], hi[c]);

  // 1. The meshed cells whose corner box comes within dilation x drainage radius of a well's
  //    meshed path (conservative: the box holds the cell).
  const double dil = cs.transition.dilation;
  for (const WellBlock& b : blocks) {
    const double reach = dil * b.radii.back();
    for (int c = 0; c < nc; ++c)
      if (cells.meshed[c] && box_polyline_within(lo[c], hi[c], b.trajectory, reach)) active[c] = 0;
  }
  for (int32_t c : extra_deactivated)
    if (c >= 0 && c < nc) active[c] = 0;
  const ReservoirGrid index_grid = make_reservoir_grid(cs.reservoir);  // index arithmetic (nx, ny, nz)
  int regularized = regularize_deactivated(index_grid, active);
  regularized += regularize_cavity_surface(cells, active, coords);

  const WellSurfaces well_side = well_surfaces(blocks, well_node_ids);
  const std::vector<int32_t>& well_vertices = well_side.vertices;
  const std::vector<std::array<int32_t, 2>>& well_edges = well_side.edges;
  const std::vector<std::vector<int32_t>>& well_polygons = well_side.polygons;
  auto well_name = [&](int32_t v) {
    for (size_t w = 0; w < well_node_ids.size(); ++w)
      if (std::find(well_node_ids[w].begin(), well_node_ids[w].end(), v) != well_node_ids[w].end())
        return "wells[" + std::to_string(blocks[w].well) + "] (" + cs.wells[blocks[w].well].name + ")";
    return std::string("a well");
  };

  // 1b. The blocks lie inside the model's meshed cells: every outer vertex of a block inside the
  //     closed surface of the deactivated cells (winding number of its triangles, which are the
  //     union's boundary; dilation >= 1 deactivates every meshed cell a block meets). A cavity may
  //     reach the model's outer surface, a block may not cross it.
  {
    std::vector<std::array<Vec3, 3>> surface;
    for (const ResTriangle& t : reservoir_triangles(cells, active, coords))
      surface.push_back({coords[t.nodes[0]], coords[t.nodes[1]], coords[t.nodes[2]]});
    for (int32_t v : well_vertices) {
      double w = 0;
      for (const auto& t : surface) w += solid_angle(coords[v], t);
      if (!(std::abs(w) > 2.0 * kPi)) {  // winding number 0 (outside), not 1 (4 pi)
        std::ostringstream os;
        os.precision(6);
        os << coords[v].z;
        throw InputError(well_name(v) + ": its well block (drainage_radius around the meshed path, and its ends) "
                         "reaches outside the meshed cells of the corner-point model " + cs.reservoir.grdecl +
                         " at depth " + os.str() + " m (above its top, below its bottom, beyond a side, or into an "
                         "inactive or zero-thickness cell): the block must lie inside the model (docs/corner-point.md)");
      }
    }
  }

  // 2. Gabriel across the two sides (paper 5.1), as in build_cavities: where a reservoir triangle
  //    or edge holds a well vertex in its diametral sphere, or a well polygon or edge a reservoir
  //    vertex, the active cells behind the reservoir triangles involved are deactivated.
  // A violation on the model's outer surface (a surface triangle or edge holding a well vertex, a
  // surface vertex in a well polygon's or edge's sphere, with no active cell behind) cannot be
  // repaired: those triangles stay on the cavity boundary whatever else is deactivated, and the well
  // block does not move. The cavity is refused, naming the cell and the well.
  auto refuse_on_surface = [&](int32_t cell, const std::string& what, int32_t well_vertex) {
    throw InputError("wells: the cavity of " + well_name(well_vertex) + " in the corner-point model " +
                     cs.reservoir.grdecl + " reaches the model's outer surface (its top, bottom or sides, or an "
                     "inactive or zero-thickness cell) at cell " + cell_name(model, cell) + ", where " + what +
                     ": the surface cannot move away from the well (no model cell behind it to deactivate), so the "
                     "cavity cannot be made Gabriel (paper 5.1); keep the well's meshed path farther from that surface "
                     "than its faces are wide, or make the model's cells near the well smaller (docs/corner-point.md)");
  };
  auto metres = [](double d) {
    std::ostringstream os;
    os.precision(3);
    os << d << " m";
    return os.str();
  };
  // The deactivated cell of the first surface triangle holding all of `nodes`.
  auto surface_cell = [](const std::vector<ResTriangle>& tris, std::initializer_list<int32_t> nodes) {
    for (const ResTriangle& t : tris) {
      bool all = t.outside < 0;
      for (int32_t v : nodes) all = all && std::find(t.nodes.begin(), t.nodes.end(), v) != t.nodes.end();
      if (all) return t.inside;
    }
    return int32_t{-1};
  };
  int repaired = 0, rounds = 0, remaining = 0;
  for (rounds = 0; rounds < 60; ++rounds) {
    const std::vector<ResTriangle> tris = reservoir_triangles(cells, active, coords);
    // Per reservoir edge and vertex: the active cells behind its triangles (none on the surface).
    std::map<std::pair<int32_t, int32_t>, std::vector<int32_t>> edge_cells;
    std::map<int32_t, std::vector<int32_t>> vertex_cells;
    std::vector<std::vector<int32_t>> polys;
    for (const ResTriangle& t : tris) {
      for (size_t i = 0; i < 3; ++i) {
        const int32_t a = t.nodes[i], b = t.nodes[(i + 1) % 3];
        std::vector<int32_t>& ec = edge_cells[{std::min(a, b), std::max(a, b)}];
        std::vector<int32_t>& vc = vertex_cells[a];
        if (t.outside >= 0) ec.push_back(t.outside), vc.push_back(t.outside);
      }
      polys.push_back(t.nodes);
    }
    std::vector<std::array<int32_t, 2>> res_edges;
    for (const auto& [e, c] : edge_cells) res_edges.push_back({e.first, e.second});
    std::vector<int32_t> res_vertices;
    for (const auto& [v, c] : vertex_cells) res_vertices.push_back(v);
    const auto bad_res = gabriel_violations(coords, res_edges, well_vertices);
    const auto bad_well = gabriel_violations(coords, well_edges, res_vertices);
    const auto bad_res_faces = face_gabriel_violations(coords, polys, well_vertices);
    const auto bad_well_faces = face_gabriel_violations(coords, well_polygons, res_vertices);
    remaining = static_cast<int>(bad_res.size() + bad_well.size() + bad_res_faces.size() + bad_well_faces.size());
    if (remaining == 0) break;
    std::set<int32_t> grow;
    for (const GabrielViolation& v : bad_res) {
      const auto& c = edge_cells.at({v.a, v.b});
      if (c.empty())
        refuse_on_surface(surface_cell(tris, {v.a, v.b}),
                          "an edge of its surface triangles (" + metres(norm(coords[v.a] - coords[v.b])) +
                              " long) holds a vertex of the well block in its diametral sphere",
                          v.p);
      grow.insert(c.begin(), c.end());
    }
    for (const GabrielViolation& v : bad_well) {
      const auto& c = vertex_cells.at(v.p);
      if (c.empty())
        refuse_on_surface(surface_cell(tris, {v.p}),
                          "a node of its surface face lies in the diametral sphere of an edge of the well block (" +
                              metres(norm(coords[v.a] - coords[v.b])) + " long)",
                          v.a);
      grow.insert(c.begin(), c.end());
    }
    for (const FaceGabrielViolation& v : bad_res_faces) {
      const ResTriangle& t = tris[v.polygon];
      if (t.outside < 0) {
        double longest = 0;
        for (size_t i = 0; i < 3; ++i) longest = std::max(longest, norm(coords[t.nodes[i]] - coords[t.nodes[(i + 1) % 3]]));
        refuse_on_surface(t.inside,
                          "a triangle of its surface face (edges up to " + metres(longest) +
                              ") holds a vertex of the well block in its diametral sphere",
                          v.p);
      }
      grow.insert(t.outside);
    }
    for (const FaceGabrielViolation& v : bad_well_faces) {
      const auto& c = vertex_cells.at(v.p);
      if (c.empty())
        refuse_on_surface(surface_cell(tris, {v.p}),
                          "a node of its surface face lies in the diametral sphere of a polygon of the well block",
                          well_polygons[v.polygon].front());
      grow.insert(c.begin(), c.end());
    }
    if (grow.empty()) break;
    for (int32_t c : grow) active[c] = 0;
    repaired += static_cast<int>(grow.size());
    regularized += regularize_deactivated(index_grid, active);
    regularized += regularize_cavity_surface(cells, active, coords);
  }
  out.gabriel_violations_remaining = remaining;
  if (remaining > 0)
    throw InputError("wells: the cavity in the corner-point model cannot be made Gabriel (" + std::to_string(remaining) +
                     " violations left after " + std::to_string(rounds) +
                     " rounds); move the wells apart or reduce their drainage_radius");
  if (repaired > 0)
    out.notes.push_back("cavity: Gabriel repair deactivated " + std::to_string(repaired) + " more model cells in " +
                        std::to_string(rounds) + " rounds (local dilation)");
  if (regularized > 0)
    out.notes.push_back("cavity: " + std::to_string(regularized) +
                        " model cells deactivated to keep the cavity boundary a 2-manifold");

  // 3. The deactivated cells. Their faces with no meshed cell across (the model's outer surface,
  //    gaps: inactive or zero-thickness cells) are constrained triangles too (step 5), whose
  //    transition faces are outer-boundary faces (docs/corner-point.md, "Outer surface").
  std::vector<int32_t> dead;
  for (int c = 0; c < nc; ++c)
    if (cells.meshed[c] && !active[c]) dead.push_back(c);

  // 4. Cavities: connected components of the deactivated cells across their faces.
  std::vector<int> comp(nc, -1);
  int n_comp = 0;
  for (int32_t s : dead) {
    if (comp[s] >= 0) continue;
    std::vector<int32_t> stack{s};
    comp[s] = n_comp;
    while (!stack.empty()) {
      const int32_t c = stack.back();
      stack.pop_back();
      for (int64_t f = cells.face_begin(c); f < cells.face_end(c); ++f)
        if (const int32_t nb = cells.neighbour[f]; nb >= 0 && cells.meshed[nb] && !active[nb] && comp[nb] < 0)
          comp[nb] = n_comp, stack.push_back(nb);
    }
    ++n_comp;
  }
  out.cavities.resize(n_comp);
  for (int32_t c : dead) out.cavities[comp[c]].deactivated_cells.push_back(c);
  // Each well to the cavity of the deactivated cell nearest the middle of its block's first segment.
  for (size_t w = 0; w < blocks.size(); ++w) {
    const Vec3 p = 0.5 * (blocks[w].layer_center[0] + blocks[w].layer_center[1]);
    int best = -1;
    double d = INFINITY;
    for (int32_t c : dead) {
      const double dc = box_polyline_distance(lo[c], hi[c], {p, p});
      if (dc < d) d = dc, best = c;
    }
    if (best < 0) throw InputError("wells[" + std::to_string(blocks[w].well) + "].trajectory: not inside a cavity");
    out.cavities[comp[best]].wells.push_back(static_cast<int>(w));
  }

  // 5. Boundaries: the reservoir triangles (toward the active cells in their order, then those on the
  //    model's outer surface: outside_cell -1, an outer-boundary face of the transition), then the
  //    blocks' polygons.
  const std::vector<ResTriangle> tris = reservoir_triangles(cells, active, coords);
  int on_surface = 0;
  for (const ResTriangle& t : tris) {
    ConstrainedFace f;
    f.nodes = t.nodes;  // into the cavity
    f.side = FaceSide::Reservoir;
    f.outside_cell = t.outside;
    f.inside_cell = t.inside;
    if (t.outside < 0) f.patch = kOuterBoundary, ++on_surface;
    out.cavities[comp[t.inside]].faces.push_back(std::move(f));
  }
  if (on_surface > 0)
    out.notes.push_back("cavity: " + std::to_string(on_surface) +
                        " constrained triangles on the corner-point model's outer surface (outer-boundary faces)");
  for (size_t k = 0; k < out.cavities.size(); ++k) {
    Cavity& cav = out.cavities[k];
    if (cav.wells.empty()) throw InputError("wells: internal error, a cavity without a well");
    add_well_polygons(cav, blocks, well_node_ids);
    double dmax = 0;
    for (int32_t c : cav.deactivated_cells) {
      double best = INFINITY;
      for (int w : cav.wells) best = std::min(best, box_polyline_distance(lo[c], hi[c], blocks[w].trajectory) / blocks[w].radii.back());
      dmax = std::max(dmax, best);
    }
    cav.dilation_used = std::max(dil, dmax);
    cav.cells_are_boxes = false;
    auto locator = std::make_shared<const CornerPointLocator>(model, cells, cav.deactivated_cells, coords);
    cav.locate_cell = [locator](Vec3 x) { return locator->cell_at(x); };
  }
  return out;
}

}  // namespace hm
