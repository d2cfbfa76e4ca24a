// Pictures of a mesh file, rendered off-screen with VTK (docs/output-formats.md, "Pictures"):
// per well an interior cut along its trajectory coloured by region and by Q_S, and one overview.
// The only module that links VTK's rendering libraries; the header stays VTK-free.
#pragma once
#include <string>
#include <vector>

#include "exporters/vtu/vtu_writer.hpp"

namespace hm {

/// What to render and how large.
struct PictureOptions {
  std::string title;                    ///< case name, written in each picture's caption
  std::vector<std::string> well_names;  ///< caption names by well index ("well K" where absent)
  int width = 1200, height = 900;       ///< pixels of every picture
};

/// The RGB colours (0..255) of the region picture, by Region code (reservoir, transition, well):
/// the legend shows them and the cut pictures are drawn unlit, so every cell face has exactly its
/// region's colour (edges aside).
struct RegionColours {
  unsigned char rgb[3][3];
};
const RegionColours& region_colours();

/// The file names (no directory) of the pictures of well k: well_K_region.png, well_K_qs.png.
std::string well_region_picture_name(int well);
std::string well_qs_picture_name(int well);
inline const char* kOverviewPictureName = "overview.png";

struct PicturesWritten {
  WriteStatus status;              ///< !ok: "pictures: reason" (nothing after the failing picture written)
  bool input_error = false;        ///< !ok because of the mesh file (unreadable, arrays missing): exit 2
  std::vector<std::string> files;  ///< paths written, in order: per well region then Q_S, then the overview
};

/// Reads the mesh file `vtu_path` (VTK's reader; the arrays region, fv_center, radial_well,
/// radial_ring, radial_segment, radial_band, radial_cap_center, cavity and Q_S that meshgen writes)
/// and writes the pictures into out_dir. Needs a usable X display (offscreen_display.hpp): call
/// display_problem() first, VTK aborts the process without one.
PicturesWritten write_mesh_pictures(const std::string& vtu_path, const std::string& out_dir,
                                    const PictureOptions& options);

/// A picture file of a mesh, as found on disk.
struct PictureFile {
  std::string caption;  ///< "well K: cut coloured by region" ...
  std::string path;
};

/// The pictures write_mesh_pictures writes that exist in dir, in its order (per well region then
/// Q_S, then the overview); wells are looked for from 0 up to the first index with neither picture.
std::vector<PictureFile> find_mesh_pictures(const std::string& dir);

/// "data:image/png;base64,..." holding the file's bytes (VTK's base64 encoder); "" when it cannot
/// be read.
std::string png_data_uri(const std::string& path);

}  // namespace hm
