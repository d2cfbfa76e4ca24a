#include "vtu_writer.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

#include "meshgen/core/mesh_builder.hpp"
#include "meshgen/core/text_file.hpp"

namespace hm {

namespace {

bool host_is_little_endian() {
  const uint16_t one = 1;
  unsigned char b;
  std::memcpy(&b, &one, 1);
  return b == 1;
}

// One appended block: the DataArray header line and the raw bytes (without the UInt64 count).
struct Block {
  std::string type, name;
  int components = 1;
  int64_t tuples = -1;  // NumberOfTuples (field data only)
  std::string bytes;
};

template <class T>
Block make_block(const std::string& type, const std::string& name, int components, const std::vector<T>& v) {
  Block b;
  b.type = type;
  b.name = name;
  b.components = components;
  b.bytes.assign(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  return b;
}

void header_line(std::ostringstream& xml, const Block& b, uint64_t offset, const char* indent) {
  xml << indent << "<DataArray type=\"" << b.type << "\" Name=\"" << xml_escape(b.name) << "\"";
  if (b.components != 1) xml << " NumberOfComponents=\"" << b.components << "\"";
  if (b.tuples >= 0) xml << " NumberOfTuples=\"" << b.tuples << "\"";
  xml << " format=\"appended\" offset=\"" << offset << "\"/>\n";
}

}  // namespace

WriteStatus write_vtu(const std::string& path, const PolyMesh& m, const std::vector<VtuCellArray>& extra) {
  auto fail = [&](const std::string& why) { return WriteStatus{false, "write_vtu " + path + ": " + why}; };
  if (path.empty()) return WriteStatus{false, "write_vtu: empty path"};
  const CsrReport csr = check_csr_invariants(m);
  if (!csr.ok) return fail("invalid mesh: " + (csr.problems.empty() ? std::string("?") : csr.problems[0]));
  const size_t nc = static_cast<size_t>(m.n_cells());
  if (m.cell_fv_center.size() != nc) return fail("cell_fv_center has the wrong size");
  std::set<std::string> names{"region", "fv_center"};
  for (const VtuCellArray& a : extra) {
    if (a.name.empty()) return fail("a cell array has an empty name");
    if (!names.insert(a.name).second) return fail("duplicate cell array name '" + a.name + "'");
    if (a.components < 1) return fail("cell array '" + a.name + "' must have >= 1 component");
    if (a.size() != nc * static_cast<size_t>(a.components))
      return fail("cell array '" + a.name + "' has " + std::to_string(a.size()) + " values, expected " +
                  std::to_string(nc * static_cast<size_t>(a.components)));
  }

  // Topology: distinct nodes of each cell in first-use order, and outward faces.
  std::vector<int64_t> connectivity, offsets, faces, faceoffsets;
  std::vector<uint8_t> types(nc, 42);
  std::vector<int32_t> face_patch;
  std::vector<int64_t> stamp(m.nodes.size(), -1);
  for (size_t c = 0; c < nc; ++c) {
    const int ci = static_cast<int>(c);
    faces.push_back(m.cell_face_ptr[c + 1] - m.cell_face_ptr[c]);
    for (const int32_t* fp = m.cell_begin(ci); fp != m.cell_end(ci); ++fp) {
      const int f = *fp, k = m.face_size(f);
      const int32_t* v = m.face_begin(f);
      faces.push_back(k);
      const bool own = m.face_owner[f] == ci;
      for (int i = 0; i < k; ++i) {
        // The neighbour sees the face reversed: v0, v_{k-1}, ..., v1.
        const int32_t id = own ? v[i] : v[(k - i) % k];
        faces.push_back(id);
        if (stamp[id] != static_cast<int64_t>(c)) {
          stamp[id] = static_cast<int64_t>(c);
          connectivity.push_back(id);
        }
      }
      face_patch.push_back(m.face_neighbour[f] >= 0 ? kInteriorFace : m.face_patch[f]);
    }
    offsets.push_back(static_cast<int64_t>(connectivity.size()));
    faceoffsets.push_back(static_cast<int64_t>(faces.size()));
  }
  std::vector<double> points(3 * m.nodes.size());
  for (size_t i = 0; i < m.nodes.size(); ++i) {
    points[3 * i] = m.nodes[i].x;
    points[3 * i + 1] = m.nodes[i].y;
    points[3 * i + 2] = m.nodes[i].z;
  }
  std::vector<double> center(3 * nc);
  for (size_t c = 0; c < nc; ++c) {
    center[3 * c] = m.cell_fv_center[c].x;
    center[3 * c + 1] = m.cell_fv_center[c].y;
    center[3 * c + 2] = m.cell_fv_center[c].z;
  }

  Block field = make_block("Int32", "face_patch", 1, face_patch);
  field.tuples = static_cast<int64_t>(face_patch.size());
  std::vector<Block> point_blocks{make_block("Float64", "Points", 3, points)};
  std::vector<Block> cell_blocks{make_block("Int64", "connectivity", 1, connectivity),
                                 make_block("Int64", "offsets", 1, offsets), make_block("UInt8", "types", 1, types),
                                 make_block("Int64", "faces", 1, faces),
                                 make_block("Int64", "faceoffsets", 1, faceoffsets)};
  std::vector<Block> data_blocks{make_block("Int32", "region", 1, m.cell_region), make_block("Float64", "fv_center", 3, center)};
  for (const VtuCellArray& a : extra)
    data_blocks.push_back(a.integer ? make_block("Int32", a.name, a.components, a.ints)
                                    : make_block("Float64", a.name, a.components, a.values));

  // XML header with running offsets (each block is an 8-byte count followed by its bytes).
  std::ostringstream xml;
  uint64_t offset = 0;
  auto place = [&](const Block& b, const char* indent) {
    header_line(xml, b, offset, indent);
    offset += sizeof(uint64_t) + b.bytes.size();
  };
  xml << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\""
      << (host_is_little_endian() ? "LittleEndian" : "BigEndian") << "\" header_type=\"UInt64\">\n";
  xml << "  <UnstructuredGrid>\n    <FieldData>\n";
  place(field, "      ");
  xml << "    </FieldData>\n    <Piece NumberOfPoints=\"" << m.nodes.size() << "\" NumberOfCells=\"" << nc << "\">\n";
  xml << "      <Points>\n";
  for (const Block& b : point_blocks) place(b, "        ");
  xml << "      </Points>\n      <Cells>\n";
  for (const Block& b : cell_blocks) place(b, "        ");
  xml << "      </Cells>\n      <CellData Scalars=\"region\">\n";
  for (const Block& b : data_blocks) place(b, "        ");
  xml << "      </CellData>\n    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _";

  const std::string tmp = path + ".tmp";
  std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
  if (!out) return fail(std::string("cannot open for writing: ") + std::strerror(errno));
  const std::string head = xml.str();
  out.write(head.data(), static_cast<std::streamsize>(head.size()));
  auto emit = [&](const Block& b) {
    const uint64_t n = b.bytes.size();
    out.write(reinterpret_cast<const char*>(&n), sizeof n);
    out.write(b.bytes.data(), static_cast<std::streamsize>(b.bytes.size()));
  };
  emit(field);
  for (const Block& b : point_blocks) emit(b);
  for (const Block& b : cell_blocks) emit(b);
  for (const Block& b : data_blocks) emit(b);
  out << "\n  </AppendedData>\n</VTKFile>\n";
  out.close();
  if (!out) {
    std::remove(tmp.c_str());
    return fail("write failed (disk full?)");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string why = std::strerror(errno);
    std::remove(tmp.c_str());
    return fail("cannot rename " + tmp + ": " + why);
  }
  return WriteStatus{};
}

}  // namespace hm
