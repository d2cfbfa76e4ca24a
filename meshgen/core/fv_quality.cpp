#include "fv_quality.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "parallel.hpp"

namespace hm {

namespace {
constexpr double kDeg = 180.0 / M_PI;

double clamp_unit(double x) { return std::min(1.0, std::max(-1.0, x)); }

// OpenFOAM's face centre and area vector (primitiveMesh face centres): a triangle
// directly; otherwise a fan around the point average whose triangle centroids are weighted
// by their area projected on the face's normal. The area points as the cycle turns.
void foam_face(const std::vector<Vec3>& nodes, const int32_t* b, const int32_t* e, Vec3* centre, Vec3* area) {
  const size_t n = static_cast<size_t>(e - b);
  if (n == 3) {
    *centre = (nodes[b[0]] + nodes[b[1]] + nodes[b[2]]) / 3.0;
    *area = 0.5 * cross(nodes[b[1]] - nodes[b[0]], nodes[b[2]] - nodes[b[0]]);
    return;
  }
  Vec3 mean;
  for (const int32_t* v = b; v != e; ++v) mean += nodes[*v];
  mean = mean / static_cast<double>(n);
  Vec3 sum_n;
  for (size_t i = 0; i < n; ++i) sum_n += cross(nodes[b[(i + 1) % n]] - nodes[b[i]], mean - nodes[b[i]]);
  Vec3 sum_c;
  double sum_a = 0;
  for (size_t i = 0; i < n; ++i) {
    const Vec3 p = nodes[b[i]], q = nodes[b[(i + 1) % n]];
    const double a = dot(cross(q - p, mean - p), sum_n);
    sum_a += a;
    sum_c += a * (p + q + mean);
  }
  *centre = sum_a > 1e-300 ? sum_c / (3.0 * sum_a) : mean;
  *area = 0.5 * sum_n;
}

// OpenFOAM's cell centre (primitiveMesh cell centres): the volume-weighted centroid of the
// pyramids from the average of the face centres. Faces are given as outward cycles, flat:
// face i is outward[off[i] .. off[i + 1]); fc and fa are scratch.
Vec3 foam_cell_centre(const std::vector<Vec3>& nodes, const std::vector<int32_t>& outward, const std::vector<int>& off,
                      std::vector<Vec3>& fc, std::vector<Vec3>& fa) {
  const size_t n_faces = off.size() - 1;
  fc.resize(n_faces);
  fa.resize(n_faces);
  Vec3 est;
  for (size_t i = 0; i < n_faces; ++i) {
    foam_face(nodes, outward.data() + off[i], outward.data() + off[i + 1], &fc[i], &fa[i]);
    est += fc[i];
  }
  if (n_faces == 0) return est;
  est = est / static_cast<double>(n_faces);
  Vec3 sum;
  double vol = 0;
  for (size_t i = 0; i < n_faces; ++i) {
    const double pv = std::max(dot(fa[i], fc[i] - est), 1e-300);
    sum += pv * (0.75 * fc[i] + 0.25 * est);
    vol += pv;
  }
  return vol > 0 ? sum / vol : est;
}

// OpenFOAM's face skewness (primitiveMeshTools::faceSkewness / boundaryFaceSkewness): the
// distance from the face centre to where the line between the cell centres crosses the face
// plane, over the face's extent in that direction (at least 0.2 |d|; 0.4 |d| on the boundary).
double foam_skewness(const std::vector<Vec3>& nodes, const int32_t* b, const int32_t* e, Vec3 fc, Vec3 fa, Vec3 own_cc,
                     const Vec3* nei_cc) {
  const Vec3 cpf = fc - own_cc;
  Vec3 d;
  double fd;
  if (nei_cc) {
    d = *nei_cc - own_cc;
    fd = 0.2 * norm(d);
  } else {
    const Vec3 nrm = fa / (norm(fa) + 1e-300);
    d = dot(nrm, cpf) * nrm;
    fd = 0.4 * norm(d);
  }
  const Vec3 sv = cpf - (dot(fa, cpf) / (dot(fa, d) + 1e-300)) * d;
  const Vec3 sv_hat = sv / (norm(sv) + 1e-300);
  fd += 1e-300;
  for (const int32_t* v = b; v != e; ++v) fd = std::max(fd, std::abs(dot(sv_hat, nodes[*v] - fc)));
  return norm(sv) / fd;
}


// The point of triangle (a, b, c) nearest to p (Ericson, Real-Time Collision Detection 5.1.5:
// Voronoi regions of the vertices, then of the edges, else the interior).
Vec3 closest_point_on_triangle(Vec3 p, Vec3 a, Vec3 b, Vec3 c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + (d1 / (d1 - d3)) * ab;
  const Vec3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  const double den = va + vb + vc;
  if (!(den > 0)) return a;  // degenerate triangle: its vertex regions cover it
  return a + (vb / den) * ab + (vc / den) * ac;
}

// Distinct undirected edges (a < b) of cell c, ascending, packed as (a << 32) | b (sorting the
// packed keys sorts the pairs).
void cell_edges(const PolyMesh& m, int c, std::vector<uint64_t>& edges) {
  edges.clear();
  for (const int32_t* fp = m.cell_begin(c); fp != m.cell_end(c); ++fp) {
    const int f = *fp, n = m.face_size(f);
    const int32_t* v = m.face_begin(f);
    for (int i = 0; i < n; ++i) {
      const uint32_t a = static_cast<uint32_t>(v[i]), b = static_cast<uint32_t>(v[i + 1 == n ? 0 : i + 1]);
      edges.push_back(a < b ? (uint64_t(a) << 32) | b : (uint64_t(b) << 32) | a);
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
}
Vec3 edge_vector(const PolyMesh& m, uint64_t e) {
  return m.nodes[static_cast<uint32_t>(e)] - m.nodes[static_cast<uint32_t>(e >> 32)];
}
}  // namespace

Vec3 boundary_flux_point(const PolyMesh& m, const MeshGeometry& geo, int f) {
  if (m.face_neighbour[f] >= 0) return geo.face_centroid[f];
  const Vec3 s = m.metric_scale;
  auto to_frame = [&](Vec3 p) { return Vec3{p.x / s.x, p.y / s.y, p.z / s.z}; };
  const Vec3 x = to_frame(m.cell_fv_center[m.face_owner[f]]);
  const int k = m.face_size(f);
  const int32_t* v = m.face_begin(f);
  Vec3 g;
  for (int i = 0; i < k; ++i) g += m.nodes[v[i]];
  g = to_frame(g / k);
  double best = std::numeric_limits<double>::infinity();
  Vec3 best_p = geo.face_centroid[f];
  for (int i = 0; i < k; ++i) {
    const Vec3 p = closest_point_on_triangle(x, g, to_frame(m.nodes[v[i]]), to_frame(m.nodes[v[(i + 1) % k]]));
    const double d2 = norm2(p - x);
    if (d2 < best) best = d2, best_p = Vec3{p.x * s.x, p.y * s.y, p.z * s.z};
  }
  return std::isfinite(best) ? best_p : geo.face_centroid[f];
}

std::vector<Vec3> boundary_flux_points(const PolyMesh& m, const MeshGeometry& geo) {
  std::vector<Vec3> out(geo.face_centroid);
  parallel_ranges(m.n_faces(), [&](int64_t fb, int64_t fe) {
    for (int f = static_cast<int>(fb); f < fe; ++f)
      if (m.face_neighbour[f] < 0) out[f] = boundary_flux_point(m, geo, f);
  });
  return out;
}

double face_orthogonality_of(const PolyMesh& m, const MeshGeometry& geo, int f, Vec3 boundary_end) {
  const double a = norm(geo.face_area[f]);
  const Vec3 p1 = m.cell_fv_center[m.face_owner[f]];
  const Vec3 p2 = m.face_neighbour[f] >= 0 ? m.cell_fv_center[m.face_neighbour[f]] : boundary_end;
  const Vec3 d = p2 - p1;
  const double l = norm(d);
  if (!(a > 0) || !(l > 0)) return 0.0;  // degenerate
  return std::asin(clamp_unit(std::fabs(dot(d, geo.face_area[f])) / (l * a))) * kDeg;
}

std::vector<double> face_orthogonality(const PolyMesh& m, const MeshGeometry& geo, BoundaryPoint boundary) {
  std::vector<double> q(m.n_faces(), 0.0);
  // The end points face by face: no array of them (an interior face's is its centroid).
  const bool flux = boundary == BoundaryPoint::Flux;
  parallel_ranges(m.n_faces(), [&](int64_t fb, int64_t fe) {
    for (int f = static_cast<int>(fb); f < fe; ++f)
      q[f] = face_orthogonality_of(m, geo, f, flux ? boundary_flux_point(m, geo, f) : geo.face_centroid[f]);
  });
  return q;
}

namespace {

// The K-non-orthogonality of every face with sqrt(K) of cell c = root_k(c) (a factor on it changes
// nothing).
template <class RootK>
std::vector<double> nonorthogonality_in(const PolyMesh& m, const MeshGeometry& geo, RootK root_k) {
  std::vector<double> q(m.n_faces(), 0.0);
  // In the cell's K^-1/2-scaled coordinates (K isotropic there): n_s = K^1/2 n, d_s = K^-1/2 d,
  // n_s . d_s = n . d; atan2 stays accurate near 0.
  auto angle = [&](int c, Vec3 area, Vec3 d) {
    const Vec3 r = root_k(c);
    const Vec3 ns{r.x * area.x, r.y * area.y, r.z * area.z}, ds{d.x / r.x, d.y / r.y, d.z / r.z};
    return std::atan2(norm(cross(ds, ns)), std::fabs(dot(ds, ns))) * kDeg;
  };
  parallel_ranges(m.n_faces(), [&](int64_t fb, int64_t fe) {
    for (int f = static_cast<int>(fb); f < fe; ++f) {
      const Vec3 a = geo.face_area[f];
      const int32_t o = m.face_owner[f], n = m.face_neighbour[f];
      const Vec3 p1 = m.cell_fv_center[o];
      const Vec3 d = (n >= 0 ? m.cell_fv_center[n] : boundary_flux_point(m, geo, f)) - p1;
      if (!(norm(a) > 0) || !(norm(d) > 0)) {
        q[f] = 90.0;  // degenerate
        continue;
      }
      q[f] = angle(o, a, d);
      if (n >= 0) q[f] = std::max(q[f], angle(n, a, d));
    }
  });
  return q;
}

}  // namespace

std::vector<double> face_k_nonorthogonality(const PolyMesh& m, const MeshGeometry& geo) {
  return nonorthogonality_in(m, geo, [&](int c) {
    const Vec3 k = m.cell_perm[c];
    return Vec3{std::sqrt(k.x), std::sqrt(k.y), std::sqrt(k.z)};
  });
}

std::vector<double> face_frame_nonorthogonality(const PolyMesh& m, const MeshGeometry& geo) {
  return nonorthogonality_in(m, geo, [&](int) { return m.metric_scale; });
}

std::vector<double> face_planarity(const PolyMesh& m, const MeshGeometry& geo) {
  std::vector<double> q(m.n_faces(), 0.0);
  parallel_ranges(m.n_faces(), [&](int64_t fb, int64_t fe) {
    for (int f = static_cast<int>(fb); f < fe; ++f) {
      const double a = norm(geo.face_area[f]);
      if (!(a > 0)) {
        q[f] = 90.0;
        continue;
      }
      const Vec3 n = geo.face_area[f] / a;
      const int k = m.face_size(f);
      const int32_t* v = m.face_begin(f);
      Vec3 g;
      for (int i = 0; i < k; ++i) g += m.nodes[v[i]];
      g = g / k;
      double worst = 0;
      for (int i = 0; i < k; ++i) {
        const Vec3 t = cross(m.nodes[v[i]] - g, m.nodes[v[(i + 1) % k]] - g);  // 2 * triangle area vector
        const double ta = norm(t);
        if (!(ta > 2 * kPlanarityNegligibleArea * a)) continue;
        worst = std::max(worst, std::acos(clamp_unit(std::fabs(dot(n, t)) / ta)) * kDeg);
      }
      q[f] = worst;
    }
  });
  return q;
}

std::vector<double> cell_min_of_faces(const PolyMesh& m, const std::vector<double>& fv) {
  std::vector<double> out(m.n_cells(), 0.0);
  parallel_ranges(m.n_cells(), [&](int64_t cb, int64_t ce) {
    for (int c = static_cast<int>(cb); c < ce; ++c) {
      double v = std::numeric_limits<double>::infinity();
      for (const int32_t* f = m.cell_begin(c); f != m.cell_end(c); ++f) v = std::min(v, fv[*f]);
      out[c] = std::isfinite(v) ? v : 0.0;
    }
  });
  return out;
}

std::vector<double> cell_max_of_faces(const PolyMesh& m, const std::vector<double>& fv) {
  std::vector<double> out(m.n_cells(), 0.0);
  parallel_ranges(m.n_cells(), [&](int64_t cb, int64_t ce) {
    for (int c = static_cast<int>(cb); c < ce; ++c) {
      double v = 0;
      for (const int32_t* f = m.cell_begin(c); f != m.cell_end(c); ++f) v = std::max(v, fv[*f]);
      out[c] = v;
    }
  });
  return out;
}

std::vector<double> cell_mean_edge_length(const PolyMesh& m) {
  std::vector<double> out(m.n_cells(), 0.0);
  parallel_ranges(m.n_cells(), [&](int64_t cb, int64_t ce) {
    std::vector<uint64_t> edges;
    for (int c = static_cast<int>(cb); c < ce; ++c) {
      cell_edges(m, c, edges);
      double s = 0;
      for (uint64_t e : edges) s += norm(edge_vector(m, e));
      out[c] = edges.empty() ? 0.0 : s / static_cast<double>(edges.size());
    }
  });
  return out;
}

std::vector<double> cell_shape_quality(const PolyMesh& m, const std::vector<double>& h_ref) {
  std::vector<double> out(m.n_cells(), 0.0);
  const bool use_ref = h_ref.size() == static_cast<size_t>(m.n_cells());
  parallel_ranges(m.n_cells(), [&](int64_t cb, int64_t ce) {
    std::vector<uint64_t> edges;
    for (int c = static_cast<int>(cb); c < ce; ++c) {
      cell_edges(m, c, edges);
      if (edges.empty()) continue;
      double h = use_ref ? h_ref[c] : 0.0;
      if (!(h > 0) || !std::isfinite(h)) {
        h = 0;
        for (uint64_t e : edges) h += norm(edge_vector(m, e));
        h /= static_cast<double>(edges.size());
      }
      if (!(h > 0)) continue;  // every edge has zero length
      double q = 1.0;
      for (uint64_t e : edges) {
        const double l = norm(edge_vector(m, e));
        q = std::min(q, l > 0 ? std::min(l / h, h / l) : 0.0);
      }
      out[c] = q;
    }
  });
  return out;
}

Stats stats_of(const std::vector<double>& values, const std::vector<bool>& mask) {
  Stats s;
  double sum = 0;
  s.min = std::numeric_limits<double>::infinity();
  s.max = -std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < values.size(); ++i) {
    if (!mask.empty() && (i >= mask.size() || !mask[i])) continue;
    const double v = values[i];
    if (std::isnan(v)) continue;
    ++s.count;
    sum += v;
    s.min = std::min(s.min, v);
    s.max = std::max(s.max, v);
  }
  if (s.count == 0) return Stats{};
  s.mean = sum / static_cast<double>(s.count);
  return s;
}

std::vector<Vec3> openfoam_cell_centres(const PolyMesh& mesh) {
  std::vector<Vec3> centre(mesh.n_cells());
  parallel_ranges(mesh.n_cells(), [&](int64_t cb, int64_t ce) {
    std::vector<int32_t> outward;
    std::vector<int> off;
    std::vector<Vec3> fc, fa;
    for (int c = static_cast<int>(cb); c < ce; ++c) {
      outward.clear();
      off.assign(1, 0);
      for (const int32_t* f = mesh.cell_begin(c); f != mesh.cell_end(c); ++f) {
        outward.insert(outward.end(), mesh.face_begin(*f), mesh.face_end(*f));
        if (mesh.face_owner[*f] != c) std::reverse(outward.begin() + off.back(), outward.end());
        off.push_back(static_cast<int>(outward.size()));
      }
      centre[c] = foam_cell_centre(mesh.nodes, outward, off, fc, fa);
    }
  });
  return centre;
}

namespace {
// checkMesh's per-face measures from the OpenFOAM centres, one face loop for whichever is asked
// (a null output is skipped): the skewness and the cosine of the non-orthogonality (1 on the boundary).
void foam_face_measures(const PolyMesh& mesh, const std::vector<Vec3>& centre, std::vector<double>* skew,
                        std::vector<double>* cosine) {
  if (skew) skew->assign(mesh.n_faces(), 0.0);
  if (cosine) cosine->assign(mesh.n_faces(), 1.0);
  parallel_ranges(mesh.n_faces(), [&](int64_t fb, int64_t fe) {
    for (int f = static_cast<int>(fb); f < fe; ++f) {
      Vec3 fc, fa;
      foam_face(mesh.nodes, mesh.face_begin(f), mesh.face_end(f), &fc, &fa);
      const int32_t n = mesh.face_neighbour[f];
      const Vec3& own = centre[mesh.face_owner[f]];
      if (skew)
        (*skew)[f] = foam_skewness(mesh.nodes, mesh.face_begin(f), mesh.face_end(f), fc, fa, own,
                                   n >= 0 ? &centre[n] : nullptr);
      if (cosine && n >= 0) {
        const Vec3 d = centre[n] - own;
        (*cosine)[f] = dot(d, fa) / (norm(d) * norm(fa) + 1e-300);
      }
    }
  });
}
}  // namespace

std::vector<double> openfoam_face_skewness(const PolyMesh& mesh, const std::vector<Vec3>& centre) {
  std::vector<double> skew;
  foam_face_measures(mesh, centre, &skew, nullptr);
  return skew;
}

std::vector<double> openfoam_face_skewness(const PolyMesh& mesh) {
  return openfoam_face_skewness(mesh, openfoam_cell_centres(mesh));
}

std::vector<double> openfoam_face_nonorthogonality_cosine(const PolyMesh& mesh, const std::vector<Vec3>& centre) {
  std::vector<double> cosine;
  foam_face_measures(mesh, centre, nullptr, &cosine);
  return cosine;
}

SkewnessSummary summarize_skewness(const std::vector<double>& face_skewness) {
  SkewnessSummary s;
  for (size_t f = 0; f < face_skewness.size(); ++f) {
    const double v = face_skewness[f];
    if (std::isnan(v)) continue;
    if (v > s.max || s.worst_face < 0) s.max = v, s.worst_face = static_cast<int32_t>(f);
    s.above_limit += v > kCheckMeshSkewnessLimit;
  }
  return s;
}

NonOrthogonalitySummary summarize_nonorthogonality(const PolyMesh& mesh, const std::vector<double>& cosine) {
  NonOrthogonalitySummary s;
  const double severe = std::cos(kCheckMeshSevereNonOrthogonality / kDeg);
  double min_cos = 1, sum = 0;
  int64_t interior = 0;
  for (size_t f = 0; f < cosine.size(); ++f) {
    const double c = cosine[f];
    if (mesh.face_neighbour[f] < 0 || std::isnan(c)) continue;
    if (c < min_cos || s.worst_face < 0) min_cos = c, s.worst_face = static_cast<int32_t>(f);
    sum += c;
    ++interior;
    s.severe += c < severe && c > kCheckMeshSmall;
    s.errors += c <= kCheckMeshSmall;
  }
  if (interior == 0) return s;
  s.max = std::acos(clamp_unit(min_cos)) * kDeg;
  s.average = std::acos(clamp_unit(sum / static_cast<double>(interior))) * kDeg;
  return s;
}

CheckMeshFigures checkmesh_figures(const PolyMesh& mesh) {
  std::vector<double> skew, cosine;
  foam_face_measures(mesh, openfoam_cell_centres(mesh), &skew, &cosine);
  return {summarize_skewness(skew), summarize_nonorthogonality(mesh, cosine)};
}

}  // namespace hm
