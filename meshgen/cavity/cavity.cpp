#include "cavity.hpp"

#include <algorithm>
#include <boost/graph/adjacency_list.hpp>
#include <boost/graph/connected_components.hpp>
#include <cmath>
#include <map>
#include <set>
#include <sstream>

#include "meshgen/grids/gabriel.hpp"

namespace hm {

namespace {

// Squared distance from an axis-aligned box to a point.
double box_point_dist2(Vec3 lo, Vec3 hi, Vec3 p) {
  double d2 = 0;
  for (int a = 0; a < 3; ++a) {
    const double e = std::max({lo[a] - p[a], 0.0, p[a] - hi[a]});
    d2 += e * e;
  }
  return d2;
}

// Distance from an axis-aligned box to a segment: the squared distance along the
// segment is convex, so golden-section search converges to the minimum.
double box_segment_dist(Vec3 lo, Vec3 hi, Vec3 a, Vec3 b) {
  auto f = [&](double t) { return box_point_dist2(lo, hi, a + t * (b - a)); };
  double l = 0, r = 1;
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = r - g * (r - l), x2 = l + g * (r - l), f1 = f(x1), f2 = f(x2);
  for (int it = 0; it < 80; ++it) {
    if (f1 < f2) { r = x2; x2 = x1; f2 = f1; x1 = r - g * (r - l); f1 = f(x1); }
    else { l = x1; x1 = x2; f1 = f2; x2 = l + g * (r - l); f2 = f(x2); }
  }
  return std::sqrt(std::min({f(0.0), f(1.0), f1, f2}));
}

double box_polyline_dist(Vec3 lo, Vec3 hi, const std::vector<Vec3>& line) {
  double d = INFINITY;
  for (size_t s = 0; s + 1 < line.size(); ++s) d = std::min(d, box_segment_dist(lo, hi, line[s], line[s + 1]));
  return d;
}

}  // namespace

int regularize_deactivated(const ReservoirGrid& g, std::vector<char>& active) {
  int added = 0;
  bool changed = true;
  while (changed) {
    changed = false;
    for (int k = 1; k < g.nz(); ++k)
      for (int j = 1; j < g.ny(); ++j)
        for (int i = 1; i < g.nx(); ++i) {
          int cells[8];
          int n_dead = 0;
          for (int b = 0; b < 8; ++b) {
            cells[b] = g.cell_index(i - 1 + (b & 1), j - 1 + ((b >> 1) & 1), k - 1 + ((b >> 2) & 1));
            n_dead += !active[cells[b]];
          }
          if (n_dead == 0 || n_dead == 8) continue;
          auto components = [&](char want_active) {
            int comp = 0;
            bool seen[8] = {};
            for (int s = 0; s < 8; ++s) {
              if (seen[s] || (active[cells[s]] != 0) != (want_active != 0)) continue;
              ++comp;
              int stack[8], top = 0;
              stack[top++] = s;
              seen[s] = true;
              while (top) {
                const int u = stack[--top];
                for (int bit = 0; bit < 3; ++bit) {
                  const int v = u ^ (1 << bit);
                  if (!seen[v] && (active[cells[v]] != 0) == (want_active != 0)) { seen[v] = true; stack[top++] = v; }
                }
              }
            }
            return comp;
          };
          if (components(0) > 1 || components(1) > 1) {
            for (int b = 0; b < 8; ++b)
              if (active[cells[b]]) { active[cells[b]] = 0; ++added; }
            changed = true;
          }
        }
  }
  return added;
}

namespace {

struct EdgeKey {
  int32_t a, b;
  bool operator<(const EdgeKey& o) const { return a < o.a || (a == o.a && b < o.b); }
};

}  // namespace

double box_polyline_distance(Vec3 lo, Vec3 hi, const std::vector<Vec3>& line) { return box_polyline_dist(lo, hi, line); }

bool box_polyline_within(Vec3 lo, Vec3 hi, const std::vector<Vec3>& line, double reach) {
  for (size_t s = 0; s + 1 < line.size(); ++s) {
    const Vec3 a = line[s], b = line[s + 1];
    // Apart by more than reach along one axis: every point of the segment is farther than reach.
    bool apart = false;
    for (int k = 0; k < 3 && !apart; ++k)
      apart = lo[k] - std::max(a[k], b[k]) > reach || std::min(a[k], b[k]) - hi[k] > reach;
    if (!apart && box_segment_dist(lo, hi, a, b) <= reach) return true;
  }
  return false;
}

WellSurfaces well_surfaces(const std::vector<WellBlock>& blocks, const std::vector<std::vector<int32_t>>& well_node_ids) {
  WellSurfaces out;
  std::set<int32_t> verts;
  std::set<EdgeKey> edges;
  for (size_t w = 0; w < blocks.size(); ++w)
    for (const auto& poly : blocks[w].surface_faces) {
      std::vector<int32_t> g;
      for (size_t i = 0; i < poly.size(); ++i) {
        const int32_t a = well_node_ids[w][poly[i]], b = well_node_ids[w][poly[(i + 1) % poly.size()]];
        verts.insert(a);
        edges.insert({std::min(a, b), std::max(a, b)});
        g.push_back(a);
      }
      out.polygons.push_back(std::move(g));
    }
  out.vertices.assign(verts.begin(), verts.end());
  for (const EdgeKey& e : edges) out.edges.push_back({e.a, e.b});
  return out;
}

void add_well_polygons(Cavity& cav, const std::vector<WellBlock>& blocks,
                       const std::vector<std::vector<int32_t>>& well_node_ids) {
  for (int w : cav.wells) {
    const WellBlock& b = blocks[w];
    for (size_t s = 0; s < b.surface_faces.size(); ++s) {
      ConstrainedFace f;
      for (int32_t v : b.surface_faces[s]) f.nodes.push_back(well_node_ids[w][v]);
      f.side = FaceSide::Well;
      f.outside_cell = b.surface_cell[s];
      f.well = b.well;
      f.patch = b.surface_patch[s];
      cav.faces.push_back(std::move(f));
    }
  }
  std::set<int32_t> verts;
  for (const auto& f : cav.faces) verts.insert(f.nodes.begin(), f.nodes.end());
  cav.vertices.assign(verts.begin(), verts.end());
}

CavitySet build_cavities(const CaseSpec& cs, const ReservoirGrid& grid, const std::vector<WellBlock>& blocks,
                         const std::vector<int32_t>& reservoir_node_ids,
                         const std::vector<std::vector<int32_t>>& well_node_ids,
                         const std::vector<Vec3>& node_coords,
                         const std::vector<int32_t>& extra_deactivated) {
  CavitySet out;
  const int nc = grid.n_cells();
  out.reservoir_active.assign(nc, 1);
  std::vector<char>& active = out.reservoir_active;
  if (blocks.empty()) return out;

  // 1. Deactivate the cells meeting each dilated block: the points within
  //    dilation x drainage_radius of the trajectory.
  const double dil = cs.transition.dilation;
  for (size_t w = 0; w < blocks.size(); ++w) {
    const std::vector<Vec3>& traj = blocks[w].trajectory;  // the meshed part
    const double reach = dil * blocks[w].radii.back();     // the block's drainage radius (meshed_trajectory.hpp)
    for (int c = 0; c < nc; ++c)
      if (box_polyline_within(grid.cell_lo(c), grid.cell_hi(c), traj, reach)) active[c] = 0;
  }
  for (int32_t c : extra_deactivated)
    if (c >= 0 && c < nc) active[c] = 0;
  int regularized = regularize_deactivated(grid, active);

  // The well side of the Gabriel test: outer-surface edges and vertices of every block.
  auto res_node = [&](int lattice) { return reservoir_node_ids[lattice]; };
  const WellSurfaces well_side = well_surfaces(blocks, well_node_ids);
  const std::vector<int32_t>& well_vertices = well_side.vertices;
  const std::vector<std::array<int32_t, 2>>& well_edges = well_side.edges;
  const std::vector<std::vector<int32_t>>& well_polygons = well_side.polygons;
  const int lattice_nx = grid.nx() + 1, lattice_ny = grid.ny() + 1;
  std::vector<int32_t> lattice_of(node_coords.size(), -1);  // builder id -> lattice node
  for (int n = 0; n < grid.n_nodes(); ++n) lattice_of[reservoir_node_ids[n]] = n;
  // Deactivates the active cells around lattice node n (within the index box [lo, hi]).
  auto cells_around = [&](int n, std::array<int, 3> lo, std::array<int, 3> hi, std::set<int>& into) {
    const int ijk[3] = {n % lattice_nx, (n / lattice_nx) % lattice_ny, n / (lattice_nx * lattice_ny)};
    const int lim[3] = {grid.nx(), grid.ny(), grid.nz()};
    for (int i = ijk[0] + lo[0]; i <= ijk[0] + hi[0]; ++i)
      for (int j = ijk[1] + lo[1]; j <= ijk[1] + hi[1]; ++j)
        for (int k = ijk[2] + lo[2]; k <= ijk[2] + hi[2]; ++k) {
          if (i < 0 || j < 0 || k < 0 || i >= lim[0] || j >= lim[1] || k >= lim[2]) continue;
          const int c = grid.cell_index(i, j, k);
          if (active[c]) into.insert(c);
        }
  };

  // Two well blocks close enough that one's surface holds the other's vertices in its
  // diametral spheres cannot be separated by changing the reservoir: refuse the input.
  for (size_t w1 = 0; w1 < blocks.size(); ++w1)
    for (size_t w2 = 0; w2 < blocks.size(); ++w2) {
      if (w1 == w2) continue;
      std::vector<std::vector<int32_t>> polys;
      std::vector<std::array<int32_t, 2>> edges;
      for (const auto& poly : blocks[w1].surface_faces) {
        std::vector<int32_t> g;
        for (size_t i = 0; i < poly.size(); ++i) {
          g.push_back(well_node_ids[w1][poly[i]]);
          const int32_t a = well_node_ids[w1][poly[i]], b = well_node_ids[w1][poly[(i + 1) % poly.size()]];
          edges.push_back({std::min(a, b), std::max(a, b)});
        }
        polys.push_back(std::move(g));
      }
      std::vector<int32_t> other(well_node_ids[w2].begin(), well_node_ids[w2].end());
      if (!face_gabriel_violations(node_coords, polys, other).empty() ||
          !gabriel_violations(node_coords, edges, other).empty())
        throw InputError("wells[" + std::to_string(blocks[w2].well) + "].trajectory: too close to wells[" +
                         std::to_string(blocks[w1].well) +
                         "]: their radial blocks are not Gabriel with respect to each other (paper 5.1); move the "
                         "wells apart or reduce their drainage_radius");
    }

  // 2. Gabriel across the two sides (paper 5.1): no reservoir boundary edge's diametral
  //    sphere holds a well vertex and vice versa; the same for the diametral spheres of the
  //    constrained polygons (what the transition's site placement needs: the Voronoi edge
  //    of each polygon must start on the cavity side). Where it fails the cavity grows
  //    locally (the paper's local dilation): the active cells at the offending reservoir
  //    edge, face or vertex are deactivated, and the test runs again.
  int repaired_cells = 0, rounds = 0, remaining = 0;
  for (rounds = 0; rounds < 60; ++rounds) {
    std::set<std::pair<int, int>> res_edge_set;
    std::set<int32_t> res_vertex_set;
    std::vector<std::vector<int32_t>> res_polygons;
    std::vector<int> res_polygon_cell;  // the active cell outside each reservoir polygon
    for (int c = 0; c < nc; ++c) {
      if (active[c]) continue;
      for (int side = 0; side < 6; ++side) {
        const int n = grid.neighbour(c, side);
        if (n < 0 || !active[n]) continue;  // the outer boundary: a mirror plane, no polygon
        const auto fn = grid.cell_face_nodes(c, side);
        std::vector<int32_t> poly;
        for (int i = 0; i < 4; ++i) {
          const int32_t a = res_node(fn[i]), b = res_node(fn[(i + 1) % 4]);
          res_vertex_set.insert(a);
          res_edge_set.insert({std::min(a, b), std::max(a, b)});
          poly.push_back(a);
        }
        res_polygons.push_back(std::move(poly));
        res_polygon_cell.push_back(n);
      }
    }
    std::vector<std::array<int32_t, 2>> res_edges;
    for (const auto& e : res_edge_set) res_edges.push_back({e.first, e.second});
    const std::vector<int32_t> res_vertices(res_vertex_set.begin(), res_vertex_set.end());
    const auto bad_res = gabriel_violations(node_coords, res_edges, well_vertices);
    const auto bad_well = gabriel_violations(node_coords, well_edges, res_vertices);
    const auto bad_res_faces = face_gabriel_violations(node_coords, res_polygons, well_vertices);
    const auto bad_well_faces = face_gabriel_violations(node_coords, well_polygons, res_vertices);
    remaining = static_cast<int>(bad_res.size() + bad_well.size() + bad_res_faces.size() + bad_well_faces.size());
    if (remaining == 0) break;
    std::set<int> grow;
    for (const GabrielViolation& v : bad_res) {
      // The cells around lattice edge (a, b): along the edge's axis only the lower node's cells.
      const int a = lattice_of[v.a], b = lattice_of[v.b];
      const int d = std::abs(b - a);
      const int axis = d == 1 ? 0 : (d == lattice_nx ? 1 : 2);
      std::array<int, 3> lo{-1, -1, -1}, hi{0, 0, 0};
      lo[axis] = 0;
      cells_around(std::min(a, b), lo, hi, grow);
    }
    for (const GabrielViolation& v : bad_well) cells_around(lattice_of[v.p], {-1, -1, -1}, {0, 0, 0}, grow);
    for (const FaceGabrielViolation& v : bad_res_faces) grow.insert(res_polygon_cell[v.polygon]);
    for (const FaceGabrielViolation& v : bad_well_faces) cells_around(lattice_of[v.p], {-1, -1, -1}, {0, 0, 0}, grow);
    if (grow.empty()) break;  // violations between two wells: nothing in the reservoir to change
    for (int c : grow) active[c] = 0;
    repaired_cells += static_cast<int>(grow.size());
    regularized += regularize_deactivated(grid, active);
  }
  out.gabriel_violations_remaining = remaining;
  if (remaining > 0)
    throw InputError("wells: the cavity cannot be made Gabriel (" + std::to_string(remaining) +
                     " edge/vertex violations left, e.g. two well blocks too close to each other); "
                     "move the wells apart or reduce their drainage_radius");
  if (repaired_cells > 0) {
    std::ostringstream os;
    os << "cavity: Gabriel repair deactivated " << repaired_cells << " more reservoir cells in " << rounds
       << " rounds (local dilation)";
    out.notes.push_back(os.str());
  }
  if (regularized > 0)
    out.notes.push_back("cavity: " + std::to_string(regularized) +
                        " reservoir cells deactivated to keep the cavity boundary a 2-manifold");

  // 3. Cavities = connected components of deactivated cells (face adjacency).
  std::vector<int> dead;
  std::vector<int> dead_index(nc, -1);
  for (int c = 0; c < nc; ++c)
    if (!active[c]) { dead_index[c] = static_cast<int>(dead.size()); dead.push_back(c); }
  using Graph = boost::adjacency_list<boost::vecS, boost::vecS, boost::undirectedS>;
  Graph graph(dead.size());
  for (size_t d = 0; d < dead.size(); ++d)
    for (int side = 1; side < 6; side += 2) {
      const int n = grid.neighbour(dead[d], side);
      if (n >= 0 && !active[n]) boost::add_edge(d, dead_index[n], graph);
    }
  std::vector<int> comp(dead.size());
  const int n_comp = dead.empty() ? 0 : boost::connected_components(graph, comp.data());
  out.cavities.resize(n_comp);
  for (size_t d = 0; d < dead.size(); ++d) out.cavities[comp[d]].deactivated_cells.push_back(dead[d]);

  // Assign each well to the cavity containing the middle of its block's first segment.
  for (size_t w = 0; w < blocks.size(); ++w) {
    const Vec3 p = 0.5 * (blocks[w].layer_center[0] + blocks[w].layer_center[1]);
    int cell = -1;
    for (int c : dead) {
      const Vec3 lo = grid.cell_lo(c), hi = grid.cell_hi(c);
      if (p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z) { cell = c; break; }
    }
    if (cell < 0) throw InputError("wells[" + std::to_string(blocks[w].well) + "].trajectory: not inside a cavity");
    out.cavities[comp[dead_index[cell]]].wells.push_back(static_cast<int>(w));
  }

  // 4. Boundary surfaces.
  for (Cavity& cav : out.cavities) {
    for (int c : cav.deactivated_cells)
      for (int side = 0; side < 6; ++side) {
        const int n = grid.neighbour(c, side);
        if (n < 0) {
          const int axis = side / 2;
          const std::vector<double>& coord = axis == 0 ? grid.x : axis == 1 ? grid.y : grid.z;
          const MirrorPlane m{axis, side % 2 ? coord.back() : coord.front()};
          if (std::find(cav.mirrors.begin(), cav.mirrors.end(), m) == cav.mirrors.end()) cav.mirrors.push_back(m);
          continue;
        }
        if (!active[n]) continue;
        ConstrainedFace f;
        const auto fn = grid.cell_face_nodes(n, side ^ 1);  // the active cell's face: outward = into the cavity
        for (int i = 0; i < 4; ++i) f.nodes.push_back(res_node(fn[i]));
        f.side = FaceSide::Reservoir;
        f.outside_cell = n;
        f.inside_cell = c;
        cav.faces.push_back(std::move(f));
      }
    add_well_polygons(cav, blocks, well_node_ids);
    // Largest local dilation: the farthest deactivated cell from its nearest well, in drainage radii.
    double dmax = 0;
    for (int c : cav.deactivated_cells) {
      double best = INFINITY;
      for (int w : cav.wells) {
        best = std::min(best, box_polyline_dist(grid.cell_lo(c), grid.cell_hi(c), blocks[w].trajectory) /
                                  blocks[w].radii.back());
      }
      dmax = std::max(dmax, best);
    }
    cav.dilation_used = std::max(dil, dmax);
    std::sort(cav.mirrors.begin(), cav.mirrors.end(), [](const MirrorPlane& a, const MirrorPlane& b) {
      return a.axis != b.axis ? a.axis < b.axis : a.value < b.value;
    });
    if (cav.wells.empty()) throw InputError("wells: internal error, a cavity without a well");
  }
  return out;
}

}  // namespace hm
