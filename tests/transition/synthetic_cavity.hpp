// Synthetic cavities for the transition tests: a rectilinear reservoir grid with a block
// of deactivated cells, and inside it stand-ins for well blocks (small rectilinear blocks
// of hexahedra, possibly rotated) whose outer quads are FaceSide::Well polygons.
// Everything goes through one MeshBuilder, so the tests check the real assembly.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include "meshgen/cavity/cavity.hpp"
#include "meshgen/core/geometry.hpp"
#include "meshgen/core/mesh_builder.hpp"
#include "meshgen/transition/transition.hpp"

namespace hm::testing {

// Local corner c of a hexahedron: bit 0 = +x, bit 1 = +y, bit 2 = +z. Faces listed with
// the right-hand normal pointing out (for any proper rotation of the hexahedron).
inline constexpr int kHexFaces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                        {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};

struct InnerBlock {
  Vec3 center;
  double half = 1;    // half edge length
  int m = 2;          // cells per axis
  Vec3 axis{0, 0, 1}; // rotation axis
  double angle = 0;   // rotation angle (rad)
};

inline Vec3 rotate(Vec3 v, Vec3 axis, double angle) {
  const Vec3 k = normalized(axis);
  return v * std::cos(angle) + cross(k, v) * std::sin(angle) + k * (dot(k, v) * (1 - std::cos(angle)));
}

struct Scene {
  ReservoirGrid grid;
  MeshBuilder builder;
  std::vector<char> active;
  Cavity cavity;
  std::vector<Vec3> coords;  // all builder nodes before the transition
  TransitionCells transition;
  PolyMesh mesh;
  BuildReport report;
  std::vector<int> transition_cell;  // mesh cell id of transition cell i
  double box_volume = 0;
};

/// Builds the scene: deactivates `inactive(i,j,k)`, places the blocks, lets `tamper` edit
/// the cavity (failure tests), runs the transition and assembles everything.
inline void build_scene_with(Scene& sc, std::vector<double> x, std::vector<double> y, std::vector<double> z,
                             const std::function<bool(int, int, int)>& inactive, const std::vector<InnerBlock>& blocks,
                             const std::function<void(Cavity&)>& tamper) {
  ReservoirGrid& g = sc.grid;
  g.x = std::move(x), g.y = std::move(y), g.z = std::move(z);
  sc.box_volume = g.box_volume();
  std::vector<int32_t> lattice(g.n_nodes());
  for (int k = 0; k <= g.nz(); ++k)
    for (int j = 0; j <= g.ny(); ++j)
      for (int i = 0; i <= g.nx(); ++i) lattice[g.node_index(i, j, k)] = sc.builder.add_node(g.node(i, j, k));
  sc.active.assign(g.n_cells(), 1);
  for (int c = 0; c < g.n_cells(); ++c) {
    const auto ijk = g.cell_ijk(c);
    if (inactive(ijk[0], ijk[1], ijk[2])) {
      sc.active[c] = 0;
      sc.cavity.deactivated_cells.push_back(c);
    }
  }
  // Blocks: nodes, cells, outer quads.
  std::vector<std::vector<std::vector<CellFace>>> block_cells;
  std::vector<std::vector<Vec3>> block_centres;
  for (size_t b = 0; b < blocks.size(); ++b) {
    const InnerBlock& bl = blocks[b];
    const int m = bl.m;
    std::vector<int32_t> ids((m + 1) * (m + 1) * (m + 1));
    auto nid = [&](int i, int j, int k) { return i + (m + 1) * (j + (m + 1) * k); };
    for (int k = 0; k <= m; ++k)
      for (int j = 0; j <= m; ++j)
        for (int i = 0; i <= m; ++i) {
          const Vec3 local{bl.half * (2.0 * i / m - 1), bl.half * (2.0 * j / m - 1), bl.half * (2.0 * k / m - 1)};
          ids[nid(i, j, k)] = sc.builder.add_node(bl.center + rotate(local, bl.axis, bl.angle));
        }
    block_cells.emplace_back();
    block_centres.emplace_back();
    sc.cavity.wells.push_back(static_cast<int>(b));
    for (int k = 0; k < m; ++k)
      for (int j = 0; j < m; ++j)
        for (int i = 0; i < m; ++i) {
          const int local_cell = i + m * (j + m * k);
          std::array<int32_t, 8> corner;
          Vec3 centre;
          for (int c = 0; c < 8; ++c) {
            corner[c] = ids[nid(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1))];
            centre += 0.125 * sc.builder.node(corner[c]);
          }
          std::vector<CellFace> faces;
          for (int s = 0; s < 6; ++s) {
            CellFace cf;
            for (int v = 0; v < 4; ++v) cf.nodes.push_back(corner[kHexFaces[s][v]]);
            faces.push_back(cf);
            const int axis = s / 2, dir = s % 2;
            const int idx[3] = {i, j, k};
            if ((dir == 0 && idx[axis] == 0) || (dir == 1 && idx[axis] == m - 1)) {
              // outward of the block = into the cavity
              sc.cavity.faces.push_back(ConstrainedFace{cf.nodes, FaceSide::Well, local_cell, -1, static_cast<int>(b)});
            }
          }
          block_cells.back().push_back(faces);
          block_centres.back().push_back(centre);
        }
  }
  // Reservoir faces of the cavity (active cell outside, deactivated inside).
  std::vector<std::vector<CellFace>> res_faces(g.n_cells());
  for (int c = 0; c < g.n_cells(); ++c) {
    if (!sc.active[c]) continue;
    const auto ijk = g.cell_ijk(c);
    std::array<int32_t, 8> corner;
    for (int v = 0; v < 8; ++v)
      corner[v] = lattice[g.node_index(ijk[0] + (v & 1), ijk[1] + ((v >> 1) & 1), ijk[2] + ((v >> 2) & 1))];
    for (int s = 0; s < 6; ++s) {
      CellFace cf;
      for (int v = 0; v < 4; ++v) cf.nodes.push_back(corner[kHexFaces[s][v]]);
      int nb[3] = {ijk[0], ijk[1], ijk[2]};
      nb[s / 2] += (s % 2) ? 1 : -1;
      const int dims[3] = {g.nx(), g.ny(), g.nz()};
      if (nb[s / 2] < 0 || nb[s / 2] >= dims[s / 2]) {
        cf.patch = kOuterBoundary;
      } else {
        const int n = g.cell_index(nb[0], nb[1], nb[2]);
        if (!sc.active[n]) {
          sc.cavity.faces.push_back(ConstrainedFace{cf.nodes, FaceSide::Reservoir, c, n});
        }
      }
      res_faces[c].push_back(cf);
    }
  }
  for (const ConstrainedFace& q : sc.cavity.faces) sc.cavity.vertices.insert(sc.cavity.vertices.end(), q.nodes.begin(), q.nodes.end());
  std::sort(sc.cavity.vertices.begin(), sc.cavity.vertices.end());
  sc.cavity.vertices.erase(std::unique(sc.cavity.vertices.begin(), sc.cavity.vertices.end()), sc.cavity.vertices.end());
  for (int32_t i = 0; i < sc.builder.n_nodes(); ++i) sc.coords.push_back(sc.builder.node(i));
  if (tamper) tamper(sc.cavity);

  sc.transition = build_transition(sc.cavity, sc.coords, g, {}, sc.builder.n_nodes());
  for (const Vec3& p : sc.transition.new_nodes) sc.builder.add_node(p);

  for (int c = 0; c < g.n_cells(); ++c) {
    if (!sc.active[c]) continue;
    CellAttributes a;
    a.region = kReservoir;
    const auto ijk = g.cell_ijk(c);
    a.fv_center = 0.5 * (g.node(ijk[0], ijk[1], ijk[2]) + g.node(ijk[0] + 1, ijk[1] + 1, ijk[2] + 1));
    a.ijk = {ijk[0], ijk[1], ijk[2]};
    sc.builder.add_cell(res_faces[c], a);
  }
  for (size_t b = 0; b < block_cells.size(); ++b)
    for (size_t c = 0; c < block_cells[b].size(); ++c) {
      CellAttributes a;
      a.region = kWell;
      a.fv_center = block_centres[b][c];
      sc.builder.add_cell(block_cells[b][c], a);
    }
  for (size_t c = 0; c < sc.transition.cells.size(); ++c) {
    CellAttributes a;
    a.region = kTransition;
    a.fv_center = sc.transition.sites[c];
    sc.transition_cell.push_back(sc.builder.add_cell(sc.transition.cells[c], a));
  }
  sc.mesh = sc.builder.finish(&sc.report);
}

inline void build_scene(Scene& sc, std::vector<double> x, std::vector<double> y, std::vector<double> z,
                        const std::function<bool(int, int, int)>& inactive, const std::vector<InnerBlock>& blocks) {
  build_scene_with(sc, std::move(x), std::move(y), std::move(z), inactive, blocks, nullptr);
}

/// Properties measured on the assembled mesh (issue #3 acceptance criteria).
struct Metrics {
  bool csr_ok = false;
  int bad_boundary_faces = 0;      ///< boundary faces neither on the outer box nor on a wellbore
  int polygons_not_once = 0;       ///< constrained polygons not exactly one face of one transition cell
  double max_closure = 0;          ///< max |sum of outward area vectors| / sum |areas| over all cells
  double volume = 0;               ///< total volume
  double max_planarity = 0;        ///< transition faces: max node distance to the face plane / h_ref
  double max_convexity = 0;        ///< transition cells: max node distance outside a face plane / h_ref
  double min_site_margin = 1e300;  ///< transition cells: min over faces of (distance of the site inside) / h_ref
  double min_orth = 90, mean_orth = 0;     ///< transition-transition faces (degrees)
  int n_orth = 0;
  double min_orth_res = 90;        ///< transition-reservoir faces (degrees)
  int transition_cells = 0, transition_faces = 0, transition_nodes = 0;
  int negative_volumes = 0;
};

// Q_O (paper eq. 8) = 90 deg - angle(P1P2, n); atan2 keeps full precision near 90 deg,
// where asin(|u.n|) loses half the digits (asin(1 - 1e-16) is 1e-8 rad off).
inline double orthogonality_deg(Vec3 p1, Vec3 p2, Vec3 area) {
  const Vec3 d = p2 - p1;
  return 90.0 - std::atan2(norm(cross(d, area)), std::abs(dot(d, area))) * 180.0 / M_PI;
}

inline Metrics measure(const Scene& sc) {
  Metrics mt;
  const PolyMesh& m = sc.mesh;
  mt.csr_ok = check_csr_invariants(m).ok;
  const MeshGeometry geo = compute_geometry(m);
  mt.volume = total_volume(geo);
  const ReservoirGrid& g = sc.grid;
  for (int f = 0; f < m.n_faces(); ++f) {
    if (m.face_neighbour[f] >= 0) continue;
    if (m.face_patch[f] == kOuterBoundary) {
      // every node on the same box side
      bool ok = false;
      for (int axis = 0; axis < 3 && !ok; ++axis)
        for (int side = 0; side < 2 && !ok; ++side) {
          const std::vector<double>& c = axis == 0 ? g.x : axis == 1 ? g.y : g.z;
          const double v = side ? c.back() : c.front();
          bool all = true;
          for (const int32_t* n = m.face_begin(f); n != m.face_end(f); ++n) all = all && m.nodes[*n][axis] == v;
          ok = all;
        }
      if (!ok) ++mt.bad_boundary_faces;
    } else if (!is_wellbore_patch(m.face_patch[f])) {
      ++mt.bad_boundary_faces;
    }
  }
  for (int c = 0; c < m.n_cells(); ++c) {
    double asum = 0;
    for (const int32_t* f = m.cell_begin(c); f != m.cell_end(c); ++f) asum += norm(geo.face_area[*f]);
    mt.max_closure = std::max(mt.max_closure, norm(cell_area_sum(m, geo, c)) / asum);
    if (geo.cell_volume[c] <= 0) ++mt.negative_volumes;
  }
  // Constrained polygons: exactly one face of one transition cell.
  std::vector<int> uses(sc.cavity.faces.size(), 0);
  for (const auto& polys : sc.transition.cell_polygons)
    for (int q : polys) ++uses[q];
  for (int u : uses) mt.polygons_not_once += u != 1;
  // Transition cells: planarity, convexity, site inside, orthogonality.
  std::set<int> tcells(sc.transition_cell.begin(), sc.transition_cell.end());
  std::set<int> tfaces, tnodes;
  double orth_sum = 0;
  for (size_t i = 0; i < sc.transition_cell.size(); ++i) {
    const int c = sc.transition_cell[i];
    const double h = sc.transition.h_ref[i];
    std::set<int32_t> cell_nodes;
    for (const int32_t* f = m.cell_begin(c); f != m.cell_end(c); ++f)
      cell_nodes.insert(m.face_begin(*f), m.face_end(*f));
    tnodes.insert(cell_nodes.begin(), cell_nodes.end());
    for (const int32_t* fp = m.cell_begin(c); fp != m.cell_end(c); ++fp) {
      const int f = *fp;
      tfaces.insert(f);
      const Vec3 n = normalized(m.face_sign(f, c) * geo.face_area[f]);
      const Vec3 x0 = geo.face_centroid[f];
      for (const int32_t* v = m.face_begin(f); v != m.face_end(f); ++v)
        mt.max_planarity = std::max(mt.max_planarity, std::abs(dot(m.nodes[*v] - x0, n)) / h);
      for (int32_t v : cell_nodes) mt.max_convexity = std::max(mt.max_convexity, dot(m.nodes[v] - x0, n) / h);
      mt.min_site_margin = std::min(mt.min_site_margin, -dot(sc.transition.sites[i] - x0, n) / h);
      const int other = m.face_owner[f] == c ? m.face_neighbour[f] : m.face_owner[f];
      if (other < 0) continue;
      const double a = orthogonality_deg(m.cell_fv_center[c], m.cell_fv_center[other], geo.face_area[f]);
      if (tcells.count(other)) {
        if (other < c) continue;  // once per face
        mt.min_orth = std::min(mt.min_orth, a);
        orth_sum += a;
        ++mt.n_orth;
      } else if (m.cell_region[other] == kReservoir) {
        mt.min_orth_res = std::min(mt.min_orth_res, a);
      }
    }
  }
  mt.mean_orth = mt.n_orth ? orth_sum / mt.n_orth : 90;
  mt.transition_cells = static_cast<int>(sc.transition_cell.size());
  mt.transition_faces = static_cast<int>(tfaces.size());
  mt.transition_nodes = static_cast<int>(tnodes.size());
  return mt;
}

}  // namespace hm::testing
