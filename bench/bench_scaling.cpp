// Scaling of the whole meshing job: a 2240 x 2240 x 100 m reservoir of 20 layers with 10
// deviated wells, at three lateral resolutions (about 10k, 100k and 1M cells; the same wells).
// Each case runs in a child process (its own peak memory) and prints one row: the stages'
// seconds (wall and CPU), peak resident memory of each stage, cells per second, the transition
// stage beside raw CGAL Regular_triangulation_3 + power cells on the same weighted sites (the
// internal sites of every cavity) in the same run, and fvcheck (the executable) on the written
// VTU. Usage: bench_scaling [LATERAL_CELLS ...] (default 22 70 224: about 10k, 100k, 1M cells).
// bench_scaling --per-well [LATERAL_CELLS ...] (default 80 112 160 224, 128k-1M cells): cells of
// 10 m at every size, each size without wells and with the ten wells; per stage, the CPU time per
// reservoir cell and the time each well adds (the issue's "time added per well independent of the
// reservoir size").
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_3.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "scaling_case.hpp"
#include "exporters/vtu/vtu_writer.hpp"
#include "meshgen/core/malloc_tunables.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

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

// Resources of the stage that just ended: wall, CPU (user + system, every thread) and peak
// resident memory. The peak is VmHWM, reset at each stage end (write "5" to
// /proc/self/clear_refs), so each stage gets its own peak.
struct StageUse {
  std::string stage;
  double wall = 0, cpu = 0, peak_mb = 0;
};

double cpu_seconds() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return ru.ru_utime.tv_sec + ru.ru_stime.tv_sec + 1e-6 * (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

double peak_mb_and_reset() {
  double kb = 0;
  if (FILE* f = std::fopen("/proc/self/status", "r")) {
    char line[256];
    while (std::fgets(line, sizeof line, f))
      if (std::strncmp(line, "VmHWM:", 6) == 0) kb = std::atof(line + 6);
    std::fclose(f);
  }
  if (FILE* f = std::fopen("/proc/self/clear_refs", "w")) {
    std::fputs("5", f);
    std::fclose(f);
  }
  return kb / 1024.0;
}

class StageMeter {
 public:
  StageMeter() { peak_mb_and_reset(); }
  void mark(const std::string& stage) {
    const Clock::time_point now = Clock::now();
    const double cpu = cpu_seconds();
    uses.push_back({stage, std::chrono::duration<double>(now - wall_).count(), cpu - cpu_, peak_mb_and_reset()});
    wall_ = Clock::now();
    cpu_ = cpu_seconds();
  }
  std::vector<StageUse> uses;

 private:
  Clock::time_point wall_ = Clock::now();
  double cpu_ = cpu_seconds();
};

// fvcheck on the written file, as its own process: wall seconds, CPU and peak memory (wait4).
StageUse run_fvcheck_binary(const std::string& vtu, bool* ok) {
  StageUse u{"fvcheck (own process)"};
  const Clock::time_point t0 = Clock::now();
  const pid_t pid = fork();
  if (pid == 0) {
    if (!std::freopen("/dev/null", "w", stdout)) std::_Exit(3);
    execl(HM_FVCHECK, HM_FVCHECK, vtu.c_str(), static_cast<char*>(nullptr));
    std::_Exit(127);
  }
  int status = 0;
  rusage ru{};
  wait4(pid, &status, 0, &ru);
  u.wall = since(t0);
  u.cpu = ru.ru_utime.tv_sec + ru.ru_stime.tv_sec + 1e-6 * (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
  u.peak_mb = static_cast<double>(ru.ru_maxrss) / 1024.0;
  *ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
  return u;
}

// Where a run writes its VTU (removed after it).
std::string scratch_vtu_path() {
  return (std::filesystem::temp_directory_path() / ("hm_bench_" + std::to_string(getpid()) + ".vtu")).string();
}

// Seconds of the transition builds (Delaunay + sites + power diagram) and of the optimisation, summed
// over the cavities: each cavity runs on one thread, so the sums are CPU seconds.
void transition_seconds(const hm::HybridMesh& h, double* build_s, double* optimize_s) {
  *build_s = *optimize_s = 0;
  for (const hm::TransitionReport& r : h.transition_reports)
    *build_s += r.seconds_delaunay + r.seconds_sites + r.seconds_power, *optimize_s += r.seconds_optimize;
}

void run_case(int lateral) {
  const hm::CaseSpec cs = hm::bench::scaling_case(lateral);
  StageMeter meter;
  hm::PipelineOptions opts;
  opts.on_stage = [&](const std::string& stage) { meter.mark(stage); };
  const Clock::time_point t0 = Clock::now();
  const double cpu0 = cpu_seconds();
  hm::HybridMesh h;
  try {
    h = hm::build_hybrid_mesh(cs, opts);  // its last stage is the self-check
  } catch (const std::exception& e) {
    std::printf("%-8d failed: %s\n", lateral, e.what());
    return;
  }
  const double mesh_s = since(t0);
  Clock::time_point t1 = Clock::now();
  const std::string vtu = scratch_vtu_path();
  const hm::WriteStatus st = hm::write_vtu(vtu, h.mesh);
  const double vtu_s = since(t1);
  meter.mark("write_vtu");
  const double total = mesh_s + vtu_s, total_cpu = cpu_seconds() - cpu0;
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  const double peak = static_cast<double>(ru.ru_maxrss) / 1024.0;  // whole job: mesh + self-check + VTU
  std::error_code ec;
  const double vtu_mb = static_cast<double>(std::filesystem::file_size(vtu, ec)) / 1e6;
  bool fv_ok = false;
  const StageUse fv = run_fvcheck_binary(vtu, &fv_ok);
  if (std::getenv("HM_BENCH_KEEP_VTU")) std::printf("         kept %s\n", vtu.c_str());  // for profiling fvcheck
  else std::filesystem::remove(vtu, ec);
  double transition_s = 0, optimize_s = 0, check_s = 0;
  int tcells = 0;
  transition_seconds(h, &transition_s, &optimize_s);
  for (const auto& [stage, s] : h.timings_s)
    if (stage == "self_check") check_s = s;
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
  std::printf("%-8d %9d %6d %8.2f %8.2f %8.2f %8.2f %8.2f %7.3f %7.2f %7.2f %8.0f %9.0f %6.0f %8.3f %7.2f %7.0f %s%s%s\n",
              lateral, h.mesh.n_cells(), tcells, mesh_s, transition_s, optimize_s, check_s, vtu_s, vtu_mb / 1e3,
              total, total_cpu, peak, h.mesh.n_cells() / total, static_cast<double>(sites.size()), raw_s, fv.wall,
              fv.peak_mb, st.ok ? "" : st.message.c_str(), fv_ok ? "" : " fvcheck FAILED",
              raw_faces < 0 ? " raw CGAL: no faces" : "");
  for (const StageUse& u : meter.uses)
    std::printf("         stage %-26s wall %7.2f s  cpu %7.2f s  peak %7.0f MB\n", u.stage.c_str(), u.wall, u.cpu,
                u.peak_mb);
  std::printf("         stage %-26s wall %7.2f s  cpu %7.2f s  peak %7.0f MB\n", fv.stage.c_str(), fv.wall, fv.cpu,
              fv.peak_mb);
  std::fflush(stdout);
}

// One run of `cs` (mesh + optimise + self-check + VTU) in a child process, for the per-well table:
// the stages' wall, CPU and peak as the child measured them, sent back through a pipe.
struct ChildRun {
  bool ok = false;
  std::string error;
  long cells = 0;
  std::vector<StageUse> uses;
  double transition_build_s = 0, optimize_s = 0;  // summed over the cavities
};

ChildRun run_in_child(const hm::CaseSpec& cs) {
  int fd[2];
  ChildRun run;
  if (pipe(fd) != 0) return run.error = "pipe failed", run;
  const pid_t pid = fork();
  if (pid == 0) {
    close(fd[0]);
    FILE* out = fdopen(fd[1], "w");
    StageMeter meter;
    hm::PipelineOptions opts;
    opts.on_stage = [&](const std::string& stage) { meter.mark(stage); };
    try {
      const hm::HybridMesh h = hm::build_hybrid_mesh(cs, opts);
      const std::string vtu = scratch_vtu_path();
      const hm::WriteStatus st = hm::write_vtu(vtu, h.mesh);
      meter.mark("write_vtu");
      std::error_code ec;
      std::filesystem::remove(vtu, ec);
      if (!st.ok) throw std::runtime_error("write_vtu: " + st.message);
      std::fprintf(out, "cells %d\n", h.mesh.n_cells());
      for (const StageUse& u : meter.uses) std::fprintf(out, "%s %.6f %.6f %.1f\n", u.stage.c_str(), u.wall, u.cpu, u.peak_mb);
      double build_s = 0, optimize_s = 0;
      transition_seconds(h, &build_s, &optimize_s);
      std::fprintf(out, "split %.6f %.6f\n", build_s, optimize_s);
    } catch (const std::exception& e) {
      std::fprintf(out, "failed %s\n", e.what());
    }
    std::fclose(out);
    std::_Exit(0);
  }
  close(fd[1]);
  FILE* in = fdopen(fd[0], "r");
  char line[4096];
  while (std::fgets(line, sizeof line, in)) {
    char name[256];
    StageUse u;
    if (std::sscanf(line, "cells %ld", &run.cells) == 1) run.ok = true;
    else if (std::sscanf(line, "split %lf %lf", &run.transition_build_s, &run.optimize_s) == 2) continue;
    else if (std::strncmp(line, "failed ", 7) == 0) run.error = line + 7;
    else if (std::sscanf(line, "%255s %lf %lf %lf", name, &u.wall, &u.cpu, &u.peak_mb) == 4) u.stage = name, run.uses.push_back(u);
  }
  std::fclose(in);
  int status = 0;
  waitpid(pid, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) run.ok = false, run.error = "crashed (status " + std::to_string(status) + ")";
  return run;
}

double cpu_of(const ChildRun& r, const std::string& stage) {
  double s = 0;
  for (const StageUse& u : r.uses)
    if (stage.empty() || u.stage == stage) s += u.cpu;
  return s;
}

// The cost of the wells against the reservoir's size (hm::bench::fixed_cell_case): each lateral
// meshed without wells and with the ten wells. Per stage, CPU seconds per reservoir cell (the run
// without wells) and added per well ((with - without) / 10).
void run_per_well(const std::vector<int>& laterals) {
  constexpr int kWells = 10;
  std::printf("10 x 10 x 5 m cells, 20 layers, 0 and %d wells (the same wells at every size); CPU seconds\n", kWells);
  for (int n : laterals) {
    const ChildRun bare = run_in_child(hm::bench::fixed_cell_case(n, 0));
    const ChildRun wells = run_in_child(hm::bench::fixed_cell_case(n, kWells));
    if (!bare.ok || !wells.ok) {
      std::printf("%-8d failed: %s%s\n", n, bare.error.c_str(), wells.error.c_str());
      continue;
    }
    std::printf("lateral %d: %ld reservoir cells, %ld cells with the wells\n", n, bare.cells, wells.cells);
    std::printf("  %-26s %12s %12s %14s %14s\n", "stage", "cpu_0_wells", "cpu_10_wells", "us/reservoir", "s added/well");
    auto row = [&](const std::string& stage, const std::string& label) {
      const double c0 = cpu_of(bare, stage), c1 = cpu_of(wells, stage);
      std::printf("  %-26s %12.3f %12.3f %14.3f %14.4f\n", label.c_str(), c0, c1, 1e6 * c0 / bare.cells, (c1 - c0) / kWells);
    };
    for (const StageUse& u : wells.uses) row(u.stage, u.stage);
    row("", "all (mesh + check + VTU)");
    double wall0 = 0, wall1 = 0, peak0 = 0, peak1 = 0;
    for (const StageUse& u : bare.uses) wall0 += u.wall, peak0 = std::max(peak0, u.peak_mb);
    for (const StageUse& u : wells.uses) wall1 += u.wall, peak1 = std::max(peak1, u.peak_mb);
    std::printf("  %-26s %12.3f %12.3f %14.3f %14.4f\n", "all, wall seconds", wall0, wall1, 1e6 * wall0 / bare.cells,
                (wall1 - wall0) / kWells);
    std::printf("  %-26s %12.0f %12.0f %14s %14.2f\n", "peak of a stage (MB)", peak0, peak1, "", (peak1 - peak0) / kWells);
    std::printf("  %-26s %12s %12.3f %14s %14.4f\n", "of the cavities: build", "", wells.transition_build_s, "",
                wells.transition_build_s / kWells);
    std::printf("  %-26s %12s %12.3f %14s %14.4f\n", "of the cavities: optimise", "", wells.optimize_s, "",
                wells.optimize_s / kWells);
    std::fflush(stdout);
  }
}

}  // namespace

int main(int argc, char** argv) {
  hm::rerun_with_malloc_tunables(argv, hm::kMallocHugePages);  // as meshgen runs (and fvcheck its own)
  std::vector<int> laterals;
  bool per_well = false;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--per-well") == 0) per_well = true;
    else laterals.push_back(std::atoi(argv[i]));
  }
  if (per_well) {
    if (laterals.empty()) laterals = {80, 112, 160, 224};
    for (int n : laterals)
      if (n < 80 || n % 2) return std::fprintf(stderr, "bench_scaling: --per-well needs even laterals >= 80 (got %d)\n", n), 2;
    run_per_well(laterals);
    return 0;
  }
  if (laterals.empty()) laterals = {22, 70, 224};
  double load[3] = {0, 0, 0};
  getloadavg(load, 3);
  std::printf("2240 x 2240 x 100 m, 20 layers, 10 deviated wells (R 6 m, 12 sectors, 6 rings); %ld cores, load "
              "average %.1f %.1f %.1f\nwall seconds unless cpu; mesh_s = the whole pipeline incl. its self-check; "
              "trans_s/optim_s: summed over cavities (run in parallel); total = mesh + VTU\n",
              sysconf(_SC_NPROCESSORS_ONLN), load[0], load[1], load[2]);
  std::printf("%-8s %9s %6s %8s %8s %8s %8s %8s %7s %7s %7s %8s %8s %6s %8s %7s %7s\n", "lateral", "cells", "trans",
              "mesh_s", "trans_s", "optim_s", "check_s", "vtu_s", "vtu_GB", "total_s", "cpu_s", "peak_MB", "cells/s",
              "sites", "rawCGAL", "fvchk_s", "fvch_MB");
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
