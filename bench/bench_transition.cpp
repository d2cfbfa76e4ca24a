// Timing of the transition mesh (paper 5.2-5.7) per cavity, on the example cases and on a
// larger well (more sectors and rings, so more constrained polygons). The cavities are
// built once (pipeline without transition); each iteration runs build_transition on
// every cavity of the case. Counters: transition cells and cells per second.
#include <benchmark/benchmark.h>

#include <map>
#include <string>

#include "meshgen/case/case.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"
#include "meshgen/transition/transition.hpp"

namespace {

const hm::HybridMesh& cavities_of(const std::string& key, const hm::CaseSpec& cs) {
  static std::map<std::string, hm::HybridMesh> cache;
  auto it = cache.find(key);
  if (it == cache.end()) {
    hm::PipelineOptions opts;
    opts.build_transition = false;
    opts.optimize = false;
    it = cache.emplace(key, hm::build_hybrid_mesh(cs, opts)).first;
  }
  return it->second;
}

void run(benchmark::State& state, const std::string& key, const hm::CaseSpec& cs) {
  const hm::HybridMesh& hm = cavities_of(key, cs);
  int64_t cells = 0;
  double delaunay = 0, sites = 0, power = 0;
  for (auto _ : state) {
    cells = 0;
    delaunay = sites = power = 0;
    for (const hm::Cavity& cav : hm.cavities.cavities) {
      hm::TransitionCells t = hm::build_transition(cav, hm.cavity_node_coords, hm.grid, hm.blocks,
                                                   static_cast<int32_t>(hm.cavity_node_coords.size()));
      cells += static_cast<int64_t>(t.cells.size());
      delaunay += t.report.seconds_delaunay, sites += t.report.seconds_sites, power += t.report.seconds_power;
      benchmark::DoNotOptimize(t);
    }
  }
  state.counters["cells"] = static_cast<double>(cells);
  state.counters["cells_per_s"] = benchmark::Counter(static_cast<double>(cells), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["delaunay_s"] = delaunay;
  state.counters["sites_s"] = sites;
  state.counters["power_s"] = power;
}

void BM_PaperExample(benchmark::State& state) {
  run(state, "paper", hm::load_case(std::string(HM_SOURCE_DIR) + "/examples/paper_single_well.yaml"));
}
BENCHMARK(BM_PaperExample)->Unit(benchmark::kMillisecond);

void BM_ThreeWells(benchmark::State& state) {
  run(state, "three", hm::load_case(std::string(HM_SOURCE_DIR) + "/examples/three_wells.yaml"));
}
BENCHMARK(BM_ThreeWells)->Unit(benchmark::kMillisecond);

// The paper example with a finer well block: 16 sectors, 2 m segments (a finer bend is
// refused by the well block: not Gabriel).
void BM_FineWell(benchmark::State& state) {
  hm::CaseSpec cs = hm::load_case(std::string(HM_SOURCE_DIR) + "/examples/paper_single_well.yaml");
  cs.wells[0].sectors = 16;
  cs.wells[0].segment_length = 2.0;
  run(state, "fine", cs);
}
BENCHMARK(BM_FineWell)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
