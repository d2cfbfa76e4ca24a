// fvcheck MESH.vtu [--json REPORT.json] [--html REPORT.html [--png]] [--min-orthogonality DEG] [--max-planarity DEG]
//         [-j N] [--quiet]
// Checks the finite-volume properties of a mesh (docs/fvcheck.md).
// Exit codes: 0 every check holds, 1 a check fails, 2 unreadable input or bad arguments.

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>

#include "exporters/png/mesh_pictures.hpp"
#include "exporters/png/offscreen_display.hpp"
#include "exporters/vtu/vtu_reader.hpp"
#include "fvcheck/lib/report.hpp"
#include "fvcheck/lib/report_json.hpp"
#include "fvcheck/lib/transmissibility.hpp"
#include "meshgen/core/malloc_tunables.hpp"
#include "meshgen/core/mesh_positions.hpp"
#include "meshgen/core/parallel.hpp"
#include "meshgen/core/progress.hpp"

namespace {

const char* kUsage =
    "usage: fvcheck MESH.vtu [--json REPORT.json] [--html REPORT.html [--png]] [--min-orthogonality DEG] "
    "[--max-planarity DEG] [-j THREADS] [--quiet]";
// --help only (an error stays one line): what --png does.
const char* kPicturesHelp =
    "  the HTML report shows the pictures meshgen --png wrote beside the mesh (when not older than it);\n"
    "  --png renders them (VTK, off-screen) beside the report instead";

int usage_error(const std::string& why) {
  std::cerr << "fvcheck: " << why << " (" << kUsage << ")\n";
  return 2;
}

bool parse_degrees(const std::string& s, double* out) {
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size() || !std::isfinite(v) || v < 0 || v > 90) return false;
  *out = v;
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  hm::rerun_with_malloc_tunables(argv, hm::kMallocHugePagesHeapReuse);  // meshgen/core/malloc_tunables.hpp
  std::string mesh_path, json_path, html_path;
  bool render_pictures = false;
  hm::CheckOptions opt;
  int threads = 0;
  bool quiet = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](std::string* out) {
      if (i + 1 >= argc) return false;
      *out = argv[++i];
      return true;
    };
    std::string v;
    if (a == "-h" || a == "--help") {
      std::cout << kUsage << "\n" << kPicturesHelp << "\n";
      return 0;
    } else if (a == "--json") {
      if (!value(&json_path) || json_path.empty()) return usage_error("--json needs a file name");
    } else if (a == "--html") {
      if (!value(&html_path) || html_path.empty()) return usage_error("--html needs a file name");
    } else if (a == "--png") {
      render_pictures = true;
    } else if (a == "--min-orthogonality") {
      if (!value(&v) || !parse_degrees(v, &opt.min_orthogonality_deg))
        return usage_error("--min-orthogonality needs an angle in [0, 90] degrees");
    } else if (a == "--max-planarity") {
      if (!value(&v) || !parse_degrees(v, &opt.max_planarity_deg))
        return usage_error("--max-planarity needs an angle in [0, 90] degrees");
    } else if (a == "-j" || a == "--jobs") {
      char* end = nullptr;
      const long j = value(&v) ? std::strtol(v.c_str(), &end, 10) : 0;
      if (v.empty() || !end || *end != '\0' || j < 1 || j > 1024)
        return usage_error("-j needs a number of threads in [1, 1024]");
      threads = static_cast<int>(j);
    } else if (a == "-q" || a == "--quiet") {
      quiet = true;
    } else if (!a.empty() && a[0] == '-') {
      return usage_error("unknown option " + a);
    } else if (mesh_path.empty()) {
      mesh_path = a;
    } else {
      return usage_error("more than one mesh file given");
    }
  }
  if (mesh_path.empty()) return usage_error("no mesh file given");
  if (render_pictures && html_path.empty()) return usage_error("--png needs --html (the pictures go beside the report)");
  if (render_pictures) {
    // Before the checks: without a display VTK would abort (offscreen_display.hpp).
    if (const std::string why = hm::ensure_display_or_rerun_under_xvfb(argv); !why.empty()) {
      std::cerr << "fvcheck: stage pictures: " << why << "\n";
      return 1;
    }
  }
  hm::set_progress_output(hm::progress_wanted(quiet), "fvcheck");
  const hm::ThreadLimit thread_limit(threads);  // 0: every core

  std::optional<hm::Progress> reading(std::in_place, "reading " + mesh_path);
  hm::ReadResult in = hm::read_vtu(mesh_path);
  reading.reset();
  if (!in.ok) {
    std::cerr << "fvcheck: " << in.error << "\n";
    return 2;
  }

  // Q_S's reference length: the pipeline's per-cell h_ref if the file carries it.
  std::vector<double> h_ref;
  for (hm::VtuCellArray& a : in.cell_arrays)
    if (a.name == "h_ref") {  // the first of the name, as ReadResult::find
      if (a.components == 1) h_ref = std::move(a.values);
      break;
    }
  const bool has_permeability = in.find("permeability") != nullptr;
  // The mesh holds every array it uses (restore_mesh_cell_arrays): the file's copies go now, not
  // after the checks (a third of the memory of a large file).
  in.cell_arrays = {};

  // Checked in a local frame, as meshgen checks it (plan_origin): shape figures do not depend on it.
  hm::translate_mesh(in.mesh, -1.0 * hm::plan_origin(in.mesh));

  hm::MeshGeometry geo;  // the checks' geometry pass, reused for the transmissibilities
  hm::FvReport report = hm::run_fvcheck(in.mesh, opt, h_ref, &in.build, &geo);
  report.source = mesh_path;
  report.notes = in.warnings;
  for (const std::string& p : in.build.problems) report.notes.push_back("builder: " + p);
  if (!in.has_fv_center) report.notes.push_back("no fv_center array: cell centroids used as FV centres");
  if (!in.has_region) report.notes.push_back("no region array: every cell counted as reservoir");
  if (h_ref.empty()) report.notes.push_back("no h_ref array: Q_S uses each cell's mean edge length as h");
  if (report.structure.ok) {
    if (!has_permeability) {
      // The signs and magnitudes of the geometric part are still worth checking.
      for (hm::Vec3& k : in.mesh.cell_perm) k = {1, 1, 1};
      report.notes.push_back("no permeability array: transmissibilities computed with k = 1 mD (geometric part)");
    }
    const hm::Progress progress("transmissibilities");
    // A corner-point model's mesh: the transmissibilities flow and solver_demo use (OPM's form on the
    // model's side, never negative; docs/transmissibility.md).
    const hm::Transmissibilities t = hm::compute_transmissibilities(
        in.mesh, geo, in.mesh.reservoir_cells_are_model ? hm::deck_transmissibility_options() : hm::TransmissibilityOptions{});
    if (in.mesh.reservoir_cells_are_model)
      report.notes.push_back("a corner-point model's mesh: transmissibilities in the deck's form (OPM's on the model's side)");
    report.transmissibility = hm::summarize_transmissibilities(t.face);
    report.transmissibility.negative_halves = t.negative;
    if (report.transmissibility.negative_faces.empty()) report.transmissibility.negative_faces = t.negative_faces;
    if (!in.has_radial)
      report.notes.push_back("no radial_* arrays: well cells get the generic two-point transmissibility "
                             "(docs/output-formats.md lists the arrays that make a mesh file lossless)");
    if (!in.has_face_patch)
      report.notes.push_back("no face_patch field data: every boundary face treated as outer boundary "
                             "(no wellbore transmissibilities)");
  }

  std::string err;
  if (!json_path.empty()) {
    const std::string text =
        hm::report_json(report).dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
    if (!hm::write_text_file(json_path, text, &err)) {
      std::cerr << "fvcheck: " << err << "\n";
      return 2;
    }
  }
  if (!html_path.empty()) {
    namespace fs = std::filesystem;
    const fs::path report_dir = fs::absolute(html_path).parent_path();
    if (render_pictures) {
      const hm::PicturesWritten pics = hm::write_mesh_pictures(mesh_path, report_dir.string(), {});
      if (!pics.status.ok) {
        std::cerr << "fvcheck: stage " << pics.status.message << "\n";
        return pics.input_error ? 2 : 1;
      }
    }
    // Pictures of this mesh only: one older than the mesh file shows an earlier mesh.
    std::error_code ec;
    const fs::file_time_type mesh_time = fs::last_write_time(mesh_path, ec);
    const fs::path dir = render_pictures ? report_dir : fs::absolute(mesh_path).parent_path();
    for (const hm::PictureFile& p : hm::find_mesh_pictures(dir.string())) {
      std::error_code pec;
      if (!ec && fs::last_write_time(p.path, pec) < mesh_time) {
        report.notes.push_back("picture " + p.path + " is older than the mesh file: not shown");
        continue;
      }
      const std::string uri = hm::png_data_uri(p.path);
      if (uri.empty()) {
        report.notes.push_back("picture " + p.path + " cannot be read: not shown");
        continue;
      }
      report.pictures.push_back({p.caption, uri});
    }
  }
  if (!html_path.empty() && !hm::write_text_file(html_path, hm::report_html(report), &err)) {
    std::cerr << "fvcheck: " << err << "\n";
    return 2;
  }
  std::cout << hm::report_summary_text(report);
  return report.ok() ? 0 : 1;
}
