#include "corner_point_multipliers.hpp"

#include <algorithm>
#include <cstdlib>
#include <array>
#include <map>
#include <set>

namespace hm {

namespace {

double multiplier(const CornerPointModel& model, int dir, int64_t c) {
  const std::vector<double>& v = model.trans_mult[dir];
  return v.empty() ? 1.0 : v[static_cast<size_t>(c)];
}

// A triangle by its corners' coordinates, sorted: the mesh's node ids are compacted after the
// builder's (unused nodes of cavity cells dropped), the coordinates are the same doubles.
using TriangleKey = std::array<std::array<double, 3>, 3>;

TriangleKey triangle_key(const std::vector<Vec3>& xyz, const int32_t* v) {
  TriangleKey t;
  for (int i = 0; i < 3; ++i) t[i] = {xyz[v[i]].x, xyz[v[i]].y, xyz[v[i]].z};
  std::sort(t.begin(), t.end());
  return t;
}

}  // namespace

bool across_pinched_layers(const CornerPointModel& model, int64_t a, int64_t b) {
  const int64_t nxy = static_cast<int64_t>(model.nx) * model.ny;
  if (a % nxy != b % nxy) return false;
  // Layers split at fault steps: the children of zero thickness away from the steps are no pinch-out.
  const auto layer = [&](int64_t c) { return model.parent_layer.empty() ? c / nxy : model.parent_layer[static_cast<size_t>(c / nxy)]; };
  return std::abs(layer(a) - layer(b)) > 1;
}

bool minpv_connects(const CornerPointModel& model, int64_t a, int64_t b) {
  if (model.minpv_connections.empty()) return false;
  const int64_t pa = cell_as_read(model, a), pb = cell_as_read(model, b);
  return std::binary_search(model.minpv_connections.begin(), model.minpv_connections.end(),
                            std::make_pair(std::min(pa, pb), std::max(pa, pb)));
}

double column_connection_multiplier(const CornerPointModel& model, int64_t a, int64_t b) {
  // OPM's applyAllZMultipliers_ (MULTZ option ALL): the smallest MULTZ from the upper cell down to
  // the last cell between; TOP: the upper cell's, as between logical neighbours.
  const int64_t nxy = static_cast<int64_t>(model.nx) * model.ny;
  const int64_t top = std::min(a, b), bottom = std::max(a, b);
  double down = multiplier(model, 4, top);
  if (model.pinch.multz_all)
    for (int64_t c = top + nxy; c < bottom; c += nxy) down = std::min(down, multiplier(model, 4, c));
  return down * multiplier(model, 5, bottom) * region_multiplier(model, a, b) * edit_nnc_multiplier(model, a, b);
}

double connection_multiplier(const CornerPointModel& model, int64_t a, int64_t b) {
  if (across_pinched_layers(model, a, b)) {
    // A pair MINPV connects has one connection, the mesh's connection without a face (its faces, where
    // the cells between had no thickness somewhere, carry none of it).
    if (!model.pinch.active || minpv_connects(model, a, b)) return 0.0;
    return column_connection_multiplier(model, a, b);
  }
  const int64_t nx = model.nx, nxy = static_cast<int64_t>(model.nx) * model.ny;
  const int64_t ia = a % nx, ja = (a / nx) % model.ny, ka = a / nxy;
  const int64_t ib = b % nx, jb = (b / nx) % model.ny, kb = b / nxy;
  const int axis = ia != ib ? 0 : ja != jb ? 1 : 2;
  const bool plus = axis == 0 ? ib > ia : axis == 1 ? jb > ja : kb > ka;
  const int dir = 2 * axis + (plus ? 0 : 1), opposite = 2 * axis + (plus ? 1 : 0);
  return multiplier(model, dir, a) * multiplier(model, opposite, b) * region_multiplier(model, a, b) *
         edit_nnc_multiplier(model, a, b);
}

FaceMultipliers face_multipliers(const PolyMesh& mesh, const CornerPointModel& model, const CornerPointCellFaces* cells,
                                 const std::vector<char>& active, const std::vector<Vec3>& coords) {
  FaceMultipliers out;
  auto model_cell = [&](int32_t c) -> int64_t {
    if (mesh.cell_region[c] != kReservoir) return -1;
    const auto& ijk = mesh.cell_ijk[c];
    return ijk[0] + static_cast<int64_t>(model.nx) * (ijk[1] + static_cast<int64_t>(model.ny) * ijk[2]);
  };
  bool pinched = false;  // a face joins two cells of a column across layers of zero thickness
  for (int32_t f = 0; f < mesh.n_faces() && !pinched; ++f) {
    const int32_t n = mesh.face_neighbour[f];
    if (n < 0) continue;
    const int64_t a = model_cell(mesh.face_owner[f]), b = model_cell(n);
    pinched = a >= 0 && b >= 0 && across_pinched_layers(model, a, b);
  }
  if (!pinched && !has_transmissibility_multipliers(model)) return out;
  // Per model cell beside a cavity: its cavity triangles and the cavity cell each faces.
  std::map<TriangleKey, int32_t> toward;
  std::vector<char> walled(model.actnum.size(), 0);
  if (cells != nullptr)
    for (int32_t f = 0; f < mesh.n_faces(); ++f) {
      const int32_t o = mesh.face_owner[f], n = mesh.face_neighbour[f];
      if (n < 0 || (mesh.cell_region[o] == kReservoir) == (mesh.cell_region[n] == kReservoir)) continue;
      const int64_t a = model_cell(mesh.cell_region[o] == kReservoir ? o : n);
      if (walled[a]) continue;
      walled[a] = 1;
      for (const CavityTriangle& t : cavity_triangles(*cells, static_cast<int>(a), active, coords))
        toward[triangle_key(coords, t.nodes.data())] = t.inside;
    }
  out.face.assign(static_cast<size_t>(mesh.n_faces()), 1.0);
  std::set<std::pair<int64_t, int64_t>> edited;  // EDITNNC pairs found on faces between model cells
  for (int32_t f = 0; f < mesh.n_faces(); ++f) {
    const int32_t n = mesh.face_neighbour[f];
    if (n < 0) continue;
    const int64_t a = model_cell(mesh.face_owner[f]), b = model_cell(n);
    if (a >= 0 && b >= 0) {
      out.face[f] = connection_multiplier(model, a, b);
      if (edit_nnc_multiplier(model, a, b) != 1.0) {
        ++out.edit_nnc_faces;
        const int64_t pa = cell_as_read(model, a), pb = cell_as_read(model, b);
        edited.insert({std::min(pa, pb), std::max(pa, pb)});
      }
      if (across_pinched_layers(model, a, b)) ++(model.pinch.active ? out.pinch_faces : out.unpinched_faces);
      else out.model_faces += out.face[f] != 1.0;
    } else if (a >= 0 || b >= 0) {
      const auto it = mesh.face_size(f) == 3 ? toward.find(triangle_key(mesh.nodes, mesh.face_begin(f))) : toward.end();
      if (it == toward.end()) {
        ++out.unmatched_walls;
        continue;
      }
      out.face[f] = connection_multiplier(model, std::max(a, b), it->second);
      out.wall_faces += out.face[f] != 1.0;
    }
  }
  out.edit_nnc_pairs_on_faces = static_cast<int64_t>(edited.size());
  if (cells != nullptr)
    for (int64_t c = 0; c < cells->n_cells(); ++c) {
      if (!cells->meshed[c] || active[c]) continue;
      for (int64_t f = cells->face_begin(c); f < cells->face_end(c); ++f) {
        const int32_t b = cells->neighbour[f];
        if (b <= c || !cells->meshed[b] || active[b]) continue;
        const double m = connection_multiplier(model, c, b);
        if (m == 1.0) continue;
        ++out.inside_cavities;
        out.inside_min = std::min(out.inside_min, m);
        out.inside_max = std::max(out.inside_max, m);
      }
    }
  return out;
}

}  // namespace hm
