#include "corner_point_straighten.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <limits>
#include <optional>

namespace hm {

namespace {

constexpr double kDegree = M_PI / 180.0;
// (s, t) of a point found in a bilinear quad may stray this far outside [0, 1] (rounding on an edge).
constexpr double kQuadEdge = 1e-9;

// (s, t) with bilinear(q, s, t) = (x, y) in plan, q in the order 00, 10, 01, 11; Newton from the
// centre. False when it does not converge to a finite point.
bool inverse_bilinear(const std::array<Vec3, 4>& q, double x, double y, double& s, double& t) {
  s = t = 0.5;
  for (int it = 0; it < 40; ++it) {
    const double w0 = (1 - s) * (1 - t), w1 = s * (1 - t), w2 = (1 - s) * t, w3 = s * t;
    const double px = w0 * q[0].x + w1 * q[1].x + w2 * q[2].x + w3 * q[3].x - x;
    const double py = w0 * q[0].y + w1 * q[1].y + w2 * q[2].y + w3 * q[3].y - y;
    const double xs = (1 - t) * (q[1].x - q[0].x) + t * (q[3].x - q[2].x), ys = (1 - t) * (q[1].y - q[0].y) + t * (q[3].y - q[2].y);
    const double xt = (1 - s) * (q[2].x - q[0].x) + s * (q[3].x - q[1].x), yt = (1 - s) * (q[2].y - q[0].y) + s * (q[3].y - q[1].y);
    const double det = xs * yt - xt * ys;
    if (!(std::abs(det) > 0)) return false;
    const double ds = (px * yt - py * xt) / det, dt = (xs * py - ys * px) / det;
    s -= ds, t -= dt;
    if (std::abs(ds) + std::abs(dt) < 1e-14) break;
  }
  return std::isfinite(s) && std::isfinite(t);
}

double bilinear(const std::array<double, 4>& v, double s, double t) {
  return (1 - s) * (1 - t) * v[0] + s * (1 - t) * v[1] + (1 - s) * t * v[2] + s * t * v[3];
}

int pillar_id(const CornerPointModel& m, int I, int J) { return I + (m.nx + 1) * J; }
size_t cell_id(const CornerPointModel& m, int I, int J, int k) { return I + size_t(m.nx) * (J + size_t(m.ny) * k); }

// Plan lean of pillar p: horizontal displacement per metre of depth.
std::array<double, 2> lean_of(const CornerPointModel& m, int p) {
  const double* a = &m.coord[6 * size_t(p)];
  const double dz = a[5] - a[2];
  if (dz == 0) return {0, 0};
  return {(a[3] - a[0]) / dz, (a[4] - a[1]) / dz};
}

double plan_distance_to_path(Vec3 x, const std::vector<Vec3>& path) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k + 1 < path.size(); ++k) {
    const double ax = path[k].x, ay = path[k].y, bx = path[k + 1].x - ax, by = path[k + 1].y - ay;
    const double len2 = bx * bx + by * by;
    const double u = len2 > 0 ? std::clamp(((x.x - ax) * bx + (x.y - ay) * by) / len2, 0.0, 1.0) : 0.0;
    best = std::min(best, std::hypot(x.x - ax - u * bx, x.y - ay - u * by));
  }
  if (path.size() == 1) best = std::hypot(x.x - path[0].x, x.y - path[0].y);
  return best;
}

// Where a search in the model's columns stopped.
enum class Walk { Found, Fault, Outside, Lost };

// The depth at plan point (x, y) of the top (side 0) or bottom (side 4) surface of layer k, made of
// its cells' bilinear faces: a walk through the columns from (I, J). A step across a column edge
// whose two corners differ between the columns is a fault.
Walk surface_depth(const CornerPointModel& m, int k, int side, double x, double y, int& I, int& J, double& z) {
  for (int step = 0; step < 2 * (m.nx + m.ny) + 4; ++step) {
    const size_t c = cell_id(m, I, J, k);
    std::array<Vec3, 4> q;
    std::array<double, 4> depth;
    for (int a = 0; a < 4; ++a) q[a] = corner(m, c, side | a), depth[a] = q[a].z;
    double s = 0, t = 0;
    if (!inverse_bilinear(q, x, y, s, t)) return Walk::Lost;
    const int di = s < -kQuadEdge ? -1 : s > 1 + kQuadEdge ? 1 : 0;
    const int dj = t < -kQuadEdge ? -1 : t > 1 + kQuadEdge ? 1 : 0;
    if (di == 0 && dj == 0) {
      z = bilinear(depth, s, t);
      return Walk::Found;
    }
    // One axis at a time, the one the point is further out along.
    const bool along_i = di != 0 && (dj == 0 || std::max(-s, s - 1) >= std::max(-t, t - 1));
    const int ni = along_i ? I + di : I, nj = along_i ? J : J + dj;
    if (ni < 0 || nj < 0 || ni >= m.nx || nj >= m.ny) return Walk::Outside;
    // The shared edge's two corners, as each column has them.
    for (int e = 0; e < 2; ++e) {
      const int here = along_i ? (di > 0 ? 1 : 0) | (e << 1) : (dj > 0 ? 2 : 0) | e;
      const int there = along_i ? (di > 0 ? 0 : 1) | (e << 1) : (dj > 0 ? 0 : 2) | e;
      if (m.zcorn[zcorn_index(m, I, J, k, side | here)] != m.zcorn[zcorn_index(m, ni, nj, k, side | there)])
        return Walk::Fault;
    }
    I = ni, J = nj;
  }
  return Walk::Lost;
}

// The column whose pillar quad at depth p.z holds p in plan, walking from (I, J).
Walk locate_column(const CornerPointModel& m, Vec3 p, int& I, int& J) {
  for (int step = 0; step < 2 * (m.nx + m.ny) + 4; ++step) {
    std::array<Vec3, 4> q;
    for (int a = 0; a < 4; ++a) q[a] = pillar_point(m, pillar_id(m, I + (a & 1), J + (a >> 1)), p.z);
    double s = 0, t = 0;
    if (!inverse_bilinear(q, p.x, p.y, s, t)) return Walk::Lost;
    const int di = s < -kQuadEdge ? -1 : s > 1 + kQuadEdge ? 1 : 0;
    const int dj = t < -kQuadEdge ? -1 : t > 1 + kQuadEdge ? 1 : 0;
    if (di == 0 && dj == 0) return Walk::Found;
    const int ni = std::clamp(I + di, 0, m.nx - 1), nj = std::clamp(J + dj, 0, m.ny - 1);
    if (ni == I && nj == J) return Walk::Outside;
    I = ni, J = nj;
  }
  return Walk::Lost;
}

std::string walk_reason(Walk w) {
  switch (w) {
    case Walk::Fault: return "a fault (ZCORN not continuous across a column edge) lies in its region";
    case Walk::Outside: return "its region reaches the model's side";
    default: return "a layer's surface could not be followed along a turned pillar";
  }
}

// Where a request turns the pillars: the pivot depth and each pillar's weight (1 within reach,
// 0 beyond the blend; empty when the pillars are left as they are).
struct Plan {
  double pivot = 0;
  std::vector<double> weight;
};

// The lean of the pillars within reach (or of the nearest one where none is: coarse columns) and
// the sharpest angle between a column's i-wall and j-wall there (planes through a pillar and its
// next pillar along j, resp. along i): 90 degrees for vertical pillars or pillars leaning along a
// grid axis.
void measure_lean(const CornerPointModel& m, const StraightenRequest& req, double pivot, StraightenOutcome& out) {
  double max_lean = 0, nearest = std::numeric_limits<double>::infinity(), nearest_lean = 0, sharpest = 90;
  for (int J = 0; J <= m.ny; ++J)
    for (int I = 0; I <= m.nx; ++I) {
      const int p = pillar_id(m, I, J);
      const auto l = lean_of(m, p);
      const Vec3 x = pillar_point(m, p, pivot);
      const double d = plan_distance_to_path(x, req.path);
      if (d < nearest) nearest = d, nearest_lean = std::hypot(l[0], l[1]);
      if (d > req.reach) continue;
      max_lean = std::max(max_lean, std::hypot(l[0], l[1]));
      if (I == m.nx || J == m.ny) continue;
      const Vec3 a = pillar_point(m, p, pivot + 1) - x;
      const Vec3 ni = cross(a, pillar_point(m, pillar_id(m, I, J + 1), pivot) - x);
      const Vec3 nj = cross(a, pillar_point(m, pillar_id(m, I + 1, J), pivot) - x);
      sharpest = std::min(sharpest, std::acos(std::min(1.0, std::abs(dot(ni, nj)) / (norm(ni) * norm(nj)))) / kDegree);
    }
  out.max_lean_deg = std::atan(nearest > req.reach ? nearest_lean : max_lean) / kDegree;
  out.wall_angle_deg = sharpest;
}

// The blend: lean x dz / kStraightenShearPerWidth, dz the largest depth distance from the pivot to a
// corner of the region's cells (the region from the range near the path first, then from that
// region's own range).
double blend_length(const CornerPointModel& m, const StraightenRequest& req, double pivot, double lean_deg) {
  double blend = 0;
  for (int pass = 0; pass < 2; ++pass) {
    double top = pivot, bottom = pivot;
    for (int J = 0; J < m.ny; ++J)
      for (int I = 0; I < m.nx; ++I) {
        if (plan_distance_to_path(pillar_point(m, pillar_id(m, I, J), pivot), req.path) > req.reach + blend) continue;
        for (int k = 0; k < m.nz; ++k)
          for (int q = 0; q < 8; ++q) {
            const double z = m.zcorn[zcorn_index(m, I, J, k, q)];
            top = std::min(top, z), bottom = std::max(bottom, z);
          }
      }
    blend = std::tan(lean_deg * kDegree) * std::max(pivot - top, bottom - pivot) / kStraightenShearPerWidth;
  }
  return blend;
}

Plan plan_request(const CornerPointModel& m, const StraightenRequest& req, double zmin, double zmax, StraightenOutcome& out) {
  Plan plan;
  if (req.path.empty()) return plan;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Vec3& x : req.path) lo = std::min(lo, x.z), hi = std::max(hi, x.z);
  // The middle of the path's depth range inside the model's.
  plan.pivot = 0.5 * (std::clamp(lo, zmin, zmax) + std::clamp(hi, zmin, zmax));
  measure_lean(m, req, plan.pivot, out);
  const bool turn = req.any_lean ? out.max_lean_deg > kUprightMinLean : out.wall_angle_deg < kStraightenWallAngleBelow;
  if (!turn) return plan;
  out.blend = blend_length(m, req, plan.pivot, out.max_lean_deg);
  plan.weight.assign((m.nx + 1) * (m.ny + 1), 0.0);
  for (size_t p = 0; p < plan.weight.size(); ++p) {
    const double d = plan_distance_to_path(pillar_point(m, static_cast<int>(p), plan.pivot), req.path);
    plan.weight[p] = d <= req.reach ? 1.0 : std::max(0.0, 1.0 - (d - req.reach) / out.blend);
  }
  return plan;
}

// One request's turned pillars and re-gridded cells; `refused` says why not.
struct Regrid {
  std::map<int, std::array<double, 6>> coord;     // pillar -> new COORD line
  std::map<std::array<int, 3>, double> depth;     // (pillar, k, side) -> depth on the turned pillar
  std::map<size_t, std::array<double, 8>> zcorn;  // cell -> new depths
  std::map<size_t, size_t> source;                // cell -> model cell its centre lies in
  std::string refused;
};

// Turned pillars: through their point at the pivot depth, lean scaled by 1 - weight.
void turn_pillars(const CornerPointModel& m, const Plan& plan, Regrid& g) {
  for (size_t p = 0; p < plan.weight.size(); ++p) {
    const double* a = &m.coord[6 * p];
    if (!(plan.weight[p] > 0) || a[5] == a[2]) continue;
    const auto l = lean_of(m, static_cast<int>(p));
    const Vec3 x0 = pillar_point(m, static_cast<int>(p), plan.pivot);
    const double f = 1.0 - plan.weight[p];
    g.coord[static_cast<int>(p)] = {x0.x + f * l[0] * (a[2] - plan.pivot), x0.y + f * l[1] * (a[2] - plan.pivot), a[2],
                                    x0.x + f * l[0] * (a[5] - plan.pivot), x0.y + f * l[1] * (a[5] - plan.pivot), a[5]};
  }
}

// Each turned pillar's depth on each layer's top and bottom surface, once per pillar so that every
// cell around it has the same corner: a fixed point of "the surface's depth below the pillar's
// point at this depth". The cells around the pillar must agree on its corner (no fault along it).
void layer_depths(const CornerPointModel& m, Regrid& g) {
  for (const auto& [p, line] : g.coord) {
    const int pi = p % (m.nx + 1), pj = p / (m.nx + 1);
    for (int k = 0; k < m.nz; ++k)
      for (int side : {0, 4}) {
        std::optional<double> z0;
        for (int a = 0; a < 4; ++a) {
          const int I = pi - 1 + (a & 1), J = pj - 1 + (a >> 1);
          if (I < 0 || J < 0 || I >= m.nx || J >= m.ny) continue;
          const double zc = m.zcorn[zcorn_index(m, I, J, k, side | (a & 1 ? 0 : 1) | (a & 2 ? 0 : 2))];
          if (z0 && *z0 != zc) return void(g.refused = walk_reason(Walk::Fault));
          z0 = zc;
        }
        int I = std::min(pi, m.nx - 1), J = std::min(pj, m.ny - 1);
        double z = *z0;
        bool converged = false;
        for (int it = 0; it < 100 && !converged; ++it) {
          const double u = (z - line[2]) / (line[5] - line[2]);
          double zn = 0;
          const Walk w = surface_depth(m, k, side, line[0] + u * (line[3] - line[0]), line[1] + u * (line[4] - line[1]), I, J, zn);
          if (w != Walk::Found) return void(g.refused = walk_reason(w));
          converged = std::abs(zn - z) <= 1e-12 * (1.0 + std::abs(zn));
          z = zn;
        }
        if (!converged) return void(g.refused = walk_reason(Walk::Lost));
        g.depth[{p, k, side}] = z;
      }
  }
}

// Cells with a turned pillar: their depths, and the model cell their centre lies in. x and y
// multipliers act on the model's faces, which the re-gridded cells no longer follow: refused.
void regrid_cells(const CornerPointModel& m, Regrid& g) {
  auto point = [&](int p, double z) {
    const auto it = g.coord.find(p);
    if (it == g.coord.end()) return pillar_point(m, p, z);
    const auto& l = it->second;
    const double u = (z - l[2]) / (l[5] - l[2]);
    return Vec3{l[0] + u * (l[3] - l[0]), l[1] + u * (l[4] - l[1]), z};
  };
  for (int k = 0; k < m.nz; ++k)
    for (int J = 0; J < m.ny; ++J)
      for (int I = 0; I < m.nx; ++I) {
        std::array<double, 8> zc;
        bool any = false;
        Vec3 centre{0, 0, 0};
        for (int q = 0; q < 8; ++q) {
          const int p = pillar_id(m, I + (q & 1), J + ((q >> 1) & 1));
          const auto it = g.depth.find({p, k, q & 4});
          any = any || it != g.depth.end();
          zc[q] = it != g.depth.end() ? it->second : m.zcorn[zcorn_index(m, I, J, k, q)];
          centre += point(p, zc[q]) / 8.0;
        }
        if (!any) continue;
        for (int q = 0; q < 4; ++q)
          if (zc[q] > zc[q | 4]) return void(g.refused = "a turned pillar meets a layer's top below its bottom");
        int si = I, sj = J;
        if (const Walk w = locate_column(m, centre, si, sj); w != Walk::Found) return void(g.refused = walk_reason(w));
        const size_t c = cell_id(m, I, J, k), s = cell_id(m, si, sj, k);
        for (int d = 0; d < 4; ++d)
          if (!m.trans_mult[d].empty() && (m.trans_mult[d][c] != 1.0 || m.trans_mult[d][s] != 1.0))
            return void(g.refused = "an x or y transmissibility multiplier (MULTX..MULTY-, FAULTS) acts in its region");
        g.zcorn[c] = zc;
        g.source[c] = s;
      }
}

// The re-gridding written into `res`: COORD of the turned pillars and ZCORN (the corners, computed from
// them, move on the turned pillars only), and each cell's rock and parent from its source cell.
void apply_regrid(const CornerPointModel& m, const Regrid& g, CornerPointModel& res) {
  for (const auto& [p, line] : g.coord) std::copy(line.begin(), line.end(), &res.coord[6 * size_t(p)]);
  for (const auto& [c, zc] : g.zcorn) {
    const int I = static_cast<int>(c % m.nx), J = static_cast<int>((c / m.nx) % m.ny), k = static_cast<int>(c / (size_t(m.nx) * m.ny));
    for (int q = 0; q < 8; ++q) res.zcorn[zcorn_index(m, I, J, k, q)] = zc[q];
  }
  for (const auto& [c, s] : g.source) {
    res.actnum[c] = m.actnum[s];
    res.permx[c] = m.permx[s], res.permy[c] = m.permy[s], res.permz[c] = m.permz[s];
    res.poro[c] = m.poro[s], res.ntg[c] = m.ntg[s];
    res.parent_cell[c] = m.parent_cell.empty() ? static_cast<int32_t>(s) : m.parent_cell[s];
    if (!m.pore_volume_mult.empty()) res.pore_volume_mult[c] = m.pore_volume_mult[s];
    for (int d = 4; d < 6; ++d)
      if (!m.trans_mult[d].empty()) res.trans_mult[d][c] = m.trans_mult[d][s];
  }
}

}  // namespace

CornerPointModel straightened_model(const CornerPointModel& m, const std::vector<StraightenRequest>& requests,
                                    std::vector<StraightenOutcome>* outcomes) {
  std::vector<StraightenOutcome> out(requests.size());
  double zmin = std::numeric_limits<double>::infinity(), zmax = -zmin;
  for (double z : m.zcorn) zmin = std::min(zmin, z), zmax = std::max(zmax, z);
  std::vector<Plan> plans;
  std::vector<int> owner((m.nx + 1) * (m.ny + 1), -1);
  for (size_t r = 0; r < requests.size(); ++r) {
    plans.push_back(plan_request(m, requests[r], zmin, zmax, out[r]));
    for (size_t p = 0; p < plans[r].weight.size(); ++p) {
      if (!(plans[r].weight[p] > 0)) continue;
      if (owner[p] >= 0) out[r].refused = out[owner[p]].refused = "its region overlaps another well's";
      owner[p] = static_cast<int>(r);
    }
  }
  std::optional<CornerPointModel> res;
  for (size_t r = 0; r < requests.size(); ++r) {
    if (plans[r].weight.empty() || !out[r].refused.empty()) continue;
    Regrid g;
    turn_pillars(m, plans[r], g);
    layer_depths(m, g);
    if (g.refused.empty()) regrid_cells(m, g);
    if (!g.refused.empty()) {
      out[r].refused = g.refused;
      continue;
    }
    if (!res) {
      res = m;
      if (res->parent_cell.empty()) {
        res->parent_cell.resize(m.n_cells());
        for (size_t c = 0; c < m.n_cells(); ++c) res->parent_cell[c] = static_cast<int32_t>(c);
        res->parent_nx = m.nx, res->parent_ny = m.ny;
      }
      res->opm_volume.clear();
    }
    apply_regrid(m, g, *res);
    out[r].straightened = true;
    out[r].pillars = static_cast<int>(g.coord.size());
  }
  if (outcomes) *outcomes = std::move(out);
  if (!res) return m;
  return std::move(*res);
}

}  // namespace hm
