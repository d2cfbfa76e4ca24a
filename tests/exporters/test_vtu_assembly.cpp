// The VTU reader's parallel mesh assembly (VtuAssembly::Parallel, docs/output-formats.md,
// "Reader") builds exactly MeshBuilder's mesh: same nodes, faces, numbering, owners, neighbours,
// patches, cell data and build report, for the examples and for any thread count; a file with an
// irregular face goes to MeshBuilder, which reports it (the pair's fail half).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <vector>
#include <cstdlib>
#include <string>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "exporters/vtu/vtu_reader.hpp"
#include "exporters/vtu/vtu_writer.hpp"
#include "meshgen/core/parallel.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"

namespace {

namespace fs = std::filesystem;

std::string vtu_bytes(const hm::PolyMesh& m, const std::string& label) {
  const fs::path p = fs::temp_directory_path() / ("hm_assembly_" + std::to_string(::getpid()) + "_" + label + ".vtu");
  const hm::WriteStatus ws = hm::write_vtu(p.string(), m);
  EXPECT_TRUE(ws.ok) << ws.message;
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  fs::remove(p);
  return ss.str();
}

void expect_same_mesh(const hm::ReadResult& a, const hm::ReadResult& b) {
  ASSERT_EQ(a.ok, b.ok) << a.error << " | " << b.error;
  EXPECT_EQ(a.error, b.error);
  const hm::PolyMesh &x = a.mesh, &y = b.mesh;
  ASSERT_EQ(x.nodes.size(), y.nodes.size());
  for (size_t i = 0; i < x.nodes.size(); ++i) ASSERT_TRUE(x.nodes[i] == y.nodes[i]) << "node " << i;
  EXPECT_EQ(x.face_node_ptr, y.face_node_ptr);
  EXPECT_EQ(x.face_nodes, y.face_nodes);
  EXPECT_EQ(x.face_owner, y.face_owner);
  EXPECT_EQ(x.face_neighbour, y.face_neighbour);
  EXPECT_EQ(x.face_patch, y.face_patch);
  EXPECT_EQ(x.cell_face_ptr, y.cell_face_ptr);
  EXPECT_EQ(x.cell_faces, y.cell_faces);
  EXPECT_EQ(x.cell_region, y.cell_region);
  EXPECT_EQ(x.cell_ijk, y.cell_ijk);
  EXPECT_EQ(x.cell_porosity, y.cell_porosity);
  ASSERT_EQ(x.cell_fv_center.size(), y.cell_fv_center.size());
  for (size_t c = 0; c < x.cell_fv_center.size(); ++c) ASSERT_TRUE(x.cell_fv_center[c] == y.cell_fv_center[c]);
  EXPECT_EQ(a.build.ok, b.build.ok);
  EXPECT_EQ(a.build.unmatched_faces, b.build.unmatched_faces);
  EXPECT_EQ(a.build.overused_faces, b.build.overused_faces);
  EXPECT_EQ(a.build.misoriented_faces, b.build.misoriented_faces);
  EXPECT_EQ(a.build.degenerate_faces, b.build.degenerate_faces);
  EXPECT_EQ(a.build.removed_unused_nodes, b.build.removed_unused_nodes);
  EXPECT_EQ(a.build.problems, b.build.problems);
}

class VtuAssembly : public ::testing::TestWithParam<const char*> {};

TEST_P(VtuAssembly, ParallelAssemblyIsMeshBuildersMeshForAnyThreadCount) {
  if (std::string(GetParam()) == "three_wells" && std::getenv("HM_LONG_TESTS") == nullptr)
    GTEST_SKIP() << "three_wells: run with HM_LONG_TESTS=1";
  const hm::CaseSpec cs = hm::load_case(std::string(HM_SOURCE_DIR) + "/examples/" + GetParam() + ".yaml");
  const hm::HybridMesh h = hm::build_hybrid_mesh(cs);
  const std::string bytes = vtu_bytes(h.mesh, GetParam());
  const hm::ReadResult serial = hm::read_vtu_buffer(bytes, hm::VtuAssembly::Serial);
  ASSERT_TRUE(serial.ok) << serial.error;
  EXPECT_FALSE(serial.assembled_in_parallel);
  EXPECT_TRUE(serial.build.ok);
  EXPECT_EQ(serial.mesh.n_cells(), h.mesh.n_cells());
  for (int threads : {1, 2, 0}) {
    SCOPED_TRACE(threads);
    const hm::ThreadLimit limit(threads);
    const hm::ReadResult parallel = hm::read_vtu_buffer(bytes, hm::VtuAssembly::Parallel);
    EXPECT_TRUE(parallel.assembled_in_parallel);
    expect_same_mesh(parallel, serial);
  }
}

INSTANTIATE_TEST_SUITE_P(Examples, VtuAssembly, ::testing::Values("paper_single_well", "three_wells"));

// Two stacked unit cubes as an ASCII VTU with face_patch; `upper_bottom` is the upper cube's
// cycle of the shared face.
std::string two_cubes(const std::string& upper_bottom) {
  std::ostringstream pts;
  for (int i = 0; i < 12; ++i) pts << i % 2 << ' ' << (i / 2) % 2 << ' ' << i / 4 << ' ';
  const std::string faces = "6 4 0 2 3 1 4 4 5 7 6 4 0 1 5 4 4 2 6 7 3 4 0 4 6 2 4 1 3 7 5 "
                            "6 4 " + upper_bottom + " 4 8 9 11 10 4 4 5 9 8 4 6 10 11 7 4 4 8 10 6 4 5 7 11 9";
  return "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
         "header_type=\"UInt64\">\n<UnstructuredGrid>\n<FieldData><DataArray type=\"Int32\" Name=\"face_patch\" "
         "NumberOfTuples=\"12\" format=\"ascii\">0 -1 0 0 0 0 -1 0 0 0 0 0</DataArray></FieldData>\n"
         "<Piece NumberOfPoints=\"12\" NumberOfCells=\"2\">\n<Points><DataArray type=\"Float64\" "
         "NumberOfComponents=\"3\" format=\"ascii\">" + pts.str() + "</DataArray></Points>\n<Cells>\n"
         "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0 1 2 3 4 5 6 7 4 5 6 7 8 9 10 11</DataArray>\n"
         "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">8 16</DataArray>\n"
         "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">42 42</DataArray>\n"
         "<DataArray type=\"Int64\" Name=\"faces\" format=\"ascii\">" + faces + "</DataArray>\n"
         "<DataArray type=\"Int64\" Name=\"faceoffsets\" format=\"ascii\">31 62</DataArray>\n"
         "</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
}

// Pass/fail pair: the regular file is assembled without problems; with the shared face named by
// both cubes in the same orientation (irregular), both assemblies give MeshBuilder's report of
// it, not a quietly different mesh.
TEST(VtuAssemblyIrregular, RegularAndMisorientedFilesGiveMeshBuildersResult) {
  const std::string good = two_cubes("4 6 7 5"), bad = two_cubes("4 5 7 6");
  const hm::ReadResult g = hm::read_vtu_buffer(good);
  ASSERT_TRUE(g.ok) << g.error;
  EXPECT_TRUE(g.build.ok);
  EXPECT_EQ(g.mesh.n_faces(), 11);
  EXPECT_EQ(g.mesh.n_cells(), 2);
  EXPECT_TRUE(g.assembled_in_parallel);
  expect_same_mesh(g, hm::read_vtu_buffer(good, hm::VtuAssembly::Serial));
  const hm::ReadResult b = hm::read_vtu_buffer(bad);
  EXPECT_FALSE(b.build.ok);
  EXPECT_EQ(b.build.misoriented_faces, 1);
  EXPECT_FALSE(b.assembled_in_parallel);
  expect_same_mesh(b, hm::read_vtu_buffer(bad, hm::VtuAssembly::Serial));
}

// A fan of 32 tetrahedra around point 0 (a ring of 16 points, one above, one below) as an ASCII
// VTU with face_patch: point 0 is the smallest point of 96 file faces, so the assembly matches
// that group by sorting it (groups of more than 32 faces) rather than pairwise. `flip` reverses
// the cycle of tetrahedron 0's face towards tetrahedron 1 (both then name it in one orientation).
std::string tet_fan(bool flip) {
  const int n = 16;
  std::ostringstream pts;
  pts << "0 0 0 ";
  for (int i = 0; i < n; ++i) pts << std::cos(2 * M_PI * i / n) << ' ' << std::sin(2 * M_PI * i / n) << " 0 ";
  pts << "0 0 1 0 0 -1";
  const int top = n + 1, bottom = n + 2;
  std::vector<std::array<int, 4>> tets;  // positively oriented (a, b, c, d)
  for (int i = 0; i < n; ++i) tets.push_back({0, 1 + i, 1 + (i + 1) % n, top});
  for (int i = 0; i < n; ++i) tets.push_back({0, 1 + (i + 1) % n, 1 + i, bottom});
  std::vector<std::vector<int>> faces;  // outward cycles, 4 per tetrahedron
  for (const auto& t : tets) {
    const int a = t[0], b = t[1], c = t[2], d = t[3];
    for (const std::vector<int>& f : {std::vector<int>{a, c, b}, {a, b, d}, {b, c, d}, {a, d, c}}) faces.push_back(f);
  }
  if (flip) std::reverse(faces[3].begin(), faces[3].end());  // tet 0's face (0, top, 2), shared with tet 1
  std::map<std::vector<int>, int> uses;
  for (std::vector<int> f : faces) std::sort(f.begin(), f.end()), ++uses[f];
  std::ostringstream stream, patch, conn, offsets, types, faceoffsets;
  size_t stream_size = 0;
  for (size_t t = 0; t < tets.size(); ++t) {
    stream << "4 ";
    ++stream_size;
    for (int k = 0; k < 4; ++k) {
      std::vector<int> f = faces[4 * t + k];
      stream << "3 " << f[0] << ' ' << f[1] << ' ' << f[2] << ' ';
      stream_size += 4;
      std::sort(f.begin(), f.end());
      patch << (uses[f] == 2 ? -1 : 0) << ' ';
      conn << tets[t][k] << ' ';
    }
    offsets << 4 * (t + 1) << ' ';
    types << "42 ";
    faceoffsets << stream_size << ' ';
  }
  return "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
         "header_type=\"UInt64\">\n<UnstructuredGrid>\n<FieldData><DataArray type=\"Int32\" Name=\"face_patch\" "
         "NumberOfTuples=\"" + std::to_string(faces.size()) + "\" format=\"ascii\">" + patch.str() +
         "</DataArray></FieldData>\n<Piece NumberOfPoints=\"" + std::to_string(n + 3) + "\" NumberOfCells=\"" +
         std::to_string(tets.size()) + "\">\n<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" "
         "format=\"ascii\">" + pts.str() + "</DataArray></Points>\n<Cells>\n"
         "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">" + conn.str() + "</DataArray>\n"
         "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">" + offsets.str() + "</DataArray>\n"
         "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">" + types.str() + "</DataArray>\n"
         "<DataArray type=\"Int64\" Name=\"faces\" format=\"ascii\">" + stream.str() + "</DataArray>\n"
         "<DataArray type=\"Int64\" Name=\"faceoffsets\" format=\"ascii\">" + faceoffsets.str() + "</DataArray>\n"
         "</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
}

// Pass/fail pair for a large group: the regular fan is assembled in parallel into MeshBuilder's
// mesh for any thread count; the flipped face sends the file to MeshBuilder, which reports it.
TEST(VtuAssemblyIrregular, FaceGroupsLargerThanPairwiseScanGiveMeshBuildersResult) {
  const std::string good = tet_fan(false), bad = tet_fan(true);
  const hm::ReadResult serial = hm::read_vtu_buffer(good, hm::VtuAssembly::Serial);
  ASSERT_TRUE(serial.ok) << serial.error;
  EXPECT_TRUE(serial.build.ok);
  EXPECT_EQ(serial.mesh.n_cells(), 32);
  EXPECT_EQ(serial.mesh.n_faces(), 32 * 4 - 48);  // 16 + 16 + 16 shared faces around the axis
  for (int threads : {1, 2, 0}) {
    SCOPED_TRACE(threads);
    const hm::ThreadLimit limit(threads);
    const hm::ReadResult g = hm::read_vtu_buffer(good);
    EXPECT_TRUE(g.assembled_in_parallel);
    expect_same_mesh(g, serial);
  }
  const hm::ReadResult b = hm::read_vtu_buffer(bad);
  EXPECT_FALSE(b.build.ok);
  EXPECT_EQ(b.build.misoriented_faces, 1);
  EXPECT_FALSE(b.assembled_in_parallel);
  expect_same_mesh(b, hm::read_vtu_buffer(bad, hm::VtuAssembly::Serial));
}

}  // namespace
