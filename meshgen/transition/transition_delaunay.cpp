// Paper 5.2-5.3: Delaunay triangulation of the cavity vertices (plus far bounding-box
// corners) and the tetrahedra attached to each constrained polygon, which give the
// polygon's Voronoi (dual) edge. One of the two CGAL translation units of the module.
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <algorithm>
#include <array>
#include <set>
#include <sstream>

#include "transition_internal.hpp"

namespace hm::transition_detail {

namespace {
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_3<int, K>;
using Tds = CGAL::Triangulation_data_structure_3<Vb>;
using Delaunay = CGAL::Delaunay_triangulation_3<K, Tds>;
using Point = K::Point_3;

Point to_cgal(Vec3 p) { return Point(p.x, p.y, p.z); }
}  // namespace

void attach_voronoi_edges(const Cavity& cavity, const std::vector<Vec3>& coords, std::vector<PolygonFrame>& frames,
                          std::vector<std::string>& notes) {
  const int nv = static_cast<int>(cavity.vertices.size());
  if (nv == 0) return;
  std::vector<std::pair<Point, int>> points;
  points.reserve(nv + 8);
  Vec3 lo = coords[cavity.vertices[0]], hi = lo;
  for (int i = 0; i < nv; ++i) {
    const Vec3 p = coords[cavity.vertices[i]];
    points.emplace_back(to_cgal(p), i);
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  }
  // Bounding-box corners one diagonal away: every polygon then has outside tetrahedra,
  // and the corners are too far to shorten a Voronoi edge near the cavity.
  const double margin = norm(hi - lo);
  for (int c = 0; c < 8; ++c) {
    const Vec3 p{(c & 1) ? hi.x + margin : lo.x - margin, (c & 2) ? hi.y + margin : lo.y - margin,
                 (c & 4) ? hi.z + margin : lo.z - margin};
    points.emplace_back(to_cgal(p), nv + c);
  }
  Delaunay dt(points.begin(), points.end());  // range insertion: spatial sort + hints

  std::vector<Delaunay::Vertex_handle> handle(nv);
  for (auto v : dt.finite_vertex_handles())
    if (v->info() < nv) handle[v->info()] = v;

  auto local_index = [&](int32_t node) {
    return static_cast<int>(std::lower_bound(cavity.vertices.begin(), cavity.vertices.end(), node) -
                            cavity.vertices.begin());
  };

  std::vector<Delaunay::Cell_handle> ball;
  for (size_t q = 0; q < cavity.faces.size(); ++q) {
    const std::vector<int32_t>& nodes = cavity.faces[q].nodes;
    PolygonFrame& f = frames[q];
    // position in the polygon's cycle of each of its local vertex indices
    std::vector<std::pair<int, int>> pos;  // (local index, cycle position), sorted by local index
    for (size_t i = 0; i < nodes.size(); ++i) pos.push_back({local_index(nodes[i]), static_cast<int>(i)});
    std::sort(pos.begin(), pos.end());
    auto cycle_pos = [&](int local) {
      auto it = std::lower_bound(pos.begin(), pos.end(), std::make_pair(local, -1));
      return (it != pos.end() && it->first == local) ? it->second : -1;
    };
    // Cells of the balls of the polygon's vertices, deduplicated by their vertex ids
    // (not by handle, so that nothing depends on memory addresses).
    std::set<std::array<int, 4>> seen;
    double sum_in = 0, sum_out = 0;
    f.inner_tets = f.outer_tets = f.sliver_tets = 0;
    for (const auto& [local, unused] : pos) {
      (void)unused;
      ball.clear();
      dt.incident_cells(handle[local], std::back_inserter(ball));
      for (Delaunay::Cell_handle c : ball) {
        if (dt.is_infinite(c)) continue;
        std::array<int, 4> key;
        for (int i = 0; i < 4; ++i) key[i] = c->vertex(i)->info();
        std::sort(key.begin(), key.end());
        if (!seen.insert(key).second) continue;
        std::array<int, 4> at;  // cycle position of each vertex, -1 if not on the polygon
        int on = 0, other = -1;
        for (int i = 0; i < 4; ++i) {
          at[i] = cycle_pos(c->vertex(i)->info());
          if (at[i] >= 0) ++on; else other = i;
        }
        if (on == 4) {  // a sliver made of the polygon's own (non-planar) vertices
          ++f.sliver_tets;
          continue;
        }
        if (on != 3) continue;
        // The three polygon vertices in cycle order span a triangle oriented like the
        // polygon (normal into the cavity): the exact orientation of the fourth vertex
        // tells the side.
        std::array<std::pair<int, int>, 3> tri;
        int k = 0;
        for (int i = 0; i < 4; ++i)
          if (i != other) tri[k++] = {at[i], i};
        std::sort(tri.begin(), tri.end());
        const CGAL::Orientation o = CGAL::orientation(c->vertex(tri[0].second)->point(), c->vertex(tri[1].second)->point(),
                                                      c->vertex(tri[2].second)->point(), c->vertex(other)->point());
        const Point cc = CGAL::circumcenter(c->vertex(0)->point(), c->vertex(1)->point(), c->vertex(2)->point(),
                                             c->vertex(3)->point());
        const double t = dot(Vec3{cc.x(), cc.y(), cc.z()} - f.center, f.normal);
        if (o == CGAL::POSITIVE) {
          sum_in += t;
          ++f.inner_tets;
        } else if (o == CGAL::NEGATIVE) {
          sum_out += t;
          ++f.outer_tets;
        }
      }
    }
    f.t_in = f.inner_tets ? sum_in / f.inner_tets : kInf;
    f.t_out = f.outer_tets ? sum_out / f.outer_tets : -kInf;
    if (f.outer_tets == 0 && notes.size() < 50) {
      std::ostringstream os;
      os << "polygon " << q << ": no attached Delaunay tetrahedron outside the cavity";
      notes.push_back(os.str());
    }
  }
}

}  // namespace hm::transition_detail
