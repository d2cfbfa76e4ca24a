#include "vtu_writer.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <algorithm>
#include <array>
#include <set>
#include <sstream>

#include "exporters/vtu/vtu_mesh_arrays.hpp"
#include "meshgen/core/fv_quality.hpp"
#include "meshgen/core/mesh_builder.hpp"
#include "meshgen/core/parallel.hpp"
#include "meshgen/core/text_file.hpp"

namespace hm {

namespace {

bool host_is_little_endian() {
  const uint16_t one = 1;
  unsigned char b;
  std::memcpy(&b, &one, 1);
  return b == 1;
}

// One appended block: the DataArray header line and views of the raw bytes (without the UInt64
// count), written one after the other; the bytes stay in the arrays they come from (no copy of the
// mesh, nor of the chunks the topology is built in).
struct Block {
  std::string type, name;
  int components = 1;
  int64_t tuples = -1;  // NumberOfTuples (field data only)
  std::vector<std::pair<const char*, size_t>> pieces;
  size_t size = 0;
  template <class T>
  void append(const std::vector<T>& v) {
    pieces.push_back({reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T)});
    size += v.size() * sizeof(T);
  }
};

template <class T>
Block make_block(const std::string& type, const std::string& name, int components, const std::vector<T>& v) {
  Block b;
  b.type = type;
  b.name = name;
  b.components = components;
  b.append(v);
  return b;
}

void header_line(std::ostringstream& xml, const Block& b, uint64_t offset, const char* indent) {
  xml << indent << "<DataArray type=\"" << b.type << "\" Name=\"" << xml_escape(b.name) << "\"";
  if (b.components != 1) xml << " NumberOfComponents=\"" << b.components << "\"";
  if (b.tuples >= 0) xml << " NumberOfTuples=\"" << b.tuples << "\"";
  xml << " format=\"appended\" offset=\"" << offset << "\"/>\n";
}

// A standard VTK cell type the writer uses for cells of its shape: its faces as local point indices,
// outward, in VTK's face order (vtkHexahedron, vtkWedge; the reader's tables), and its points as the
// "base" points (the outward cycle of VTK face `base_face`, reordered by `base`) followed by the base
// points' partners across the side edges.
struct StandardCell {
  uint8_t vtk_type;
  int n_points, n_faces, n_base, base_face;
  std::array<int, 4> base;  ///< point i (< n_base) is vertex base[i] of the base face's outward cycle
  std::array<std::array<int, 4>, 6> faces;
  std::array<int, 6> face_size;
};
constexpr StandardCell kHexahedron{
    12, 8, 6, 4, 4, {0, 3, 2, 1}, {{{0, 4, 7, 3}, {1, 2, 6, 5}, {0, 1, 5, 4}, {3, 7, 6, 2}, {0, 3, 2, 1}, {4, 5, 6, 7}}},
    {4, 4, 4, 4, 4, 4}};
constexpr StandardCell kWedge{13, 6, 5, 3, 0, {0, 1, 2, 0}, {{{0, 1, 2}, {3, 5, 4}, {0, 3, 4, 1}, {1, 4, 5, 2}, {2, 5, 3, 0}}},
                              {3, 3, 4, 4, 4, 0}};

// The canonical form of a cycle of 3 or 4 ids (smallest first, then its smaller neighbour), without
// allocation; `reversed` says whether that reverses it.
std::array<int32_t, 4> canonical_small_cycle(const int32_t* q, int k, bool* reversed) {
  const int s = static_cast<int>(std::min_element(q, q + k) - q);
  const bool rev = q[(s + k - 1) % k] < q[(s + 1) % k];
  std::array<int32_t, 4> out{-1, -1, -1, -1};
  for (int i = 0; i < k; ++i) out[i] = rev ? q[(s + k - i) % k] : q[(s + i) % k];
  *reversed = rev;
  return out;
}

// A cell whose outward faces are, cycle for cycle and orientation for orientation, the faces of
// `type` on distinct nodes: returns true with the point ids in VTK order and, for each VTK face k,
// the cell-local index of the face it is (`which[k]`). Combinatorial only: the geometry (planar or
// not) is the same whichever type is written. The cell's outward cycles are nodes[off[i] .. off[i + 1]).
bool as_standard_cell(const StandardCell& type, const std::vector<int32_t>& nodes, const std::vector<int>& off,
                      std::array<int32_t, 8>* pts, std::array<int, 6>* which) {
  const int n_faces = static_cast<int>(off.size()) - 1;
  if (n_faces != type.n_faces) return false;
  std::array<int, 6> sizes{};
  int triangles = 0, want_triangles = 0;
  for (int q = 0; q < n_faces; ++q) {
    sizes[q] = off[q + 1] - off[q];
    if (sizes[q] != 3 && sizes[q] != 4) return false;
    triangles += sizes[q] == 3;
    want_triangles += type.face_size[q] == 3;
  }
  if (triangles != want_triangles) return false;
  auto face = [&](int q) { return nodes.data() + off[q]; };
  // The base: the cell's first face of the base face's size, taken as that VTK face.
  int base_face = 0;
  while (sizes[base_face] != type.face_size[type.base_face]) ++base_face;
  const int32_t* b = face(base_face);
  std::array<int32_t, 8> p;
  p.fill(-1);
  for (int i = 0; i < type.n_base; ++i) p[i] = b[type.base[i]];
  const auto base_end = p.begin() + type.n_base;
  for (int i = 0; i < type.n_base; ++i) {
    // p[i + n_base]: the one node joined to p[i] by an edge that is not on the base face.
    for (int q = 0; q < n_faces; ++q) {
      const int32_t* f = face(q);
      for (int e = 0; e < sizes[q]; ++e) {
        const int32_t u = f[e], v = f[(e + 1) % sizes[q]];
        const int32_t other = u == p[i] ? v : v == p[i] ? u : -1;
        if (other < 0 || std::find(p.begin(), base_end, other) != base_end) continue;
        if (p[i + type.n_base] >= 0 && p[i + type.n_base] != other) return false;
        p[i + type.n_base] = other;
      }
    }
    if (p[i + type.n_base] < 0) return false;
  }
  for (int i = 0; i < type.n_points; ++i)
    for (int j = 0; j < i; ++j)
      if (p[i] == p[j]) return false;
  std::array<std::array<int32_t, 4>, 6> keys;
  std::array<bool, 6> revs{};
  for (int q = 0; q < n_faces; ++q) keys[q] = canonical_small_cycle(face(q), sizes[q], &revs[q]);
  for (int k = 0; k < n_faces; ++k) {
    int32_t cycle[4];
    for (int i = 0; i < type.face_size[k]; ++i) cycle[i] = p[type.faces[k][i]];
    bool rev = false;
    const std::array<int32_t, 4> key = canonical_small_cycle(cycle, type.face_size[k], &rev);
    int found = -1;
    for (int q = 0; q < n_faces && found < 0; ++q)
      if (sizes[q] == type.face_size[k] && keys[q] == key && revs[q] == rev) found = q;
    if (found < 0) return false;
    (*which)[k] = found;
  }
  *pts = p;
  return true;
}

// The topology arrays of a run of consecutive cells: offsets and faceoffsets from the run's start
// until write_vtu shifts them.
struct TopologyChunk {
  std::vector<int64_t> connectivity, offsets, faces, faceoffsets;
  std::vector<int32_t> face_patch;
  std::vector<double> face_mult;  // PolyMesh::face_trans_mult, in face_patch's order
};
constexpr size_t kCellsPerChunk = 16384;  // a fixed partition: the file does not depend on the threads

// A cell's outward cycles, flat (reused from cell to cell).
struct CellScratch {
  std::vector<int32_t> local;
  std::vector<int> local_off;
  std::vector<int32_t> local_patch;
  std::vector<double> local_mult;
};

// Appends cell c to `out` and sets its VTK type.
void append_cell_topology(const PolyMesh& m, int c, bool has_mult, CellScratch& s, TopologyChunk& out,
                          uint8_t& type) {
  s.local.clear();
  s.local_off.assign(1, 0);
  s.local_patch.clear();
  s.local_mult.clear();
  for (const int32_t* fp = m.cell_begin(c); fp != m.cell_end(c); ++fp) {
    const int f = *fp, k = m.face_size(f);
    const int32_t* v = m.face_begin(f);
    const bool own = m.face_owner[f] == c;
    // The neighbour sees the face reversed: v0, v_{k-1}, ..., v1.
    for (int i = 0; i < k; ++i) s.local.push_back(own ? v[i] : v[(k - i) % k]);
    s.local_off.push_back(static_cast<int>(s.local.size()));
    s.local_patch.push_back(m.face_neighbour[f] >= 0 ? kInteriorFace : m.face_patch[f]);
    if (has_mult) s.local_mult.push_back(m.face_trans_mult[f]);
  }
  std::array<int32_t, 8> pts{};
  std::array<int, 6> which{};
  const StandardCell* standard = nullptr;
  for (const StandardCell* t : {&kHexahedron, &kWedge})
    if (!standard && as_standard_cell(*t, s.local, s.local_off, &pts, &which)) standard = t;
  if (standard) {
    type = standard->vtk_type;
    out.connectivity.insert(out.connectivity.end(), pts.begin(), pts.begin() + standard->n_points);
    for (int k = 0; k < standard->n_faces; ++k) out.face_patch.push_back(s.local_patch[which[k]]);
    if (has_mult)
      for (int k = 0; k < standard->n_faces; ++k) out.face_mult.push_back(s.local_mult[which[k]]);
  } else {
    type = 42;
    const size_t first_point = out.connectivity.size();
    const size_t n_local = s.local_off.size() - 1;
    out.faces.push_back(static_cast<int64_t>(n_local));
    for (size_t q = 0; q < n_local; ++q) {
      out.faces.push_back(static_cast<int64_t>(s.local_off[q + 1] - s.local_off[q]));
      for (int i = s.local_off[q]; i < s.local_off[q + 1]; ++i) {
        const int32_t id = s.local[i];
        out.faces.push_back(id);
        // The cell's distinct nodes in first-use order: a few dozen at most, searched in place.
        if (std::find(out.connectivity.begin() + first_point, out.connectivity.end(), id) == out.connectivity.end())
          out.connectivity.push_back(id);
      }
      out.face_patch.push_back(s.local_patch[q]);
      if (has_mult) out.face_mult.push_back(s.local_mult[q]);
    }
  }
  out.offsets.push_back(static_cast<int64_t>(out.connectivity.size()));
  // VTK's faceoffsets: end of the cell's face stream, -1 for a cell that is not a polyhedron.
  out.faceoffsets.push_back(type == 42 ? static_cast<int64_t>(out.faces.size()) : -1);
}

}  // namespace

WriteStatus write_vtu(const std::string& path, const PolyMesh& m, const std::vector<VtuCellArray>& extra) {
  auto fail = [&](const std::string& why) { return WriteStatus{false, "write_vtu " + path + ": " + why}; };
  if (path.empty()) return WriteStatus{false, "write_vtu: empty path"};
  const CsrReport csr = check_csr_invariants(m);
  if (!csr.ok) return fail("invalid mesh: " + (csr.problems.empty() ? std::string("?") : csr.problems[0]));
  const size_t nc = static_cast<size_t>(m.n_cells());
  if (m.cell_fv_center.size() != nc) return fail("cell_fv_center has the wrong size");
  std::set<std::string> names;
  for (const VtuCellArray& a : extra) {
    if (a.name.empty()) return fail("a cell array has an empty name");
    if (is_mesh_array_name(a.name)) return fail("cell array name '" + a.name + "' is reserved for the mesh's own data");
    if (!names.insert(a.name).second) return fail("duplicate cell array name '" + a.name + "'");
    if (a.components < 1) return fail("cell array '" + a.name + "' must have >= 1 component");
    if (a.size() != nc * static_cast<size_t>(a.components))
      return fail("cell array '" + a.name + "' has " + std::to_string(a.size()) + " values, expected " +
                  std::to_string(nc * static_cast<size_t>(a.components)));
  }

  // Topology: hexahedra as VTK_HEXAHEDRON (12), triangular prisms as VTK_WEDGE (13); every other cell
  // as VTK_POLYHEDRON (42) with its distinct nodes in first-use order and its outward faces. face_patch
  // follows the faces as a reader sees them: the face stream of a polyhedron, VTK's face order otherwise.
  // Built in chunks of cells in parallel, each chunk's offsets then shifted by the chunks before it.
  std::vector<uint8_t> types(nc, 42);
  const bool has_mult = !m.face_trans_mult.empty();
  const int64_t n_chunks = static_cast<int64_t>((nc + kCellsPerChunk - 1) / kCellsPerChunk);
  std::vector<TopologyChunk> chunks(static_cast<size_t>(n_chunks));
  parallel_ranges(
      n_chunks,
      [&](int64_t first, int64_t last) {
        CellScratch scratch;
        for (int64_t k = first; k < last; ++k) {
          const size_t begin = static_cast<size_t>(k) * kCellsPerChunk, end = std::min(nc, begin + kCellsPerChunk);
          for (size_t c = begin; c < end; ++c)
            append_cell_topology(m, static_cast<int>(c), has_mult, scratch, chunks[k], types[c]);
        }
      },
      1);
  bool any_polyhedron = false;
  int64_t connectivity_base = 0, faces_base = 0;
  for (TopologyChunk& t : chunks) {
    for (int64_t& o : t.offsets) o += connectivity_base;
    for (int64_t& o : t.faceoffsets)
      if (o >= 0) o += faces_base;
    connectivity_base += static_cast<int64_t>(t.connectivity.size());
    faces_base += static_cast<int64_t>(t.faces.size());
    any_polyhedron = any_polyhedron || !t.faces.empty();
  }
  auto chunked_block = [&](const std::string& type, const std::string& name, auto member) {
    Block b;
    b.type = type;
    b.name = name;
    for (const TopologyChunk& t : chunks) b.append(t.*member);
    return b;
  };
  std::vector<double> points(3 * m.nodes.size());
  for (size_t i = 0; i < m.nodes.size(); ++i) {
    points[3 * i] = m.nodes[i].x;
    points[3 * i + 1] = m.nodes[i].y;
    points[3 * i + 2] = m.nodes[i].z;
  }
  Block field = chunked_block("Int32", "face_patch", &TopologyChunk::face_patch);
  field.tuples = static_cast<int64_t>(field.size / sizeof(int32_t));
  Block mult_field = chunked_block("Float64", "face_trans_mult", &TopologyChunk::face_mult);
  mult_field.tuples = static_cast<int64_t>(mult_field.size / sizeof(double));
  // The mesh's reservoir cells are a corner-point model's (PolyMesh::reservoir_cells_are_model).
  const std::vector<int32_t> one{1};
  Block model_field = make_block("Int32", "reservoir_cells_are_model", 1, one);
  model_field.tuples = 1;
  // Connections without a face (a model's NNC, its MINPV connections): cell ids and transmissibilities.
  const bool has_nnc = m.n_nncs() > 0;
  std::vector<int32_t> nnc_pairs;
  for (const auto& p : m.nnc_cells) nnc_pairs.insert(nnc_pairs.end(), p.begin(), p.end());
  Block nnc_cells_field = make_block("Int32", "nnc_cells", 2, nnc_pairs);
  nnc_cells_field.tuples = m.n_nncs();
  Block nnc_trans_field = make_block("Float64", "nnc_trans", 1, m.nnc_trans);
  nnc_trans_field.tuples = m.n_nncs();
  std::vector<Block> point_blocks{make_block("Float64", "Points", 3, points)};
  std::vector<Block> cell_blocks{chunked_block("Int64", "connectivity", &TopologyChunk::connectivity),
                                 chunked_block("Int64", "offsets", &TopologyChunk::offsets),
                                 make_block("UInt8", "types", 1, types)};
  if (any_polyhedron) {
    cell_blocks.push_back(chunked_block("Int64", "faces", &TopologyChunk::faces));
    cell_blocks.push_back(chunked_block("Int64", "faceoffsets", &TopologyChunk::faceoffsets));
  }
  std::vector<Block> data_blocks;
  const std::vector<VtuCellArray> own_arrays = mesh_cell_arrays(m);
  for (const VtuCellArray& a : own_arrays)
    data_blocks.push_back(a.integer ? make_block("Int32", a.name, a.components, a.ints)
                                    : make_block("Float64", a.name, a.components, a.values));
  for (const VtuCellArray& a : extra)
    data_blocks.push_back(a.integer ? make_block("Int32", a.name, a.components, a.ints)
                                    : make_block("Float64", a.name, a.components, a.values));

  // XML header with running offsets (each block is an 8-byte count followed by its bytes).
  std::ostringstream xml;
  uint64_t offset = 0;
  auto place = [&](const Block& b, const char* indent) {
    header_line(xml, b, offset, indent);
    offset += sizeof(uint64_t) + b.size;
  };
  xml << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\""
      << (host_is_little_endian() ? "LittleEndian" : "BigEndian") << "\" header_type=\"UInt64\">\n";
  xml << "  <UnstructuredGrid>\n    <FieldData>\n";
  place(field, "      ");
  if (has_mult) place(mult_field, "      ");
  if (m.reservoir_cells_are_model) place(model_field, "      ");
  if (has_nnc) place(nnc_cells_field, "      "), place(nnc_trans_field, "      ");
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
    const uint64_t n = b.size;
    out.write(reinterpret_cast<const char*>(&n), sizeof n);
    for (const auto& [data, size] : b.pieces) out.write(data, static_cast<std::streamsize>(size));
  };
  emit(field);
  if (has_mult) emit(mult_field);
  if (m.reservoir_cells_are_model) emit(model_field);
  if (has_nnc) emit(nnc_cells_field), emit(nnc_trans_field);
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

std::vector<VtuCellArray> mesh_file_quality_arrays(const PolyMesh& mesh, const MeshGeometry& geo,
                                                   const std::vector<int32_t>& cell_cavity,
                                                   const std::vector<double>& cell_h_ref) {
  return {VtuCellArray::int32("cavity", 1, cell_cavity),
          VtuCellArray::real("volume", 1, geo.cell_volume),
          VtuCellArray::real("h_ref", 1, cell_h_ref),
          VtuCellArray::real("Q_S", 1, cell_shape_quality(mesh, cell_h_ref)),
          VtuCellArray::real("Q_O", 1, cell_min_of_faces(mesh, face_orthogonality(mesh, geo))),
          VtuCellArray::real("Q_P", 1, cell_max_of_faces(mesh, face_planarity(mesh, geo)))};
}

}  // namespace hm
