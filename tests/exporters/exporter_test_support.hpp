// Shared helpers of the exporter tests: small meshes built with MeshBuilder, subprocesses with
// a timeout, temporary directories, checkMesh and flow runners, and a reference TPFA solve.
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

// Eigen is header-only and installed system-wide; this test target does not link Eigen3::Eigen,
// so it is included by its full path (the same headers).
#include <eigen3/Eigen/SparseCholesky>

#include "fvcheck/lib/transmissibility.hpp"
#include "meshgen/case/case.hpp"
#include "meshgen/core/geometry.hpp"
#include "meshgen/core/mesh_builder.hpp"
#include "meshgen/grids/reservoir_grid.hpp"
#include "meshgen/grids/well_block.hpp"

namespace hmtest {

namespace fs = std::filesystem;
using hm::Vec3;

// ---------------------------------------------------------------- processes and files

struct CommandResult {
  int exit_code = -1;
  bool timed_out = false;
  std::string output;  ///< stdout and stderr
};

inline std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

/// Runs `command` through /bin/sh under coreutils `timeout`, capturing stdout+stderr.
inline CommandResult run_command(const std::string& command, int timeout_s) {
  CommandResult r;
  const std::string full = "timeout " + std::to_string(timeout_s) + " sh -c " + shell_quote(command) + " 2>&1";
  FILE* p = popen(full.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
  const int status = pclose(p);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.timed_out = r.exit_code == 124;
  return r;
}

inline bool have_executable(const std::string& name) {
  return run_command("command -v " + name, 10).exit_code == 0;
}

/// A fresh empty directory under the system temp dir, removed at destruction.
struct TempDir {
  fs::path path;
  explicit TempDir(const std::string& tag) {
    std::random_device rd;
    path = fs::temp_directory_path() / ("hm_" + tag + "_" + std::to_string(rd()) + std::to_string(rd()));
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    if (std::getenv("HM_KEEP_TEST_OUTPUT") == nullptr) fs::remove_all(path, ec);
  }
  std::string str() const { return path.string(); }
};

inline std::string read_text(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

/// Every regular file under `root`, as paths relative to it, sorted.
inline std::vector<std::string> list_files(const fs::path& root) {
  std::vector<std::string> out;
  std::error_code ec;
  if (!fs::exists(root, ec)) return out;
  for (const auto& e : fs::recursive_directory_iterator(root))
    if (e.is_regular_file()) out.push_back(fs::relative(e.path(), root).string());
  std::sort(out.begin(), out.end());
  return out;
}

// ---------------------------------------------------------------- meshes

inline hm::CaseSpec box_case(std::vector<double> x, std::vector<double> y, std::vector<double> z) {
  hm::CaseSpec cs;
  cs.name = "box";
  cs.reservoir.x = std::move(x);
  cs.reservoir.y = std::move(y);
  cs.reservoir.z = std::move(z);
  cs.reservoir.permeability = {120, 80, 15};
  cs.reservoir.porosity = 0.25;
  cs.reservoir.initial_pressure = 200;
  return cs;
}

/// Every lattice cell of the case, as hexahedra (the grids module).
inline hm::PolyMesh build_box_mesh(const hm::CaseSpec& cs, hm::BuildReport* report) {
  const hm::ReservoirGrid grid = hm::make_reservoir_grid(cs.reservoir);
  hm::MeshBuilder b;
  const auto nodes = hm::add_reservoir_nodes(grid, b);
  hm::add_reservoir_cells(grid, cs.reservoir, nodes, std::vector<char>(grid.n_cells(), 1), b);
  return b.finish(report);
}

/// Adds a vertical well to the case through lattice node (i, j) (interior node), top to bottom.
inline void add_vertical_well(hm::CaseSpec& cs, const std::string& name, hm::WellType type, int i, int j, double bhp,
                              double half_diagonal) {
  hm::WellSpec w;
  w.name = name;
  w.type = type;
  w.trajectory = {{cs.reservoir.x[i], cs.reservoir.y[j], cs.reservoir.z.front()},
                  {cs.reservoir.x[i], cs.reservoir.y[j], cs.reservoir.z.back()}};
  w.radius = half_diagonal;
  w.bhp = bhp;
  cs.wells.push_back(w);
}

/// The lattice of the case in which every vertical well (trajectory through a lattice node, see
/// add_vertical_well) is a diamond-shaped hole of half-diagonal `radius` around that node: the 4
/// cells around the node lose their corner triangle (convex pentagonal prisms, region kWell,
/// no (i,j,k), so that the Eclipse layout must put them in extra columns) and the hole's walls
/// are wellbore faces of that well.
inline hm::PolyMesh build_box_with_vertical_wells(const hm::CaseSpec& cs, hm::BuildReport* report) {
  const auto& X = cs.reservoir.x;
  const auto& Y = cs.reservoir.y;
  const auto& Z = cs.reservoir.z;
  const int nx = static_cast<int>(X.size()) - 1, ny = static_cast<int>(Y.size()) - 1, nz = static_cast<int>(Z.size()) - 1;
  hm::MeshBuilder b;
  auto lattice = [&](int i, int j, int k) { return i + (nx + 1) * (j + (ny + 1) * k); };
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) b.add_node({X[i], Y[j], Z[k]});
  // Well nodes: the lattice node (i, j) of each well and its 4 hole nodes per level.
  std::map<std::pair<int, int>, int> well_at;
  std::vector<std::array<std::vector<int32_t>, 4>> hole(cs.wells.size());  // [w][dir][k], dir: +x, +y, -x, -y
  for (size_t w = 0; w < cs.wells.size(); ++w) {
    const Vec3 p = cs.wells[w].trajectory.front();
    const int i = static_cast<int>(std::find(X.begin(), X.end(), p.x) - X.begin());
    const int j = static_cast<int>(std::find(Y.begin(), Y.end(), p.y) - Y.begin());
    if (i <= 0 || i >= nx || j <= 0 || j >= ny) throw std::runtime_error("well not on an interior lattice node");
    well_at[{i, j}] = static_cast<int>(w);
    const double r = cs.wells[w].radius;
    const Vec3 d[4] = {{r, 0, 0}, {0, r, 0}, {-r, 0, 0}, {0, -r, 0}};
    for (int dir = 0; dir < 4; ++dir)
      for (int k = 0; k <= nz; ++k) hole[w][dir].push_back(b.add_node(Vec3{X[i], Y[j], Z[k]} + d[dir]));
  }
  auto dir_of = [](int di, int dj) { return di > 0 ? 0 : dj > 0 ? 1 : di < 0 ? 2 : 3; };
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        // CCW corners in (x, y); a corner at a well node becomes its two hole nodes.
        const int ci[4] = {i, i + 1, i + 1, i}, cj[4] = {j, j, j + 1, j + 1};
        std::vector<int32_t> lo, hi;   // polygon at z[k] and z[k+1]
        std::vector<int32_t> edge_patch;  // patch of the side face from polygon vertex e to e+1
        std::vector<Vec3> poly_xy;
        int well = -1;
        for (int c = 0; c < 4; ++c) {
          auto it = well_at.find({ci[c], cj[c]});
          if (it == well_at.end()) {
            lo.push_back(lattice(ci[c], cj[c], k));
            hi.push_back(lattice(ci[c], cj[c], k + 1));
            continue;
          }
          well = it->second;
          const int p = (c + 3) % 4, n = (c + 1) % 4;
          const int din = dir_of(ci[p] - ci[c], cj[p] - cj[c]), dout = dir_of(ci[n] - ci[c], cj[n] - cj[c]);
          lo.push_back(hole[well][din][k]);
          hi.push_back(hole[well][din][k + 1]);
          lo.push_back(hole[well][dout][k]);
          hi.push_back(hole[well][dout][k + 1]);
        }
        const int m = static_cast<int>(lo.size());
        for (int e = 0; e < m; ++e) poly_xy.push_back(b.node(lo[e]));
        std::vector<hm::CellFace> faces;
        auto on_outer = [&](Vec3 a, Vec3 c) {
          return (a.x == X.front() && c.x == X.front()) || (a.x == X.back() && c.x == X.back()) ||
                 (a.y == Y.front() && c.y == Y.front()) || (a.y == Y.back() && c.y == Y.back());
        };
        for (int e = 0; e < m; ++e) {
          const int e1 = (e + 1) % m;
          hm::CellFace f;
          f.nodes = {lo[e], lo[e1], hi[e1], hi[e]};
          const Vec3 a = b.node(lo[e]), c = b.node(lo[e1]);
          const bool wall = well >= 0 && a.x != c.x && a.y != c.y;  // the only diagonal edge
          f.patch = wall ? hm::wellbore_patch(well) : on_outer(a, c) ? hm::kOuterBoundary : hm::kInteriorFace;
          faces.push_back(f);
        }
        hm::CellFace top, bottom;
        top.nodes.assign(lo.rbegin(), lo.rend());  // normal -z (up, out of the cell)
        top.patch = k == 0 ? hm::kOuterBoundary : hm::kInteriorFace;
        bottom.nodes = hi;                         // normal +z
        bottom.patch = k == nz - 1 ? hm::kOuterBoundary : hm::kInteriorFace;
        faces.push_back(top);
        faces.push_back(bottom);
        // FV centre: the prism's centroid (polygon centroid, mid depth).
        double a2 = 0, cx = 0, cy = 0;
        for (int e = 0; e < m; ++e) {
          const Vec3 p = poly_xy[e], q = poly_xy[(e + 1) % m];
          const double cr = p.x * q.y - q.x * p.y;
          a2 += cr;
          cx += (p.x + q.x) * cr;
          cy += (p.y + q.y) * cr;
        }
        hm::CellAttributes at;
        at.fv_center = {cx / (3 * a2), cy / (3 * a2), 0.5 * (Z[k] + Z[k + 1])};
        at.perm = cs.reservoir.permeability;
        at.porosity = cs.reservoir.porosity;
        if (well >= 0) {
          at.region = hm::kWell;
        } else {
          at.region = hm::kReservoir;
          at.ijk = {i, j, k};
        }
        b.add_cell(faces, at);
      }
  return b.finish(report);
}

/// A box lattice with the cells around one radial well block removed, plus the block; the faces
/// the transition mesh would claim (block outer surface, cavity walls) are declared outer boundary.
/// Two disconnected pieces: fine for file-format tests, not for flow.
inline hm::PolyMesh build_box_with_radial_block(const hm::CaseSpec& cs, double clearance, hm::BuildReport* report) {
  const hm::ReservoirGrid grid = hm::make_reservoir_grid(cs.reservoir);
  hm::MeshBuilder b;
  const auto nodes = hm::add_reservoir_nodes(grid, b);
  const hm::WellBlock block = hm::make_well_block(cs, 0, cs.wells[0].sectors);
  Vec3 lo = block.nodes.front(), hi = block.nodes.front();
  for (const Vec3& p : block.nodes)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], p[a]);
      hi[a] = std::max(hi[a], p[a]);
    }
  std::vector<char> active(grid.n_cells(), 1);
  for (int c = 0; c < grid.n_cells(); ++c) {
    const Vec3 l = grid.cell_lo(c), h = grid.cell_hi(c);
    bool overlap = true;
    for (int a = 0; a < 3; ++a) overlap = overlap && l[a] < hi[a] + clearance && h[a] > lo[a] - clearance;
    if (overlap) active[c] = 0;
  }
  hm::add_reservoir_cells(grid, cs.reservoir, nodes, active, b);
  hm::add_well_block(block, b);
  hm::PolyMesh mesh = b.finish(report);
  for (int f = 0; f < mesh.n_faces(); ++f)
    if (mesh.face_patch[f] == hm::kUnmatchedFace) mesh.face_patch[f] = hm::kOuterBoundary;
  return mesh;
}

// ---------------------------------------------------------------- checkMesh

struct CheckMeshResult {
  bool ran = false;
  int exit_code = -1;
  bool mesh_ok = false;                 ///< a line "Mesh OK."
  std::vector<std::string> failures;    ///< lines starting with "***" (after indentation)
  long long cells = -1;                 ///< "cells:" count
  double total_volume = -1;             ///< "Total volume = "
  std::string output;
};

/// Runs checkMesh on a COPY of the case (it writes sets into constant/polyMesh).
inline CheckMeshResult run_check_mesh(const fs::path& case_dir, int timeout_s = 600) {
  CheckMeshResult r;
  TempDir copy("checkmesh");
  fs::copy(case_dir, copy.path / "case", fs::copy_options::recursive);
  const CommandResult c = run_command("WM_PROJECT_DIR=/usr/share/openfoam checkMesh -case " +
                                          shell_quote((copy.path / "case").string()),
                                      timeout_s);
  r.ran = !c.timed_out;
  r.exit_code = c.exit_code;
  r.output = c.output;
  std::istringstream in(c.output);
  std::string line;
  const std::regex cells_re(R"(^\s*cells:\s+(\d+))"), vol_re(R"(Total volume = ([0-9.eE+-]+))");
  std::smatch m;
  while (std::getline(in, line)) {
    // checkMesh indents its failure lines (" ***Error in face pyramids ...").
    const size_t first = line.find_first_not_of(" \t");
    if (first != std::string::npos && line.compare(first, 3, "***") == 0) r.failures.push_back(line);
    if (line.find("Mesh OK.") != std::string::npos) r.mesh_ok = true;
    if (std::regex_search(line, m, cells_re)) r.cells = std::stoll(m[1]);
    if (std::regex_search(line, m, vol_re)) r.total_volume = std::stod(m[1]);
  }
  return r;
}

// ---------------------------------------------------------------- reference TPFA solve

constexpr double kGravity = 9.80665;  // m/s2, as in OPM
constexpr double kBarPerPa = 1e-5;

struct TpfaSolution {
  std::vector<double> pressure;    ///< bar, per cell
  std::vector<double> well_rate;   ///< per well, rm3/day, production positive
};

/// Solves the steady equation of opm-flow-deck.md with the mesh's own transmissibilities:
/// sum_j T_ij/mu (p_i - p_j - rho g (z_i - z_j)) + CF/mu (p_i - (BHP + rho g (z_i - z_ref))) = 0
/// (z = FV centre depth, z_ref = first trajectory point), with a sparse Cholesky factorisation.
inline TpfaSolution reference_tpfa_solve(const hm::CaseSpec& cs, const hm::PolyMesh& mesh,
                                         const hm::Transmissibilities& trans) {
  const int n = mesh.n_cells();
  const double mu = cs.fluid.viscosity, rg = cs.fluid.density * kGravity * kBarPerPa;  // bar/m
  std::vector<Eigen::Triplet<double>> trip;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
  for (int f = 0; f < mesh.n_faces(); ++f) {
    const int i = mesh.face_owner[f], j = mesh.face_neighbour[f];
    if (j < 0) continue;
    const double t = trans.face[f] / mu;
    const double dz = mesh.cell_fv_center[i].z - mesh.cell_fv_center[j].z;
    trip.emplace_back(i, i, t);
    trip.emplace_back(j, j, t);
    trip.emplace_back(i, j, -t);
    trip.emplace_back(j, i, -t);
    rhs[i] += t * rg * dz;
    rhs[j] -= t * rg * dz;
  }
  const auto wells = hm::well_connection_factors(mesh, trans, static_cast<int>(cs.wells.size()));
  for (size_t w = 0; w < wells.size(); ++w)
    for (const auto& [c, cf] : wells[w]) {
      const double t = cf / mu;
      trip.emplace_back(c, c, t);
      rhs[c] += t * (cs.wells[w].bhp + rg * (mesh.cell_fv_center[c].z - cs.wells[w].trajectory.front().z));
    }
  Eigen::SparseMatrix<double> A(n, n);
  A.setFromTriplets(trip.begin(), trip.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(A);
  Eigen::VectorXd p = ldlt.solve(rhs);
  // One step of iterative refinement: the matrix mixes very different transmissibilities.
  p += ldlt.solve(rhs - A * p);
  TpfaSolution s;
  s.pressure.assign(p.data(), p.data() + n);
  s.well_rate.assign(wells.size(), 0.0);
  for (size_t w = 0; w < wells.size(); ++w)
    for (const auto& [c, cf] : wells[w])
      s.well_rate[w] += cf / mu *
                        (p[c] - (cs.wells[w].bhp + rg * (mesh.cell_fv_center[c].z - cs.wells[w].trajectory.front().z)));
  return s;
}

}  // namespace hmtest
