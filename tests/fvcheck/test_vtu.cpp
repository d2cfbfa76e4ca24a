// VTU writer and reader: exact round trip, every supported encoding, faces read as the file
// orients them (a reversed face fails the checks), and malformed files (which must give an
// error, never a crash or a hang).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <sstream>

#include "exporters/vtu/vtu_reader.hpp"
#include "exporters/vtu/vtu_writer.hpp"
#include "fvcheck/lib/report.hpp"
#include "fv_test_meshes.hpp"

using namespace hm;
using namespace fvtest;
namespace fs = std::filesystem;

namespace {

fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("hm_vtu_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string hm_slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}


// ------------------------------------------------------------ an independent mini VTU encoder
enum class Fmt { Ascii, BinaryJoint, BinarySplit, AppendedRaw, AppendedBase64 };

struct Arr {
  std::string name, type;
  int comps = 1, elem = 8;
  std::string bytes;  // host (little-endian) order
  std::string ascii;
};

template <class T>
Arr arr(const std::string& name, const std::string& type, int comps, const std::vector<T>& v) {
  Arr a;
  a.name = name;
  a.type = type;
  a.comps = comps;
  a.elem = sizeof(T);
  a.bytes.assign(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  std::ostringstream os;
  os.precision(17);
  for (const T& x : v) os << +x << ' ';
  a.ascii = os.str();
  return a;
}

std::string b64(const std::string& in) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string o;
  size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const uint32_t w = (uint8_t(in[i]) << 16) | (uint8_t(in[i + 1]) << 8) | uint8_t(in[i + 2]);
    o += t[w >> 18];
    o += t[(w >> 12) & 63];
    o += t[(w >> 6) & 63];
    o += t[w & 63];
  }
  if (i + 1 == in.size()) {
    const uint32_t w = uint8_t(in[i]) << 16;
    o += t[w >> 18];
    o += t[(w >> 12) & 63];
    o += "==";
  } else if (i + 2 == in.size()) {
    const uint32_t w = (uint8_t(in[i]) << 16) | (uint8_t(in[i + 1]) << 8);
    o += t[w >> 18];
    o += t[(w >> 12) & 63];
    o += t[(w >> 6) & 63];
    o += '=';
  }
  return o;
}

std::string swap_elems(const std::string& s, int elem) {
  std::string o = s;
  for (size_t i = 0; i + elem <= o.size(); i += elem) std::reverse(o.begin() + i, o.begin() + i + elem);
  return o;
}

struct RawGrid {
  std::vector<double> pts;
  std::vector<int64_t> conn, offsets, faces, faceoffsets;
  std::vector<uint8_t> types;
  std::vector<int32_t> region;
  std::vector<double> center;
  int n_points() const { return static_cast<int>(pts.size() / 3); }
  int n_cells() const { return static_cast<int>(types.size()); }
};

std::string make_vtu(const RawGrid& g, Fmt fmt, bool header64, bool big_endian) {
  std::vector<Arr> points{arr("Points", "Float64", 3, g.pts)};
  std::vector<Arr> cells{arr("connectivity", "Int64", 1, g.conn), arr("offsets", "Int64", 1, g.offsets),
                         arr("types", "UInt8", 1, g.types)};
  if (!g.faces.empty()) {
    cells.push_back(arr("faces", "Int64", 1, g.faces));
    cells.push_back(arr("faceoffsets", "Int64", 1, g.faceoffsets));
  }
  std::vector<Arr> data;
  if (!g.region.empty()) data.push_back(arr("region", "Int32", 1, g.region));
  if (!g.center.empty()) data.push_back(arr("fv_center", "Float32", 3, std::vector<float>(g.center.begin(), g.center.end())));
  auto header = [&](uint64_t n) {
    std::string h;
    if (header64) h.assign(reinterpret_cast<const char*>(&n), 8);
    else {
      const uint32_t m = static_cast<uint32_t>(n);
      h.assign(reinterpret_cast<const char*>(&m), 4);
    }
    return big_endian ? swap_elems(h, static_cast<int>(h.size())) : h;
  };
  std::string appended;
  std::ostringstream x;
  auto emit = [&](const Arr& a) {
    const std::string body = big_endian ? swap_elems(a.bytes, a.elem) : a.bytes;
    x << "<DataArray type=\"" << a.type << "\" Name=\"" << a.name << "\" NumberOfComponents=\"" << a.comps << "\" ";
    switch (fmt) {
      case Fmt::Ascii: x << "format=\"ascii\">\n" << a.ascii << "\n</DataArray>\n"; break;
      case Fmt::BinaryJoint: x << "format=\"binary\">\n" << b64(header(body.size()) + body) << "\n</DataArray>\n"; break;
      case Fmt::BinarySplit: x << "format=\"binary\">" << b64(header(body.size())) << b64(body) << "</DataArray>\n"; break;
      case Fmt::AppendedRaw:
        x << "format=\"appended\" offset=\"" << appended.size() << "\"/>\n";
        appended += header(body.size()) + body;
        break;
      case Fmt::AppendedBase64:
        x << "format=\"appended\" offset=\"" << appended.size() << "\"/>\n";
        appended += b64(header(body.size()) + body);
        break;
    }
  };
  x << "<?xml version=\"1.0\"?>\n<!-- test file -->\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\""
    << (big_endian ? "BigEndian" : "LittleEndian") << "\" header_type=\"" << (header64 ? "UInt64" : "UInt32")
    << "\">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"" << g.n_points() << "\" NumberOfCells=\"" << g.n_cells()
    << "\">\n<Points>\n";
  for (const Arr& a : points) emit(a);
  x << "</Points>\n<Cells>\n";
  for (const Arr& a : cells) emit(a);
  x << "</Cells>\n<CellData>\n";
  for (const Arr& a : data) emit(a);
  x << "</CellData>\n</Piece>\n</UnstructuredGrid>\n";
  if (fmt == Fmt::AppendedRaw || fmt == Fmt::AppendedBase64)
    x << "<AppendedData encoding=\"" << (fmt == Fmt::AppendedRaw ? "raw" : "base64") << "\">\n _" << appended
      << "\n</AppendedData>\n";
  x << "</VTKFile>\n";
  return x.str();
}

// Two unit cubes along x: cell 0 a VTK_HEXAHEDRON, cell 1 a VTK_POLYHEDRON with outward faces.
RawGrid two_cubes() {
  RawGrid g;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 3; ++i) g.pts.insert(g.pts.end(), {double(i), double(j), double(k)});
  auto P = [](int i, int j, int k) { return int64_t(k * 6 + j * 3 + i); };
  // Hexahedron: VTK order (bottom counter-clockwise, then top).
  g.conn = {P(0, 0, 0), P(1, 0, 0), P(1, 1, 0), P(0, 1, 0), P(0, 0, 1), P(1, 0, 1), P(1, 1, 1), P(0, 1, 1)};
  g.offsets = {8};
  g.types = {12};
  g.faceoffsets = {-1};
  const std::vector<std::vector<int64_t>> f{
      {P(1, 0, 1), P(1, 1, 1), P(1, 1, 0), P(1, 0, 0)},  // x = 1, outward (-x)
      {P(2, 0, 0), P(2, 1, 0), P(2, 1, 1), P(2, 0, 1)},  // x = 2, outward (+x)
      {P(1, 0, 0), P(2, 0, 0), P(2, 0, 1), P(1, 0, 1)},  // y = 0, outward (-y)
      {P(1, 1, 0), P(1, 1, 1), P(2, 1, 1), P(2, 1, 0)},  // y = 1, outward (+y)
      {P(1, 1, 0), P(2, 1, 0), P(2, 0, 0), P(1, 0, 0)},  // z = 0, outward (-z)
      {P(1, 0, 1), P(2, 0, 1), P(2, 1, 1), P(1, 1, 1)}}; // z = 1, outward (+z)
  std::vector<int64_t> conn1;
  g.faces.push_back(6);
  for (const auto& face : f) {
    g.faces.push_back(static_cast<int64_t>(face.size()));
    for (int64_t v : face) {
      g.faces.push_back(v);
      if (std::find(conn1.begin(), conn1.end(), v) == conn1.end()) conn1.push_back(v);
    }
  }
  g.conn.insert(g.conn.end(), conn1.begin(), conn1.end());
  g.offsets.push_back(static_cast<int64_t>(g.conn.size()));
  g.types.push_back(42);
  g.faceoffsets.push_back(static_cast<int64_t>(g.faces.size()));
  g.region = {0, 1};
  g.center = {0.5, 0.5, 0.5, 1.5, 0.25, 0.5};
  return g;
}

void expect_two_cubes(const ReadResult& r, const std::string& what) {
  ASSERT_TRUE(r.ok) << what << ": " << r.error;
  EXPECT_TRUE(r.build.ok) << what;
  const PolyMesh& m = r.mesh;
  EXPECT_EQ(m.n_cells(), 2) << what;
  EXPECT_EQ(m.n_faces(), 11) << what;
  EXPECT_EQ(m.n_nodes(), 12) << what;
  EXPECT_TRUE(check_csr_invariants(m).ok) << what;
  const MeshGeometry g = compute_geometry(m);
  EXPECT_NEAR(g.cell_volume[0], 1.0, 1e-14) << what;
  EXPECT_NEAR(g.cell_volume[1], 1.0, 1e-14) << what;
  for (int c = 0; c < 2; ++c) EXPECT_LT(norm(cell_area_sum(m, g, c)), 1e-14) << what;
  EXPECT_EQ(m.cell_region[1], 1) << what;
  EXPECT_TRUE(m.cell_fv_center[1] == (Vec3{1.5, 0.25, 0.5})) << what;
}

// A cell's faces as seen from it: canonical outward cycle, orientation flag and what lies beyond
// (neighbour cell or boundary patch), sorted. Equal for two meshes that differ only in face and
// node-cycle numbering.
std::vector<std::tuple<std::vector<int32_t>, bool, int32_t, int32_t>> cell_signature(const PolyMesh& m, int c) {
  std::vector<std::tuple<std::vector<int32_t>, bool, int32_t, int32_t>> out;
  for (const int32_t* fp = m.cell_begin(c); fp != m.cell_end(c); ++fp) {
    const int f = *fp, k = m.face_size(f);
    std::vector<int32_t> cyc(m.face_begin(f), m.face_end(f));
    if (m.face_owner[f] != c)
      for (int i = 0; i < k; ++i) cyc[i] = m.face_begin(f)[(k - i) % k];
    bool rev = false;
    std::vector<int32_t> key = canonical_cycle(cyc, &rev);
    const int32_t beyond = m.face_owner[f] == c ? m.face_neighbour[f] : m.face_owner[f];
    out.emplace_back(std::move(key), rev, beyond, m.face_patch[f]);
  }
  std::sort(out.begin(), out.end());
  return out;
}

// Every per-cell field and every cell's faces are identical (face ids may be renumbered).
void expect_same_mesh(const PolyMesh& q, const PolyMesh& m) {
  ASSERT_EQ(q.n_cells(), m.n_cells());
  EXPECT_EQ(q.n_faces(), m.n_faces());
  EXPECT_TRUE(std::equal(q.nodes.begin(), q.nodes.end(), m.nodes.begin(), m.nodes.end()));
  EXPECT_EQ(q.cell_region, m.cell_region);
  EXPECT_EQ(q.cell_ijk, m.cell_ijk);
  EXPECT_EQ(q.cell_porosity, m.cell_porosity);
  EXPECT_EQ(q.cell_pore_volume_mult, m.cell_pore_volume_mult);  // empty stays empty
  EXPECT_EQ(q.nnc_cells, m.nnc_cells);
  EXPECT_EQ(q.nnc_trans, m.nnc_trans);
  for (int c = 0; c < m.n_cells(); ++c) {
    EXPECT_TRUE(q.cell_fv_center[c] == m.cell_fv_center[c]) << c;
    EXPECT_TRUE(q.cell_perm[c] == m.cell_perm[c]) << c;
    const RadialCellInfo &a = q.cell_radial[c], &b = m.cell_radial[c];
    EXPECT_TRUE(a.well == b.well && a.ring == b.ring && a.sector == b.sector && a.segment == b.segment &&
                a.band == b.band && a.r_in == b.r_in && a.r_out == b.r_out && a.r_center == b.r_center &&
                a.angle == b.angle && a.length == b.length && a.cap_center == b.cap_center)
        << c;
    EXPECT_EQ(cell_signature(q, c), cell_signature(m, c)) << c;
  }
}

// The cells of m in a builder, those in `split` with their first outer-boundary quad cut in two
// triangles (one of them a wellbore face): polyhedra of seven faces, hanging-node free.
// Attributes: region and FV centre as in m, radial.well = the cell's index.
MeshBuilder with_a_boundary_face_split(const PolyMesh& m, const std::set<int>& split) {
  MeshBuilder mb;
  for (const Vec3& p : m.nodes) mb.add_node(p);
  for (int c = 0; c < m.n_cells(); ++c) {
    std::vector<CellFace> faces;
    bool cut = false;
    for (const int32_t* fp = m.cell_begin(c); fp != m.cell_end(c); ++fp) {
      const int f = *fp, k = m.face_size(f);
      CellFace cf;
      for (int i = 0; i < k; ++i) cf.nodes.push_back(m.face_owner[f] == c ? m.face_begin(f)[i] : m.face_begin(f)[(k - i) % k]);
      cf.patch = m.face_neighbour[f] >= 0 ? kInteriorFace : m.face_patch[f];
      if (!cut && split.count(c) && m.face_neighbour[f] < 0 && k == 4 && cf.patch == kOuterBoundary) {
        faces.push_back({{cf.nodes[0], cf.nodes[1], cf.nodes[2]}, wellbore_patch(1)});
        faces.push_back({{cf.nodes[0], cf.nodes[2], cf.nodes[3]}, kOuterBoundary});
        cut = true;
        continue;
      }
      faces.push_back(cf);
    }
    CellAttributes at;
    at.region = m.cell_region[c];
    at.fv_center = m.cell_fv_center[c];
    at.radial.well = c;
    mb.add_cell(faces, at);
  }
  return mb;
}

}  // namespace

// ------------------------------------------------------------ writer + reader round trip
TEST(VtuRoundTrip, TopologyCoordinatesAndArraysAreIdentical) {
  PolyMesh m = box_grid(3, 2, 2, true);
  // Distinct coordinates that are not exactly representable in decimal, and one wellbore face.
  for (Vec3& p : m.nodes) p = {p.x * 0.1 + 1e5 / 3.0, p.y * 0.7 + 0.3, 1000 + p.z * 1.0 / 3.0};
  for (int c = 0; c < m.n_cells(); ++c) m.cell_fv_center[c] = compute_geometry(m).cell_centroid[c];
  int wb = -1;
  for (int f = 0; f < m.n_faces() && wb < 0; ++f)
    if (m.face_neighbour[f] < 0) wb = f;
  m.face_patch[wb] = wellbore_patch(0);
  // Every per-cell field set to something that is not its default.
  for (int c = 0; c < m.n_cells(); ++c) {
    m.cell_ijk[c] = {c, 2 * c, 3 * c};
    m.cell_perm[c] = {100.0 / 3 + c, 0.1 * c, 1e-3};
    m.cell_porosity[c] = 0.1 + c / 7.0;
    m.cell_pore_volume_mult.resize(m.n_cells());
    m.cell_pore_volume_mult[c] = c % 3 == 0 ? 1000.0 / 3 : 1.0;
    RadialCellInfo& r = m.cell_radial[c];
    r = {c % 2, c, c + 1, c + 2, 0.1 * c, 0.2 + c, 1.0 / 3, 2 * M_PI / 7, 0.7, c % 3 - 1, Vec3{1.0 / 3, 2, c + 0.5}};
  }
  // Connections without a face (a model's NNC), values not exact in decimal.
  m.nnc_cells = {{0, m.n_cells() - 1}, {5, 2}};
  m.nnc_trans = {1.0 / 3, 7e-5};
  const MeshGeometry g = compute_geometry(m);

  const fs::path d = temp_dir("roundtrip");
  const std::string path = (d / "mesh.vtu").string();
  const WriteStatus st = write_vtu(path, m, {VtuCellArray::real("volume", 1, g.cell_volume)});
  ASSERT_TRUE(st.ok) << st.message;
  EXPECT_FALSE(fs::exists(path + ".tmp"));
  // Hexahedra go out as VTK_HEXAHEDRON (issue 13), without a polyhedron face stream.
  const std::string text = hm_slurp(path);
  EXPECT_EQ(text.find("Name=\"faces\""), std::string::npos);

  const ReadResult r = read_vtu(path);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_TRUE(r.build.ok);
  EXPECT_TRUE(r.has_region && r.has_fv_center && r.has_face_patch && r.has_radial);
  EXPECT_TRUE(r.missing_mesh_arrays.empty());
  expect_same_mesh(r.mesh, m);
  const VtuCellArray* vol = r.find("volume");
  ASSERT_NE(vol, nullptr);
  EXPECT_EQ(vol->values, g.cell_volume);
  fs::remove_all(d);
}

TEST(VtuRoundTrip, PolyhedraAndHexahedraTogether) {
  // A box grid whose first cell is split into two prisms: polyhedra beside hexahedra, and
  // face_patch must follow each type's face order.
  PolyMesh m = box_grid(2, 2, 1, true);
  for (int f = 0; f < m.n_faces(); ++f)
    if (m.face_neighbour[f] < 0 && f % 3 == 0) m.face_patch[f] = wellbore_patch(f % 2);
  // Turn cell 0 into a polyhedron by rotating one face's cycle: still a hexahedron for VTK. So
  // instead give it a seventh face by cutting a boundary face in two (a hanging-free split).
  MeshBuilder mb = with_a_boundary_face_split(m, {0});
  BuildReport br;
  const PolyMesh q = mb.finish(&br);
  ASSERT_TRUE(br.ok);
  const fs::path d = temp_dir("mixed");
  const std::string path = (d / "mesh.vtu").string();
  ASSERT_TRUE(write_vtu(path, q).ok);
  const std::string text = hm_slurp(path);
  EXPECT_NE(text.find("Name=\"faces\""), std::string::npos);
  const ReadResult r = read_vtu(path);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_TRUE(r.build.ok);
  expect_same_mesh(r.mesh, q);
  fs::remove_all(d);
}

// The writer builds the topology in chunks of cells in parallel (16384 cells each) and shifts each
// chunk's offsets by the chunks before it: a mesh of several chunks with polyhedra in the first, a
// middle and the last one, between hexahedra, and a multiplier on every face; read back, the same
// mesh and multipliers.
TEST(VtuRoundTrip, CellsInSeveralChunksKeepTheirOffsets) {
  const PolyMesh grid = box_grid(40, 30, 30, true);
  ASSERT_GT(grid.n_cells(), 2 * 16384);
  BuildReport br;
  PolyMesh q = with_a_boundary_face_split(grid, {0, 20000, grid.n_cells() - 1}).finish(&br);
  ASSERT_TRUE(br.ok);
  q.face_trans_mult.resize(q.n_faces());
  for (int f = 0; f < q.n_faces(); ++f) q.face_trans_mult[f] = 1.0 + f / 3.0;
  const fs::path d = temp_dir("chunks");
  const std::string path = (d / "mesh.vtu").string();
  ASSERT_TRUE(write_vtu(path, q).ok);
  const ReadResult r = read_vtu(path);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_TRUE(r.build.ok);
  expect_same_mesh(r.mesh, q);
  // Each face's multiplier, matched by its nodes.
  std::map<std::vector<int32_t>, double> mult;
  auto key_of = [](const PolyMesh& m, int f) {
    std::vector<int32_t> k(m.face_begin(f), m.face_end(f));
    std::sort(k.begin(), k.end());
    return k;
  };
  for (int f = 0; f < q.n_faces(); ++f) mult[key_of(q, f)] = q.face_trans_mult[f];
  ASSERT_EQ(r.mesh.face_trans_mult.size(), static_cast<size_t>(r.mesh.n_faces()));
  int differ = 0;
  for (int f = 0; f < r.mesh.n_faces(); ++f) differ += mult.at(key_of(r.mesh, f)) != r.mesh.face_trans_mult[f];
  EXPECT_EQ(differ, 0);
  fs::remove_all(d);
}

// Triangular prisms (the cells of a hemispherical cap's rings) go out as VTK_WEDGE (13), whose
// parametric centre is the cell's own (a polyhedron's is its bounding-box centre, which VTK 9.1's
// validator uses: docs/output-formats.md), with face_patch in vtkWedge's face order; read back, the
// same mesh. A box cut along a diagonal plane into two prisms, one boundary face per prism a wellbore.
TEST(VtuRoundTrip, TriangularPrismsAsWedges) {
  MeshBuilder mb;
  const Vec3 corner[8] = {{0, 0, 0}, {2, 0, 0}, {0, 3, 0}, {2, 3, 0}, {0, 0, 1}, {2, 0, 1}, {0, 3, 1}, {2, 3, 1}};
  for (const Vec3& p : corner) mb.add_node(p);
  // Prism A: bottom (0, 1, 2), top (4, 5, 6); prism B: bottom (1, 3, 2), top (5, 7, 6); shared quad 1-2-6-5.
  const std::vector<CellFace> a = {{{0, 2, 1}, kOuterBoundary}, {{4, 5, 6}, kOuterBoundary}, {{0, 1, 5, 4}, wellbore_patch(0)},
                                   {{1, 2, 6, 5}, kInteriorFace}, {{0, 4, 6, 2}, kOuterBoundary}};
  const std::vector<CellFace> b = {{{1, 2, 3}, kOuterBoundary}, {{5, 7, 6}, kOuterBoundary}, {{1, 3, 7, 5}, kOuterBoundary},
                                   {{3, 2, 6, 7}, wellbore_patch(1)}, {{2, 1, 5, 6}, kInteriorFace}};
  CellAttributes at;
  at.fv_center = {0.6, 1, 0.5};
  mb.add_cell(a, at);
  at.fv_center = {1.4, 2, 0.5};
  mb.add_cell(b, at);
  BuildReport br;
  const PolyMesh m = mb.finish(&br);
  ASSERT_TRUE(br.ok);
  const MeshGeometry g = compute_geometry(m);
  EXPECT_NEAR(g.cell_volume[0] + g.cell_volume[1], 6.0, 1e-12);
  const fs::path d = temp_dir("wedges");
  const std::string path = (d / "mesh.vtu").string();
  ASSERT_TRUE(write_vtu(path, m).ok);
  EXPECT_EQ(hm_slurp(path).find("Name=\"faces\""), std::string::npos);  // no polyhedron
  const ReadResult r = read_vtu(path);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_TRUE(r.build.ok);
  expect_same_mesh(r.mesh, m);
  fs::remove_all(d);
}

TEST(VtuWriter, UnwritablePathGivesAStatusAndLeavesNoFile) {
  const PolyMesh m = box_grid(1, 1, 1);
  const WriteStatus a = write_vtu("/nonexistent_dir_hm/x.vtu", m);
  EXPECT_FALSE(a.ok);
  EXPECT_NE(a.message.find("cannot open"), std::string::npos) << a.message;
  // A directory as target: the temporary file is written but the rename fails.
  const fs::path d = temp_dir("unwritable");
  const WriteStatus b = write_vtu(d.string(), m);
  EXPECT_FALSE(b.ok);
  EXPECT_NE(b.message.find("rename"), std::string::npos) << b.message;
  EXPECT_FALSE(fs::exists(d.string() + ".tmp"));
  EXPECT_TRUE(fs::is_directory(d));
  fs::remove_all(d);
}

TEST(VtuWriter, RejectsBadArraysAndInvalidMeshes) {
  const PolyMesh m = box_grid(2, 1, 1);
  const fs::path d = temp_dir("bad_arrays");
  const std::string path = (d / "m.vtu").string();
  EXPECT_FALSE(write_vtu(path, m, {VtuCellArray::real("volume", 1, {1.0})}).ok);           // 1 value, 2 cells
  EXPECT_FALSE(write_vtu(path, m, {VtuCellArray::real("region", 1, {1.0, 2.0})}).ok);      // reserved name
  EXPECT_FALSE(write_vtu(path, m, {VtuCellArray::real("", 1, {1.0, 2.0})}).ok);
  PolyMesh broken = m;
  broken.face_nodes[0] = 99;
  const WriteStatus s = write_vtu(path, broken);
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("invalid mesh"), std::string::npos);
  EXPECT_FALSE(fs::exists(path));
  EXPECT_TRUE(write_vtu(path, m, {VtuCellArray::real("volume", 1, {1.0, 1.0})}).ok);
  fs::remove_all(d);
}

// ------------------------------------------------------------ reader: encodings
TEST(VtuReader, EveryEncodingHeaderTypeAndByteOrder) {
  const RawGrid g = two_cubes();
  for (Fmt f : {Fmt::Ascii, Fmt::BinaryJoint, Fmt::BinarySplit, Fmt::AppendedRaw, Fmt::AppendedBase64})
    for (bool h64 : {false, true})
      for (bool be : {false, true}) {
        if (f == Fmt::Ascii && (h64 || be)) continue;
        const std::string what = "format " + std::to_string(int(f)) + " h64 " + std::to_string(h64) + " be " + std::to_string(be);
        expect_two_cubes(read_vtu_buffer(make_vtu(g, f, h64, be)), what);
      }
}

TEST(VtuReader, MissingRegionAndCentreGetDefaults) {
  RawGrid g = two_cubes();
  g.region.clear();
  g.center.clear();
  const ReadResult r = read_vtu_buffer(make_vtu(g, Fmt::Ascii, false, false));
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_FALSE(r.has_region);
  EXPECT_FALSE(r.has_fv_center);
  EXPECT_EQ(r.mesh.cell_region, (std::vector<int32_t>{0, 0}));
  EXPECT_NEAR(r.mesh.cell_fv_center[1].x, 1.5, 1e-14);
  EXPECT_NEAR(r.mesh.cell_fv_center[1].y, 0.5, 1e-14);
}

// fvcheck reports, never repairs: the same file with one face's cycle reversed fails the checks.
TEST(VtuReader, OneReversedFaceFailsTheChecksTheOriginalPasses) {
  const RawGrid good = two_cubes();
  const ReadResult ok = read_vtu_buffer(make_vtu(good, Fmt::Ascii, false, false));
  ASSERT_TRUE(ok.ok) << ok.error;
  const FvReport pass = run_fvcheck(ok.mesh, {}, {}, &ok.build);
  EXPECT_TRUE(pass.ok()) << report_summary_text(pass);
  // Face k of the polyhedron (cell 1) reversed: k = 0 is the face shared with the hexahedron,
  // k = 1 a boundary face.
  for (int k : {0, 1}) {
    RawGrid g = good;
    size_t p = 1;
    for (int i = 0; i < k; ++i) p += 1 + static_cast<size_t>(g.faces[p]);
    const int64_t n = g.faces[p];
    std::reverse(g.faces.begin() + static_cast<long>(p) + 1, g.faces.begin() + static_cast<long>(p) + 1 + n);
    const ReadResult r = read_vtu_buffer(make_vtu(g, Fmt::Ascii, false, false));
    ASSERT_TRUE(r.ok) << r.error;
    const FvReport fail = run_fvcheck(r.mesh, {}, {}, &r.build);
    EXPECT_FALSE(fail.ok()) << "face " << k << "\n" << report_summary_text(fail);
    ASSERT_NE(fail.find("conformity"), nullptr);
    EXPECT_GT(fail.find("conformity")->violations, 0) << k;
  }
}

TEST(VtuReader, StandardCellTypesHaveExactVolumes) {
  struct Case {
    uint8_t type;
    std::vector<double> pts;
    double volume;
  };
  const std::vector<Case> cases{
      {10, {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1}, 1.0 / 6.0},
      {11, {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0, 0, 1, 1, 0, 1, 0, 1, 1, 1, 1, 1}, 1.0},
      {12, {0, 0, 0, 2, 0, 0, 2, 1, 0, 0, 1, 0, 0, 0, 3, 2, 0, 3, 2, 1, 3, 0, 1, 3}, 6.0},
      // VTK's wedge: (0, 1, 2) has its right-hand normal away from (3, 4, 5) (vtkCellSizeFilter
      // gives -1 and vtkCellValidator 'faces oriented incorrectly' for the mirrored order).
      {13, {0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 0, 2, 0, 1, 2, 1, 0, 2}, 1.0},
      {14, {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5, 0.5, 1}, 1.0 / 3.0}};
  for (const Case& c : cases) {
    RawGrid g;
    g.pts = c.pts;
    for (int i = 0; i < g.n_points(); ++i) g.conn.push_back(i);
    g.offsets = {static_cast<int64_t>(g.conn.size())};
    g.types = {c.type};
    const ReadResult r = read_vtu_buffer(make_vtu(g, Fmt::Ascii, false, false));
    ASSERT_TRUE(r.ok) << int(c.type) << ": " << r.error;
    const MeshGeometry geo = compute_geometry(r.mesh);
    EXPECT_NEAR(geo.cell_volume[0], c.volume, 1e-14) << int(c.type);
    EXPECT_LT(norm(cell_area_sum(r.mesh, geo, 0)), 1e-14) << int(c.type);
    EXPECT_TRUE(check_csr_invariants(r.mesh).ok);
  }
}

// ------------------------------------------------------------ reader: malformed input
// Field data nnc_cells / nnc_trans (connections without a face): read back when valid; a pair that is not
// two distinct cells of the file, a negative value or one array without the other refused with the reason.
TEST(VtuReader, ConnectionsWithoutAFaceAreCheckedOnRead) {
  const std::string grid = make_vtu(two_cubes(), Fmt::Ascii, false, false);
  auto with = [&](const std::string& cells, const std::string& trans) {
    std::string field = "<FieldData>";
    if (!cells.empty())
      field += "<DataArray type=\"Int32\" Name=\"nnc_cells\" NumberOfComponents=\"2\" NumberOfTuples=\"1\" "
               "format=\"ascii\">" + cells + "</DataArray>";
    if (!trans.empty())
      field += "<DataArray type=\"Float64\" Name=\"nnc_trans\" NumberOfTuples=\"1\" format=\"ascii\">" + trans +
               "</DataArray>";
    field += "</FieldData>";
    std::string t = grid;
    const size_t p = t.find("<UnstructuredGrid>");
    t.insert(p + std::string("<UnstructuredGrid>").size(), field);
    return read_vtu_buffer(t);
  };
  const ReadResult ok = with("0 1", "2.5");
  ASSERT_TRUE(ok.ok) << ok.error;
  ASSERT_EQ(ok.mesh.n_nncs(), 1);
  EXPECT_EQ(ok.mesh.nnc_cells[0], (std::array<int32_t, 2>{0, 1}));
  EXPECT_EQ(ok.mesh.nnc_trans[0], 2.5);
  for (const auto& [cells, trans, message] :
       std::vector<std::array<std::string, 3>>{{"1 1", "2.5", "not a pair of two distinct cells"},
                                               {"0 2", "2.5", "not a pair of two distinct cells"},
                                               {"0 1", "-1", "not a finite value >= 0"},
                                               {"0 1", "", "come together"}}) {
    const ReadResult r = with(cells, trans);
    EXPECT_FALSE(r.ok) << cells << " " << trans;
    EXPECT_NE(r.error.find(message), std::string::npos) << r.error;
  }
}

TEST(VtuReaderMalformed, ClearErrorsForBrokenFiles) {
  // Every case must fail with a one-line message; the messages of VTK's XML layer are VTK's,
  // the ones about ids and face streams are ours.
  auto err = [](const std::string& text) {
    const ReadResult r = read_vtu_buffer(text);
    EXPECT_FALSE(r.ok);
    EXPECT_FALSE(r.error.empty());
    EXPECT_EQ(r.error.find('\n'), std::string::npos) << r.error;
    return r.error;
  };
  EXPECT_EQ(err(""), "empty file");
  err("hello");
  err("<VTKFile type=\"PolyData\"></VTKFile>");
  err("<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid>");

  const RawGrid good = two_cubes();
  {  // a point id out of range in the faces stream
    RawGrid g = good;
    g.faces[2] = 99;
    const std::string e = err(make_vtu(g, Fmt::Ascii, false, false));
    EXPECT_NE(e.find("cell 1: point id 99 out of range [0, 12)"), std::string::npos) << e;
  }
  {  // negative id in connectivity of the hexahedron
    RawGrid g = good;
    g.conn[3] = -1;
    EXPECT_NE(err(make_vtu(g, Fmt::AppendedRaw, true, false)).find("out of range"), std::string::npos);
  }
  {  // faceoffsets beyond the faces array
    RawGrid g = good;
    g.faceoffsets[1] = 1000;
    err(make_vtu(g, Fmt::Ascii, false, false));
  }
  {  // a face claiming more nodes than the stream holds
    RawGrid g = good;
    g.faces[1] = 40;
    err(make_vtu(g, Fmt::Ascii, false, false));
  }
  {  // decreasing offsets
    RawGrid g = good;
    g.offsets[1] = 3;
    err(make_vtu(g, Fmt::Ascii, false, false));
  }
  {  // wrong counts: NumberOfCells far larger than the arrays (must not allocate for it)
    std::string t = make_vtu(good, Fmt::AppendedRaw, true, false);
    const size_t p = t.find("NumberOfCells=\"2\"");
    ASSERT_NE(p, std::string::npos);
    t.replace(p, 17, "NumberOfCells=\"2000000000\"");
    err(t);
  }
  {  // an appended offset past the end
    std::string t = make_vtu(good, Fmt::AppendedRaw, false, false);
    const size_t p = t.find("offset=\"0\"");
    ASSERT_NE(p, std::string::npos);
    t.replace(p, 10, "offset=\"999999\"");
    err(t);
  }
  {  // missing faceoffsets for polyhedra
    std::string t = make_vtu(good, Fmt::Ascii, false, false);
    const size_t p = t.find("Name=\"faceoffsets\"");
    t.replace(p, 18, "Name=\"faceoffsetz\"");
    err(t);
  }
  {  // unsupported cell type
    RawGrid g = good;
    g.types[0] = 7;
    EXPECT_NE(err(make_vtu(g, Fmt::Ascii, false, false)).find("unsupported VTK cell type 7"), std::string::npos);
  }
}

TEST(VtuReaderMalformed, EveryTruncationFailsCleanly) {
  for (Fmt f : {Fmt::AppendedRaw, Fmt::AppendedBase64, Fmt::BinaryJoint, Fmt::Ascii}) {
    const std::string full = make_vtu(two_cubes(), f, f == Fmt::AppendedRaw, false);
    ASSERT_TRUE(read_vtu_buffer(full).ok);
    // The appended sections end with the data; after it only closing tags follow, which a
    // reader of appended data does not need. Every cut before the end of the data must fail.
    const size_t data_end = f == Fmt::AppendedRaw || f == Fmt::AppendedBase64 ? full.rfind("\n</AppendedData>") : full.size() - std::strlen("</VTKFile>\n");
    for (size_t cut = 0; cut < data_end; ++cut) {
      const ReadResult r = read_vtu_buffer(full.substr(0, cut));
      EXPECT_FALSE(r.ok) << "format " << int(f) << " cut at " << cut;
      EXPECT_FALSE(r.error.empty());
    }
  }
}

TEST(VtuReaderMalformed, RandomByteCorruptionNeverCrashes) {
  // Deterministic fuzzing: single and multiple byte changes of valid files. The reader must
  // return (ok or a message) every time; ASan/UBSan builds check memory safety.
  std::mt19937 rng(12345);
  int failures = 0, runs = 0;
  for (Fmt f : {Fmt::AppendedRaw, Fmt::Ascii, Fmt::BinarySplit}) {
    const std::string full = make_vtu(two_cubes(), f, true, false);
    for (int k = 0; k < 1500; ++k) {
      std::string t = full;
      const int changes = 1 + static_cast<int>(rng() % 4);
      for (int c = 0; c < changes; ++c) t[rng() % t.size()] = static_cast<char>(rng() % 256);
      const ReadResult r = read_vtu_buffer(t);
      ++runs;
      if (!r.ok) {
        ++failures;
        EXPECT_FALSE(r.error.empty());
      } else {
        EXPECT_EQ(r.mesh.n_cells(), 2);
      }
    }
  }
  EXPECT_GT(failures, 0);
  EXPECT_EQ(runs, 4500);
}

TEST(VtuReader, MissingFileAndDirectoryGiveErrors) {
  const ReadResult a = read_vtu("/nonexistent_dir_hm/none.vtu");
  EXPECT_FALSE(a.ok);
  EXPECT_NE(a.error.find("cannot open"), std::string::npos);
  const ReadResult b = read_vtu(fs::temp_directory_path().string());
  EXPECT_FALSE(b.ok);
  EXPECT_NE(b.error.find("directory"), std::string::npos);
}

// The fuzz corpus: VTK's own files in six encodings read back as the same two cells; the
// regression inputs the fuzzer found (a forged compressed-block count that made VTK 9.1's
// vtkXMLDataParser allocate 2^62 bytes) fail with a message.
TEST(VtuReaderMalformed, FuzzCorpusSeedsAndRegressions) {
  int seeds = 0, regressions = 0;
  for (const auto& e : fs::directory_iterator(fs::path(HM_SOURCE_DIR) / "tests/fuzz/corpus_vtu")) {
    const ReadResult r = read_vtu(e.path().string());
    if (e.path().filename().string().rfind("regress_", 0) == 0) {
      EXPECT_FALSE(r.ok) << e.path();
      EXPECT_FALSE(r.error.empty());
      ++regressions;
    } else {
      ASSERT_TRUE(r.ok) << e.path() << ": " << r.error;
      EXPECT_EQ(r.mesh.n_cells(), 2);
      EXPECT_TRUE(r.build.ok && r.has_face_patch && r.has_region && r.has_fv_center) << e.path();
      EXPECT_NEAR(compute_geometry(r.mesh).cell_volume[1], 1.0, 1e-14);
      ++seeds;
    }
  }
  EXPECT_EQ(seeds, 6);
  EXPECT_GE(regressions, 1);
}
