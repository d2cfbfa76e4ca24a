#include "optimize.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>

#include "fvcheck/lib/checks.hpp"
#include "meshgen/core/geometry.hpp"
#include "meshgen/core/mesh_builder.hpp"

namespace hm {

namespace {

constexpr double kRadToDeg = 180.0 / M_PI;
constexpr double kSkewnessLimit = kOpenFoamSkewnessLimit;

// A mutable copy of the mesh: faces as node cycles (owner orientation) that edge
// operations rewrite in place, with enough incidence to find the ball of a node.
struct EditableMesh {
  std::vector<Vec3> nodes;
  std::vector<char> fixed;  // node used by a reservoir or well cell: never moves
  std::vector<std::vector<int32_t>> faces;
  std::vector<char> alive;
  std::vector<int32_t> owner, neighbour;
  std::vector<std::vector<int32_t>> cell_faces;
  std::vector<std::set<int32_t>> node_faces;  // alive faces containing each node
};

struct CellMeasures {
  bool valid = false;     // closed, >= 4 faces, non-degenerate faces, positive volume
  bool convex = false;
  bool centred = false;   // site strictly inside
  double q_o = 90, q_p = 0, q_s = 1;
  int failed = 0;         // with limits: the first control found to fail (kFail*), 0 if none
};

// The controls a cell must pass (measure_cell stops at the first failure it finds: most
// candidate operations are refused, and the convexity test is the expensive part).
struct CellLimits {
  double min_q_o = 0, max_q_p = 90;
  bool keep_convex = false, keep_centred = false;
};
enum { kFailOrthogonality = 1, kFailPlanarity, kFailCentering, kFailConvexity };

// Outward node cycle of face f seen from cell c.
std::vector<int32_t> outward_cycle(const EditableMesh& m, int32_t f, int32_t c) {
  std::vector<int32_t> cyc = m.faces[f];
  if (m.owner[f] != c) std::reverse(cyc.begin(), cyc.end());
  return cyc;
}

void face_area_centroid(const EditableMesh& m, const std::vector<int32_t>& cyc, Vec3* area, Vec3* g) {
  Vec3 mean;
  for (int32_t v : cyc) mean += m.nodes[v];
  mean = mean / static_cast<double>(cyc.size());
  Vec3 a;
  for (size_t i = 0; i < cyc.size(); ++i) a += 0.5 * cross(m.nodes[cyc[i]] - mean, m.nodes[cyc[(i + 1) % cyc.size()]] - mean);
  *area = a;
  *g = mean;
}

// Paper eq. 10: the largest angle between the face normal and its fan triangles' normals.
double face_planarity_deg(const EditableMesh& m, const std::vector<int32_t>& cyc, Vec3 area, Vec3 g) {
  const double an = norm(area);
  if (an == 0) return 90;
  const Vec3 n = area / an;
  double worst = 0;
  for (size_t i = 0; i < cyc.size(); ++i) {
    const Vec3 t = cross(m.nodes[cyc[i]] - g, m.nodes[cyc[(i + 1) % cyc.size()]] - g);
    const double tn = norm(t);
    if (tn <= 1e-12 * an) continue;
    worst = std::max(worst, std::acos(std::min(1.0, std::abs(dot(n, t / tn)))) * kRadToDeg);
  }
  return worst;
}

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
// pyramids from the average of the face centres. Faces are given as outward cycles.
Vec3 foam_cell_centre(const std::vector<Vec3>& nodes, const std::vector<std::vector<int32_t>>& outward) {
  std::vector<Vec3> fc(outward.size()), fa(outward.size());
  Vec3 est;
  for (size_t i = 0; i < outward.size(); ++i) {
    foam_face(nodes, outward[i].data(), outward[i].data() + outward[i].size(), &fc[i], &fa[i]);
    est += fc[i];
  }
  if (outward.empty()) return est;
  est = est / static_cast<double>(outward.size());
  Vec3 sum;
  double vol = 0;
  for (size_t i = 0; i < outward.size(); ++i) {
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

CellMeasures measure_cell(const EditableMesh& m, const PolyMesh& src, const std::vector<double>& h_ref, int32_t c,
                          const CellLimits* lim = nullptr) {
  CellMeasures r;
  std::vector<std::vector<int32_t>> cycles;
  for (int32_t f : m.cell_faces[c])
    if (m.alive[f]) cycles.push_back(outward_cycle(m, f, c));
  if (cycles.size() < 4) return r;
  // Combinatorial closure: each directed edge once, and its reverse once (sorted vectors:
  // this runs for every cell of every candidate operation).
  std::vector<std::pair<int32_t, int32_t>> directed;
  std::vector<int32_t> cell_nodes;
  for (const auto& cyc : cycles) {
    if (cyc.size() < 3) return r;
    std::vector<int32_t> distinct(cyc);
    std::sort(distinct.begin(), distinct.end());
    if (std::adjacent_find(distinct.begin(), distinct.end()) != distinct.end()) return r;
    for (size_t i = 0; i < cyc.size(); ++i) {
      directed.push_back({cyc[i], cyc[(i + 1) % cyc.size()]});
      cell_nodes.push_back(cyc[i]);
    }
  }
  std::sort(directed.begin(), directed.end());
  if (std::adjacent_find(directed.begin(), directed.end()) != directed.end()) return r;
  for (const auto& e : directed)
    if (!std::binary_search(directed.begin(), directed.end(), std::make_pair(e.second, e.first))) return r;
  std::sort(cell_nodes.begin(), cell_nodes.end());
  cell_nodes.erase(std::unique(cell_nodes.begin(), cell_nodes.end()), cell_nodes.end());

  Vec3 lo = m.nodes[cell_nodes.front()], hi = lo;
  for (int32_t v : cell_nodes)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], m.nodes[v][a]);
      hi[a] = std::max(hi[a], m.nodes[v][a]);
    }
  const double L = norm(hi - lo);
  const double tol = 1e-9 * L;
  const Vec3 site = src.cell_fv_center[c];
  double vol = 0;
  r.convex = true;
  r.centred = true;
  r.q_o = 90;
  r.q_p = 0;
  std::vector<Vec3> normals(cycles.size()), centres(cycles.size());
  size_t k = 0;
  for (int32_t f : m.cell_faces[c]) {
    if (!m.alive[f]) continue;
    const auto& cyc = cycles[k];
    Vec3 area, g;
    face_area_centroid(m, cyc, &area, &g);
    const double an = norm(area);
    if (an <= 1e-12 * L * L) return r;
    const Vec3 n = area / an;
    // The plane of a (possibly non-planar) face for the centering and convexity tests goes
    // through its area-weighted centroid, as in fvcheck (through the vertex mean, a cell of
    // three_wells passed here and failed fvcheck's convexity by 5e-6 of its size).
    Vec3 area_w, gw;
    polygon_area_centroid(m.nodes, cyc.data(), cyc.data() + cyc.size(), &area_w, &gw);
    normals[k] = n;
    centres[k] = gw;
    ++k;
    for (size_t i = 0; i < cyc.size(); ++i)
      vol += dot(g - site, cross(m.nodes[cyc[i]] - site, m.nodes[cyc[(i + 1) % cyc.size()]] - site)) / 6.0;
    if (dot(n, site - gw) >= -tol) r.centred = false;
    // Q_O (eq. 8): the segment to the other cell's FV centre (or the face centroid on the boundary).
    const int32_t other = m.owner[f] == c ? m.neighbour[f] : m.owner[f];
    const Vec3 u = (other >= 0 ? src.cell_fv_center[other] : g) - site;
    const double un = norm(u);
    r.q_o = std::min(r.q_o, un > 0 ? std::asin(std::min(1.0, std::abs(dot(u / un, n)))) * kRadToDeg : 0.0);
    r.q_p = std::max(r.q_p, face_planarity_deg(m, cyc, area, g));
    if (lim) {
      if (r.q_o < lim->min_q_o) r.failed = kFailOrthogonality;
      else if (r.q_p > lim->max_q_p) r.failed = kFailPlanarity;
      else if (lim->keep_centred && !r.centred) r.failed = kFailCentering;
      if (r.failed) {
        r.valid = true;  // valid as far as measured: the caller reports the failed control
        return r;
      }
    }
  }
  if (vol <= 1e-12 * L * L * L) return r;
  // Convexity: no node of the cell outside a face's plane, and every face polygon simple
  // with no reflex vertex (as fvcheck).
  if (!lim || lim->keep_convex) {
    for (size_t i = 0; i < cycles.size() && r.convex; ++i) {
      const auto& cyc = cycles[i];
      for (int32_t v : cell_nodes)
        if (dot(normals[i], m.nodes[v] - centres[i]) > tol && std::find(cyc.begin(), cyc.end(), v) == cyc.end()) {
          r.convex = false;
          break;
        }
      if (r.convex && face_polygon_defect(m.nodes, cyc.data(), cyc.data() + cyc.size(), 1e-9) != 0) r.convex = false;
    }
    if (lim && !r.convex) {
      r.failed = kFailConvexity;
      r.valid = true;
      return r;
    }
  }
  // Q_S (eq. 7) over the distinct edges.
  const double h = h_ref.size() > static_cast<size_t>(c) && h_ref[c] > 0 ? h_ref[c] : L;
  r.q_s = 1;
  for (const auto& e : directed) {
    if (e.first > e.second) continue;
    const double l = norm(m.nodes[e.first] - m.nodes[e.second]);
    r.q_s = std::min(r.q_s, l > 0 ? std::min(l / h, h / l) : 0.0);
  }
  r.valid = true;
  return r;
}

EditableMesh to_editable(const PolyMesh& mesh) {
  EditableMesh m;
  m.nodes = mesh.nodes;
  m.fixed.assign(mesh.n_nodes(), 0);
  const int nf = mesh.n_faces();
  m.faces.resize(nf);
  m.alive.assign(nf, 1);
  m.owner = mesh.face_owner;
  m.neighbour = mesh.face_neighbour;
  m.node_faces.resize(mesh.n_nodes());
  for (int f = 0; f < nf; ++f) {
    m.faces[f].assign(mesh.face_begin(f), mesh.face_end(f));
    for (int32_t v : m.faces[f]) m.node_faces[v].insert(f);
    const int32_t o = mesh.face_owner[f], n = mesh.face_neighbour[f];
    // Nodes of reservoir/well faces and of boundary faces (wellbore caps, outer boundary)
    // are constrained: moving them would break conformity or change the domain.
    const bool interior_transition = mesh.cell_region[o] == kTransition && n >= 0 && mesh.cell_region[n] == kTransition;
    if (!interior_transition)
      for (int32_t v : m.faces[f]) m.fixed[v] = 1;
  }
  m.cell_faces.resize(mesh.n_cells());
  for (int c = 0; c < mesh.n_cells(); ++c) m.cell_faces[c].assign(mesh.cell_begin(c), mesh.cell_end(c));
  return m;
}

PolyMesh from_editable(const EditableMesh& m, const PolyMesh& src) {
  MeshBuilder b;
  for (const Vec3& p : m.nodes) b.add_node(p);
  for (int c = 0; c < src.n_cells(); ++c) {
    std::vector<CellFace> faces;
    for (int32_t f : m.cell_faces[c]) {
      if (!m.alive[f]) continue;
      CellFace cf;
      cf.nodes = outward_cycle(m, f, c);
      cf.patch = src.face_patch[f] == kInteriorFace ? kInteriorFace : src.face_patch[f];
      faces.push_back(std::move(cf));
    }
    CellAttributes at;
    at.region = src.cell_region[c];
    at.fv_center = src.cell_fv_center[c];
    at.ijk = src.cell_ijk[c];
    at.perm = src.cell_perm[c];
    at.porosity = src.cell_porosity[c];
    at.radial = src.cell_radial[c];
    b.add_cell(faces, at);
  }
  BuildReport rep;
  PolyMesh out = b.finish(&rep);
  if (!rep.ok)
    throw std::runtime_error("optimize: the optimised mesh is not conforming: " +
                             (rep.problems.empty() ? std::string("?") : rep.problems[0]));
  return out;
}

// Solves A x = rhs for a symmetric positive definite 3x3 A (Cramer's rule); false if singular.
bool solve3(const double A[3][3], const double rhs[3], Vec3* x) {
  auto det3 = [](const double M[3][3]) {
    return M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) - M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
           M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0]);
  };
  const double D = det3(A);
  if (!(std::abs(D) > 0)) return false;
  for (int k = 0; k < 3; ++k) {
    double M[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) M[i][j] = j == k ? rhs[i] : A[i][j];
    (*x)[k] = det3(M) / D;
  }
  return true;
}

class Optimizer {
 public:
  Optimizer(const PolyMesh& src, const std::vector<double>& h_ref, const OptimizeParams& p)
      : src_(src), h_ref_(h_ref), p_(p), m_(to_editable(src)) {
    const int nc = src.n_cells();
    thr_o_.assign(nc, p.omega_o);
    thr_p_.assign(nc, p.omega_p);
    convex0_.assign(nc, 0);
    centred0_.assign(nc, 0);
    cell_stamp_.assign(nc, 0);
    qs_.assign(nc, 1.0);
    for (int c = 0; c < nc; ++c) {
      if (src.cell_region[c] != kTransition) continue;
      const CellMeasures cm = measure_cell(m_, src_, h_ref_, c);
      thr_o_[c] = std::min(p.omega_o, cm.q_o);  // a cell that starts below omega_o keeps its own level
      thr_p_[c] = std::max(p.omega_p, cm.q_p);
      convex0_[c] = cm.valid && cm.convex;
      centred0_[c] = cm.valid && cm.centred;
      qs_[c] = cm.q_s;
    }
    centre_.resize(nc);
    for (int c = 0; c < nc; ++c) centre_[c] = cell_centre(c);
    skew_ok_.resize(m_.faces.size());
    for (size_t f = 0; f < m_.faces.size(); ++f)
      skew_ok_[f] = face_skewness(static_cast<int32_t>(f), {}) <= kSkewnessLimit;
  }

  // Phase: 0 = remove edges < G1 h, 1 = remove edges < G2 h, 2 = expand edges < G3 h.
  // Every phase applies the FV controls. The paper removes the G1 edges without control
  // because its power vertices carry round-off duplicates; ours are identified
  // combinatorially, and on examples/paper_single_well.yaml uncontrolled removal pushed 81
  // of 578 cells above omega_p and one face to Q_O = 43 degrees (docs/optimization.md).
  int run_phase(int phase, double gamma, OptimizeReport* rep) {
    int total = 0;
    for (int pass = 0; pass < p_.max_passes; ++pass) {
      ++rep->passes;
      report_ = rep;
      int changed = phase == 2 ? 0 : collapse_small_faces(gamma);
      rep->collapsed_faces += changed;
      for (const auto& cand : short_edges(gamma)) {
        const int32_t a = cand.second.first, b = cand.second.second;
        if (!edge_exists(a, b) || norm(m_.nodes[a] - m_.nodes[b]) >= gamma * edge_h(a, b)) continue;
        report_ = rep;
        // A refused operation is retried only once a cell around it has changed.
        const auto key = std::make_pair(a, b);
        const auto old = refused_.find(key);
        if (old != refused_.end() && old->second.first == phase && latest_change(a, b) <= old->second.second) continue;
        if (phase == 2 ? try_expand(a, b) : try_collapse(a, b)) {
          ++changed;
          refused_.erase(key);
        } else {
          refused_[key] = {phase, op_count_};
        }
      }
      total += changed;
      if (changed == 0) break;
    }
    return total;
  }

  PolyMesh result() const { return from_editable(m_, src_); }

  // Skewness phase: faces of transition cells whose OpenFOAM skewness exceeds the limit
  // (typically a sliver at the far tip of a needle cell, whose centre is far from the
  // face) are collapsed to a point, or lose their edges one at a time, under every control;
  // an operation counts only if the face disappears or becomes less skewed.
  int run_skewness_phase(OptimizeReport* rep) {
    report_ = rep;
    int total = 0;
    for (int pass = 0; pass < p_.max_passes; ++pass) {
      ++rep->passes;
      std::vector<std::pair<double, int32_t>> skewed;
      for (size_t f = 0; f < m_.faces.size(); ++f) {
        if (!m_.alive[f] || !transition_face(static_cast<int32_t>(f))) continue;
        const double sk = face_skewness(static_cast<int32_t>(f), {});
        if (sk > kSkewnessLimit) skewed.push_back({-sk, static_cast<int32_t>(f)});
      }
      std::sort(skewed.begin(), skewed.end());  // most skewed first; ties by face id
      int changed = 0;
      for (const auto& [neg_sk, f] : skewed) {
        (void)neg_sk;
        if (m_.alive[f] && reduce_skewness(f)) ++changed;
      }
      total += changed;
      if (changed == 0) break;
    }
    return total;
  }

  int skewed_faces(double* worst) const {
    int n = 0;
    *worst = 0;
    for (size_t f = 0; f < m_.faces.size(); ++f) {
      if (!m_.alive[f]) continue;
      const int32_t o = m_.owner[f], nb = m_.neighbour[f];
      if (src_.cell_region[o] != kTransition && (nb < 0 || src_.cell_region[nb] != kTransition)) continue;
      const double sk = face_skewness(static_cast<int32_t>(f), {});
      *worst = std::max(*worst, sk);
      if (sk > kSkewnessLimit) ++n;
    }
    return n;
  }

  // The last accepted operation that changed a cell around a or b.
  long latest_change(int32_t a, int32_t b) const {
    long t = 0;
    for (int32_t v : {a, b})
      for (int32_t f : m_.node_faces[v])
        if (m_.alive[f])
          for (int32_t c : {m_.owner[f], m_.neighbour[f]})
            if (c >= 0) t = std::max(t, cell_stamp_[c]);
    return t;
  }

 private:
  struct Saved {
    std::vector<std::pair<int32_t, std::vector<int32_t>>> faces;
    std::vector<std::pair<int32_t, char>> alive;
    std::vector<std::pair<int32_t, Vec3>> nodes;
  };

  // Q_S (eq. 7) of transition cell c as the mesh is now (as measure_cell computes it).
  double cell_shape_quality(int32_t c) const {
    const double h = h_ref_.size() > static_cast<size_t>(c) ? h_ref_[c] : 0;
    if (!(h > 0)) return measure_cell(m_, src_, h_ref_, c).q_s;  // its h is then the cell's size
    double q = 1;
    for (int32_t f : m_.cell_faces[c]) {
      if (!m_.alive[f]) continue;
      const auto& cyc = m_.faces[f];
      for (size_t i = 0; i < cyc.size(); ++i) {
        const double l = norm(m_.nodes[cyc[i]] - m_.nodes[cyc[(i + 1) % cyc.size()]]);
        q = std::min(q, l > 0 && h > 0 ? std::min(l / h, h / l) : 0.0);
      }
    }
    return q;
  }

  // OpenFOAM centre of cell c as the mesh is now.
  Vec3 cell_centre(int32_t c) const {
    std::vector<std::vector<int32_t>> cycles;
    for (int32_t f : m_.cell_faces[c])
      if (m_.alive[f]) cycles.push_back(outward_cycle(m_, f, c));
    return foam_cell_centre(m_.nodes, cycles);
  }

  // OpenFOAM skewness of face f, with the centres in `moved` overriding the cached ones.
  double face_skewness(int32_t f, const std::vector<std::pair<int32_t, Vec3>>& moved) const {
    auto centre = [&](int32_t c) {
      for (const auto& [mc, p] : moved)
        if (mc == c) return p;
      return centre_[c];
    };
    const auto& cyc = m_.faces[f];
    Vec3 fc, fa;
    foam_face(m_.nodes, cyc.data(), cyc.data() + cyc.size(), &fc, &fa);
    const Vec3 own = centre(m_.owner[f]);
    if (m_.neighbour[f] < 0) return foam_skewness(m_.nodes, cyc.data(), cyc.data() + cyc.size(), fc, fa, own, nullptr);
    const Vec3 nei = centre(m_.neighbour[f]);
    return foam_skewness(m_.nodes, cyc.data(), cyc.data() + cyc.size(), fc, fa, own, &nei);
  }

  bool transition_face(int32_t f) const {
    return src_.cell_region[m_.owner[f]] == kTransition && m_.neighbour[f] >= 0 &&
           src_.cell_region[m_.neighbour[f]] == kTransition;
  }

  // Reference length of an edge: the largest h of the transition cells around it (an edge
  // is small if it is small for any cell that has it).
  double edge_h(int32_t a, int32_t b) const {
    double h = 0;
    for (int32_t f : m_.node_faces[a]) {
      if (!m_.alive[f] || !m_.node_faces[b].count(f)) continue;
      for (int32_t c : {m_.owner[f], m_.neighbour[f]})
        if (c >= 0 && src_.cell_region[c] == kTransition && c < static_cast<int32_t>(h_ref_.size())) h = std::max(h, h_ref_[c]);
    }
    return h;
  }

  bool edge_exists(int32_t a, int32_t b) const {
    for (int32_t f : m_.node_faces[a]) {
      if (!m_.alive[f]) continue;
      const auto& cyc = m_.faces[f];
      for (size_t i = 0; i < cyc.size(); ++i) {
        const int32_t u = cyc[i], v = cyc[(i + 1) % cyc.size()];
        if ((u == a && v == b) || (u == b && v == a)) return true;
      }
    }
    return false;
  }

  // Candidate edges (not both fixed) shorter than gamma * h, shortest (relative) first;
  // ties broken by node ids so that the result is deterministic.
  std::vector<std::pair<double, std::pair<int32_t, int32_t>>> short_edges(double gamma) const {
    const std::vector<double> node_h = node_h_bound();
    std::vector<std::pair<int32_t, int32_t>> edges;
    for (size_t f = 0; f < m_.faces.size(); ++f) {
      if (!m_.alive[f] || !transition_face(static_cast<int32_t>(f))) continue;
      const auto& cyc = m_.faces[f];
      for (size_t i = 0; i < cyc.size(); ++i) {
        int32_t a = cyc[i], b = cyc[(i + 1) % cyc.size()];
        if (a > b) std::swap(a, b);
        if (m_.fixed[a] && m_.fixed[b]) continue;
        if (norm(m_.nodes[a] - m_.nodes[b]) >= gamma * std::min(node_h[a], node_h[b])) continue;  // long for every cell
        edges.push_back({a, b});
      }
    }
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    std::vector<std::pair<double, std::pair<int32_t, int32_t>>> out;
    for (const auto& [a, b] : edges) {
      const double h = edge_h(a, b);
      const double l = norm(m_.nodes[a] - m_.nodes[b]);
      if (h > 0 && l < gamma * h) out.push_back({l / h, {a, b}});
    }
    std::sort(out.begin(), out.end());
    return out;
  }

  // Per node, the largest h of the transition cells around it: an upper bound of the
  // reference length of every edge at that node (edge_h), to skip long edges cheaply.
  std::vector<double> node_h_bound() const {
    std::vector<double> node_h(m_.nodes.size(), 0.0);
    for (size_t f = 0; f < m_.faces.size(); ++f) {
      if (!m_.alive[f]) continue;
      double h = 0;
      for (int32_t c : {m_.owner[f], m_.neighbour[f]})
        if (c >= 0 && src_.cell_region[c] == kTransition && c < static_cast<int32_t>(h_ref_.size())) h = std::max(h, h_ref_[c]);
      for (int32_t v : m_.faces[f]) node_h[v] = std::max(node_h[v], h);
    }
    return node_h;
  }

  std::set<int32_t> ball(int32_t v) const {
    std::set<int32_t> cells;
    for (int32_t f : m_.node_faces[v]) {
      if (!m_.alive[f]) continue;
      for (int32_t c : {m_.owner[f], m_.neighbour[f]})
        if (c >= 0 && src_.cell_region[c] == kTransition) cells.insert(c);
    }
    return cells;
  }

  bool reject(int OptimizeReport::*reason) {
    ++(report_->*reason);
    ++report_->rejected;
    return false;
  }

  void restore(const Saved& s) {
    for (const auto& [f, cyc] : s.faces) m_.faces[f] = cyc;
    for (const auto& [f, al] : s.alive) m_.alive[f] = al;
    for (const auto& [v, p] : s.nodes) m_.nodes[v] = p;
  }

  // Validity (closed, non-degenerate, positive volume, still convex if it was) and the FV
  // controls of paper 6.2 (per-cell orthogonality and planarity thresholds,
  // auto-centering) on every touched cell. (An expansion's shape test is its caller's:
  // try_expand_ends compares the mean Q_S from edge lengths first.)
  bool accept(const std::set<int32_t>& cells, int32_t target_face = -1, double target_skew = 0) {
    std::vector<std::pair<int32_t, CellMeasures>> measured;
    for (int32_t c : cells) {
      CellLimits lim;
      lim.min_q_o = thr_o_[c];
      lim.max_q_p = thr_p_[c];
      lim.keep_convex = convex0_[c];
      lim.keep_centred = centred0_[c];
      const CellMeasures cm = measure_cell(m_, src_, h_ref_, c, &lim);
      if (!cm.valid) return reject(&OptimizeReport::rejected_invalid);
      if (cm.failed == kFailConvexity) return reject(&OptimizeReport::rejected_convexity);
      if (cm.failed == kFailOrthogonality) return reject(&OptimizeReport::rejected_orthogonality);
      if (cm.failed == kFailPlanarity) return reject(&OptimizeReport::rejected_planarity);
      if (cm.failed == kFailCentering) return reject(&OptimizeReport::rejected_centering);
      measured.push_back({c, cm});
    }
    // OpenFOAM skewness of every face of the touched cells (their centres moved): a face
    // within the limit stays within it. (A cap at each skewed face's own level refused
    // operations that removed skewed faces elsewhere: three_wells kept 138 instead of 106.)
    std::vector<std::pair<int32_t, Vec3>> moved;
    for (int32_t c : cells) moved.push_back({c, cell_centre(c)});
    std::vector<std::pair<int32_t, double>> skews;
    std::set<int32_t> seen;
    for (int32_t c : cells)
      for (int32_t f : m_.cell_faces[c]) {
        if (!m_.alive[f] || !seen.insert(f).second) continue;
        const double sk = face_skewness(f, moved);
        if (skew_ok_[f] && sk > kSkewnessLimit) return reject(&OptimizeReport::rejected_skewness);
        skews.push_back({f, sk});
      }
    if (target_face >= 0 && m_.alive[target_face]) {
      const auto it = std::find_if(skews.begin(), skews.end(), [&](const auto& e) { return e.first == target_face; });
      const double now = it != skews.end() ? it->second : face_skewness(target_face, moved);
      if (now >= target_skew) return reject(&OptimizeReport::rejected_skewness);
    }
    // A cell's thresholds follow its improvements (paper 6.2).
    ++op_count_;
    for (const auto& [c, cc] : moved) centre_[c] = cc;
    for (const auto& [f, sk] : skews)
      if (sk <= kSkewnessLimit) skew_ok_[f] = 1;
    for (const auto& [c, cm] : measured) {
      cell_stamp_[c] = op_count_;
      qs_[c] = cm.q_s;
      thr_o_[c] = std::max(thr_o_[c], std::min(p_.omega_o, cm.q_o));
      thr_p_[c] = std::min(thr_p_[c], std::max(p_.omega_p, cm.q_p));
    }
    return true;
  }

  // Where two free vertices merge. The paper takes the midpoint; moving a vertex off the
  // planes of its faces tilts them, which costs orthogonality and planarity. Each face
  // between two transition cells should lie in a plane normal to the segment between the
  // two sites (that is what makes the power diagram orthogonal), so the merged vertex is
  // the least-squares point of those planes (each through its face's current centroid),
  // regularised toward the midpoint; it falls back to the midpoint if that point strays
  // farther than the edge's length.
  Vec3 merge_position(const std::vector<int32_t>& verts) const {
    Vec3 mid;
    for (int32_t v : verts) mid += m_.nodes[v];
    mid = mid / static_cast<double>(verts.size());
    double l = 0;  // the farthest the merged vertex may go: the set's diameter
    for (int32_t v : verts)
      for (int32_t w : verts) l = std::max(l, norm(m_.nodes[v] - m_.nodes[w]));
    double A[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}, rhs[3] = {0, 0, 0};
    std::set<int32_t> faces;
    for (int32_t v : verts)
      for (int32_t f : m_.node_faces[v])
        if (m_.alive[f] && transition_face(f)) faces.insert(f);
    int n_planes = 0;
    for (int32_t f : faces) {
      const Vec3 d = src_.cell_fv_center[m_.neighbour[f]] - src_.cell_fv_center[m_.owner[f]];
      const double dn = norm(d);
      if (dn == 0) continue;
      const Vec3 n = d / dn;
      Vec3 g;
      for (int32_t v : m_.faces[f]) g += m_.nodes[v];
      g = g / static_cast<double>(m_.faces[f].size());
      const double off = dot(n, g);
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) A[i][j] += n[i] * n[j];
        rhs[i] += n[i] * off;
      }
      ++n_planes;
    }
    if (n_planes == 0) return mid;
    const double lambda = 1e-3 * n_planes;  // pulls the free directions to the midpoint
    for (int i = 0; i < 3; ++i) {
      A[i][i] += lambda;
      rhs[i] += lambda * mid[i];
    }
    Vec3 p;
    if (!solve3(A, rhs, &p)) return mid;
    return norm(p - mid) <= l ? p : mid;
  }

  // Merges a set of vertices (an edge, or all the vertices of a small face) into one:
  // the constrained vertex if the set has one (it stays in place), else a new position
  // (merge_position). Faces that fall below 3 vertices disappear. Accepted only if every
  // touched cell stays valid and passes the controls; otherwise everything is restored.
  bool try_merge(std::vector<int32_t> verts, int target_choice = 0, int32_t skew_face = -1, double skew_before = 0) {
    std::sort(verts.begin(), verts.end());
    int32_t keep = verts.front();
    int n_fixed = 0;
    for (int32_t v : verts)
      if (m_.fixed[v]) {
        keep = v;
        ++n_fixed;
      }
    if (n_fixed > 1) return false;
    const bool keep_moves = n_fixed == 0;
    // target_choice 0: the plane-fitting position; -1: the midpoint; k > 0: where verts[k - 1] is.
    Vec3 mid;
    for (int32_t v : verts) mid += m_.nodes[v];
    mid = mid / static_cast<double>(verts.size());
    const Vec3 target = !keep_moves ? m_.nodes[keep]
                        : target_choice == 0 ? merge_position(verts)
                        : target_choice < 0  ? mid
                                             : m_.nodes[verts[target_choice - 1]];
    // Touched: faces of the vertices that disappear, and faces of the keeper if it moves.
    std::set<int32_t> touched, cells;
    for (int32_t v : verts) {
      if (v == keep && !keep_moves) continue;
      for (int32_t f : m_.node_faces[v])
        if (m_.alive[f]) touched.insert(f);
      for (int32_t c : ball(v)) cells.insert(c);
    }
    Saved s;
    for (int32_t v : verts) s.nodes.push_back({v, m_.nodes[v]});
    for (int32_t f : touched) {
      if (!transition_face(f)) return false;  // never rewrite a reservoir or well face
      s.faces.push_back({f, m_.faces[f]});
      s.alive.push_back({f, m_.alive[f]});
    }
    auto merged = [&](int32_t v) { return std::binary_search(verts.begin(), verts.end(), v) ? keep : v; };
    m_.nodes[keep] = target;
    for (int32_t f : touched) {
      std::vector<int32_t> cyc;
      for (int32_t v : m_.faces[f]) {
        const int32_t w = merged(v);
        if (cyc.empty() || cyc.back() != w) cyc.push_back(w);
      }
      while (cyc.size() > 1 && cyc.front() == cyc.back()) cyc.pop_back();
      m_.faces[f] = cyc;
      if (cyc.size() < 3) m_.alive[f] = 0;
    }
    if (!accept(cells, skew_face, skew_before)) {
      restore(s);
      return false;
    }
    for (int32_t v : verts) {
      if (v == keep) continue;
      for (int32_t f : m_.node_faces[v])
        if (m_.alive[f]) m_.node_faces[keep].insert(f);
      m_.node_faces[v].clear();
    }
    for (auto it = m_.node_faces[keep].begin(); it != m_.node_faces[keep].end();)
      it = m_.alive[*it] ? std::next(it) : m_.node_faces[keep].erase(it);
    return true;
  }

  // An edge of two free vertices merges at the plane-fitting position, or failing that at
  // either end (which leaves that end's faces untouched); a constrained end stays put.
  bool try_collapse(int32_t a, int32_t b, int32_t skew_face = -1, double skew_before = 0) {
    if (try_merge({a, b}, 0, skew_face, skew_before)) return true;
    if (m_.fixed[a] || m_.fixed[b]) return false;
    if (try_merge({a, b}, -1, skew_face, skew_before)) return true;
    return try_merge({a, b}, 1, skew_face, skew_before) || try_merge({a, b}, 2, skew_face, skew_before);
  }

  // One operation that removes face f or makes it less skewed: the whole face to a point
  // (where its planes meet, or at one of its vertices), else one of its edges collapsed,
  // shortest first.
  bool reduce_skewness(int32_t f) {
    const double before = face_skewness(f, {});
    const std::vector<int32_t> cyc = m_.faces[f];
    // With a constrained vertex the face can only go to that vertex: one attempt.
    const bool any_fixed = std::any_of(cyc.begin(), cyc.end(), [&](int32_t v) { return m_.fixed[v] != 0; });
    const size_t targets = any_fixed ? 0 : cyc.size();
    for (size_t k = 0; k <= targets; ++k)
      if (try_merge(cyc, static_cast<int>(k), f, before)) return true;
    std::vector<std::pair<double, std::pair<int32_t, int32_t>>> edges;
    for (size_t i = 0; i < cyc.size(); ++i) {
      int32_t a = cyc[i], b = cyc[(i + 1) % cyc.size()];
      if (a > b) std::swap(a, b);
      if (!(m_.fixed[a] && m_.fixed[b])) edges.push_back({norm(m_.nodes[a] - m_.nodes[b]), {a, b}});
    }
    std::sort(edges.begin(), edges.end());
    for (const auto& e : edges)
      if (try_collapse(e.second.first, e.second.second, f, before)) return true;
    return false;
  }

  // Small faces (paper 6.2: "small faces are then removed in an implicit way"): a face
  // whose edges are all shorter than gamma h collapses to a point in one operation.
  // Collapsing its edges one at a time would first turn it into a tilted sliver that the
  // orthogonality control refuses.
  int collapse_small_faces(double gamma) {
    std::vector<std::pair<double, int32_t>> small;
    const std::vector<double> node_h = node_h_bound();
    for (size_t f = 0; f < m_.faces.size(); ++f) {
      if (!m_.alive[f] || !transition_face(static_cast<int32_t>(f))) continue;
      const auto& cyc = m_.faces[f];
      double longest = 0, bound = 1e300;
      for (size_t i = 0; i < cyc.size(); ++i) {
        longest = std::max(longest, norm(m_.nodes[cyc[i]] - m_.nodes[cyc[(i + 1) % cyc.size()]]));
        bound = std::min(bound, node_h[cyc[i]]);
      }
      if (longest >= gamma * bound) continue;  // not small for any choice of h
      double h = 1e300;
      for (size_t i = 0; i < cyc.size(); ++i) h = std::min(h, edge_h(cyc[i], cyc[(i + 1) % cyc.size()]));
      if (h > 0 && longest < gamma * h) small.push_back({longest / h, static_cast<int32_t>(f)});
    }
    std::sort(small.begin(), small.end());
    int merged = 0;
    for (const auto& [ratio, f] : small) {
      (void)ratio;
      if (!m_.alive[f]) continue;
      if (try_merge(m_.faces[f])) ++merged;
    }
    return merged;
  }

  bool try_expand(int32_t a, int32_t b) {
    if (m_.fixed[b] && !m_.fixed[a]) std::swap(a, b);
    if (m_.fixed[a] && m_.fixed[b]) return false;
    if (try_expand_ends(a, b, !m_.fixed[a], true)) return true;
    if (m_.fixed[a]) return false;
    // Not in the paper: when moving both ends is refused, either end alone (the move of its
    // case 2) under the same controls. Mean Q_S with the tip-site transition: 0.289 -> 0.311
    // (paper_single_well), 0.250 -> 0.275 (three_wells).
    return try_expand_ends(a, b, false, true) || try_expand_ends(a, b, true, false);
  }

  // Expansion of edge ab (paper 6.2.2): a moves by -(alpha-1)/2 ab, b by +(alpha-1)/2 ab,
  // each only if asked to.
  bool try_expand_ends(int32_t a, int32_t b, bool move_a, bool move_b) {
    const Vec3 ab = m_.nodes[b] - m_.nodes[a];
    const double s = 0.5 * (p_.expansion - 1.0);
    std::set<int32_t> cells;
    if (move_b) cells = ball(b);
    if (move_a)
      for (int32_t c : ball(a)) cells.insert(c);
    double qs_before = 0;
    for (int32_t c : cells) qs_before += qs_[c];
    qs_before /= std::max<size_t>(1, cells.size());
    Saved saved;
    saved.nodes = {{a, m_.nodes[a]}, {b, m_.nodes[b]}};
    if (move_a) m_.nodes[a] = m_.nodes[a] - s * ab;
    if (move_b) m_.nodes[b] = m_.nodes[b] + s * ab;
    // The shape control first: it needs only edge lengths, and most expansions fail it.
    double qs_after = 0;
    for (int32_t c : cells) qs_after += cell_shape_quality(c);
    if (qs_after / std::max<size_t>(1, cells.size()) <= qs_before) {
      restore(saved);
      return reject(&OptimizeReport::rejected_shape);
    }
    if (!accept(cells)) {
      restore(saved);
      return false;
    }
    return true;
  }

  const PolyMesh& src_;
  const std::vector<double>& h_ref_;
  OptimizeParams p_;
  EditableMesh m_;
  std::vector<double> thr_o_, thr_p_;
  std::vector<double> qs_;          // Q_S of each transition cell as the mesh is now
  std::vector<Vec3> centre_;        // OpenFOAM cell centres (geometric centroids), kept current
  std::vector<char> skew_ok_;       // per face: its skewness is within kSkewnessLimit, and must stay so
  std::vector<char> convex0_, centred0_;  // initial state: a control never makes a cell worse
  int collapsed_ = 0;
  long op_count_ = 0;                 // accepted operations so far
  std::vector<long> cell_stamp_;      // per cell: the accepted operation that last changed it
  std::map<std::pair<int32_t, int32_t>, std::pair<int, long>> refused_;  // edge -> (phase, op_count_)
  OptimizeReport* report_ = nullptr;

};

}  // namespace

std::vector<double> openfoam_face_skewness(const PolyMesh& mesh) {
  std::vector<Vec3> centre(mesh.n_cells());
  for (int c = 0; c < mesh.n_cells(); ++c) {
    std::vector<std::vector<int32_t>> outward;
    for (const int32_t* f = mesh.cell_begin(c); f != mesh.cell_end(c); ++f) {
      outward.emplace_back(mesh.face_begin(*f), mesh.face_end(*f));
      if (mesh.face_owner[*f] != c) std::reverse(outward.back().begin(), outward.back().end());
    }
    centre[c] = foam_cell_centre(mesh.nodes, outward);
  }
  std::vector<double> skew(mesh.n_faces());
  for (int f = 0; f < mesh.n_faces(); ++f) {
    Vec3 fc, fa;
    foam_face(mesh.nodes, mesh.face_begin(f), mesh.face_end(f), &fc, &fa);
    const int32_t n = mesh.face_neighbour[f];
    skew[f] = foam_skewness(mesh.nodes, mesh.face_begin(f), mesh.face_end(f), fc, fa, centre[mesh.face_owner[f]],
                            n >= 0 ? &centre[n] : nullptr);
  }
  return skew;
}

PolyMesh optimize_transition(const PolyMesh& mesh, const std::vector<double>& h_ref, const OptimizeParams& params,
                             OptimizeReport* report) {
  OptimizeReport rep;
  Optimizer opt(mesh, h_ref, params);
  rep.removed_below_g1 = opt.run_phase(0, params.gamma[0], &rep);
  rep.removed_below_g2 = opt.run_phase(1, params.gamma[1], &rep);
  rep.expanded = opt.run_phase(2, params.gamma[2], &rep);
  // The expansions move vertices, which frees some removals that were refused: one more
  // round of removal and expansion.
  rep.removed_below_g2 += opt.run_phase(1, params.gamma[1], &rep);
  rep.expanded += opt.run_phase(2, params.gamma[2], &rep);
  rep.skewness_removed = opt.run_skewness_phase(&rep);
  rep.skewed_faces = opt.skewed_faces(&rep.max_skewness);
  if (report) *report = rep;
  return opt.result();
}

}  // namespace hm
