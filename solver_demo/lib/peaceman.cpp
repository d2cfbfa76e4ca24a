#include "peaceman.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>

#include "fvcheck/lib/transmissibility.hpp"

namespace hm {

namespace {
constexpr double kPi = 3.14159265358979323846;

int locate(const std::vector<double>& nodes, double v) {
  const int n = static_cast<int>(nodes.size()) - 1;
  if (v < nodes.front() || v > nodes.back()) return -1;
  const int i = static_cast<int>(std::upper_bound(nodes.begin(), nodes.end(), v) - nodes.begin()) - 1;
  return std::min(i, n - 1);
}
}  // namespace

CartesianMesh make_cartesian_mesh(const ReservoirSpec& spec) {
  CartesianMesh cm;
  cm.grid = make_reservoir_grid(spec);
  MeshBuilder b;
  const std::vector<int32_t> nodes = add_reservoir_nodes(cm.grid, b);
  cm.mesh_cell = add_reservoir_cells(cm.grid, spec, nodes, std::vector<char>(cm.grid.n_cells(), 1), b);
  BuildReport rep;
  cm.mesh = b.finish(&rep);
  if (!rep.ok) throw std::runtime_error("make_cartesian_mesh: the lattice did not assemble: " + rep.problems.at(0));
  cm.geo = compute_geometry(cm.mesh);
  return cm;
}

std::vector<TrajectoryInCell> trajectory_cells(const ReservoirGrid& grid, const std::vector<Vec3>& poly) {
  std::vector<TrajectoryInCell> out;
  std::map<int32_t, size_t> slot;
  for (size_t k = 0; k + 1 < poly.size(); ++k) {
    const Vec3 a = poly[k], ab = poly[k + 1] - poly[k];
    std::vector<double> ts = {0.0, 1.0};
    const std::vector<double>* axes[3] = {&grid.x, &grid.y, &grid.z};
    for (int d = 0; d < 3; ++d) {
      if (ab[d] == 0) continue;
      for (double c : *axes[d]) {
        const double t = (c - a[d]) / ab[d];
        if (t > 0 && t < 1) ts.push_back(t);
      }
    }
    std::sort(ts.begin(), ts.end());
    for (size_t i = 0; i + 1 < ts.size(); ++i) {
      if (!(ts[i + 1] > ts[i])) continue;
      const Vec3 piece = (ts[i + 1] - ts[i]) * ab;
      const Vec3 mid = a + (0.5 * (ts[i] + ts[i + 1])) * ab;
      const int ci = locate(grid.x, mid.x), cj = locate(grid.y, mid.y), ck = locate(grid.z, mid.z);
      if (ci < 0 || cj < 0 || ck < 0) continue;
      const int32_t c = grid.cell_index(ci, cj, ck);
      auto [it, fresh] = slot.try_emplace(c, out.size());
      if (fresh) out.push_back({c, {}, 0.0, {}});
      TrajectoryInCell& tc = out[it->second];
      const double len = norm(piece);
      tc.extent += Vec3{std::fabs(piece.x), std::fabs(piece.y), std::fabs(piece.z)};
      tc.midpoint = (tc.length * tc.midpoint + len * mid) / (tc.length + len);
      tc.length += len;
    }
  }
  return out;
}

double peaceman_radius(double d1, double d2, double k1, double k2) {
  const double r21 = std::sqrt(k2 / k1), r12 = std::sqrt(k1 / k2);
  return 0.28 * std::sqrt(r21 * d1 * d1 + r12 * d2 * d2) / (std::sqrt(r21) + std::sqrt(r12));
}

double peaceman_connection_factor(Vec3 size, Vec3 perm, Vec3 extent, double r_w) {
  double sum2 = 0;
  for (int d = 0; d < 3; ++d) {
    if (extent[d] == 0) continue;
    const int a = (d + 1) % 3, b = (d + 2) % 3;  // the two axes across a well along d
    const double r_o = peaceman_radius(size[a], size[b], perm[a], perm[b]);
    if (!(r_o > r_w))
      throw std::invalid_argument("Peaceman: equivalent radius " + std::to_string(r_o) + " m <= wellbore radius " +
                                  std::to_string(r_w) + " m (cell too small for the well)");
    const double wi = kDarcyMetric * 2 * kPi * std::sqrt(perm[a] * perm[b]) * extent[d] / std::log(r_o / r_w);
    sum2 += wi * wi;
  }
  return std::sqrt(sum2);
}

std::vector<WellConnection> peaceman_connections(const CartesianMesh& cm, const std::vector<Vec3>& polyline,
                                                 double r_w, int well) {
  std::vector<WellConnection> out;
  for (const TrajectoryInCell& tc : trajectory_cells(cm.grid, polyline)) {
    const int32_t c = cm.mesh_cell[tc.grid_cell];
    const Vec3 size = cm.grid.cell_hi(tc.grid_cell) - cm.grid.cell_lo(tc.grid_cell);
    out.push_back({well, c, peaceman_connection_factor(size, cm.mesh.cell_perm[c], tc.extent, r_w), tc.midpoint});
  }
  return out;
}

std::vector<WellConnection> peaceman_connections(const CartesianMesh& cm, const WellSpec& ws, int well) {
  return peaceman_connections(cm, ws.trajectory, ws.radius, well);
}

}  // namespace hm
