// Paper 5.6-5.7: power diagram of the cavity sites (CGAL Regular_triangulation_3) and
// its conformity with the constrained polygons. One of the two CGAL translation units.
//
// Power vertices are identified combinatorially (as geogram does): RT cells whose power
// spheres coincide (exact predicate across a facet) are one vertex (union-find), and a
// vertex whose four sites share exactly one constrained node IS that node. Only what is
// left on the external faces is snapped to the nearest constrained vertex (5.7).
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Mpzf.h>
#include <CGAL/mpq_class.h>
#include <CGAL/Regular_triangulation_3.h>
#include <CGAL/Triangulation_cell_base_with_info_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <algorithm>
#include <cmath>
#include <array>
#include <atomic>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <numeric>
#include <set>
#include <sstream>
#include <stdexcept>

#include "transition_internal.hpp"

namespace hm::transition_detail {

namespace {
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vbb = CGAL::Regular_triangulation_vertex_base_3<K>;
using Vb = CGAL::Triangulation_vertex_base_with_info_3<int, K, Vbb>;
using Cbb = CGAL::Regular_triangulation_cell_base_3<K>;
// Per RT cell: its index in one extraction, and its power centre once computed. A cell that
// a site move leaves in place keeps its centre: the optimiser recomputes only the cells that
// the moves created (PowerDiagram).
struct CellInfo {
  int index = -1;
  bool has_center = false, exact = false;
  Vec3 center;
  // The sorted site ids of the cell, and the constrained nodes its four sites share (none
  // with a guard point): fixed while the cell lives (a cell never changes its vertices).
  bool has_common = false, guard = false;
  std::array<int, 4> key{};
  int n_common = 0;          // 0, 1 or 2 (two or more: recomputed when used, rare)
  int32_t common_node = -1;  // the shared node when n_common == 1
  // A number no other cell of any triangulation has had (0: none yet), and per facet the number of
  // the neighbour whose power sphere was compared with this one's, and whether they coincide.
  uint64_t serial = 0;
  std::array<uint64_t, 4> compared_with{};
  std::array<bool, 4> same_sphere{};
};
std::atomic<uint64_t> next_cell_serial{1};
uint64_t serial_of(CellInfo& ci) {
  if (ci.serial == 0) ci.serial = next_cell_serial.fetch_add(1, std::memory_order_relaxed);
  return ci.serial;
}
using Cb = CGAL::Triangulation_cell_base_with_info_3<CellInfo, K, Cbb>;
using Tds = CGAL::Triangulation_data_structure_3<Vb, Cb>;
using Regular = CGAL::Regular_triangulation_3<K, Tds>;
using WPoint = K::Weighted_point_3;
using BPoint = K::Point_3;

// The power vertex of a cell. Co-spherical sites make many nearly flat cells, on which the
// double formula loses up to 1e-8 relative; those (|det| of the edge vectors below 1e-4 of
// the product of their lengths) are computed exactly and rounded once. Well-shaped cells
// keep the fast double formula (error about cond x 1e-16).
//
// Exactly: the determinants of the weighted circumcentre (CGAL's weighted_circumcenterC3, the
// origin at the first point) in Mpzf, exact for + - x and much cheaper than rationals, then one
// rational division per coordinate. The exact centre is unique: this is the double that CGAL's
// rational kernel (Exact_rational = mpq_class here) gives, to_double truncating as mpq_get_d does.
Vec3 exact_power_center(const Regular::Cell_handle& c) {
  using Z = CGAL::Mpzf;
  const WPoint& w0 = c->vertex(0)->point();
  const Z px(w0.x()), py(w0.y()), pz(w0.z()), pw(w0.weight());
  std::array<std::array<Z, 4>, 3> d;  // per other point: x, y, z and squared norm minus weight, from point 0
  for (int i = 0; i < 3; ++i) {
    const WPoint& w = c->vertex(i + 1)->point();
    d[i][0] = Z(w.x()) - px, d[i][1] = Z(w.y()) - py, d[i][2] = Z(w.z()) - pz;
    d[i][3] = d[i][0] * d[i][0] + d[i][1] * d[i][1] + d[i][2] * d[i][2] - (Z(w.weight()) - pw);
  }
  auto det = [&](int a, int b, int e) {  // columns a, b, e of the three rows
    return d[0][a] * (d[1][b] * d[2][e] - d[2][b] * d[1][e]) - d[1][a] * (d[0][b] * d[2][e] - d[2][b] * d[0][e]) +
           d[2][a] * (d[0][b] * d[1][e] - d[1][b] * d[0][e]);
  };
  const mpq_class two_den = 2 * static_cast<mpq_class>(det(0, 1, 2));
  const mpq_class x = static_cast<mpq_class>(px) + static_cast<mpq_class>(det(1, 2, 3)) / two_den;
  const mpq_class y = static_cast<mpq_class>(py) - static_cast<mpq_class>(det(0, 2, 3)) / two_den;
  const mpq_class z = static_cast<mpq_class>(pz) + static_cast<mpq_class>(det(0, 1, 3)) / two_den;
  return Vec3{CGAL::to_double(x), CGAL::to_double(y), CGAL::to_double(z)};
}

// The four points in the order of their site ids: the rounded centre then depends on the cell
// alone, not on the order a triangulation's history gave its vertices.
Vec3 computed_power_center(const Regular& rt, const Regular::Cell_handle& c, bool* exact) {
  std::array<const WPoint*, 4> w;
  {
    std::array<std::pair<int, int>, 4> order;
    for (int i = 0; i < 4; ++i) order[i] = {c->vertex(i)->info(), i};
    std::sort(order.begin(), order.end());
    for (int i = 0; i < 4; ++i) w[i] = &c->vertex(order[i].second)->point();
  }
  auto at = [&](int i) { return Vec3{w[i]->x(), w[i]->y(), w[i]->z()}; };
  const Vec3 p0 = at(0), r1 = at(1) - p0, r2 = at(2) - p0, r3 = at(3) - p0;
  const double det = dot(r1, cross(r2, r3));
  if (std::abs(det) > 1e-4 * norm(r1) * norm(r2) * norm(r3)) {
    const BPoint p = rt.geom_traits().construct_weighted_circumcenter_3_object()(*w[0], *w[1], *w[2], *w[3]);
    return Vec3{p.x(), p.y(), p.z()};
  }
  *exact = true;
  return exact_power_center(c);
}

Vec3 power_center(const Regular& rt, const Regular::Cell_handle& c, int* exact_count) {
  CellInfo& ci = c->info();
  if (!ci.has_center) ci.center = computed_power_center(rt, c, &ci.exact), ci.has_center = true;
  if (ci.exact) ++*exact_count;
  return ci.center;
}

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(int n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  }
  bool unite(int a, int b) {
    a = find(a), b = find(b);
    if (a == b) return false;
    if (b < a) std::swap(a, b);
    parent[b] = a;
    return true;
  }
};

std::vector<int32_t> intersect(const std::vector<int32_t>& a, const std::vector<int32_t>& b) {
  std::vector<int32_t> out;
  std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(out));
  return out;
}

// A vertex of a face cycle before numbering: a constrained node id (>= 0) or a free power
// vertex, encoded as -1 - class.
using Token = int64_t;

// Three vertices whose angle at the middle one is this close to 0 or 180 degrees (its sine, in radians)
// lie on one line: the duals of tetrahedra of nearly co-spherical sites (mirror images across a boundary
// plane make them), rounded off the line by the vertex computation (measured: 8e-9 m off the middle of a
// 2 m edge in realistic sweep seed 1521, 1e-9 m along a line of five vertices 0.1-5 m apart in seed 1405).
// An angle, not a distance: a vertex microns from one neighbour and metres from the other is a corner of
// a sliver face, never on a line by a distance relative to the edge (seed 1256).
constexpr double kVertexOnLine = 1e-6;

// The sine of the angle at x between the directions to a and b is below kVertexOnLine.
bool on_one_line(Vec3 a, Vec3 x, Vec3 b) {
  const Vec3 u = a - x, v = b - x;
  const double lengths = norm(u) * norm(v);
  return lengths > 0 && norm(cross(u, v)) <= kVertexOnLine * lengths;
}

// True when every vertex of the cycle is on one line with its two neighbours: a face of no area (a
// segment traversed back and forth), where two cells touch along an edge only.
template <class Position>
bool collinear_cycle(const std::vector<Token>& c, Position position) {
  const size_t n = c.size();
  for (size_t k = 0; k < n; ++k)
    if (!on_one_line(position(c[(k + n - 1) % n]), position(c[k]), position(c[(k + 1) % n]))) return false;
  return true;
}

// True when the vertex at c[k] lies on the segment between its two neighbours in c (an angle of 180
// degrees there).
template <class Position>
bool inside_its_edge(const std::vector<Token>& c, size_t k, Position position) {
  const size_t n = c.size();
  const Token ta = c[(k + n - 1) % n], tb = c[(k + 1) % n];
  if (ta == tb) return false;
  const Vec3 a = position(ta), b = position(tb), x = position(c[k]);
  return dot(a - x, b - x) < 0 && on_one_line(a, x, b);
}

// Power vertices of nearly co-circular sites fall, rounded, along one line (the circle's axis): faces
// of no area join them, and each cell around the line holds its own subset of them, which would hang on
// its neighbours' edges. A free vertex is dropped from every face when, in each face holding it, it lies
// inside the edge between its neighbours or the whole face lies on a line; repeated until none is left
// (each drop can straighten its neighbours' edges). A face of no area whose vertices all go is removed;
// one that keeps three (the corners of a sliver face elsewhere) stays as it was. Returns the faces left
// with fewer than 3 vertices.
// Free vertices are tokens -1 - class with class < n_classes.
template <class Position>
int drop_vertices_inside_edges(std::vector<std::vector<Token>>& cycles, int n_classes, Position position) {
  std::vector<char> collinear(cycles.size());
  for (size_t i = 0; i < cycles.size(); ++i) collinear[i] = cycles[i].size() >= 3 && collinear_cycle(cycles[i], position);
  int degenerate = 0;
  std::vector<char> straight(n_classes);  // per free vertex: inside its edge (or in a face of no area) in every face so far
  for (bool dropped_any = true; dropped_any;) {
    dropped_any = false;
    std::fill(straight.begin(), straight.end(), 1);
    for (size_t i = 0; i < cycles.size(); ++i) {
      const std::vector<Token>& c = cycles[i];
      if (c.size() < 3) continue;
      for (size_t k = 0; k < c.size(); ++k)
        if (c[k] < 0) {
          char& s = straight[static_cast<size_t>(-1 - c[k])];
          s = s && (collinear[i] || inside_its_edge(c, k, position));
        }
    }
    for (std::vector<Token>& c : cycles) {
      if (c.size() < 3) continue;
      const size_t before = c.size();
      c.erase(std::remove_if(c.begin(), c.end(), [&](Token t) { return t < 0 && straight[static_cast<size_t>(-1 - t)]; }),
              c.end());
      if (c.size() == before) continue;
      dropped_any = true;
      degenerate += c.size() < 3;
    }
  }
  return degenerate;
}

// Removes consecutive repeats and spikes (x y x -> x) cyclically: what vertex
// identification leaves in a face. Both keep a closed cell surface closed.
void clean_cycle(std::vector<Token>& c) {
  bool changed = true;
  while (changed && c.size() >= 2) {
    changed = false;
    for (size_t i = 0; i < c.size() && c.size() >= 2; ++i) {
      const size_t n = c.size(), j = (i + 1) % n;
      if (c[i] == c[j]) {
        c.erase(c.begin() + static_cast<long>(j));
        changed = true;
        break;
      }
      if (n >= 3 && c[i] == c[(i + 2) % n]) {  // spike i -> i+1 -> i
        const size_t a = j, b = (i + 2) % n;
        c.erase(c.begin() + static_cast<long>(std::max(a, b)));
        c.erase(c.begin() + static_cast<long>(std::min(a, b)));
        changed = true;
        break;
      }
    }
  }
}

std::vector<int32_t> rotate_to_min(std::vector<int32_t> c) {
  std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
  return c;
}

bool same_cycle(const std::vector<int32_t>& a, const std::vector<int32_t>& b) {
  return a.size() == b.size() && rotate_to_min(a) == rotate_to_min(b);
}

struct RawFace {
  int s = -1, t = -1;          // sites; s internal; cycle is outward for s
  std::vector<int> classes;    // power vertex classes in cycle order
  bool external = false;       // t is an external site
  bool boundary = false;       // t is the image of s: the face lies in an outer-boundary plane
  bool stray = false;          // t is the image of another site (zero area in exact geometry)
};

}  // namespace

std::vector<int> imaged_sites(const SiteSet& set) {
  std::vector<int> out;
  for (size_t s = 0; s < set.sites.size(); ++s)
    if (set.sites[s].alive && set.sites[s].kind != SiteKind::Guard) out.push_back(static_cast<int>(s));
  return out;
}

namespace {
// The real sites plus, per outer-boundary plane, the image of every live site.
SiteSet with_images(const SiteSet& real, const BoundaryImages& images) {
  SiteSet set = real;
  const std::vector<int> sites = imaged_sites(real);
  for (int k = 0; k < static_cast<int>(images.planes.size()); ++k)
    for (int s : sites) {
      const Site& r = real.sites[s];
      Site im;
      im.kind = SiteKind::Image;
      im.p = reflect(r.p, images.planes[k]);
      im.w2 = r.w2;
      im.unchecked = false;
      im.vertices = images.image_of(k, r.vertices);
      im.image_of = s;
      im.plane = k;
      set.sites.push_back(std::move(im));
    }
  return set;
}

// The regular triangulation of the live sites of `set` plus 8 far guard points of weight 0
// (ids ns .. ns + 7), vertex info = site id.
void triangulate(const SiteSet& set, Regular& rt) {
  const int ns = static_cast<int>(set.sites.size());
  std::vector<std::pair<WPoint, int>> points;
  Vec3 lo{kInf, kInf, kInf}, hi = -lo;
  for (int s = 0; s < ns; ++s) {
    const Site& site = set.sites[s];
    if (!site.alive || site.kind == SiteKind::Guard) continue;
    points.emplace_back(WPoint(BPoint(site.p.x, site.p.y, site.p.z), site.w2), s);
    const double r = std::sqrt(site.w2);
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], site.p[k] - r), hi[k] = std::max(hi[k], site.p[k] + r);
  }
  const double margin = norm(hi - lo);
  for (int c = 0; c < 8; ++c)
    points.emplace_back(WPoint(BPoint((c & 1) ? hi.x + margin : lo.x - margin, (c & 2) ? hi.y + margin : lo.y - margin,
                                      (c & 4) ? hi.z + margin : lo.z - margin),
                               0.0),
                        ns + c);
  rt.clear();
  rt.insert(points.begin(), points.end());
}

// An RT edge as one cell holding it and the edge's two vertex indices in that cell.
struct FiniteEdge {
  Regular::Cell_handle cell;
  int i, j;
};

// Every finite RT edge with an internal endpoint, once: from the star of each internal site (an edge
// between two internal sites from the smaller id's). Cheaper than the triangulation's edge iterator,
// which circulates around every edge of the whole triangulation to find its representative cell.
template <class IsInternal>
std::vector<FiniteEdge> edges_of_internal_sites(const Regular& rt, const std::vector<Regular::Vertex_handle>& vertex_of,
                                                const IsInternal& is_internal) {
  std::vector<FiniteEdge> edges;
  std::vector<Regular::Cell_handle> star;
  std::vector<int> seen_from(vertex_of.size(), -1);  // per vertex id: the last star it was met in
  for (size_t s = 0; s < vertex_of.size(); ++s) {
    const Regular::Vertex_handle v = vertex_of[s];
    if (v == Regular::Vertex_handle() || !is_internal(static_cast<int>(s))) continue;
    star.clear();
    rt.incident_cells(v, std::back_inserter(star));
    for (const Regular::Cell_handle& c : star)
      for (int k = 0; k < 4; ++k) {
        const Regular::Vertex_handle w = c->vertex(k);
        if (w == v || rt.is_infinite(w) || seen_from[w->info()] == static_cast<int>(s)) continue;
        seen_from[w->info()] = static_cast<int>(s);
        if (is_internal(w->info()) && w->info() < static_cast<int>(s)) continue;  // listed from w's star
        edges.push_back({c, c->index(v), k});
      }
  }
  return edges;
}

// Power cells of the internal sites of `set` (the real sites first, n_real of them, then
// their images) from its regular triangulation `rt`: what build_power_cells returns.
std::vector<int> extract_power_cells(Regular& rt, const SiteSet& set, int n_real, const Cavity& cavity,
                                     const std::vector<Vec3>& coords, const std::vector<PolygonFrame>& frames,
                                     TransitionCells& out, const BoundaryImages& images) {
  const int ns = static_cast<int>(set.sites.size());
  TransitionReport& rep = out.report;
  std::vector<Regular::Vertex_handle> vertex_of(ns + 8);
  for (auto v : rt.finite_vertex_handles()) vertex_of[v->info()] = v;
  std::vector<int> hidden;
  for (int s = 0; s < ns; ++s)
    if (set.sites[s].alive && set.sites[s].kind != SiteKind::Guard && vertex_of[s] == Regular::Vertex_handle())
      hidden.push_back(s < n_real ? s : set.sites[s].image_of);  // an image is hidden with its site
  std::sort(hidden.begin(), hidden.end());
  hidden.erase(std::unique(hidden.begin(), hidden.end()), hidden.end());
  if (!hidden.empty()) return hidden;
  auto is_guard = [&](int id) { return id >= ns; };
  auto is_internal = [&](int id) { return id < ns && set.sites[id].internal(); };

  // ---- power vertices: merge cells with the same power sphere (exact), union-find
  std::vector<Regular::Cell_handle> cells;
  for (auto c : rt.finite_cell_handles()) {
    c->info().index = static_cast<int>(cells.size());
    cells.push_back(c);
  }
  const int nc = static_cast<int>(cells.size());
  UnionFind uf(nc);
  const auto power_side = rt.geom_traits().power_side_of_oriented_power_sphere_3_object();
  int merged_count = 0;
  // A pair of cells that a rebuild left in place keeps its answer (the optimiser's rounds).
  auto same_sphere = [&](const Regular::Cell_handle& c, int i, const Regular::Cell_handle& n) {
    CellInfo& ci = c->info();
    const uint64_t other = serial_of(n->info());
    if (ci.compared_with[i] != other) {
      const Regular::Vertex_handle opp = n->vertex(n->index(c));
      ci.same_sphere[i] = power_side(c->vertex(0)->point(), c->vertex(1)->point(), c->vertex(2)->point(),
                                     c->vertex(3)->point(), opp->point()) == CGAL::ON_ORIENTED_BOUNDARY;
      ci.compared_with[i] = other;
    }
    return ci.same_sphere[i];
  };
  for (int a = 0; a < nc; ++a) {
    const Regular::Cell_handle c = cells[a];
    for (int i = 0; i < 4; ++i) {
      const Regular::Cell_handle n = c->neighbor(i);
      if (n->info().index < a || rt.is_infinite(n)) continue;  // an infinite cell has no index (-1)
      if (same_sphere(c, i, n)) merged_count += uf.unite(a, n->info().index) ? 1 : 0;
    }
  }
  rep.merged_cells = merged_count;

  // Per class (lazily, for classes used by a face of an internal site): a deterministic
  // key (smallest sorted site tuple of its cells), coordinates, identified node.
  struct ClassInfo {
    bool done = false;
    std::array<int, 4> key{};
    Vec3 point;
    int32_t node = -1;     // identified constrained node, -1 if free
    int ambiguous = 0;
  };
  // Only the classes in use get one (lazily): an index per class, not a record.
  std::vector<int> info_index(nc, -1);
  std::vector<ClassInfo> infos;
  infos.reserve(nc);  // references into it stay valid
  int exact_centers = 0;
  // The cells of each class (CSR over class roots, cells ascending).
  std::vector<int> class_begin(nc + 1, 0), class_members(nc), root_of(nc);
  for (int a = 0; a < nc; ++a) root_of[a] = uf.find(a), ++class_begin[root_of[a] + 1];
  for (int a = 0; a < nc; ++a) class_begin[a + 1] += class_begin[a];
  {
    std::vector<int> fill(class_begin.begin(), class_begin.end() - 1);
    for (int a = 0; a < nc; ++a) class_members[fill[root_of[a]]++] = a;
  }
  auto cell_class_info = [&](int cls) -> ClassInfo& {
    if (info_index[cls] < 0) info_index[cls] = static_cast<int>(infos.size()), infos.emplace_back();
    ClassInfo& ci = infos[info_index[cls]];
    if (ci.done) return ci;
    ci.done = true;
    bool first = true;
    int rep_cell = -1;
    std::vector<int32_t> candidates;
    for (int k = class_begin[cls]; k < class_begin[cls + 1]; ++k) {
      const int a = class_members[k];
      CellInfo& cell = cells[a]->info();
      auto shared_nodes = [&] {
        std::vector<int32_t> common = set.sites[cell.key[0]].vertices;
        for (int i = 1; i < 4 && !common.empty(); ++i) common = intersect(common, set.sites[cell.key[i]].vertices);
        return common;
      };
      if (!cell.has_common) {
        cell.has_common = true;
        for (int i = 0; i < 4; ++i) cell.key[i] = cells[a]->vertex(i)->info();
        std::sort(cell.key.begin(), cell.key.end());
        cell.guard = is_guard(cell.key[3]);  // guards have the largest ids
        if (!cell.guard) {
          const std::vector<int32_t> common = shared_nodes();
          cell.n_common = std::min<int>(static_cast<int>(common.size()), 2);
          if (common.size() == 1) cell.common_node = common[0];
        }
      }
      const std::array<int, 4>& key = cell.key;
      if (first || key < ci.key) ci.key = key, rep_cell = a, first = false;
      if (cell.guard) continue;
      if (cell.n_common == 1) candidates.push_back(cell.common_node);
      else if (cell.n_common > 1) {
        const std::vector<int32_t> common = shared_nodes();
        ++ci.ambiguous, candidates.insert(candidates.end(), common.begin(), common.end());
      }
    }
    ci.point = power_center(rt, cells[rep_cell], &exact_centers);
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
    if (!candidates.empty()) {
      if (candidates.size() > 1) ++ci.ambiguous;
      ci.node = candidates[0];
      // Several candidates: the cell's sites share an edge AB (rounding made a sliver of
      // sites that are coplanar in exact geometry); its power centre lies on line AB and
      // the nearest end is the vertex it stands for.
      for (int32_t v : candidates)
        if (norm2(coords[v] - ci.point) < norm2(coords[ci.node] - ci.point)) ci.node = v;
      if (!ci.ambiguous)
        rep.max_identification_shift = std::max(rep.max_identification_shift, norm(coords[ci.node] - ci.point));
    }
    return ci;
  };

  // ---- faces: one per RT edge with an internal endpoint, from the cells around it
  std::vector<RawFace> faces;
  for (const FiniteEdge& e : edges_of_internal_sites(rt, vertex_of, is_internal)) {
    const Regular::Cell_handle c = e.cell;
    int s = c->vertex(e.i)->info(), t = c->vertex(e.j)->info();
    const bool si = is_internal(s), ti = is_internal(t);
    RawFace f;
    auto circ = rt.incident_cells(c, e.i, e.j), done = circ;
    bool unbounded = false;
    do {
      if (rt.is_infinite(circ)) { unbounded = true; break; }
      f.classes.push_back(uf.find(circ->info().index));
    } while (++circ != done);
    const int inner = si ? s : t, other = si ? t : s;
    if (unbounded || is_guard(other)) {
      std::ostringstream os;
      os << "transition: the cavity leaked: internal site " << inner;
      if (!set.sites[inner].polygons.empty()) os << " (polygon " << set.sites[inner].polygons.front() << ")";
      os << " meets the far guard points";
      throw std::runtime_error(os.str());
    }
    // Drop repeated classes (co-spherical cells merged): a zero-area face has < 3 left.
    f.classes.erase(std::unique(f.classes.begin(), f.classes.end()), f.classes.end());
    while (f.classes.size() > 1 && f.classes.front() == f.classes.back()) f.classes.pop_back();
    if (f.classes.size() < 3) continue;
    // The circulator turns positively around the oriented edge s -> t, so the cycle's
    // right-hand normal points from s to t: outward for s.
    // Internal site first; between two internal sites, the smaller id first (the edge's
    // direction comes from the triangulation's memory layout, not from the input).
    if (!si || (ti && t < s)) {
      std::swap(s, t);
      std::reverse(f.classes.begin(), f.classes.end());
    }
    f.s = s;
    f.t = t;
    f.external = !ti || !si;
    if (set.sites[t].kind == SiteKind::Image) {
      f.external = false;
      (set.sites[t].image_of == s ? f.boundary : f.stray) = true;
    }
    faces.push_back(std::move(f));
  }
  // Deterministic face order: by (s, t) site ids.
  std::sort(faces.begin(), faces.end(), [](const RawFace& a, const RawFace& b) {
    return a.s != b.s ? a.s < b.s : a.t < b.t;
  });

  // ---- numerically coincident power vertices. Sites that are co-spherical in exact
  // geometry (lattice nodes, coplanar polygons) stop being so once their coordinates are
  // rounded to doubles: the exact predicates then see several power vertices a few ulps
  // apart, joined by zero-area faces whose normals are noise. Vertices closer than
  // kCoincidence x (cavity size) are one vertex (the same point is the same vertex of a
  // power diagram).
  constexpr double kCoincidence = 1e-9;
  std::vector<int> used;  // ascending
  {
    std::vector<char> is_used(nc, 0);
    for (const RawFace& f : faces)
      for (int cls : f.classes) is_used[cls] = 1;
    for (int cls = 0; cls < nc; ++cls)
      if (is_used[cls]) used.push_back(cls);
  }
  double scale = 0;
  {
    Vec3 clo = coords[cavity.vertices.front()], chi = clo;
    for (int32_t v : cavity.vertices)
      for (int k = 0; k < 3; ++k) clo[k] = std::min(clo[k], coords[v][k]), chi[k] = std::max(chi[k], coords[v][k]);
    scale = norm(chi - clo);
  }
  const double eps = kCoincidence * scale;
  std::vector<Vec3> used_points;
  used_points.reserve(used.size());
  for (int cls : used) used_points.push_back(cell_class_info(cls).point);
  int coincident = 0;
  for (const auto& [a, b] : coincident_pairs(used_points, eps)) coincident += uf.unite(used[a], used[b]) ? 1 : 0;
  rep.coincident_vertices = coincident;
  // Merged classes: smallest key, its point; identified node if any member has one.
  // (per class root: its index in `merged`, -1 for roots of no class in use)
  std::vector<ClassInfo> merged;
  std::vector<int> merged_index(nc, -1);
  for (int cls : used) {
    const ClassInfo& ci = cell_class_info(cls);
    const int root = uf.find(cls);
    if (merged_index[root] < 0) {
      merged_index[root] = static_cast<int>(merged.size());
      merged.push_back(ci);
      continue;
    }
    ClassInfo& m = merged[merged_index[root]];
    if (ci.node >= 0 && m.node >= 0 && ci.node != m.node) ++m.ambiguous;
    if (ci.key < m.key) {
      const int32_t node = m.node >= 0 ? m.node : ci.node;
      const int amb = m.ambiguous + ci.ambiguous;
      m = ci;
      m.node = node, m.ambiguous = amb;
    } else if (m.node < 0) {
      m.node = ci.node;
    }
  }
  auto class_info = [&](int cls) -> ClassInfo& {
    if (cls < 0 || cls >= nc || merged_index[cls] < 0) throw std::out_of_range("transition: power vertex class without info");
    return merged[merged_index[cls]];
  };
  {
    std::vector<RawFace> kept;
    for (RawFace& f : faces) {
      for (int& cls : f.classes) cls = uf.find(cls);
      f.classes.erase(std::unique(f.classes.begin(), f.classes.end()), f.classes.end());
      while (f.classes.size() > 1 && f.classes.front() == f.classes.back()) f.classes.pop_back();
      if (f.classes.size() >= 3) kept.push_back(std::move(f));
    }
    faces.swap(kept);
  }

  // ---- conformity (5.7): vertices of external faces become constrained vertices
  std::map<int, std::vector<int32_t>> snap_candidates;  // free class -> candidate nodes
  auto common_polygons = [&](int s, int t) {
    std::vector<int> a = set.sites[s].polygons, b = set.sites[t].polygons, o;
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(o));
    return o;
  };
  for (const RawFace& f : faces) {
    if (!f.external) continue;
    std::vector<int> polys = common_polygons(f.s, f.t);
    if (polys.empty()) polys = set.sites[f.s].polygons;
    std::vector<int32_t> cand;
    for (int q : polys) cand.insert(cand.end(), cavity.faces[q].nodes.begin(), cavity.faces[q].nodes.end());
    for (int cls : f.classes) {
      if (class_info(cls).node >= 0) continue;
      auto& v = snap_candidates[cls];
      v.insert(v.end(), cand.begin(), cand.end());
    }
  }
  std::vector<int32_t> snapped(nc, -1);  // class -> node
  int snapped_count = 0;
  for (auto& [cls, cand] : snap_candidates) {
    std::sort(cand.begin(), cand.end());
    cand.erase(std::unique(cand.begin(), cand.end()), cand.end());
    const Vec3 p = class_info(cls).point;
    int32_t best = cand[0];
    for (int32_t v : cand)
      if (norm2(coords[v] - p) < norm2(coords[best] - p)) best = v;
    snapped[cls] = best, ++snapped_count;
    rep.max_snap_shift = std::max(rep.max_snap_shift, norm(coords[best] - p));
  }
  rep.snapped_vertices = snapped_count;

  auto token = [&](int cls) -> Token {
    const ClassInfo& ci = class_info(cls);
    if (ci.node >= 0) return ci.node;
    if (snapped[cls] >= 0) return snapped[cls];
    return -1 - static_cast<Token>(cls);
  };
  std::vector<std::vector<Token>> cycles(faces.size());
  int removed = 0;
  for (size_t i = 0; i < faces.size(); ++i) {
    for (int cls : faces[i].classes) cycles[i].push_back(token(cls));
    clean_cycle(cycles[i]);
    if (cycles[i].size() < 3) ++removed;
    // A cell is on its site's side of every outer-boundary plane: it never reaches an image vertex.
    for (Token tk : cycles[i])
      if (!images.empty() && cycles[i].size() >= 3 && tk >= images.first_image)
        throw std::runtime_error("transition: the cell of site " + std::to_string(faces[i].s) +
                                 " reaches the image of a cavity vertex through an outer-boundary plane");
  }
  removed += drop_vertices_inside_edges(cycles, nc, [&](Token tk) { return tk >= 0 ? coords[tk] : class_info(static_cast<int>(-1 - tk)).point; });
  rep.removed_faces = removed;

  // ---- number the free vertices by their class key (deterministic)
  std::vector<std::pair<std::array<int, 4>, int>> free_classes;
  constexpr int32_t kNoFreeId = std::numeric_limits<int32_t>::min();
  std::vector<int32_t> free_id(nc, kNoFreeId);  // class -> node id of its free vertex
  auto free_id_of = [&](int cls) {
    if (cls < 0 || cls >= nc || free_id[cls] == kNoFreeId) throw std::out_of_range("transition: free vertex without id");
    return free_id[cls];
  };
  int identified = 0, ambiguous = 0;
  {
    std::vector<char> seen_class(nc, 0);
    for (size_t i = 0; i < faces.size(); ++i) {
      if (cycles[i].size() < 3) continue;
      for (int cls : faces[i].classes) {
        if (seen_class[cls]) continue;
        seen_class[cls] = 1;
        const ClassInfo& ci = class_info(cls);
        ambiguous += ci.ambiguous ? 1 : 0;
        if (ci.node >= 0) ++identified;
      }
      for (Token tk : cycles[i])
        if (tk < 0 && free_id[static_cast<int>(-1 - tk)] == kNoFreeId) {
          const int cls = static_cast<int>(-1 - tk);
          free_id[cls] = -1;
          free_classes.push_back({class_info(cls).key, cls});
        }
    }
  }
  std::sort(free_classes.begin(), free_classes.end());
  out.new_nodes.clear();
  out.new_node_sites.clear();
  for (const auto& [key, cls] : free_classes) {
    free_id[cls] = out.base_node_id + static_cast<int32_t>(out.new_nodes.size());
    out.new_nodes.push_back(class_info(cls).point);
    out.new_node_sites.push_back(key);
  }
  // Free vertices of the faces in an outer-boundary plane lie in it exactly (the images are
  // reflections rounded once: the power vertices are within rounding of the plane).
  for (size_t i = 0; i < faces.size(); ++i) {
    if (!faces[i].boundary || cycles[i].size() < 3) continue;
    const MirrorPlane& m = images.planes[set.sites[faces[i].t].plane];
    for (Token tk : cycles[i])
      if (tk < 0) out.new_nodes[free_id_of(static_cast<int>(-1 - tk)) - out.base_node_id][m.axis] = m.value;
  }
  rep.identified_vertices = identified;
  rep.free_vertices = static_cast<int>(out.new_nodes.size());
  rep.ambiguous_vertices = ambiguous;
  rep.exact_power_centers = exact_centers;
  auto node_of = [&](Token tk) -> int32_t { return tk >= 0 ? static_cast<int32_t>(tk) : free_id_of(static_cast<int>(-1 - tk)); };

  // ---- cells
  std::vector<int> cell_of_site(ns, -1);
  std::vector<int> internal_sites;
  for (int s = 0; s < ns; ++s)
    if (set.sites[s].alive && set.sites[s].internal()) {
      cell_of_site[s] = static_cast<int>(internal_sites.size());
      internal_sites.push_back(s);
    }
  const size_t ncell = internal_sites.size();
  out.cell_site.assign(internal_sites.begin(), internal_sites.end());
  out.cells.assign(ncell, {});
  out.cell_polygons.assign(ncell, {});
  out.sites.resize(ncell);
  out.weights.resize(ncell);
  out.h_ref.resize(ncell);
  std::vector<int> polygon_uses(cavity.faces.size(), 0);
  int unmatched = 0, n_faces = 0;
  for (size_t i = 0; i < faces.size(); ++i) {
    if (cycles[i].size() < 3) continue;
    const RawFace& f = faces[i];
    std::vector<int32_t> cyc;
    for (Token tk : cycles[i]) cyc.push_back(node_of(tk));
    CellFace cf;
    if (f.boundary || f.stray) {
      // In an outer-boundary plane: a boundary face of the cell (a stray face, which cannot
      // have area in exact geometry, is left interior so that the builder reports it).
      cf.nodes = rotate_to_min(cyc);
      cf.patch = f.boundary ? kOuterBoundary : kInteriorFace;
      if (f.stray) {
        ++unmatched;
        std::ostringstream os;
        os << "face of site " << f.s << " toward the image of site " << set.sites[f.t].image_of
           << " has area (outer-boundary plane)";
        if (rep.notes.size() < 50) rep.notes.push_back(os.str());
      }
      out.cells[cell_of_site[f.s]].push_back(cf);
      ++n_faces;
      continue;
    }
    if (!f.external) {
      cf.nodes = rotate_to_min(cyc);
      out.cells[cell_of_site[f.s]].push_back(cf);
      std::reverse(cyc.begin(), cyc.end());
      cf.nodes = rotate_to_min(cyc);
      out.cells[cell_of_site[f.t]].push_back(cf);
      ++n_faces;
      continue;
    }
    // External face: must be exactly one of the polygons shared by s and t.
    std::vector<int32_t> sorted_cyc = cyc;
    std::sort(sorted_cyc.begin(), sorted_cyc.end());
    int match = -1;
    for (int q : common_polygons(f.s, f.t)) {
      std::vector<int32_t> qs = cavity.faces[q].nodes;
      std::sort(qs.begin(), qs.end());
      if (qs == sorted_cyc) match = q;
    }
    ++n_faces;
    if (match < 0) {
      ++unmatched;
      std::ostringstream os;
      os << "external face of site " << f.s << " toward site " << f.t << " (" << cyc.size()
         << " nodes) matches no constrained polygon";
      if (rep.notes.size() < 50) rep.notes.push_back(os.str());
      cf.nodes = rotate_to_min(cyc);
      out.cells[cell_of_site[f.s]].push_back(cf);
      continue;
    }
    std::vector<int32_t> outward(cavity.faces[match].nodes.rbegin(), cavity.faces[match].nodes.rend());
    if (!same_cycle(outward, cyc)) {
      ++unmatched;
      std::ostringstream os;
      os << "external face of site " << f.s << " has the nodes of polygon " << match << " in another order";
      if (rep.notes.size() < 50) rep.notes.push_back(os.str());
    }
    if (polygon_uses[match]++ > 0) {
      ++unmatched;
      std::ostringstream os;
      os << "polygon " << match << " is the face of two power faces";
      if (rep.notes.size() < 50) rep.notes.push_back(os.str());
      continue;
    }
    cf.nodes = rotate_to_min(outward);
    cf.patch = cavity.faces[match].patch;
    out.cells[cell_of_site[f.s]].push_back(cf);
    out.cell_polygons[cell_of_site[f.s]].push_back(match);
  }
  rep.faces = n_faces;
  rep.unmatched_external_faces = unmatched;
  int missing = 0;
  for (size_t q = 0; q < cavity.faces.size(); ++q)
    if (polygon_uses[q] == 0) {
      ++missing;
      std::ostringstream os;
      os << "polygon " << q << " is no face of the transition mesh";
      if (rep.notes.size() < 50) rep.notes.push_back(os.str());
    }
  rep.missing_polygons = missing;
  for (size_t c = 0; c < ncell; ++c) {
    const Site& site = set.sites[internal_sites[c]];
    out.sites[c] = site.p;
    out.weights[c] = std::sqrt(site.w2);
    double len = 0;
    int edges = 0;
    for (int q : site.polygons) {
      const auto& nodes = cavity.faces[q].nodes;
      for (size_t k = 0; k < nodes.size(); ++k, ++edges) len += norm(coords[nodes[(k + 1) % nodes.size()]] - coords[nodes[k]]);
    }
    if (edges == 0) {  // a tip site: no constrained polygon, the cell's own edges
      auto at = [&](int32_t v) { return v >= out.base_node_id ? out.new_nodes[v - out.base_node_id] : coords[v]; };
      for (const CellFace& cf : out.cells[c])
        for (size_t k = 0; k < cf.nodes.size(); ++k, ++edges)
          len += norm(at(cf.nodes[(k + 1) % cf.nodes.size()]) - at(cf.nodes[k]));
    }
    out.h_ref[c] = edges ? len / edges : 0.0;
    std::sort(out.cell_polygons[c].begin(), out.cell_polygons[c].end());
    if (out.cells[c].size() < 4) {
      std::ostringstream os;
      os << "cell of site " << internal_sites[c] << " has only " << out.cells[c].size() << " faces";
      if (rep.notes.size() < 50) rep.notes.push_back(os.str());
    }
  }
  // Distinct power vertices used by the cells: every free vertex (numbered only if used) and the
  // constrained nodes the cells reach.
  {
    std::vector<int32_t> constrained;
    for (const auto& cell : out.cells)
      for (const CellFace& cf : cell)
        for (int32_t v : cf.nodes)
          if (v < out.base_node_id) constrained.push_back(v);
    std::sort(constrained.begin(), constrained.end());
    rep.power_vertices = static_cast<int>(out.new_nodes.size()) +
                         static_cast<int>(std::unique(constrained.begin(), constrained.end()) - constrained.begin());
  }
  (void)frames;
  return {};
}
}  // namespace

std::vector<int> build_power_cells(const SiteSet& real_set, const Cavity& cavity, const std::vector<Vec3>& coords,
                                   const std::vector<PolygonFrame>& frames, TransitionCells& out,
                                   const BoundaryImages& images) {
  const SiteSet imaged = images.empty() ? SiteSet{} : with_images(real_set, images);
  const SiteSet& set = images.empty() ? real_set : imaged;
  Regular rt;
  triangulate(set, rt);
  return extract_power_cells(rt, set, static_cast<int>(real_set.sites.size()), cavity, coords, frames, out, images);
}

struct PowerDiagram::Impl {
  Regular rt;
  bool ready = false;
  std::vector<Regular::Vertex_handle> vertex;  // per site, null if not in rt
  std::vector<Vec3> p;                        // the point and weight each site has in rt
  std::vector<double> w2;
  std::vector<char> alive;
};

PowerDiagram::PowerDiagram() : impl_(std::make_unique<Impl>()) {}
PowerDiagram::~PowerDiagram() = default;

void PowerDiagram::save() {
  const Impl& d = *impl_;
  if (!d.ready) return saved_.reset();
  if (!saved_) saved_ = std::make_unique<Impl>();
  Impl& c = *saved_;
  c.rt = d.rt;  // the cells' cached centres and comparisons come along
  c.vertex.assign(d.vertex.size(), Regular::Vertex_handle());
  for (auto v : c.rt.finite_vertex_handles())
    if (v->info() < static_cast<int>(c.vertex.size())) c.vertex[v->info()] = v;
  c.p = d.p, c.w2 = d.w2, c.alive = d.alive, c.ready = true;
}

std::vector<int> PowerDiagram::cells(const SiteSet& real_set, const Cavity& cavity, const std::vector<Vec3>& coords,
                                     const std::vector<PolygonFrame>& frames, TransitionCells& out,
                                     const BoundaryImages& images) {
  const SiteSet imaged = images.empty() ? SiteSet{} : with_images(real_set, images);
  const SiteSet& set = images.empty() ? real_set : imaged;
  const int ns = static_cast<int>(set.sites.size());
  auto live = [&](int s) { return set.sites[s].alive && set.sites[s].kind != SiteKind::Guard; };
  // The sites to move in a triangulation (ns + 1 where it must start from scratch).
  auto updates = [&](const Impl& t) {
    if (!t.ready || static_cast<int>(t.p.size()) != ns) return ns + 1;
    int n = 0;
    for (int s = 0; s < ns; ++s) {
      if ((live(s) ? 1 : 0) != t.alive[s]) return ns + 1;
      n += t.alive[s] && !(set.sites[s].p == t.p[s] && set.sites[s].w2 == t.w2[s]);
    }
    return n;
  };
  if (saved_ && updates(*saved_) < updates(*impl_)) std::swap(impl_, saved_);
  Impl& d = *impl_;
  bool fresh = updates(d) > ns;
  moved_ = 0;
  // Incrementally: remove and insert again each site whose point or weight changed. A move
  // that hides a site (or whose site is hidden) changes the vertex count: then from scratch
  // (the extraction reports the hidden sites).
  for (int s = 0; s < ns && !fresh; ++s) {
    if (!d.alive[s] || (set.sites[s].p == d.p[s] && set.sites[s].w2 == d.w2[s])) continue;
    const Site& site = set.sites[s];
    const Regular::Vertex_handle v = d.vertex[s];
    const size_t count = d.rt.number_of_vertices();
    // A cell outside v's star survives its removal: the hint for the insertion.
    const Regular::Cell_handle hint = v->cell()->neighbor(v->cell()->index(v));
    d.rt.remove(v);
    const Regular::Vertex_handle nv = d.rt.insert(WPoint(BPoint(site.p.x, site.p.y, site.p.z), site.w2), hint);
    fresh = nv == Regular::Vertex_handle() || d.rt.number_of_vertices() != count;
    if (!fresh) nv->info() = s, d.vertex[s] = nv, ++moved_;
  }
  if (fresh) {
    triangulate(set, d.rt);
    d.vertex.assign(ns, Regular::Vertex_handle());
    for (auto v : d.rt.finite_vertex_handles())
      if (v->info() < ns) d.vertex[v->info()] = v;
  }
  d.p.resize(ns), d.w2.resize(ns), d.alive.resize(ns);
  int expected = 8;
  for (int s = 0; s < ns; ++s) {
    d.p[s] = set.sites[s].p, d.w2[s] = set.sites[s].w2, d.alive[s] = live(s) ? 1 : 0;
    expected += d.alive[s];
  }
  // Hidden sites after a fresh triangulation: the next call starts from scratch again.
  d.ready = static_cast<int>(d.rt.number_of_vertices()) == expected;
  return extract_power_cells(d.rt, set, static_cast<int>(real_set.sites.size()), cavity, coords, frames, out, images);
}

// Buckets of side kBucket x eps: two points within eps share a bucket, or each lies within eps of
// the bucket face between them, so a point meets the points of its own bucket and, only where it
// lies that near a face, those of the buckets beyond it.
std::vector<std::pair<int, int>> coincident_pairs(const std::vector<Vec3>& points, double eps) {
  constexpr double kBucket = 1024;
  const double side = kBucket * eps;
  struct Bucketed {
    std::array<int64_t, 3> cell;
    int index;
    bool operator<(const Bucketed& o) const { return cell != o.cell ? cell < o.cell : index < o.index; }
  };
  std::vector<Bucketed> grid(points.size());
  for (size_t i = 0; i < points.size(); ++i)
    grid[i] = {{static_cast<int64_t>(std::floor(points[i].x / side)), static_cast<int64_t>(std::floor(points[i].y / side)),
                static_cast<int64_t>(std::floor(points[i].z / side))},
               static_cast<int>(i)};
  std::sort(grid.begin(), grid.end());
  std::vector<std::pair<int, int>> pairs;
  auto meet = [&](int a, int b) {
    if (norm(points[a] - points[b]) <= eps) pairs.emplace_back(a, b);
  };
  const double near = 2 * eps / side;  // twice eps: a bucket comes from a rounded quotient
  for (size_t i = 0; i < grid.size(); ++i) {
    const Bucketed& b = grid[i];
    // In one bucket: from the pair's first point in bucket order (ascending index).
    for (size_t k = i + 1; k < grid.size() && grid[k].cell == b.cell; ++k) meet(b.index, grid[k].index);
    // Per axis: the neighbouring buckets whose face lies within eps.
    std::array<std::array<int, 3>, 3> steps;
    std::array<int, 3> n_steps;
    for (int a = 0; a < 3; ++a) {
      const double f = points[b.index][a] / side - static_cast<double>(b.cell[a]);
      steps[a][0] = 0, n_steps[a] = 1;
      if (f < near) steps[a][n_steps[a]++] = -1;
      if (f > 1 - near) steps[a][n_steps[a]++] = 1;
    }
    for (int x = 0; x < n_steps[0]; ++x)
      for (int y = 0; y < n_steps[1]; ++y)
        for (int z = 0; z < n_steps[2]; ++z) {
          if (x == 0 && y == 0 && z == 0) continue;
          const Bucketed lo{{b.cell[0] + steps[0][x], b.cell[1] + steps[1][y], b.cell[2] + steps[2][z]}, -1};
          // Across a face: both points lie near it and each sees the other; the smaller index keeps it.
          for (auto it = std::lower_bound(grid.begin(), grid.end(), lo); it != grid.end() && it->cell == lo.cell; ++it)
            if (b.index < it->index) meet(b.index, it->index);
        }
  }
  return pairs;
}

}  // namespace hm::transition_detail
