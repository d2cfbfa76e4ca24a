// meshgen CASE.yaml -o OUTDIR [--no-optimize] [--no-transition] [-j N] [--quiet] [--export vtu,eclipse,openfoam] [--eclipse-steady] [--png] [--png-size WxH]
// Exit codes: 0 success, 1 meshing failure (a stage, wells named; a mesh that fails the
// self-check is never written), 2 bad input or arguments.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>

#include "exporters/eclipse/eclipse_deck.hpp"
#include "exporters/openfoam/openfoam_case.hpp"
#include "exporters/png/mesh_pictures.hpp"
#include "exporters/png/offscreen_display.hpp"
#include "exporters/vtu/vtu_writer.hpp"
#include "fvcheck/lib/quality.hpp"
#include "fvcheck/lib/report.hpp"
#include "fvcheck/lib/transmissibility.hpp"
#include "meshgen/core/cli.hpp"
#include "meshgen/core/malloc_tunables.hpp"
#include "meshgen/core/parallel.hpp"
#include "meshgen/core/progress.hpp"
#include "meshgen/core/text_file.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"
#include "meshgen/pipeline/local_frame.hpp"
#include "meshgen/pipeline/summary.hpp"

namespace fs = std::filesystem;

namespace {

// checkMesh's view of the mesh's skewness, and the two cells of its worst face.
std::string skewed_face_text(const hm::PolyMesh& mesh, const hm::SkewnessSummary& skew) {
  std::string text = hm::openfoam_skewness_text(skew);
  if (skew.worst_face < 0) return text;
  const int32_t a = mesh.face_owner[skew.worst_face], b = mesh.face_neighbour[skew.worst_face];
  text += "; the worst face is cell " + std::to_string(a) + "'s (" + hm::region_name(mesh.cell_region[a]) + ")";
  if (b >= 0) text += " toward cell " + std::to_string(b) + " (" + hm::region_name(mesh.cell_region[b]) + ")";
  return text + ", cells numbered as in mesh.vtu and the polyMesh";
}

int usage(const std::string& why) {
  std::cerr << "meshgen: " << why << "\n"
            << "usage: meshgen CASE.yaml -o OUTDIR [--no-optimize] [--no-transition] [-j N] [--quiet] [--export vtu,eclipse,openfoam] [--eclipse-steady] [--png] [--png-size WxH]\n"
            << "  -j N: at most N threads (cavities meshed and optimised at once, parallel checks; default: every core)\n"
            << "  --quiet: no progress lines on stderr (shown only on a terminal, for stages over 2 s)\n"
            << "  mesh.vtu, summary.json and cavity_K.obj are always written; --export adds\n"
            << "  OUTDIR/eclipse/NAME.DATA (OPM Flow deck + GRDECL) and OUTDIR/openfoam/ (polyMesh case).\n"
            << "  --eclipse-steady: the deck is two long steps, a steady-state solve for flow with the options its first\n"
            << "  line names (default: a transient that flow runs as typed; docs/export-eclipse.md).\n"
            << "  --png: pictures beside mesh.vtu (VTK, off-screen; re-runs under xvfb-run without an X display):\n"
            << "  well_K_region.png and well_K_qs.png (a cut along well K's trajectory), overview.png;\n"
            << "  --png-size WxH: their size in pixels (default 1200x900; implies --png).\n";
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  hm::rerun_with_malloc_tunables(argv, hm::kMallocHugePages);  // meshgen/core/malloc_tunables.hpp
  std::string case_path, out_dir;
  hm::PipelineOptions opts;
  bool export_eclipse = false, export_openfoam = false, pictures = false, quiet = false;
  hm::PictureOptions picture_opts;
  hm::EclipseDeckOptions deck_opts;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-o" || a == "--output") {
      if (++i >= argc) return usage("-o needs a directory");
      out_dir = argv[i];
    } else if (a == "--no-optimize") {
      opts.optimize = false;
    } else if (a == "-j" || a == "--jobs") {
      if (++i >= argc) return usage("-j needs a number of threads");
      char* end = nullptr;
      const long j = std::strtol(argv[i], &end, 10);
      if (!end || *end != '\0' || j < 1 || j > 1024) return usage("-j: expected a number of threads in [1, 1024], got '" + std::string(argv[i]) + "'");
      opts.threads = static_cast<int>(j);
    } else if (a == "-q" || a == "--quiet") {
      quiet = true;
    } else if (a == "--no-transition") {
      opts.build_transition = false;
    } else if (a == "--export") {
      if (++i >= argc) return usage("--export needs a list, e.g. vtu,eclipse,openfoam");
      std::string list = argv[i];
      size_t start = 0;
      while (start <= list.size()) {
        const size_t comma = std::min(list.find(',', start), list.size());
        const std::string item = list.substr(start, comma - start);
        if (item == "eclipse") export_eclipse = true;
        else if (item == "openfoam") export_openfoam = true;
        else if (item != "vtu") return usage("--export: unknown format '" + item + "' (expected vtu, eclipse or openfoam)");
        start = comma + 1;
      }
    } else if (a == "--eclipse-steady") {
      deck_opts.schedule = hm::EclipseSchedule::Steady;
    } else if (a == "--png") {
      pictures = true;
    } else if (a == "--png-size") {
      if (++i >= argc) return usage("--png-size needs WIDTHxHEIGHT, e.g. 1200x900");
      int w = 0, h = 0;
      char tail = 0;
      if (std::sscanf(argv[i], "%dx%d%c", &w, &h, &tail) != 2 || w < 64 || h < 64 || w > 8192 || h > 8192)
        return usage("--png-size: expected WIDTHxHEIGHT within 64..8192 pixels, got '" + std::string(argv[i]) + "'");
      picture_opts.width = w;
      picture_opts.height = h;
      pictures = true;
    } else if (a == "-h" || a == "--help") {
      usage("help");
      return 0;
    } else if (const std::string why = hm::take_case_argument(a, &case_path); !why.empty()) {
      return usage(why);
    }
  }
  if (const std::string why = hm::check_case_and_output(case_path, out_dir); !why.empty()) return usage(why);
  // Before meshing: without a display VTK would abort after all the work (offscreen_display.hpp).
  if (pictures) {
    if (const std::string why = hm::ensure_display_or_rerun_under_xvfb(argv); !why.empty()) {
      std::cerr << "meshgen: stage pictures: " << why << "\n";
      return 1;
    }
  }
  hm::set_progress_output(hm::progress_wanted(quiet), "meshgen");
  const hm::ThreadLimit thread_limit(opts.threads);  // every parallel loop, not only the cavities

  hm::CaseSpec cs;
  hm::HybridMesh result;
  hm::Vec3 origin;
  try {
    cs = hm::load_case(case_path);
    if (const std::string why = hm::create_output_directory(out_dir); !why.empty()) {
      std::cerr << "meshgen: " << why << "\n";
      return 2;
    }
    // Mesh in the local frame (local_frame.hpp); the user's coordinates come back when writing.
    origin = hm::case_origin(cs);
    result = hm::build_hybrid_mesh_in_local_frame(cs, opts);
  } catch (const hm::InputError& e) {
    std::cerr << "meshgen: " << e.what() << "\n";
    return 2;
  } catch (const hm::MeshingError& e) {
    std::cerr << "meshgen: meshing failed at stage " << e.stage << ": " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "meshgen: meshing failed (internal error, not caused by the input): " << e.what() << "\n";
    return 1;
  }

  // Everything that depends only on the mesh's shape is computed in the local frame, then the
  // mesh moves to the user's coordinates for the writers.
  const hm::PolyMesh& m = result.mesh;
  // write_vtu adds the mesh's own per-cell data (region, FV centre, ijk, rock, radial structure).
  const std::vector<hm::VtuCellArray> extra =
      hm::mesh_file_quality_arrays(m, result.geometry, result.cell_cavity, result.cell_h_ref);
  std::optional<hm::Transmissibilities> trans;
  // The deck's transmissibilities are the ones solver_demo solves with (deck_transmissibility_options).
  if (export_eclipse)
    trans = hm::compute_transmissibilities(result.mesh, result.geometry, hm::deck_transmissibility_options());
  nlohmann::json summary = hm::make_summary(cs, result);
  hm::translate_mesh(result.mesh, origin);

  const fs::path out(out_dir);
  std::vector<std::string> written;
  for (size_t k = 0; k < result.cavities.cavities.size(); ++k) {
    const fs::path p = out / ("cavity_" + std::to_string(k) + ".obj");
    if (!hm::write_cavity_surface(result.cavities.cavities[k], result.cavity_node_coords, p.string(), origin)) {
      std::cerr << "meshgen: cannot write '" << p.string() << "'\n";
      return 2;
    }
    written.push_back(p.string());
  }
  {
    // mesh.vtu: the hybrid mesh with its FV data and per-cell quality for ParaView.
    const fs::path p = out / "mesh.vtu";
    const hm::Progress progress("writing mesh.vtu");
    const hm::WriteStatus st = hm::write_vtu(p.string(), m, extra);
    if (!st.ok) {
      std::cerr << "meshgen: " << st.message << "\n";
      return 2;
    }
    written.push_back(p.string());
  }
  if (export_eclipse) {
    // Flow leaves out connections below its threshold; the deck does not carry them, and solver_demo
    // drops the same ones (a mesh without a deck layout is refused by write_eclipse_deck below).
    hm::FlowDroppedConnections dropped;
    std::string no_layout;
    if (hm::drop_connections_flow_ignores(cs.reservoir, result.mesh, deck_opts, &*trans, &dropped, &no_layout) &&
        dropped.pairs > 0)
      std::cout << "  eclipse: " << hm::describe(dropped) << "\n";
    hm::EclipseDeckInfo info;
    const hm::WriteStatus st =
        hm::write_eclipse_deck((out / "eclipse").string(), cs, result.mesh, result.geometry, *trans, deck_opts, &info);
    if (!st.ok) {
      std::cerr << "meshgen: " << st.message << "\n";
      return 2;
    }
    for (const std::string& w : info.warnings) std::cout << "  eclipse: " << w << "\n";
    written.push_back(info.data_file);
  }
  if (export_openfoam) {
    hm::OpenFoamOptions of;
    for (const hm::WellSpec& w : cs.wells) of.well_names.push_back(w.name);
    of.n_wells = static_cast<int>(cs.wells.size());
    of.binary = result.mesh.n_cells() > 200000;  // ASCII is easier to read; binary pays off on big meshes
    const hm::WriteStatus st = hm::write_openfoam_case((out / "openfoam").string(), result.mesh, of);
    if (!st.ok) {
      std::cerr << "meshgen: " << st.message << "\n";
      return 2;
    }
    written.push_back((out / "openfoam").string() + "/");
    // checkMesh fails faces above its skewness limit or at 90 degrees of non-orthogonality; the files
    // are right, but the user is told, from the points as written (checkMesh's own view).
    const hm::CheckMeshFigures foam = hm::checkmesh_figures(result.mesh);
    const hm::SkewnessSummary& skew = foam.skewness;
    const hm::NonOrthogonalitySummary& ortho = foam.nonorthogonality;
    summary["openfoam"] = {{"max_skewness", skew.max},
                           {"faces_above_checkmesh_skewness_limit", skew.above_limit},
                           {"max_nonorthogonality_deg", ortho.max},
                           {"average_nonorthogonality_deg", ortho.average},
                           {"faces_above_checkmesh_severe_nonorthogonality", ortho.severe},
                           {"checkmesh_nonorthogonality_errors", ortho.errors}};
    if (skew.above_limit > 0) {
      std::cerr << "meshgen: warning: openfoam: " << skewed_face_text(result.mesh, skew);
      // The common cause in a permeability frame: checkMesh measures in the Euclidean sense.
      if (cs.metric == hm::MeshMetric::Permeability)
        std::cerr << " (metric: permeability: K-orthogonal cells are skewed in checkMesh's Euclidean measure, the more "
                     "so the smaller kv/kh; metric: euclidean builds them orthogonal in it, docs/anisotropy.md)";
      std::cerr << "\n";
    }
    if (ortho.errors > 0)
      std::cerr << "meshgen: warning: openfoam: " << hm::openfoam_nonorthogonality_text(ortho) << "\n";
  }
  double picture_seconds = -1;
  if (pictures) {
    picture_opts.title = cs.name;
    for (const hm::WellSpec& w : cs.wells) picture_opts.well_names.push_back(w.name);
    const auto start = std::chrono::steady_clock::now();
    const hm::PicturesWritten pics = hm::write_mesh_pictures((out / "mesh.vtu").string(), out.string(), picture_opts);
    picture_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!pics.status.ok) {
      std::cerr << "meshgen: stage " << pics.status.message << "\n";
      return 1;
    }
    written.insert(written.end(), pics.files.begin(), pics.files.end());
  }
  std::string error;
  if (!hm::write_text_file((out / "summary.json").string(), summary.dump(2) + "\n", &error)) {
    std::cerr << "meshgen: " << error << "\n";
    return 2;
  }
  written.push_back((out / "summary.json").string());
  std::cout << "meshgen: " << cs.name << ": " << result.mesh.n_cells() << " cells ("
            << summary["cells"]["reservoir"] << " reservoir, " << summary["cells"]["transition"] << " transition, "
            << summary["cells"]["well"] << " well), " << summary["cavities"] << " cavities\n";
  for (const std::string& n : result.notes) std::cout << "  note: " << n << "\n";
  for (const std::string& w : written) std::cout << "  wrote " << w << "\n";
  if (picture_seconds >= 0) std::printf("  pictures: %.2f s (reading mesh.vtu and rendering)\n", picture_seconds);
  return 0;
}
