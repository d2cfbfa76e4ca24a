// meshgen --png: the pictures decode (VTK's PNG reader), have the requested size and show what they
// claim: the region cut has each region's colour in plausible amounts, the radial block near the
// middle of the frame; the Q_S cut is a colour map, not a flat image. Plus the refusal without a
// display. meshgen itself re-runs under xvfb-run when DISPLAY is unset (offscreen_display.hpp).
#include <gtest/gtest.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>

#include "../e2e/run_command.hpp"
#include "exporters/png/mesh_pictures.hpp"
#include "small_case.hpp"

namespace fs = std::filesystem;
using hm_test::fresh_dir;
using hm_test::q;
using hm_test::run_command;

namespace {

const std::string kMeshgen = std::string(HM_BIN_DIR) + "/meshgen";
const std::string kFvcheck = std::string(HM_BIN_DIR) + "/fvcheck";

size_t occurrences(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + what.size())) ++n;
  return n;
}

using hm::test::kSmallCase;

struct Image {
  int width = 0, height = 0, components = 0;
  std::vector<std::array<uint8_t, 3>> rgb;  // row 0 = bottom (VTK's order)
  const std::array<uint8_t, 3>& at(int x, int y) const { return rgb[static_cast<size_t>(y) * width + x]; }
};

/// Decodes a PNG with VTK's reader; width 0 when it does not decode.
Image read_png(const fs::path& p) {
  Image im;
  vtkNew<vtkPNGReader> r;
  if (!r->CanReadFile(p.string().c_str())) return im;
  r->SetFileName(p.string().c_str());
  r->Update();
  vtkImageData* d = r->GetOutput();
  int dims[3];
  d->GetDimensions(dims);
  im.width = dims[0];
  im.height = dims[1];
  im.components = d->GetNumberOfScalarComponents();
  if (im.components < 3 || d->GetScalarType() != VTK_UNSIGNED_CHAR) return im;
  const auto* px = static_cast<const uint8_t*>(d->GetScalarPointer());
  im.rgb.resize(static_cast<size_t>(im.width) * im.height);
  for (size_t i = 0; i < im.rgb.size(); ++i)
    for (int c = 0; c < 3; ++c) im.rgb[i][c] = px[i * im.components + c];
  return im;
}

/// Pixels of each region's exact colour in the picture's left 80 % (the legend is on the right).
struct RegionCounts {
  std::array<int64_t, 3> count{0, 0, 0};
  int64_t white = 0, total = 0;
  double radial_x = 0, radial_y = 0;  ///< mean position of the radial pixels, fraction of the size
};
RegionCounts count_region_colours(const Image& im) {
  RegionCounts rc;
  const hm::RegionColours& col = hm::region_colours();
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width * 8 / 10; ++x) {
      const auto& p = im.at(x, y);
      ++rc.total;
      if (p[0] == 255 && p[1] == 255 && p[2] == 255) ++rc.white;
      for (int r = 0; r < 3; ++r)
        if (p[0] == col.rgb[r][0] && p[1] == col.rgb[r][1] && p[2] == col.rgb[r][2]) {
          ++rc.count[r];
          if (r == hm::kWell) rc.radial_x += x, rc.radial_y += y;
        }
    }
  if (rc.count[hm::kWell] > 0) {
    rc.radial_x /= rc.count[hm::kWell] * static_cast<double>(im.width);
    rc.radial_y /= rc.count[hm::kWell] * static_cast<double>(im.height);
  }
  return rc;
}

/// What a region cut must show: every region in plausible amounts, the radial block near the middle.
::testing::AssertionResult shows_the_three_regions(const Image& im) {
  const RegionCounts rc = count_region_colours(im);
  if (rc.total == 0) return ::testing::AssertionFailure() << "empty image";
  const double f_res = double(rc.count[hm::kReservoir]) / rc.total, f_tr = double(rc.count[hm::kTransition]) / rc.total,
               f_well = double(rc.count[hm::kWell]) / rc.total, f_white = double(rc.white) / rc.total;
  std::ostringstream what;
  what << "reservoir " << f_res << ", transition " << f_tr << ", radial " << f_well << ", white " << f_white
       << ", radial centre (" << rc.radial_x << ", " << rc.radial_y << ")";
  if (f_res < 0.05 || f_tr < 0.05 || f_well < 0.005 || f_white > 0.5 || rc.radial_x < 0.25 || rc.radial_x > 0.75 ||
      rc.radial_y < 0.25 || rc.radial_y > 0.75)
    return ::testing::AssertionFailure() << what.str();
  return ::testing::AssertionSuccess() << what.str();
}

size_t distinct_colours(const Image& im) {
  std::set<uint32_t> s;
  for (const auto& p : im.rgb) s.insert(uint32_t(p[0]) << 16 | uint32_t(p[1]) << 8 | p[2]);
  return s.size();
}

}  // namespace

TEST(MeshPictures, MeshgenPngWritesPicturesThatShowTheRegionsAndQs) {
  const fs::path d = fresh_dir("pictures");
  hm_test::RemoveAtExit cleanup{d};
  std::ofstream(d / "case.yaml") << kSmallCase;
  const auto r = run_command(kMeshgen + " " + q(d / "case.yaml") + " -o " + q(d / "out") + " --png-size 640x480", 300);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  for (const char* name : {"well_0_region.png", "well_0_qs.png", "overview.png"})
    EXPECT_NE(r.out.find((d / "out" / name).string()), std::string::npos) << name << " not listed:\n" << r.out;

  const Image region = read_png(d / "out" / hm::well_region_picture_name(0));
  ASSERT_EQ(region.width, 640);
  ASSERT_EQ(region.height, 480);
  const ::testing::AssertionResult regions = shows_the_three_regions(region);
  EXPECT_TRUE(regions);
  std::cout << "region picture: " << regions.message() << "\n";

  const Image qs = read_png(d / "out" / hm::well_qs_picture_name(0));
  ASSERT_EQ(qs.width, 640);
  ASSERT_EQ(qs.height, 480);
  EXPECT_GE(distinct_colours(qs), 12u);  // a colour map over many cells and the colour bar
  EXPECT_FALSE(shows_the_three_regions(qs)) << "the Q_S picture is coloured by region";

  const Image overview = read_png(d / "out" / hm::kOverviewPictureName);
  ASSERT_EQ(overview.width, 640);
  ASSERT_EQ(overview.height, 480);
  EXPECT_GE(distinct_colours(overview), 50u);  // lit cells, not a blank frame

  // fvcheck's HTML report embeds the three pictures beside the mesh (data: URIs, self-contained)...
  const fs::path html = d / "report.html";
  auto c = run_command(kFvcheck + " " + q(d / "out" / "mesh.vtu") + " --html " + q(html));
  EXPECT_EQ(c.exit_code, 0) << c.out << c.err;
  std::string page = hm_test::slurp(html);
  EXPECT_EQ(occurrences(page, "<img src='data:image/png;base64,"), 3u);
  EXPECT_NE(page.find("well 0: cut along its trajectory, coloured by Q_S"), std::string::npos);
  // ... but not pictures older than the mesh (they show an earlier mesh).
  fs::last_write_time(d / "out" / "mesh.vtu", fs::file_time_type::clock::now() + std::chrono::seconds(5));
  c = run_command(kFvcheck + " " + q(d / "out" / "mesh.vtu") + " --html " + q(html));
  page = hm_test::slurp(html);
  EXPECT_EQ(occurrences(page, "<img src="), 0u);
  EXPECT_NE(page.find("is older than the mesh file: not shown"), std::string::npos);
  // --png renders them beside the report (the mesh's time put back in the past first).
  fs::last_write_time(d / "out" / "mesh.vtu", fs::file_time_type::clock::now() - std::chrono::seconds(60));
  fs::create_directories(d / "fv");
  c = run_command(kFvcheck + " " + q(d / "out" / "mesh.vtu") + " --html " + q(d / "fv" / "report.html") + " --png", 300);
  EXPECT_EQ(c.exit_code, 0) << c.out << c.err;
  EXPECT_EQ(read_png(d / "fv" / hm::kOverviewPictureName).width, 1200);
  EXPECT_EQ(occurrences(hm_test::slurp(d / "fv" / "report.html"), "<img src='data:image/png;base64,"), 3u);
}

// A horizontal well whose cavity fills its thin layer top to bottom: the vertical plane through it
// cuts no reservoir cell near the well, so the cut is the horizontal plane (a map view), which
// shows all three regions.
TEST(MeshPictures, HorizontalWellInAThinLayerIsCutInTheHorizontalPlane) {
  const fs::path d = fresh_dir("pictures_thin");
  hm_test::RemoveAtExit cleanup{d};
  std::ofstream(d / "case.yaml") << R"(name: thin
reservoir:
  x: [0, 6, 12, 18, 24, 30, 36, 42, 48]
  y: [0, 6, 12, 18, 24, 30, 36, 42, 48]
  z: [1000, 1002.5, 1005, 1007.5, 1010]
  permeability: [100, 100, 10]
  porosity: 0.2
  initial_pressure: 200
wells:
  - name: H1
    trajectory: [[-10, 24, 1005], [58, 24, 1005]]
    radius: 0.1
    drainage_radius: 4
    rings: 3
    sectors: 12
    segment_length: 6
    bhp: 150
    end_caps: flat
)";
  const auto r = run_command(kMeshgen + " " + q(d / "case.yaml") + " -o " + q(d / "out") + " --png-size 640x480", 300);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const Image region = read_png(d / "out" / hm::well_region_picture_name(0));
  ASSERT_EQ(region.width, 640);
  const ::testing::AssertionResult regions = shows_the_three_regions(region);
  EXPECT_TRUE(regions);
  std::cout << "thin-layer region picture: " << regions.message() << "\n";
}

TEST(MeshPictures, TheRegionCheckFailsOnABlankOrSingleRegionImage) {
  Image blank;
  blank.width = 100, blank.height = 100;
  blank.rgb.assign(100 * 100, {255, 255, 255});
  EXPECT_FALSE(shows_the_three_regions(blank));
  Image reservoir_only = blank;
  const unsigned char* c = hm::region_colours().rgb[hm::kReservoir];
  for (auto& p : reservoir_only.rgb) p = {c[0], c[1], c[2]};
  EXPECT_FALSE(shows_the_three_regions(reservoir_only));
}

TEST(MeshPictures, WithoutDisplayOrXvfbRunMeshgenStopsBeforeMeshingWithExit1) {
  const fs::path d = fresh_dir("pictures_nodisplay");
  hm_test::RemoveAtExit cleanup{d};
  std::ofstream(d / "case.yaml") << kSmallCase;
  // No DISPLAY and a PATH without xvfb-run: a clear refusal naming the stage, nothing meshed.
  const auto r = run_command("env -u DISPLAY PATH=/nonexistent " + kMeshgen + " " + q(d / "case.yaml") + " -o " +
                             q(d / "out") + " --png");
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.err.find("stage pictures"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("xvfb"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(d / "out" / "mesh.vtu"));
  // Bad size: exit 2, before anything else.
  const auto bad = run_command(kMeshgen + " " + q(d / "case.yaml") + " -o " + q(d / "out") + " --png-size 10x10");
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_NE(bad.err.find("--png-size"), std::string::npos) << bad.err;
  const auto no_html = run_command(kFvcheck + " " + q(d / "case.yaml") + " --png");
  EXPECT_EQ(no_html.exit_code, 2) << no_html.err;
  EXPECT_NE(no_html.err.find("--png needs --html"), std::string::npos) << no_html.err;
}
