// Scaling of the whole meshing job: a 2240 x 2240 x 100 m reservoir of 20 layers with 10
// deviated wells, at three lateral resolutions (about 10k, 100k and 1M cells; the same wells).
// Each case runs in a child process (its own peak memory) and prints one row: the stages'
// seconds, peak resident memory (getrusage), cells per second, and the transition stage beside
// raw CGAL Regular_triangulation_3 + power cells on the same weighted sites (the internal sites
// of every cavity), in the same run. Usage: bench_scaling [LATERAL_CELLS ...] (default 22 71 224).
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_3.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "exporters/vtu/vtu_writer.hpp"
#include "fvcheck/lib/checks.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

std::vector<double> lattice(double lo, double hi, int n) {
  std::vector<double> v(n + 1);
  for (int i = 0; i <= n; ++i) v[i] = lo + (hi - lo) * i / n;
  return v;
}

hm::CaseSpec scaling_case(int lateral) {
  hm::CaseSpec cs;
  cs.name = "scaling_" + std::to_string(lateral);
  cs.reservoir.x = lattice(0, 2240, lateral);
  cs.reservoir.y = lattice(0, 2240, lateral);
  cs.reservoir.z = lattice(2000, 2100, 20);
  for (int k = 0; k < 10; ++k) {
    hm::WellSpec w;
    w.name = "W" + std::to_string(k + 1);
    const double x = 320 + 400 * (k % 5), y = 620 + 1000 * (k / 5);
    // Deviated: 60 m of horizontal offset over 60 m of depth, alternating directions.
    const double dx = k % 2 ? 40 : -40, dy = k % 3 ? 45 : -45;
    w.trajectory = {{x, y, 2020}, {x + dx, y + dy, 2080}};
    w.radius = 0.1;
    w.drainage_radius = 6;
    w.rings = 6;
    w.sectors = 12;
    cs.wells.push_back(w);
  }
  return cs;
}

// Raw CGAL on the same sites: the regular triangulation of the internal sites of all
// cavities (weights as built) plus every power vertex (weighted circumcentre of each finite
// cell) and every power face (one per finite edge, circulating its cells).
double raw_cgal_seconds(const std::vector<std::pair<hm::Vec3, double>>& sites, long* faces) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using RT = CGAL::Regular_triangulation_3<K>;
  const Clock::time_point t0 = Clock::now();
  std::vector<K::Weighted_point_3> pts;
  pts.reserve(sites.size());
  for (const auto& [p, w] : sites) pts.emplace_back(K::Point_3(p.x, p.y, p.z), w * w);
  RT rt(pts.begin(), pts.end());
  std::vector<K::Point_3> centres;
  for (auto c : rt.finite_cell_handles()) centres.push_back(rt.dual(c));
  long n = 0, corners = 0;
  for (auto e : rt.finite_edges()) {
    auto circ = rt.incident_cells(e), done = circ;
    int k = 0;
    do ++k;
    while (++circ != done);
    corners += k;
    ++n;
  }
  *faces = n;
  if (corners < 3 * n || centres.empty()) *faces = -1;  // every face has >= 3 corners: uses the work
  return since(t0);
}

void run_case(int lateral) {
  const hm::CaseSpec cs = scaling_case(lateral);
  const Clock::time_point t0 = Clock::now();
  hm::HybridMesh h;
  try {
    h = hm::build_hybrid_mesh(cs);
  } catch (const std::exception& e) {
    std::printf("%-8d failed: %s\n", lateral, e.what());
    return;
  }
  const double mesh_s = since(t0);
  Clock::time_point t1 = Clock::now();
  // The checks fvcheck runs (the self-check of a written mesh).
  bool ok = true;
  for (const hm::CheckResult& r :
       {hm::check_convexity(h.mesh, h.geometry), hm::check_conformity(h.mesh, h.geometry, {}, &h.build_report),
        hm::check_closure(h.mesh, h.geometry), hm::check_volume(h.mesh, h.geometry),
        hm::check_orthogonality(h.mesh, h.geometry), hm::check_auto_centering(h.mesh, h.geometry),
        hm::check_planarity(h.mesh, h.geometry)})
    ok = ok && r.ok();
  const double check_s = since(t1);
  t1 = Clock::now();
  const std::string vtu = (std::filesystem::temp_directory_path() / ("hm_bench_" + std::to_string(getpid()) + ".vtu")).string();
  const hm::WriteStatus st = hm::write_vtu(vtu, h.mesh);
  const double vtu_s = since(t1);
  std::error_code ec;
  const double vtu_mb = static_cast<double>(std::filesystem::file_size(vtu, ec)) / 1e6;
  std::filesystem::remove(vtu, ec);
  double transition_s = 0, optimize_s = 0;
  int tcells = 0;
  for (const hm::TransitionReport& r : h.transition_reports)
    transition_s += r.seconds_delaunay + r.seconds_sites + r.seconds_power, optimize_s += r.seconds_optimize;
  // The same sites again (the transition meshes are deterministic) for raw CGAL.
  std::vector<std::pair<hm::Vec3, double>> sites;
  for (const hm::Cavity& cav : h.cavities.cavities) {
    hm::TransitionCells t = hm::build_transition(cav, h.cavity_node_coords, h.grid, h.blocks,
                                                 static_cast<int32_t>(h.cavity_node_coords.size()));
    tcells += static_cast<int>(t.cells.size());
    for (size_t c = 0; c < t.sites.size(); ++c) sites.push_back({t.sites[c], t.weights[c]});
  }
  long raw_faces = 0;
  const double raw_s = raw_cgal_seconds(sites, &raw_faces);
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  const double total = mesh_s + check_s + vtu_s;
  std::printf("%-8d %9d %6d %8.2f %8.2f %8.2f %8.2f %8.2f %7.2f %7.2f %8.2f %8.0f %9.0f %8.3f %s%s\n", lateral,
              h.mesh.n_cells(), tcells, mesh_s, transition_s, optimize_s, check_s, vtu_s, vtu_mb / 1e3, total,
              static_cast<double>(ru.ru_maxrss) / 1024.0, h.mesh.n_cells() / total, static_cast<double>(sites.size()),
              raw_s, ok ? "" : "checks FAILED ", st.ok ? "" : st.message.c_str());
  for (const auto& [stage, s] : h.timings_s) std::printf("         stage %-26s %8.2f s\n", stage.c_str(), s);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> laterals;
  for (int i = 1; i < argc; ++i) laterals.push_back(std::atoi(argv[i]));
  if (laterals.empty()) laterals = {22, 71, 224};
  std::printf("2240 x 2240 x 100 m, 20 layers, 10 deviated wells (R 6 m, 12 sectors, 6 rings); wall seconds; "
              "transition/optimise: summed over cavities (run in parallel)\n");
  std::printf("%-8s %9s %6s %8s %8s %8s %8s %8s %7s %7s %8s %8s %9s %8s\n", "lateral", "cells", "trans", "mesh_s",
              "trans_s", "optim_s", "check_s", "vtu_s", "vtu_GB", "total_s", "peak_MB", "cells/s", "rawsites",
              "rawCGAL_s");
  std::fflush(stdout);
  for (int n : laterals) {
    const pid_t pid = fork();
    if (pid == 0) {
      run_case(n);
      std::fflush(stdout);
      std::_Exit(0);
    }
    int status = 0;
    waitpid(pid, &status, 0);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) std::printf("%-8d crashed (status %d)\n", n, status);
  }
  return 0;
}
