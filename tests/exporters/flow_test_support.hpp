// Running OPM Flow on an exported deck and comparing it with the reference TPFA solve.
#pragma once
#include <sys/resource.h>

#include <nlohmann/json.hpp>

#include "exporter_test_support.hpp"
#include "exporters/eclipse/eclipse_deck.hpp"

namespace hmtest {

#define REQUIRE_FLOW()                                                                                 \
  if (!hmtest::have_executable("flow") || !hmtest::fs::exists("/usr/bin/python3"))                    \
  GTEST_SKIP() << "OPM Flow (Debian packages libopm-simulators-bin, python3-opm-common) is not "       \
                  "installed; scripts/install-deps.sh --validators installs it"

struct FlowRun {
  CommandResult flow;
  CommandResult reader;
  nlohmann::json results;  ///< scripts/validate_flow.py output (null if it failed)
  double seconds = 0;      ///< wall time of the flow run
  double cpu_seconds = 0;  ///< user + system CPU time of the flow run (children of this process)
  int newton = -1;         ///< "Overall Newton Iterations" flow printed (-1: not found)
};

inline double children_cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_CHILDREN, &u);
  return u.ru_utime.tv_sec + u.ru_stime.tv_sec + 1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

enum class FlowInvocation {
  AsTyped,      ///< `flow NAME.DATA`: no options (the default deck, EclipseSchedule::AsTyped)
  WithOptions,  ///< `flow <flow_steady_state_options()> NAME.DATA` (for EclipseSchedule::Steady)
};

/// Runs flow on dir/NAME.DATA (output in dir/out; --output-dir only chooses where flow writes),
/// as a user types it or with the exporter's optional steady-state options, then reads the
/// results back with scripts/validate_flow.py.
inline FlowRun run_flow(const fs::path& dir, const std::string& name, FlowInvocation how = FlowInvocation::AsTyped,
                        int timeout_s = 900) {
  FlowRun r;
  std::string cmd = "cd " + shell_quote(dir.string()) + " && flow";
  if (how == FlowInvocation::WithOptions)
    for (const std::string& a : hm::flow_steady_state_options()) cmd += " " + a;
  cmd += " --output-dir=out " + shell_quote(name + ".DATA");
  const auto t0 = std::chrono::steady_clock::now();
  const double c0 = children_cpu_seconds();
  r.flow = run_command(cmd, timeout_s);
  r.cpu_seconds = children_cpu_seconds() - c0;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const size_t at = r.flow.output.rfind("Overall Newton Iterations:");
  if (at != std::string::npos) r.newton = std::atoi(r.flow.output.c_str() + at + 26);
  if (r.flow.exit_code != 0) return r;
  r.reader = run_command("/usr/bin/python3 " + shell_quote(std::string(HM_SOURCE_DIR) + "/scripts/validate_flow.py") +
                             " " + shell_quote((dir / "out").string()) + " " + shell_quote(name) + " 2>/dev/null",
                         300);
  if (r.reader.exit_code == 0) r.results = nlohmann::json::parse(r.reader.output, nullptr, false);
  return r;
}

/// Debugging aid: with HM_KEEP_TEST_OUTPUT set, writes our solution in flow's active order
/// (dir/ours.json: "pressure", "rates" by well name) next to the kept deck.
inline void dump_ours_if_kept(const fs::path& dir, const hm::CaseSpec& cs, const hm::EclipseLayout& L,
                              const TpfaSolution& ours) {
  if (std::getenv("HM_KEEP_TEST_OUTPUT") == nullptr) return;
  nlohmann::json j;
  std::vector<double> p;
  for (int32_t c : L.deck_cell)
    if (c >= 0) p.push_back(ours.pressure[c]);
  j["pressure"] = p;
  for (size_t w = 0; w < cs.wells.size(); ++w) j["rates"][cs.wells[w].name] = ours.well_rate[w];
  std::ofstream(dir / "ours.json") << j.dump();
}

inline std::string to_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

struct FlowComparison {
  double max_rel_pressure = 0;  ///< max |p_flow - p_ours| / |p_ours| over cells
  double max_rel_rate = 0;      ///< max |q_flow - q_ours| / |q_ours| over wells
  double max_rel_porv = 0;      ///< INIT PORV vs ours
  double max_depth_diff = 0;    ///< |INIT DEPTH - FV centre z| (m)
  double max_rel_connection = 0;  ///< flow's transmissibility per cell pair (INIT) vs ours
  size_t our_connections = 0;     ///< cell pairs the deck connects (TRANX/Y/Z + NNC)
  size_t flow_connections = 0;    ///< cell pairs flow connects (INIT TRANX/Y/Z + TRANNNC)
  size_t flow_nnc = 0;            ///< TRANNNC entries (NNCs not merged into a face)
  std::string worst_connection;   ///< the pair behind max_rel_connection
  size_t dropped_by_flow = 0;     ///< our NNCs below flow's threshold, which flow sets to 0
  size_t expected_dropped = 0;    ///< how many the exporter predicted (EclipseConnections::below_flow_threshold)
  double dropped_sum = 0;         ///< their summed transmissibility
  std::string problem;          ///< structural mismatch (counts, missing arrays), empty if none
};

/// Compares a flow run with the reference solve: active cells map one to one onto mesh cells in
/// natural deck order; pressures, well rates (WWPR - WWIR = production), INIT PORV/DEPTH and the
/// NNC list (no NNC dropped, none added) must all match.
inline FlowComparison compare_flow(const hm::CaseSpec& cs, const hm::PolyMesh& mesh, const hm::MeshGeometry& geo,
                                   const hm::EclipseDeckInfo& info, const TpfaSolution& ours,
                                   const hm::EclipseConnections& conn, const nlohmann::json& res) {
  FlowComparison c;
  c.expected_dropped = static_cast<size_t>(conn.below_flow_threshold);
  const hm::EclipseLayout& L = info.layout;
  // Active cells in natural order -> mesh cells.
  std::vector<int32_t> active_cell;
  for (size_t g = 0; g < L.deck_cell.size(); ++g)
    if (L.deck_cell[g] >= 0) active_cell.push_back(L.deck_cell[g]);
  if (res.is_discarded() || res.is_null()) {
    c.problem = "no results";
    return c;
  }
  const auto dims = res["dims"];
  if (dims[0] != L.deck_nx || dims[1] != L.ny || dims[2] != L.nz) {
    c.problem = "deck dims differ: " + dims.dump();
    return c;
  }
  if (res["active"].get<size_t>() != active_cell.size()) {
    c.problem = "flow has " + res["active"].dump() + " active cells, the mesh " + std::to_string(active_cell.size());
    return c;
  }
  const auto& p = res["pressure"];
  const auto& depth = res["init"]["depth"];
  const auto& porv = res["init"]["porv"];  // global
  if (p.size() != active_cell.size() || depth.size() != active_cell.size()) {
    c.problem = "PRESSURE/DEPTH sizes differ from the active cell count";
    return c;
  }
  for (size_t a = 0; a < active_cell.size(); ++a) {
    const int32_t cell = active_cell[a];
    const double po = ours.pressure[cell];
    c.max_rel_pressure = std::max(c.max_rel_pressure, std::abs(p[a].get<double>() - po) / std::abs(po));
    c.max_depth_diff = std::max(c.max_depth_diff, std::abs(depth[a].get<double>() - mesh.cell_fv_center[cell].z));
  }
  if (porv.size() == L.deck_cell.size()) {
    for (size_t g = 0; g < L.deck_cell.size(); ++g) {
      if (L.deck_cell[g] < 0) continue;
      const int32_t cell = L.deck_cell[g];
      const double pv = geo.cell_volume[cell] * mesh.cell_porosity[cell] * mesh.pore_volume_mult(cell);
      c.max_rel_porv = std::max(c.max_rel_porv, std::abs(porv[g].get<double>() - pv) / pv);
    }
  } else {
    c.problem = "INIT PORV has " + std::to_string(porv.size()) + " values";
  }
  // Rates relative to the rate itself, or to 1e-3 of the well's rate at the initial drawdown when
  // the steady rate is ~0 (a lone producer in a closed box ends hydrostatic at its BHP).
  for (size_t w = 0; w < cs.wells.size(); ++w) {
    const auto& wj = res["wells"][cs.wells[w].name];
    const double q = wj.value("WWPR", 0.0) - wj.value("WWIR", 0.0);
    double scale = 0;
    for (const auto& connection : info.well_connections[w])
      scale += connection.second / cs.fluid.viscosity * std::abs(cs.reservoir.initial_pressure - cs.wells[w].bhp);
    const double denom = std::max(std::abs(ours.well_rate[w]), 1e-3 * scale);
    c.max_rel_rate = std::max(c.max_rel_rate, std::abs(q - ours.well_rate[w]) / denom);
  }
  // Connections: flow merges an NNC between cells that share a geometric face into that face's
  // TRANX/Y/Z, so compare per cell pair: flow's TRANX/Y/Z (active order, converted to pairs)
  // plus its TRANNNC list must be exactly our TRANX/Y/Z plus NNC: none dropped, none added. Flow's
  // TRANZ of a cell is its connection to the next active cell down the column: an NNC across
  // inactive cells of zero thickness (a pinched-out layer) is reported there and in TRANNNC.
  std::map<std::pair<int32_t, int32_t>, double> mine, theirs, across_inactive;
  const int32_t step[3] = {1, L.deck_nx, L.deck_nx * L.ny};
  const std::vector<double>* tran_ours[3] = {&conn.tranx, &conn.trany, &conn.tranz};
  const char* tran_keys[3] = {"tranx", "trany", "tranz"};
  for (int d = 0; d < 3; ++d) {
    const auto& arr = res["init"][tran_keys[d]];
    if (arr.size() != active_cell.size()) {
      c.problem = std::string("INIT ") + tran_keys[d] + " has " + std::to_string(arr.size()) + " values";
      return c;
    }
    size_t a = 0;
    for (int32_t g = 0; g < static_cast<int32_t>(L.deck_cell.size()); ++g) {
      if ((*tran_ours[d])[g] != 0) mine[{g, g + step[d]}] += (*tran_ours[d])[g];
      if (L.deck_cell[g] < 0) continue;
      const double v = arr[a++].get<double>();
      int32_t below = g + step[d];
      while (d == 2 && below < static_cast<int32_t>(L.deck_cell.size()) && L.deck_cell[below] < 0) below += step[d];
      if (v != 0) (below == g + step[d] ? theirs : across_inactive)[{g, below}] += v;
    }
  }
  for (const auto& r : conn.nnc) mine[{r.a, r.b}] += r.t;
  const auto& t = res["init"]["trannnc"];
  const auto& n1 = res["init"]["nnc1"];
  const auto& n2 = res["init"]["nnc2"];
  c.flow_nnc = t.size();
  if (n1.size() != t.size() || n2.size() != t.size()) {
    c.problem = "INIT TRANNNC has " + std::to_string(t.size()) + " values, EGRID NNC1/NNC2 " +
                std::to_string(n1.size()) + "/" + std::to_string(n2.size());
    return c;
  }
  for (size_t k = 0; k < t.size(); ++k) {
    int32_t a = n1[k].get<int32_t>() - 1, b = n2[k].get<int32_t>() - 1;
    if (a > b) std::swap(a, b);
    const double v = t[k].get<double>();
    // A negative TRANNNC is flow saying "the deck gave T here, I use 0": a connection below its
    // threshold. Allowed only for our NNCs below hm::kFlowNncThreshold (dropped, not a mismatch).
    auto it = mine.find({a, b});
    if (v < 0 && it != mine.end() && it->second < hm::kFlowNncThreshold &&
        std::abs(-v - it->second) <= 1e-6 * it->second) {
      ++c.dropped_by_flow;
      c.dropped_sum += it->second;
      mine.erase(it);
      continue;
    }
    theirs[{a, b}] += v;
  }
  // An NNC of the deck across inactive cells is in TRANNNC and again in the upper cell's TRANZ: once.
  for (const auto& [pair, v] : across_inactive)
    if (!theirs.count(pair)) theirs[pair] += v;
  c.our_connections = mine.size();
  c.flow_connections = theirs.size();
  for (const auto& [pair, v] : theirs) {
    auto it = mine.find(pair);
    if (it == mine.end()) {
      c.problem = "flow connects deck cells " + std::to_string(pair.first) + " and " + std::to_string(pair.second) +
                  " (T = " + std::to_string(v) + "), the deck does not";
      return c;
    }
    const double rel = std::abs(v - it->second) / std::abs(it->second);
    if (rel > c.max_rel_connection) {
      c.max_rel_connection = rel;
      c.worst_connection = "deck cells " + std::to_string(pair.first) + "-" + std::to_string(pair.second) +
                           ": flow " + to_text(v) + ", ours " + to_text(it->second);
    }
  }
  if (mine.size() != theirs.size()) {
    c.problem = "flow kept " + std::to_string(theirs.size()) + " connections, the deck has " + std::to_string(mine.size());
    return c;
  }
  return c;
}

}  // namespace hmtest
