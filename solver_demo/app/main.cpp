// solver_demo CASE.yaml -o OUTDIR [--mesh MESH.vtu]
//   Builds the hybrid mesh (or reads it from MESH.vtu, as meshgen wrote it: no re-meshing), solves the steady single-phase problem the exported deck poses (wells
//   at their BHP, no-flow outer boundary, gravity) and writes solution.json and pressure.vtu.
// solver_demo --accuracy CASE.yaml -o OUTDIR [--levels N] [--kv-kh R] [--kx-ky Q]
//   The near-well accuracy study (docs/accuracy.md): accuracy.json and accuracy.svg.
// Exit codes: 0 success, 1 failure (meshing, solver), 2 bad input or arguments.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

#include "exporters/eclipse/eclipse_deck.hpp"
#include "exporters/vtu/vtu_reader.hpp"
#include "exporters/vtu/vtu_writer.hpp"
#include "fvcheck/lib/transmissibility.hpp"
#include "meshgen/core/cli.hpp"
#include "meshgen/core/mesh_positions.hpp"
#include "meshgen/core/text_file.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"
#include "meshgen/pipeline/local_frame.hpp"
#include "solver_demo/lib/accuracy.hpp"
#include "solver_demo/lib/case_problem.hpp"
#include "solver_demo/lib/tpfa.hpp"

namespace fs = std::filesystem;

namespace {

constexpr const char* kUsage =
    "usage: solver_demo CASE.yaml -o OUTDIR [--mesh MESH.vtu]\n"
    "         (--mesh: solve on the mesh file meshgen wrote for CASE.yaml instead of meshing again)\n"
    "       solver_demo --accuracy CASE.yaml -o OUTDIR [--levels N] [--source-to-tips] [--kv-kh R] [--kx-ky Q]\n"
    "                [--metric permeability|euclidean | --compare-metrics]\n"
    "         (N refinement levels, default 3; --source-to-tips: the line source runs to the well's end\n"
    "          points, singular on the end caps, instead of stopping r_w short of them; --kv-kh, --kx-ky:\n"
    "          the case's permeability made anisotropic keeping kh = sqrt(kx ky), kz = R kh, kx / ky = Q;\n"
    "          --metric: overrides the case's metric key; --compare-metrics: the hybrid mesh with\n"
    "          metric: permeability and with metric: euclidean)\n";

int usage(const std::string& why) {
  std::cerr << "solver_demo: " << why << "\n" << kUsage;
  return 2;
}

// Runs `work`; an InputError is the user's (exit 2), anything else a failure (exit 1); 0 if it ran.
template <class Work>
int guarded(Work work) {
  try {
    work();
  } catch (const hm::InputError& e) {
    std::cerr << "solver_demo: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "solver_demo: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

// The mesh of a case read from a file meshgen wrote: the file must carry the finite-volume data
// (radial structure, wellbore patches) and its wells must be the case's.
std::string load_mesh_file(const hm::CaseSpec& cs, const std::string& path, hm::PolyMesh* mesh) {
  hm::ReadResult r = hm::read_vtu(path);
  if (!r.ok) return r.error;
  if (!r.build.ok) return path + ": the cells do not form a conforming mesh";
  if (!r.missing_mesh_arrays.empty())
    return path + ": no '" + r.missing_mesh_arrays.front() + "' cell array (not a mesh file meshgen wrote)";
  if (!r.has_face_patch) return path + ": no face_patch field data (the wellbores are unknown)";
  std::vector<int> faces_of_well(cs.wells.size(), 0);
  for (int f = 0; f < r.mesh.n_faces(); ++f)
    if (r.mesh.face_neighbour[f] < 0 && hm::is_wellbore_patch(r.mesh.face_patch[f])) {
      const int w = hm::well_of_patch(r.mesh.face_patch[f]);
      if (w >= static_cast<int>(cs.wells.size()))
        return path + ": wellbore faces of well " + std::to_string(w) + ", the case has " +
               std::to_string(cs.wells.size()) + " wells";
      ++faces_of_well[w];
    }
  for (size_t w = 0; w < cs.wells.size(); ++w)
    if (faces_of_well[w] == 0) return path + ": no wellbore face of well '" + cs.wells[w].name + "'";
  *mesh = std::move(r.mesh);
  return {};
}

// cs is as given on return (build_hybrid_mesh_in_local_frame holds a large model once meanwhile).
int run_flow(hm::CaseSpec& cs, const fs::path& out, const std::string& mesh_file) {
  // Solved in a local frame, as meshgen meshes and computes the deck's numbers (docs/architecture.md,
  // "Local frame"); pressure.vtu gets the user's coordinates back.
  hm::HybridMesh mesh;
  hm::Vec3 origin;
  hm::FlowSolution sol;
  if (!mesh_file.empty()) {
    if (const std::string why = load_mesh_file(cs, mesh_file, &mesh.mesh); !why.empty()) {
      std::cerr << "solver_demo: " << why << "\n";
      return 2;
    }
    origin = hm::plan_origin(mesh.mesh);
    hm::translate_mesh(mesh.mesh, -1.0 * origin);
    mesh.geometry = hm::compute_geometry(mesh.mesh);
  }
  if (const int rc = guarded([&] {
        if (mesh_file.empty()) {
          mesh = hm::build_hybrid_mesh_in_local_frame(cs);
          origin = hm::case_origin(cs);
        }
        const hm::FlowProblem pb = hm::deck_flow_problem(cs, mesh.mesh, mesh.geometry);
        // The transmissibilities of the exported deck (docs/export-eclipse.md, "A corner-point model"),
        // without the connections flow leaves out of it: the deck's equation.
        hm::Transmissibilities trans =
            hm::compute_transmissibilities(mesh.mesh, mesh.geometry, hm::deck_transmissibility_options());
        hm::FlowDroppedConnections dropped;
        std::string no_layout;
        if (hm::drop_connections_flow_ignores(cs.reservoir, mesh.mesh, {}, &trans, &dropped, &no_layout) &&
            dropped.pairs > 0)
          std::cout << "solver_demo: " << hm::describe(dropped) << "\n";
        sol = hm::solve_tpfa(pb, trans);
      }))
    return rc;

  nlohmann::json j;
  j["case"] = cs.name;
  j["wells"] = nlohmann::json::array();
  for (size_t w = 0; w < cs.wells.size(); ++w)
    j["wells"].push_back({{"name", cs.wells[w].name},
                          {"rate_m3_per_day", w < sol.well_rate_m3_per_day.size() ? sol.well_rate_m3_per_day[w] : 0.0},
                          {"bhp", cs.wells[w].bhp}});
  double pmin = 0, pmax = 0, vol = 0, pv = 0;
  if (!sol.pressure.empty()) {
    pmin = *std::min_element(sol.pressure.begin(), sol.pressure.end());
    pmax = *std::max_element(sol.pressure.begin(), sol.pressure.end());
  }
  for (int c = 0; c < mesh.mesh.n_cells(); ++c) {
    vol += mesh.geometry.cell_volume[c];
    pv += mesh.geometry.cell_volume[c] * sol.pressure[c];
  }
  j["pressure"] = {{"min", pmin}, {"max", pmax}, {"mean", vol > 0 ? pv / vol : 0.0}};
  j["cells"] = mesh.mesh.n_cells();
  j["solver"] = {{"name", sol.solver},
                 {"iterations", sol.iterations},
                 {"nonlinear_iterations", sol.nonlinear_iterations},
                 {"relative_residual", sol.relative_residual},
                 {"max_cell_imbalance_m3_per_day", sol.max_cell_imbalance}};
  if (std::string error; !hm::write_text_file((out / "solution.json").string(), j.dump(2) + "\n", &error)) {
    std::cerr << "solver_demo: " << error << "\n";
    return 2;
  }
  hm::translate_mesh(mesh.mesh, origin);
  const hm::WriteStatus st = hm::write_vtu((out / "pressure.vtu").string(), mesh.mesh,
                                           {hm::VtuCellArray::real("pressure", 1, sol.pressure)});
  if (!st.ok) {
    std::cerr << "solver_demo: " << st.message << "\n";
    return 2;
  }
  std::cout << "solver_demo: " << cs.name << ": " << mesh.mesh.n_cells() << " cells, " << sol.solver << ", "
            << sol.nonlinear_iterations << " nonlinear / " << sol.iterations << " linear iterations, relative residual "
            << sol.relative_residual << ", max cell imbalance " << sol.max_cell_imbalance << " m3/day\n";
  for (size_t w = 0; w < cs.wells.size(); ++w)
    std::cout << "  " << cs.wells[w].name << ": bhp " << cs.wells[w].bhp << " bar, rate "
              << sol.well_rate_m3_per_day[w] << " sm3/day\n";
  std::cout << "  wrote " << (out / "solution.json").string() << "\n  wrote " << (out / "pressure.vtu").string()
            << "\n";
  return 0;
}

std::string percent(double v) {
  std::ostringstream os;
  os << std::setprecision(3) << v * 100 << " %";
  return os.str();
}

int run_accuracy(const hm::CaseSpec& cs, const fs::path& out, int levels, const hm::AccuracyOptions& opt) {
  hm::AccuracyStudy st;
  if (const int rc = guarded([&] { st = hm::run_accuracy_study(cs, levels, opt); })) return rc;
  for (const auto& [name, status] :
       {std::pair{std::string("accuracy.json"), hm::write_accuracy_json((out / "accuracy.json").string(), st)},
        std::pair{std::string("accuracy.svg"), hm::write_accuracy_svg((out / "accuracy.svg").string(), st)},
        std::pair{std::string("cells.csv"), hm::write_accuracy_cells_csv((out / "cells.csv").string(), st)}})
    if (!status.ok) {
      std::cerr << "solver_demo: " << status.message << "\n";
      return 2;
    }
  std::cout << "solver_demo: accuracy of " << cs.name << " (errors relative to the exact rate / the drawdown)\n";
  for (const hm::RefinementLevel& lv : st.refinement)
    std::cout << "  x" << lv.factor << ": hybrid (" << lv.hybrid_cells << " cells) rate " << percent(lv.hybrid.rate_rel_error)
              << ", near-well " << percent(lv.hybrid.near_well_pressure_rel_error) << "; Cartesian + Peaceman ("
              << lv.cartesian_cells << " cells) rate " << percent(lv.peaceman.rate_rel_error) << ", near-well "
              << percent(lv.peaceman.near_well_pressure_rel_error)
              << (lv.has_euclidean ? "; Euclidean hybrid (" + std::to_string(lv.hybrid_euclidean_cells) + " cells) rate " +
                                         percent(lv.hybrid_euclidean.rate_rel_error) + ", near-well " +
                                         percent(lv.hybrid_euclidean.near_well_pressure_rel_error)
                                   : std::string())
              << "\n";
  std::cout << "  wrote " << (out / "accuracy.json").string() << "\n  wrote " << (out / "accuracy.svg").string() << "\n";
  return 0;
}

// A positive finite number, or a usage message naming the flag.
std::string parse_ratio(const std::string& flag, const char* text, double* out) {
  try {
    size_t used = 0;
    *out = std::stod(text, &used);
    if (used != std::string(text).size()) throw std::invalid_argument("trailing characters");
  } catch (const std::exception&) {
    return flag + ": not a number: '" + text + "'";
  }
  if (!(*out > 0) || !std::isfinite(*out)) return flag + ": must be a positive number";
  return {};
}

}  // namespace

int main(int argc, char** argv) {
  std::string case_path, out_dir, mesh_file;
  bool accuracy = false, anisotropy = false;
  int levels = 3;
  double kv_kh = 1, kx_ky = 1;
  std::string metric;  // empty: the case's
  hm::AccuracyOptions acc_opt;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-o" || a == "--output") {
      if (++i >= argc) return usage("-o needs a directory");
      out_dir = argv[i];
    } else if (a == "--mesh") {
      if (++i >= argc) return usage("--mesh needs a .vtu file");
      mesh_file = argv[i];
    } else if (a == "--accuracy") {
      accuracy = true;
    } else if (a == "--kv-kh" || a == "--kx-ky") {
      if (++i >= argc) return usage(a + " needs a number");
      if (const std::string why = parse_ratio(a, argv[i], a == "--kv-kh" ? &kv_kh : &kx_ky); !why.empty())
        return usage(why);
      anisotropy = true;
    } else if (a == "--metric") {
      if (++i >= argc) return usage("--metric needs permeability or euclidean");
      const std::string m = argv[i];
      if (m != "permeability" && m != "euclidean") return usage("--metric: expected permeability or euclidean, got '" + m + "'");
      metric = m;
    } else if (a == "--compare-metrics") {
      acc_opt.compare_metrics = true;
    } else if (a == "--source-to-tips") {
      acc_opt.source_to_tips = true;
    } else if (a == "--levels") {
      if (++i >= argc) return usage("--levels needs a number");
      try {
        size_t used = 0;
        levels = std::stoi(argv[i], &used);
        if (used != std::string(argv[i]).size()) throw std::invalid_argument("trailing characters");
      } catch (const std::exception&) {
        return usage(std::string("--levels: not an integer: '") + argv[i] + "'");
      }
      if (levels < 1 || levels > 4) return usage("--levels: must be in [1, 4]");
    } else if (a == "-h" || a == "--help") {
      std::cout << kUsage;
      return 0;
    } else if (const std::string why = hm::take_case_argument(a, &case_path); !why.empty()) {
      return usage(why);
    }
  }
  if (const std::string why = hm::check_case_and_output(case_path, out_dir); !why.empty()) return usage(why);
  if ((anisotropy || acc_opt.compare_metrics || !metric.empty()) && !accuracy)
    return usage("--kv-kh, --kx-ky, --metric and --compare-metrics go with --accuracy");
  if (acc_opt.compare_metrics && !metric.empty()) return usage("--metric and --compare-metrics exclude each other");

  hm::CaseSpec cs;
  try {
    cs = hm::load_case(case_path);
  } catch (const hm::InputError& e) {
    std::cerr << "solver_demo: " << e.what() << "\n";
    return 2;
  }
  if (const std::string why = hm::create_output_directory(out_dir); !why.empty()) {
    std::cerr << "solver_demo: " << why << "\n";
    return 2;
  }
  if (accuracy && !mesh_file.empty()) return usage("--mesh and --accuracy exclude each other (the study meshes each level)");
  if (anisotropy && !cs.reservoir.cell_permx.empty())
    return usage("--kv-kh / --kx-ky: the case has per-cell permeability (reservoir.grdecl)");
  if (anisotropy) cs = hm::anisotropic_case(cs, kv_kh, kx_ky);
  if (!metric.empty()) cs.metric = metric == "permeability" ? hm::MeshMetric::Permeability : hm::MeshMetric::Euclidean;
  return accuracy ? run_accuracy(cs, out_dir, levels, acc_opt) : run_flow(cs, out_dir, mesh_file);
}
