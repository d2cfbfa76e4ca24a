// End-to-end: the fvcheck executable on hand-written ASCII .vtu files (independent of the
// project's writer): exit codes 0/1/2, the JSON report's documented shape, the HTML report.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>

#include "run_command.hpp"

namespace fs = std::filesystem;
using hm_test::fresh_dir;
using hm_test::q;
using hm_test::run_command;
using hm_test::slurp;

namespace {
const std::string kFvcheck = std::string(HM_BIN_DIR) + "/fvcheck";

struct Hex {
  double x0, x1, y0, y1, z0, z1;
  double cx, cy, cz;  // FV centre
  int region;
};

// ASCII VTU of axis-aligned boxes as VTK_HEXAHEDRON cells; equal coordinates share a point.
std::string ascii_vtu(const std::vector<Hex>& hexes) {
  std::vector<std::array<double, 3>> pts;
  std::vector<int> conn;
  auto point = [&](double x, double y, double z) {
    for (size_t i = 0; i < pts.size(); ++i)
      if (pts[i][0] == x && pts[i][1] == y && pts[i][2] == z) return static_cast<int>(i);
    pts.push_back({x, y, z});
    return static_cast<int>(pts.size() - 1);
  };
  for (const Hex& h : hexes) {
    const double xs[8] = {h.x0, h.x1, h.x1, h.x0, h.x0, h.x1, h.x1, h.x0};
    const double ys[8] = {h.y0, h.y0, h.y1, h.y1, h.y0, h.y0, h.y1, h.y1};
    const double zs[8] = {h.z0, h.z0, h.z0, h.z0, h.z1, h.z1, h.z1, h.z1};
    for (int k = 0; k < 8; ++k) conn.push_back(point(xs[k], ys[k], zs[k]));
  }
  std::ostringstream s;
  s.precision(17);
  s << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
       "<UnstructuredGrid><Piece NumberOfPoints=\""
    << pts.size() << "\" NumberOfCells=\"" << hexes.size()
    << "\">\n<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (const auto& p : pts) s << p[0] << ' ' << p[1] << ' ' << p[2] << '\n';
  s << "</DataArray></Points>\n<Cells><DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">\n";
  for (int v : conn) s << v << ' ';
  s << "\n</DataArray><DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">\n";
  for (size_t c = 1; c <= hexes.size(); ++c) s << 8 * c << ' ';
  s << "\n</DataArray><DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (size_t c = 0; c < hexes.size(); ++c) s << "12 ";
  s << "\n</DataArray></Cells>\n<CellData><DataArray type=\"Int32\" Name=\"region\" format=\"ascii\">\n";
  for (const Hex& h : hexes) s << h.region << ' ';
  s << "\n</DataArray><DataArray type=\"Float64\" Name=\"fv_center\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (const Hex& h : hexes) s << h.cx << ' ' << h.cy << ' ' << h.cz << '\n';
  s << "</DataArray></CellData></Piece></UnstructuredGrid></VTKFile>\n";
  return s.str();
}

std::vector<Hex> two_boxes() {
  return {{0, 1, 0, 1, 0, 1, 0.5, 0.5, 0.5, 0}, {1, 3, 0, 1, 0, 1, 2.0, 0.5, 0.5, 1}};
}

fs::path write(const fs::path& d, const std::string& name, const std::string& text) {
  std::ofstream(d / name) << text;
  return d / name;
}


}  // namespace

TEST(FvcheckCli, GoodMeshExitsZeroWithDocumentedJsonAndHtml) {
  const fs::path d = fresh_dir("fvcheck_good");
  const fs::path mesh = write(d, "good.vtu", ascii_vtu(two_boxes()));
  const auto r = run_command(kFvcheck + " " + q(mesh) + " --json " + q(d / "r.json") + " --html " + q(d / "r.html"));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  EXPECT_NE(r.out.find("result: OK"), std::string::npos) << r.out;
  const nlohmann::json j = nlohmann::json::parse(slurp(d / "r.json"));
  EXPECT_TRUE(j["ok"].get<bool>());
  EXPECT_EQ(j["cells"].get<int>(), 2);
  EXPECT_EQ(j["faces"].get<int>(), 11);
  for (const char* k : {"convexity", "conformity", "closure", "volume", "orthogonality", "auto_centering", "planarity"}) {
    ASSERT_TRUE(j["checks"].contains(k)) << k;
    EXPECT_EQ(j["checks"][k]["violations"].get<int>(), 0) << k;
    EXPECT_TRUE(j["checks"][k]["worst_ids"].is_array()) << k;
  }
  EXPECT_NEAR(j["checks"]["orthogonality"]["min_deg"].get<double>(), 90.0, 1e-9);
  EXPECT_NEAR(j["checks"]["planarity"]["max_deg"].get<double>(), 0.0, 1e-9);
  // Q_S of the 2 x 1 x 1 box with h = mean edge length 4/3: min(1/(4/3), (4/3)/2) = 2/3.
  EXPECT_NEAR(j["quality"]["Q_S"]["min"].get<double>(), 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(j["quality"]["Q_S"]["max"].get<double>(), 1.0, 1e-12);
  EXPECT_EQ(j["quality"]["by_region"]["transition"]["cells"].get<int>(), 1);
  EXPECT_TRUE(j["quality"]["by_region"]["reservoir"]["Q_O"].contains("mean"));
  ASSERT_TRUE(j.contains("transmissibility"));
  EXPECT_EQ(j["transmissibility"]["count"].get<int>(), 1);  // one interior face, no wellbore
  EXPECT_EQ(j["transmissibility"]["negative"].get<int>(), 0);
  const std::string html = slurp(d / "r.html");
  EXPECT_NE(html.find("<svg"), std::string::npos);
  EXPECT_NE(html.find("ALL CHECKS HOLD"), std::string::npos);
  EXPECT_FALSE(fs::exists(d / "r.json.tmp"));
}

TEST(FvcheckCli, CentreOutsideExitsOneAndNamesTheCell) {
  const fs::path d = fresh_dir("fvcheck_outside");
  std::vector<Hex> h = two_boxes();
  h[1].cx = 3.5;  // beyond the face x = 3
  const fs::path mesh = write(d, "bad.vtu", ascii_vtu(h));
  const auto r = run_command(kFvcheck + " " + q(mesh) + " --json " + q(d / "r.json") + " --html " + q(d / "r.html"));
  ASSERT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("FAILED"), std::string::npos);
  const nlohmann::json j = nlohmann::json::parse(slurp(d / "r.json"));
  EXPECT_FALSE(j["ok"].get<bool>());
  EXPECT_EQ(j["checks"]["auto_centering"]["violations"].get<int>(), 1);
  EXPECT_EQ(j["checks"]["auto_centering"]["worst_ids"][0].get<int>(), 1);
  EXPECT_EQ(j["checks"]["convexity"]["violations"].get<int>(), 0);
  EXPECT_NE(slurp(d / "r.html").find("Failed checks"), std::string::npos);
}

TEST(FvcheckCli, HangingNodesExitOne) {
  const fs::path d = fresh_dir("fvcheck_hanging");
  // A = [0,1]^3 against B and C, which split A's face x = 1 at z = 0.5.
  const std::vector<Hex> h{{0, 1, 0, 1, 0, 1, 0.5, 0.5, 0.5, 0},
                           {1, 2, 0, 1, 0, 0.5, 1.5, 0.5, 0.25, 0},
                           {1, 2, 0, 1, 0.5, 1, 1.5, 0.5, 0.75, 0}};
  const auto r = run_command(kFvcheck + " " + q(write(d, "h.vtu", ascii_vtu(h))) + " --json " + q(d / "r.json"));
  ASSERT_EQ(r.exit_code, 1) << r.out << r.err;
  const nlohmann::json j = nlohmann::json::parse(slurp(d / "r.json"));
  EXPECT_EQ(j["checks"]["conformity"]["counts"]["hanging_nodes"].get<int>(), 2);
  EXPECT_EQ(j["checks"]["conformity"]["worst_ids"][0].get<int>(), 0);
}

TEST(FvcheckCli, OrthogonalityThresholdOption) {
  const fs::path d = fresh_dir("fvcheck_ortho");
  // Centres (0.5,.25,.5) and (1.5,.75,.5) across x = 1: Q_O = asin(1/sqrt(1.25)) = 63.43 deg.
  const std::vector<Hex> h{{0, 1, 0, 1, 0, 1, 0.5, 0.25, 0.5, 0}, {1, 2, 0, 1, 0, 1, 1.5, 0.75, 0.5, 0}};
  const fs::path mesh = write(d, "o.vtu", ascii_vtu(h));
  EXPECT_EQ(run_command(kFvcheck + " " + q(mesh)).exit_code, 0);
  EXPECT_EQ(run_command(kFvcheck + " " + q(mesh) + " --min-orthogonality 60").exit_code, 0);
  const auto r = run_command(kFvcheck + " " + q(mesh) + " --min-orthogonality 70 --json " + q(d / "r.json"));
  EXPECT_EQ(r.exit_code, 1) << r.out;
  const nlohmann::json j = nlohmann::json::parse(slurp(d / "r.json"));
  EXPECT_NEAR(j["checks"]["orthogonality"]["min_deg"].get<double>(), std::asin(1 / std::sqrt(1.25)) * 180 / M_PI, 1e-9);
  EXPECT_EQ(j["checks"]["orthogonality"]["threshold_deg"].get<double>(), 70.0);
  EXPECT_EQ(run_command(kFvcheck + " " + q(mesh) + " --max-planarity 0").exit_code, 0);
}

TEST(FvcheckCli, UnreadableInputAndBadArgumentsExitTwoWithOneLine) {
  const fs::path d = fresh_dir("fvcheck_bad");
  const fs::path good = write(d, "good.vtu", ascii_vtu(two_boxes()));
  const fs::path garbage = write(d, "garbage.vtu", "this is not a mesh\n");
  std::string truncated = ascii_vtu(two_boxes());
  truncated.resize(truncated.size() / 2);
  const fs::path trunc = write(d, "trunc.vtu", truncated);
  const std::vector<std::string> cmds{
      kFvcheck,
      kFvcheck + " " + q(d / "missing.vtu"),
      kFvcheck + " " + q(garbage),
      kFvcheck + " " + q(trunc),
      kFvcheck + " " + q(good) + " --bogus",
      kFvcheck + " " + q(good) + " --min-orthogonality abc",
      kFvcheck + " " + q(good) + " --max-planarity 120",
      kFvcheck + " " + q(good) + " --json",
      kFvcheck + " " + q(good) + " " + q(good),
      kFvcheck + " " + q(good) + " --json " + q(d / "no_such_dir" / "r.json"),
  };
  for (const std::string& c : cmds) {
    const auto r = run_command(c);
    EXPECT_EQ(r.exit_code, 2) << c << "\n" << r.out << r.err;
    EXPECT_EQ(r.err.rfind("fvcheck: ", 0), 0u) << c << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c << ": " << r.err;
  }
  EXPECT_FALSE(fs::exists(d / "no_such_dir"));
}

// fvcheck reports what the file holds: VTK's own file of a hexahedron and a polyhedron passes;
// the same file with the cycle of the polyhedron's first face reversed fails conformity (exit
// 1), with no re-orientation note.
TEST(FvcheckCli, OneReversedFaceFailsTheSameFileUnreversedPasses) {
  const fs::path d = hm_test::fresh_dir("fvcheck_reversed");
  const std::string good = hm_test::slurp(std::string(HM_SOURCE_DIR) + "/tests/fuzz/corpus_vtu/ascii.vtu");
  const std::string stream = "6 4 7 10 4 1";
  const size_t p = good.find(stream);
  ASSERT_NE(p, std::string::npos);
  std::string bad = good;
  bad.replace(p, stream.size(), "6 4 1 4 10 7");
  const std::string fvcheck = std::string(HM_BIN_DIR) + "/fvcheck ";
  const auto ok = hm_test::run_command(fvcheck + hm_test::q(write(d, "good.vtu", good)));
  EXPECT_EQ(ok.exit_code, 0) << ok.out << ok.err;
  EXPECT_NE(ok.out.find("result: OK"), std::string::npos);
  const auto r = hm_test::run_command(fvcheck + hm_test::q(write(d, "bad.vtu", bad)) + " --html " +
                                      hm_test::q(d / "bad.html"));
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("conformity      FAILED"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("result: FAILED"), std::string::npos);
  EXPECT_EQ(r.out.find("re-oriented"), std::string::npos) << r.out;
  EXPECT_NE(hm_test::slurp(d / "bad.html").find("CHECKS FAILED"), std::string::npos);
}
