#include "geometry.hpp"

#include <array>
#include <cmath>

#include "parallel.hpp"

namespace hm {

void polygon_area_centroid(const std::vector<Vec3>& nodes, const int32_t* begin, const int32_t* end,
                           Vec3* area, Vec3* centroid) {
  const int n = static_cast<int>(end - begin);
  Vec3 g;
  for (const int32_t* v = begin; v != end; ++v) g += nodes[*v];
  g = g / n;
  Vec3 a_sum, c_sum;
  // Fan triangle areas: on the stack for the usual faces (no allocation per face).
  std::array<Vec3, 32> small;
  std::vector<Vec3> large;
  if (n > static_cast<int>(small.size())) large.resize(n);
  Vec3* tri_area = n > static_cast<int>(small.size()) ? large.data() : small.data();
  for (int i = 0; i < n; ++i) {
    const Vec3 a = nodes[begin[i]], b = nodes[begin[(i + 1) % n]];
    tri_area[i] = 0.5 * cross(a - g, b - g);
    a_sum += tri_area[i];
  }
  // Weight each triangle's centroid by its area projected on the face normal, so that
  // a non-planar face has a centroid consistent with its area vector.
  const double a2 = norm2(a_sum);
  double w_sum = 0;
  for (int i = 0; i < n; ++i) {
    const Vec3 a = nodes[begin[i]], b = nodes[begin[(i + 1) % n]];
    const double w = a2 > 0 ? dot(tri_area[i], a_sum) / std::sqrt(a2) : 0.0;
    c_sum += w * ((g + a + b) / 3.0);
    w_sum += w;
  }
  *area = a_sum;
  *centroid = w_sum != 0 ? c_sum / w_sum : g;
}

MeshGeometry compute_geometry(const PolyMesh& m) {
  MeshGeometry geo;
  const int nf = m.n_faces(), nc = m.n_cells();
  geo.face_area.resize(nf);
  geo.face_centroid.resize(nf);
  parallel_ranges(nf, [&](int64_t b, int64_t e) {
    for (int f = static_cast<int>(b); f < e; ++f)
      polygon_area_centroid(m.nodes, m.face_begin(f), m.face_end(f), &geo.face_area[f], &geo.face_centroid[f]);
  });
  geo.cell_volume.assign(nc, 0.0);
  geo.cell_centroid.assign(nc, Vec3{});
  parallel_ranges(nc, [&](int64_t cb, int64_t ce) {
    for (int c = static_cast<int>(cb); c < ce; ++c) {
      // Reference point: mean of face centroids (inside for convex cells; any point works
      // for the signed decomposition).
      Vec3 x0;
      int nfc = 0;
      for (const int32_t* f = m.cell_begin(c); f != m.cell_end(c); ++f, ++nfc) x0 += geo.face_centroid[*f];
      x0 = x0 / nfc;
      double vol = 0;
      Vec3 mom;
      for (const int32_t* fp = m.cell_begin(c); fp != m.cell_end(c); ++fp) {
        const int f = *fp;
        const double s = m.face_sign(f, c);
        const int n = m.face_size(f);
        const int32_t* v = m.face_begin(f);
        Vec3 g;
        for (int i = 0; i < n; ++i) g += m.nodes[v[i]];
        g = g / n;
        for (int i = 0; i < n; ++i) {
          const Vec3 a = m.nodes[v[i]], b = m.nodes[v[(i + 1) % n]];
          const double tv = s * dot(g - x0, cross(a - x0, b - x0)) / 6.0;
          vol += tv;
          mom += tv * ((x0 + g + a + b) / 4.0);
        }
      }
      geo.cell_volume[c] = vol;
      geo.cell_centroid[c] = vol != 0 ? mom / vol : x0;
    }
  });
  return geo;
}

Vec3 cell_area_sum(const PolyMesh& m, const MeshGeometry& geo, int c) {
  Vec3 s;
  for (const int32_t* f = m.cell_begin(c); f != m.cell_end(c); ++f) s += m.face_sign(*f, c) * geo.face_area[*f];
  return s;
}

double total_volume(const MeshGeometry& geo) {
  double v = 0;
  for (double x : geo.cell_volume) v += x;
  return v;
}

double triangle_solid_angle(Vec3 a, Vec3 b, Vec3 c) {
  const double la = norm(a), lb = norm(b), lc = norm(c);
  const double num = dot(a, cross(b, c));
  const double den = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
  return 2.0 * std::atan2(num, den);
}

}  // namespace hm
