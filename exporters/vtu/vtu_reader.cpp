#include "vtu_reader.hpp"

#include <vtkBase64Utilities.h>
#include <vtkCommand.h>
#include <vtkDataCompressor.h>
#include <vtkLZ4DataCompressor.h>
#include <vtkLZMADataCompressor.h>
#include <vtkLogger.h>
#include <vtkNew.h>
#include <vtkOutputWindow.h>
#include <vtkSmartPointer.h>
#include <vtkStringOutputWindow.h>
#include <vtkType.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLDataParser.h>
#include <vtkZLibDataCompressor.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include "exporters/vtu/vtu_mesh_arrays.hpp"
#include "meshgen/core/geometry.hpp"
#include "meshgen/core/parallel.hpp"

namespace hm {

namespace {

// Internal failure: caught in convert() and turned into ReadResult::error.
struct VtuError {
  std::string what;
};
[[noreturn]] void fail(const std::string& what) { throw VtuError{what}; }

// Collects the reader's error and warning events (VTK reports a bad file that way, not by
// throwing or by a return code).
class MessageCatcher : public vtkCommand {
 public:
  static MessageCatcher* New() { return new MessageCatcher; }
  void Execute(vtkObject*, unsigned long event, void* data) override {
    std::string text = data ? static_cast<const char*>(data) : "";
    while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
    // VTK prefixes the source location ("... vtkXMLReader.cxx, line 123\n...: "): keep the reason.
    if (const size_t colon = text.rfind(": "); colon != std::string::npos) text = text.substr(colon + 2);
    std::replace(text.begin(), text.end(), '\n', ' ');
    if (text.empty()) text = "VTK reported an error without a message";
    (event == vtkCommand::ErrorEvent ? errors : warnings).push_back(text);
  }
  std::vector<std::string> errors, warnings;
};

// Routes VTK's global message window to a string while a file is read, so that messages of
// objects without an observer (the XML parser, the decompressors) are caught, not printed.
class QuietVtk {
 public:
  QuietVtk() : previous_(vtkOutputWindow::GetInstance()), verbosity_(vtkLogger::GetCurrentVerbosityCutoff()) {
    window_->SetDisplayModeToAlways();
    vtkOutputWindow::SetInstance(window_);
    vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
  }
  ~QuietVtk() {
    vtkOutputWindow::SetInstance(previous_);
    vtkLogger::SetStderrVerbosity(verbosity_);
  }
  QuietVtk(const QuietVtk&) = delete;
  QuietVtk& operator=(const QuietVtk&) = delete;
  std::string text() { return window_->GetOutput(); }

 private:
  vtkSmartPointer<vtkOutputWindow> previous_;
  vtkLogger::Verbosity verbosity_;
  vtkNew<vtkStringOutputWindow> window_;
};

// Faces of the linear VTK cells as local point indices, outward for a cell of positive VTK
// orientation (vtkTetra, vtkVoxel, vtkHexahedron, vtkWedge, vtkPyramid face order).
const std::vector<std::vector<int>>* standard_faces(int type, int* npts) {
  static const std::vector<std::vector<int>> tet{{0, 1, 3}, {1, 2, 3}, {2, 0, 3}, {0, 2, 1}};
  static const std::vector<std::vector<int>> voxel{{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                                   {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  static const std::vector<std::vector<int>> hex{{0, 4, 7, 3}, {1, 2, 6, 5}, {0, 1, 5, 4},
                                                 {3, 7, 6, 2}, {0, 3, 2, 1}, {4, 5, 6, 7}};
  static const std::vector<std::vector<int>> wedge{{0, 1, 2}, {3, 5, 4}, {0, 3, 4, 1}, {1, 4, 5, 2}, {2, 5, 3, 0}};
  static const std::vector<std::vector<int>> pyramid{{0, 3, 2, 1}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
  switch (type) {
    case 10: *npts = 4; return &tet;
    case 11: *npts = 8; return &voxel;
    case 12: *npts = 8; return &hex;
    case 13: *npts = 6; return &wedge;
    case 14: *npts = 5; return &pyramid;
    default: return nullptr;
  }
}

constexpr int64_t kMaxIds = std::numeric_limits<int32_t>::max() - 1;

// One decoded DataArray.
struct Array {
  std::string name;
  int components = 1;
  bool is_int = true;
  std::vector<int64_t> i;  // when is_int
  std::vector<double> d;   // otherwise
  size_t size() const { return is_int ? i.size() : d.size(); }
  double as_double(size_t k) const { return is_int ? static_cast<double>(i[k]) : d[k]; }
};

// The XML document and its data, decoded by VTK's vtkXMLDataParser (formats, base64, byte
// order, header type, compressors); everything it returns is checked here before use.
struct Source {
  vtkXMLDataParser* parser = nullptr;
  std::istream* stream = nullptr;  // the parser's; a read that hits its end means truncated data
  uint64_t max_words = 0;  // no array can hold more values than this (from the file size)
  uint64_t file_bytes = 0;
  bool compressed = false;
  int header_bytes = 8;        // header_type UInt64 (8) or UInt32 (4)
  bool swap = false;           // the file's byte order is not the host's
  bool appended_base64 = false;
};

std::string attr(vtkXMLDataElement* e, const char* name) {
  const char* v = e->GetAttribute(name);
  return v ? v : "";
}

// vtkXMLDataParser sizes its block tables and its decompression buffer from a compressed
// array's header (number of blocks, uncompressed block size, last block size, compressed sizes)
// before reading anything else: a forged header would allocate without limit inside VTK. So the header is read
// here (raw or base64, as the array is stored) and bounded before VTK sees them.
// `n` bytes stored at `pos` (raw) or base64-encoded from `pos` after `skip_chars` characters of
// an earlier base64 unit (whitespace ignored). Fails when the file ends first.
std::vector<unsigned char> read_bytes(const Source& src, std::streamoff pos, bool base64, size_t skip, size_t n) {
  std::istream& in = *src.stream;
  in.clear();
  std::vector<unsigned char> out(n + 3, 0);
  if (!base64) {
    in.seekg(pos + static_cast<std::streamoff>(skip));
    in.read(reinterpret_cast<char*>(out.data()), static_cast<std::streamsize>(n));
    if (in.gcount() != static_cast<std::streamsize>(n)) fail("the file ends inside the data (truncated?)");
  } else {
    in.seekg(pos);
    const size_t chars = (n + 2) / 3 * 4;
    std::vector<unsigned char> text;
    text.reserve(chars);
    size_t skipped = 0;
    while (text.size() < chars) {
      const int ch = in.get();
      if (ch == EOF) break;
      if (ch == ' ' || ch == '\n' || ch == '\r' || ch == '\t') continue;
      if (skipped < skip) {
        ++skipped;
        continue;
      }
      text.push_back(static_cast<unsigned char>(ch));
    }
    if (text.size() < chars || vtkBase64Utilities::DecodeSafely(text.data(), chars, out.data(), out.size()) < n)
      fail("the file ends inside the data (truncated or bad base64)");
  }
  in.clear();
  out.resize(n);
  return out;
}

uint64_t header_word(const Source& src, unsigned char* p) {
  if (src.swap) std::reverse(p, p + src.header_bytes);
  if (src.header_bytes == 4) {
    uint32_t v;
    std::memcpy(&v, p, 4);
    return v;
  }
  uint64_t v;
  std::memcpy(&v, p, 8);
  return v;
}

// Largest uncompressed block accepted (VTK writes 32 KiB blocks; ParaView too).
constexpr uint64_t kMaxCompressedBlockBytes = uint64_t(64) << 20;

// A compressed array, decompressed here with VTK's compressor classes (zlib, LZ4, LZMA) rather
// than by vtkXMLDataParser, which crashes on forged or corrupt compressed data (VTK 9.1: a
// 2^62-byte block table, a division by a zero block size, a null block after a failed
// decompression). Layout (VTK): header words [blocks, block size, last block size, compressed
// size of each block], then the compressed blocks; in base64 form the header and the blocks
// are two separately encoded units. Returns the first `needed` bytes, in host byte order for
// words of `word` bytes.
std::vector<unsigned char> read_compressed(const Source& src, vtkXMLDataElement* e, const std::string& format,
                                           int64_t offset, size_t needed, size_t word) {
  const std::string what = "array " + attr(e, "Name") + ": ";
  std::streamoff pos = 0;
  bool base64 = true;
  if (format == "appended") {
    pos = static_cast<std::streamoff>(src.parser->GetAppendedDataPosition()) + static_cast<std::streamoff>(offset);
    base64 = src.appended_base64;
  } else {
    std::istream& in = *src.stream;  // inline binary: the base64 text after the start tag
    in.clear();
    in.seekg(static_cast<std::streamoff>(e->GetXMLByteIndex()));
    int ch = 0;
    while ((ch = in.get()) != EOF && ch != '>') {
    }
    if (ch == EOF) fail(what + "no data");
    pos = in.tellg();
  }
  const size_t hb = static_cast<size_t>(src.header_bytes);
  std::vector<unsigned char> h = read_bytes(src, pos, base64, 0, 3 * hb);
  const uint64_t blocks = header_word(src, &h[0]), block = header_word(src, &h[hb]), last = header_word(src, &h[2 * hb]);
  if (blocks > src.file_bytes / hb) fail(what + std::to_string(blocks) + " compressed blocks cannot be in a file of this size");
  if (blocks > 0 && (block == 0 || block > kMaxCompressedBlockBytes || last > block))
    fail(what + "bad compressed block sizes " + std::to_string(block) + " / " + std::to_string(last));
  const size_t header_size = (3 + static_cast<size_t>(blocks)) * hb;
  h = read_bytes(src, pos, base64, 0, header_size);
  std::vector<uint64_t> csize(blocks);
  uint64_t total = 0;
  for (size_t k = 0; k < blocks; ++k) {
    csize[k] = header_word(src, &h[(3 + k) * hb]);
    if (csize[k] > src.file_bytes) fail(what + "a compressed block is larger than the file");
    total += csize[k];
  }
  if (total > src.file_bytes) fail(what + "the compressed blocks are larger than the file");
  auto usize = [&](size_t k) { return k + 1 == blocks && last > 0 ? last : block; };
  const uint64_t available = blocks == 0 ? 0 : (blocks - 1) * block + usize(blocks - 1);
  if (available < needed) fail(what + "the compressed data holds fewer values than expected");
  const std::vector<unsigned char> packed =
      read_bytes(src, pos, base64, base64 ? (header_size + 2) / 3 * 4 : header_size, static_cast<size_t>(total));
  vtkDataCompressor* z = src.parser->GetCompressor();
  if (!z) fail(what + "no decompressor");
  std::vector<unsigned char> out(needed);
  size_t done = 0, at = 0;
  std::vector<unsigned char> tmp;
  for (size_t k = 0; k < blocks && done < needed; ++k) {
    const size_t u = static_cast<size_t>(usize(k));
    tmp.assign(u, 0);
    if (z->Uncompress(packed.data() + at, static_cast<size_t>(csize[k]), tmp.data(), u) != u)
      fail(what + "corrupt compressed block " + std::to_string(k));
    const size_t take = std::min(u, needed - done);
    std::memcpy(out.data() + done, tmp.data(), take);
    done += take;
    at += static_cast<size_t>(csize[k]);
  }
  if (src.swap && word > 1)
    for (size_t k = 0; k + word <= out.size(); k += word) std::reverse(out.begin() + k, out.begin() + k + word);
  return out;
}

int64_t count_attr(vtkXMLDataElement* e, const char* name, int64_t max_value) {
  const std::string v = attr(e, name);
  if (v.empty()) fail(std::string("missing ") + name);
  int64_t n = -1;
  size_t used = 0;
  try {
    n = std::stoll(v, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != v.size() || n < 0 || n > max_value) fail(std::string("bad ") + name + " '" + v + "'");
  return n;
}

template <class T>
void convert_words(const T* w, size_t n, Array& a) {
  if (a.is_int) {
    a.i.resize(n);
    for (size_t k = 0; k < n; ++k) {
      if constexpr (std::is_same_v<T, unsigned long long> || std::is_same_v<T, unsigned long>) {
        if (w[k] > static_cast<T>(std::numeric_limits<int64_t>::max())) fail("array " + a.name + ": value too large");
      }
      a.i[k] = static_cast<int64_t>(w[k]);
    }
  } else {
    a.d.resize(n);
    for (size_t k = 0; k < n; ++k) a.d[k] = static_cast<double>(w[k]);
  }
}

// Decodes `values` words of a DataArray element (values = tuples x components).
Array read_array(const Source& src, vtkXMLDataElement* e, int64_t values) {
  Array a;
  a.name = attr(e, "Name");
  const std::string what = "array " + (a.name.empty() ? std::string("(unnamed)") : a.name) + ": ";
  if (e->GetAttribute("NumberOfComponents"))
    a.components = static_cast<int>(count_attr(e, "NumberOfComponents", 1 << 16));
  if (a.components < 1) fail(what + "NumberOfComponents must be >= 1");
  int type = 0;
  if (!e->GetWordTypeAttribute("type", type)) fail(what + "unknown type '" + attr(e, "type") + "'");
  switch (type) {
    case VTK_FLOAT: case VTK_DOUBLE: a.is_int = false; break;
    case VTK_CHAR: case VTK_SIGNED_CHAR: case VTK_UNSIGNED_CHAR: case VTK_SHORT: case VTK_UNSIGNED_SHORT:
    case VTK_INT: case VTK_UNSIGNED_INT: case VTK_LONG: case VTK_UNSIGNED_LONG: case VTK_LONG_LONG:
    case VTK_UNSIGNED_LONG_LONG: case VTK_ID_TYPE: a.is_int = true; break;
    default: fail(what + "unsupported type '" + attr(e, "type") + "'");
  }
  if (values < 0 || static_cast<uint64_t>(values) > src.max_words)
    fail(what + std::to_string(values) + " values cannot be in a file of this size");
  if (values == 0) return a;
  const size_t word = src.parser->GetWordTypeSize(type);
  const std::string format = attr(e, "format");
  const bool compressed = src.compressed && (format == "appended" || format == "binary");
  // Float64 and signed 64-bit words are the values' own type: VTK decodes them straight into the
  // array (no byte buffer, no conversion copy). Other types go through a buffer and convert_words.
  const bool direct = !compressed && ((!a.is_int && type == VTK_DOUBLE) ||
                                      (a.is_int && word == sizeof(int64_t) &&
                                       (type == VTK_LONG_LONG || type == VTK_ID_TYPE || type == VTK_LONG)));
  std::vector<unsigned char> buf;
  void* dst = nullptr;
  if (direct) {
    if (a.is_int) a.i.resize(static_cast<size_t>(values)), dst = a.i.data();
    else a.d.resize(static_cast<size_t>(values)), dst = a.d.data();
  } else if (!compressed) {
    buf.resize(static_cast<size_t>(values) * word);
    dst = buf.data();
  }
  size_t got = 0;
  if (compressed) {
    const int64_t offset =
        format == "appended" ? count_attr(e, "offset", std::numeric_limits<int64_t>::max() / 2) : 0;
    buf = read_compressed(src, e, format, offset, static_cast<size_t>(values) * word, word);
    got = static_cast<size_t>(values);
  } else if (format == "appended") {
    const int64_t offset = count_attr(e, "offset", std::numeric_limits<int64_t>::max() / 2);
    got = src.parser->ReadAppendedData(offset, dst, 0, static_cast<size_t>(values), type);
  } else if (format == "ascii" || format == "binary") {
    got = src.parser->ReadInlineData(e, format == "ascii", dst, 0, static_cast<size_t>(values), type);
  } else {
    fail(what + "unknown format '" + format + "'");
  }
  // vtkXMLDataParser reports the words asked for even when the stream ends inside them.
  if (!src.stream->good()) fail(what + "the file ends inside the data (truncated?)");
  if (got != static_cast<size_t>(values))
    fail(what + "expected " + std::to_string(values) + " values, the file holds " + std::to_string(got));
  if (!direct) {
    switch (type) {
      vtkTemplateMacro(convert_words(reinterpret_cast<const VTK_TT*>(buf.data()), static_cast<size_t>(values), a));
      default: fail(what + "unsupported type");
    }
  }
  if (!a.is_int)
    for (double v : a.d)
      if (!std::isfinite(v)) fail(what + "a value is not finite");
  return a;
}

vtkXMLDataElement* child(vtkXMLDataElement* parent, const char* name) {
  return parent ? parent->FindNestedElementWithName(name) : nullptr;
}

vtkXMLDataElement* data_array(vtkXMLDataElement* parent, const char* name) {
  if (!parent) return nullptr;
  for (int k = 0; k < parent->GetNumberOfNestedElements(); ++k) {
    vtkXMLDataElement* e = parent->GetNestedElement(k);
    if (e && e->GetName() && std::strcmp(e->GetName(), "DataArray") == 0 && attr(e, "Name") == name) return e;
  }
  return nullptr;
}

// Length of an array known only from its last offset: connectivity from offsets, faces from
// faceoffsets. Offsets must be non-decreasing (-1 allowed for faceoffsets: not a polyhedron).
int64_t end_from_offsets(const Array& offsets, bool allow_minus_one, const char* name) {
  int64_t end = 0;
  for (size_t k = 0; k < offsets.i.size(); ++k) {
    const int64_t v = offsets.i[k];
    if (allow_minus_one && v == -1) continue;
    if (v < end) fail(std::string(name) + ": entry " + std::to_string(k) + " (" + std::to_string(v) + ") decreases");
    end = v;
  }
  return end;
}

// The file's cells, flat (no vector per face): cell c's faces are face ids
// [cell_ptr[c], cell_ptr[c + 1]), face f's point ids nodes[face_ptr[f] .. face_ptr[f + 1]).
struct RawCells {
  std::vector<int32_t> nodes;
  std::vector<int64_t> face_ptr{0};
  std::vector<int64_t> cell_ptr{0};
  int64_t size() const { return static_cast<int64_t>(cell_ptr.size()) - 1; }
  int64_t faces() const { return static_cast<int64_t>(face_ptr.size()) - 1; }
  void end_face() { face_ptr.push_back(static_cast<int64_t>(nodes.size())); }
  void end_cell() { cell_ptr.push_back(faces()); }
};

struct Parsed {
  std::vector<Vec3> points;
  RawCells cells;
  struct CellDataPiece {
    vtkXMLDataElement* piece;
    int64_t cells;       // the piece's cells
    int64_t point_base;  // points of the pieces before it
  };
  std::vector<CellDataPiece> cell_data_pieces;  // read by read_cell_data
  std::vector<Array> cell_data;
  std::vector<int32_t> face_patch;
  bool has_face_patch = false;
  std::vector<double> face_mult;  ///< field data face_trans_mult, in face_patch's order (empty: none)
  bool reservoir_cells_are_model = false;  ///< field data reservoir_cells_are_model (1)
  std::vector<std::array<int32_t, 2>> nnc_cells;  ///< field data nnc_cells (connections without a face)
  std::vector<double> nnc_trans;                  ///< field data nnc_trans
  std::vector<std::string> warnings;
};

// Field data nnc_cells (pairs of distinct cell ids) and nnc_trans (finite, >= 0), both or neither.
void read_nnc_fields(const Source& src, vtkXMLDataElement* field_data, int64_t n_cells, Parsed& out) {
  vtkXMLDataElement* cells = data_array(field_data, "nnc_cells");
  vtkXMLDataElement* trans = data_array(field_data, "nnc_trans");
  if (!cells && !trans) return;
  if (!cells || !trans) fail("field data nnc_cells and nnc_trans come together");
  const int64_t n = count_attr(cells, "NumberOfTuples", kMaxIds);
  if (count_attr(trans, "NumberOfTuples", kMaxIds) != n) fail("field data nnc_cells and nnc_trans differ in length");
  const Array c = read_array(src, cells, 2 * n), t = read_array(src, trans, n);
  if (!c.is_int || c.components != 2) fail("nnc_cells must be a 2-component integer array");
  if (t.components != 1) fail("nnc_trans must be a 1-component array");
  for (int64_t q = 0; q < n; ++q) {
    const int64_t a = c.i[2 * q], b = c.i[2 * q + 1];
    if (a < 0 || a >= n_cells || b < 0 || b >= n_cells || a == b)
      fail("nnc_cells: connection " + std::to_string(q) + " is not a pair of two distinct cells of the file");
    const double v = t.is_int ? static_cast<double>(t.i[q]) : t.d[q];
    if (!(std::isfinite(v) && v >= 0)) fail("nnc_trans: " + std::to_string(v) + " is not a finite value >= 0");
    out.nnc_cells.push_back({static_cast<int32_t>(a), static_cast<int32_t>(b)});
    out.nnc_trans.push_back(v);
  }
}

void read_piece(const Source& src, vtkXMLDataElement* piece, Parsed& out) {
  const int64_t np = count_attr(piece, "NumberOfPoints", kMaxIds), nc = count_attr(piece, "NumberOfCells", kMaxIds);
  const int64_t base = static_cast<int64_t>(out.points.size());
  if (base + np > kMaxIds || static_cast<int64_t>(out.cells.size()) + nc > kMaxIds) fail("too many points or cells");
  if (np > 0) {
    vtkXMLDataElement* pts = child(piece, "Points");
    vtkXMLDataElement* arr = pts ? child(pts, "DataArray") : nullptr;
    if (!arr) fail("piece without <Points><DataArray>");
    const Array p = read_array(src, arr, 3 * np);
    if (p.components != 3) fail("Points must have 3 components");
    out.points.reserve(static_cast<size_t>(base + np));
    for (int64_t k = 0; k < np; ++k) out.points.push_back({p.as_double(3 * k), p.as_double(3 * k + 1), p.as_double(3 * k + 2)});
  }
  if (nc > 0) {
    vtkXMLDataElement* cx = child(piece, "Cells");
    vtkXMLDataElement *e_types = data_array(cx, "types"), *e_offsets = data_array(cx, "offsets"),
                      *e_conn = data_array(cx, "connectivity");
    if (!e_types || !e_offsets || !e_conn) fail("<Cells> needs connectivity, offsets and types");
    const Array types = read_array(src, e_types, nc), offsets = read_array(src, e_offsets, nc);
    if (!types.is_int || !offsets.is_int) fail("offsets and types must be integer arrays");
    const Array conn = read_array(src, e_conn, end_from_offsets(offsets, false, "offsets"));
    if (!conn.is_int) fail("connectivity must be an integer array");
    Array faces, faceoffsets;
    if (std::find(types.i.begin(), types.i.end(), 42) != types.i.end()) {
      vtkXMLDataElement *e_faces = data_array(cx, "faces"), *e_fo = data_array(cx, "faceoffsets");
      if (!e_faces || !e_fo) fail("polyhedral cells need the faces and faceoffsets arrays");
      faceoffsets = read_array(src, e_fo, nc);
      if (!faceoffsets.is_int) fail("faceoffsets must be an integer array");
      faces = read_array(src, e_faces, end_from_offsets(faceoffsets, true, "faceoffsets"));
      if (!faces.is_int) fail("faces must be an integer array");
    }
    {  // room for every face and face node (a polyhedron's stream bounds its own)
      int64_t faces_needed = 0, nodes_needed = 0;
      for (int64_t c = 0; c < nc; ++c) {
        int npts = 0;
        const std::vector<std::vector<int>>* tmpl =
            standard_faces(static_cast<int>(std::clamp<int64_t>(types.i[c], -1, 1000)), &npts);
        if (!tmpl) continue;
        faces_needed += static_cast<int64_t>(tmpl->size());
        for (const auto& lf : *tmpl) nodes_needed += static_cast<int64_t>(lf.size());
      }
      nodes_needed += static_cast<int64_t>(faces.i.size());
      faces_needed += static_cast<int64_t>(faces.i.size()) / 4;
      out.cells.nodes.reserve(out.cells.nodes.size() + static_cast<size_t>(nodes_needed));
      out.cells.face_ptr.reserve(out.cells.face_ptr.size() + static_cast<size_t>(faces_needed));
      out.cells.cell_ptr.reserve(out.cells.cell_ptr.size() + static_cast<size_t>(nc));
    }
    int64_t conn_begin = 0, face_begin = 0;
    for (int64_t c = 0; c < nc; ++c) {
      const int64_t cid = out.cells.size();
      const std::string where_prefix = "cell ";
      auto where = [&] { return where_prefix + std::to_string(cid) + ": "; };
      auto point_id = [&](int64_t v) {
        if (v < 0 || v >= np)
          fail(where() + "point id " + std::to_string(v) + " out of range [0, " + std::to_string(np) + ")");
        return static_cast<int32_t>(base + v);
      };
      const int64_t conn_end = offsets.i[c];
      RawCells& rc = out.cells;
      const int64_t t = types.i[c];
      if (t == 42) {
        const int64_t face_end = faceoffsets.i[c];
        if (face_end < face_begin) fail(where() + "polyhedron without a face stream");
        int64_t p = face_begin;
        auto next = [&]() {
          if (p >= face_end) fail(where() + "face stream ends early");
          return faces.i[p++];
        };
        const int64_t nfaces = next();
        if (nfaces < 1 || nfaces > face_end - p) fail(where() + "bad number of faces " + std::to_string(nfaces));
        for (int64_t k = 0; k < nfaces; ++k) {
          const int64_t nv = next();
          if (nv < 0 || nv > face_end - p) fail(where() + "bad face size " + std::to_string(nv));
          for (int64_t q = 0; q < nv; ++q) rc.nodes.push_back(point_id(next()));
          rc.end_face();
        }
        if (p != face_end) fail(where() + "faces stream has " + std::to_string(face_end - p) + " extra entries");
        face_begin = face_end;
      } else {
        int npts = 0;
        const std::vector<std::vector<int>>* tmpl =
            standard_faces(static_cast<int>(std::clamp<int64_t>(t, -1, 1000)), &npts);
        if (!tmpl) fail(where() + "unsupported VTK cell type " + std::to_string(t));
        if (conn_end - conn_begin != npts)
          fail(where() + "type " + std::to_string(t) + " needs " + std::to_string(npts) + " points, got " +
               std::to_string(conn_end - conn_begin));
        for (const auto& lf : *tmpl) {
          for (int k : lf) rc.nodes.push_back(point_id(conn.i[conn_begin + k]));
          rc.end_face();
        }
      }
      conn_begin = conn_end;
      rc.end_cell();
    }
  }
  // Cell data: read after the mesh is assembled (read_cell_data), when the file's cells are gone.
  out.cell_data_pieces.push_back({piece, nc, base});
}

// The cell data of every piece, appended to the previous pieces' arrays of the same name.
void read_cell_data(const Source& src, Parsed& out) {
  for (const Parsed::CellDataPiece& p : out.cell_data_pieces) {
    const int64_t nc = p.cells;
    std::vector<Array> mine;
    if (vtkXMLDataElement* cd = child(p.piece, "CellData"))
      for (int k = 0; k < cd->GetNumberOfNestedElements(); ++k) {
        vtkXMLDataElement* e = cd->GetNestedElement(k);
        if (!e || !e->GetName() || std::strcmp(e->GetName(), "DataArray") != 0) continue;
        int comps = 1;
        if (e->GetAttribute("NumberOfComponents")) comps = static_cast<int>(count_attr(e, "NumberOfComponents", 1 << 16));
        mine.push_back(read_array(src, e, nc * comps));
      }
    if (p.point_base == 0 && out.cell_data.empty()) {
      out.cell_data = std::move(mine);
      continue;
    }
    std::vector<Array> merged;
    for (Array& a : out.cell_data) {
      auto it = std::find_if(mine.begin(), mine.end(), [&](const Array& b) {
        return b.name == a.name && b.components == a.components && b.is_int == a.is_int;
      });
      if (it == mine.end()) {
        out.warnings.push_back("cell array '" + a.name + "' missing in some piece: ignored");
        continue;
      }
      a.i.insert(a.i.end(), it->i.begin(), it->i.end());
      a.d.insert(a.d.end(), it->d.begin(), it->d.end());
      merged.push_back(std::move(a));
    }
    out.cell_data = std::move(merged);
  }
  out.cell_data_pieces.clear();
}

Parsed parse_document(Source& src) {
  vtkXMLDataElement* root = src.parser->GetRootElement();
  if (!root || !root->GetName() || std::strcmp(root->GetName(), "VTKFile") != 0)
    fail("not a VTK XML file (no <VTKFile> root)");
  if (attr(root, "type") != "UnstructuredGrid")
    fail("not an UnstructuredGrid file (type=\"" + attr(root, "type") + "\")");
  const std::string comp = attr(root, "compressor");
  if (comp == "vtkZLibDataCompressor") src.parser->SetCompressor(vtkSmartPointer<vtkZLibDataCompressor>::New());
  else if (comp == "vtkLZ4DataCompressor") src.parser->SetCompressor(vtkSmartPointer<vtkLZ4DataCompressor>::New());
  else if (comp == "vtkLZMADataCompressor") src.parser->SetCompressor(vtkSmartPointer<vtkLZMADataCompressor>::New());
  else if (!comp.empty()) fail("unknown compressor '" + comp + "'");
  src.compressed = !comp.empty();
  src.header_bytes = attr(root, "header_type") == "UInt64" ? 8 : 4;
  const uint16_t one = 1;
  unsigned char first;
  std::memcpy(&first, &one, 1);
  src.swap = (attr(root, "byte_order") == "BigEndian") == (first == 1);
  if (vtkXMLDataElement* ad = child(root, "AppendedData")) src.appended_base64 = attr(ad, "encoding") == "base64";
  vtkXMLDataElement* grid = child(root, "UnstructuredGrid");
  if (!grid) fail("no <UnstructuredGrid> element");
  Parsed out;
  int pieces = 0;
  for (int k = 0; k < grid->GetNumberOfNestedElements(); ++k) {
    vtkXMLDataElement* e = grid->GetNestedElement(k);
    if (!e || !e->GetName() || std::strcmp(e->GetName(), "Piece") != 0) continue;
    ++pieces;
    read_piece(src, e, out);
  }
  if (pieces == 0) fail("no <Piece> element");
  if (out.cells.size() == 0) fail("the file has no cells");
  const int64_t total_faces = out.cells.faces();
  if (vtkXMLDataElement* fp = data_array(child(grid, "FieldData"), "face_patch")) {
    const int64_t n = count_attr(fp, "NumberOfTuples", kMaxIds);
    if (n == total_faces && pieces == 1) {
      const Array a = read_array(src, fp, n);
      if (!a.is_int || a.components != 1) fail("face_patch must be a 1-component integer array");
      for (int64_t v : a.i) {
        // interior (-1), outer (0), wellbore (>= 1) or closed wellbore (<= -3) codes
        const bool is_code = v >= -1 || (v <= closed_wellbore_patch(0) && v > -(1 << 30));
        if (!is_code || v >= (1 << 30)) fail("face_patch: " + std::to_string(v) + " is not a patch code");
        out.face_patch.push_back(static_cast<int32_t>(v));
      }
      out.has_face_patch = true;
    } else {
      out.warnings.push_back("field data face_patch does not match the faces: ignored");
    }
  }
  if (vtkXMLDataElement* fm = data_array(child(grid, "FieldData"), "face_trans_mult")) {
    const int64_t n = count_attr(fm, "NumberOfTuples", kMaxIds);
    if (n != total_faces || pieces != 1) fail("field data face_trans_mult does not match the faces");
    const Array a = read_array(src, fm, n);
    if (a.components != 1) fail("face_trans_mult must be a 1-component array");
    out.face_mult.resize(static_cast<size_t>(n));
    for (int64_t q = 0; q < n; ++q) {
      const double v = a.is_int ? static_cast<double>(a.i[q]) : a.d[q];
      if (!(std::isfinite(v) && v >= 0)) fail("face_trans_mult: " + std::to_string(v) + " is not a finite value >= 0");
      out.face_mult[q] = v;
    }
  }
  if (vtkXMLDataElement* rm = data_array(child(grid, "FieldData"), "reservoir_cells_are_model")) {
    if (count_attr(rm, "NumberOfTuples", kMaxIds) != 1) fail("field data reservoir_cells_are_model must be one value");
    const Array a = read_array(src, rm, 1);
    const double v = a.is_int ? static_cast<double>(a.i[0]) : a.d[0];
    if (a.components != 1 || !(v == 0 || v == 1)) fail("field data reservoir_cells_are_model must be one value, 0 or 1");
    out.reservoir_cells_are_model = v == 1;
  }
  read_nnc_fields(src, child(grid, "FieldData"), static_cast<int64_t>(out.cells.size()), out);
  return out;
}

// Canonical form of every face of a file (start at the smallest id, direction towards the
// smaller neighbour, as canonical_cycle_into).
struct FaceKeys {
  std::vector<int32_t> start;
  std::vector<uint8_t> rev;
};

// Fills the keys on all cores; false if a face has fewer than 3 nodes or a repeated node.
bool face_keys(const RawCells& cells, FaceKeys* keys) {
  const int64_t nq = cells.faces();
  const int32_t* nodes = cells.nodes.data();
  const int64_t* fp = cells.face_ptr.data();
  std::vector<int32_t>& start = keys->start;
  std::vector<uint8_t>& rev = keys->rev;
  start.resize(static_cast<size_t>(nq));
  rev.resize(static_cast<size_t>(nq));
  std::vector<uint8_t> irregular(static_cast<size_t>(nq), 0);
  parallel_ranges(nq, [&](int64_t b, int64_t e) {
    std::vector<int32_t> sorted;
    for (int64_t q = b; q < e; ++q) {
      const int32_t* c = nodes + fp[q];
      const int64_t n = fp[q + 1] - fp[q];
      bool repeated = false;
      if (n <= 16) {  // pairwise: no copy for the usual 3-8 nodes
        for (int64_t i = 1; i < n && !repeated; ++i)
          for (int64_t j = 0; j < i && !repeated; ++j) repeated = c[i] == c[j];
      } else {
        sorted.assign(c, c + n);
        std::sort(sorted.begin(), sorted.end());
        repeated = std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end();
      }
      if (n < 3 || repeated) {
        irregular[q] = 1;
        continue;
      }
      const int64_t k = std::min_element(c, c + n) - c;
      start[q] = static_cast<int32_t>(k);
      rev[q] = c[(k + n - 1) % n] < c[(k + 1) % n];
    }
  });
  return std::none_of(irregular.begin(), irregular.end(), [](uint8_t x) { return x != 0; });
}

// The partner of each file face (the other file face with the same cycle, -1 if none). Faces are
// grouped by their smallest point (counted and scattered in file order: a face and its partner
// share it), and each group is matched on its own in file order, so the result does not depend
// on the threads. False if a face is named a third time, twice by one cell or twice in one
// orientation.
bool match_faces(const RawCells& cells, int64_t n_points, const FaceKeys& keys, const std::vector<int32_t>& cell_of,
                 std::vector<int32_t>* partner_out) {
  const int64_t nq = cells.faces();
  const int32_t* nodes = cells.nodes.data();
  const int64_t* fp = cells.face_ptr.data();
  const std::vector<int32_t>& start = keys.start;
  const std::vector<uint8_t>& rev = keys.rev;
  auto smallest = [&](int64_t q) { return nodes[fp[q] + start[q]]; };
  auto same = [&](int64_t a, int64_t b) {
    const int64_t n = fp[a + 1] - fp[a];
    if (n != fp[b + 1] - fp[b]) return false;
    const int32_t *ca = nodes + fp[a], *cb = nodes + fp[b];
    for (int64_t i = 0, ja = start[a], jb = start[b]; i < n; ++i) {
      if (ca[ja] != cb[jb]) return false;
      ja = rev[a] ? (ja == 0 ? n - 1 : ja - 1) : (ja == n - 1 ? 0 : ja + 1);
      jb = rev[b] ? (jb == 0 ? n - 1 : jb - 1) : (jb == n - 1 ? 0 : jb + 1);
    }
    return true;
  };
  std::vector<int32_t> group_ptr(static_cast<size_t>(n_points) + 1, 0);
  for (int64_t q = 0; q < nq; ++q) ++group_ptr[smallest(q) + 1];
  for (int64_t v = 0; v < n_points; ++v) group_ptr[v + 1] += group_ptr[v];
  std::vector<int32_t> order(static_cast<size_t>(nq));  // file faces, by smallest point, in file order
  {
    std::vector<int32_t> fill(group_ptr.begin(), group_ptr.end() - 1);
    for (int64_t q = 0; q < nq; ++q) order[fill[smallest(q)]++] = static_cast<int32_t>(q);
  }
  // Canonical cycles compared in order (sizes first), then file order: equal faces end up
  // adjacent and in file order.
  auto canonical_less = [&](int32_t a, int32_t b) {
    const int64_t na = fp[a + 1] - fp[a], nb = fp[b + 1] - fp[b];
    if (na != nb) return na < nb;
    const int32_t *ca = nodes + fp[a], *cb = nodes + fp[b];
    for (int64_t i = 0, ja = start[a], jb = start[b]; i < na; ++i) {
      if (ca[ja] != cb[jb]) return ca[ja] < cb[jb];
      ja = rev[a] ? (ja == 0 ? na - 1 : ja - 1) : (ja == na - 1 ? 0 : ja + 1);
      jb = rev[b] ? (jb == 0 ? nb - 1 : jb - 1) : (jb == nb - 1 ? 0 : jb + 1);
    }
    return a < b;
  };
  std::vector<int32_t>& partner = *partner_out;
  partner.assign(static_cast<size_t>(nq), -1);
  std::vector<uint8_t> bad(static_cast<size_t>(n_points), 0);
  constexpr int64_t kPairwiseGroup = 32;  // larger groups are sorted (no quadratic cost)
  parallel_ranges(n_points, [&](int64_t b, int64_t e) {
    std::vector<int32_t> sorted;
    for (int64_t v = b; v < e; ++v) {
      int32_t* lo = order.data() + group_ptr[v];
      int32_t* hi = order.data() + group_ptr[v + 1];
      // *i is a later use of the face first named by *j (or by *j's partner)
      auto pair_up = [&](int32_t j, int32_t i) {
        if (partner[j] >= 0 || partner[i] >= 0 || cell_of[j] == cell_of[i] || rev[j] == rev[i]) bad[v] = 1;
        partner[j] = i;
        partner[i] = j;
      };
      if (hi - lo <= kPairwiseGroup) {
        for (const int32_t* i = lo + 1; i < hi; ++i)
          for (const int32_t* j = lo; j < i; ++j)
            if (same(*j, *i)) {
              pair_up(*j, *i);
              break;
            }
        continue;
      }
      // The same pairs as the pairwise scan: each later face of a run of equal faces with its first.
      sorted.assign(lo, hi);
      std::sort(sorted.begin(), sorted.end(), canonical_less);
      for (size_t r = 0; r < sorted.size();) {
        size_t end = r + 1;
        while (end < sorted.size() && same(sorted[r], sorted[end])) pair_up(sorted[r], sorted[end]), ++end;
        r = end;
      }
    }
  });
  return std::none_of(bad.begin(), bad.end(), [](uint8_t x) { return x != 0; });
}

// The mesh of a file whose faces are all regular, assembled on all cores: exactly what
// MeshBuilder builds from the same cells (faces numbered by first use, the owner's cycle stored,
// nodes compacted in their order). False, building nothing, at any irregularity (face_keys,
// match_faces, or an interior patch on a face with one cell): MeshBuilder then builds the mesh
// and reports the problems in order.
bool build_regular_mesh(const RawCells& cells, const std::vector<Vec3>& points, const std::vector<int32_t>& face_patch,
                        PolyMesh* out, BuildReport* report) {
  const int64_t nq = cells.faces(), nc = cells.size();
  if (nq >= std::numeric_limits<int32_t>::max() || static_cast<int64_t>(cells.nodes.size()) >= std::numeric_limits<int32_t>::max())
    return false;
  const int32_t* nodes = cells.nodes.data();
  const int64_t* fp = cells.face_ptr.data();
  FaceKeys keys;
  if (!face_keys(cells, &keys)) return false;
  std::vector<int32_t> cell_of(static_cast<size_t>(nq));
  parallel_ranges(nc, [&](int64_t b, int64_t e) {
    for (int64_t c = b; c < e; ++c)
      for (int64_t q = cells.cell_ptr[c]; q < cells.cell_ptr[c + 1]; ++q) cell_of[q] = static_cast<int32_t>(c);
  });
  std::vector<int32_t> partner;
  if (!match_faces(cells, static_cast<int64_t>(points.size()), keys, cell_of, &partner)) return false;
  keys = FaceKeys{};
  // Faces numbered by first use (file order), as MeshBuilder numbers them.
  std::vector<int32_t> face_id(static_cast<size_t>(nq));
  std::vector<int64_t> first_use;
  first_use.reserve(static_cast<size_t>(nq / 2 + 1));
  for (int64_t q = 0; q < nq; ++q) {
    if (partner[q] < 0 || partner[q] > q) {
      face_id[q] = static_cast<int32_t>(first_use.size());
      first_use.push_back(q);
    } else {
      face_id[q] = face_id[partner[q]];
    }
  }
  const int64_t nf = static_cast<int64_t>(first_use.size());
  for (int64_t f = 0; f < nf; ++f)  // a boundary face the file calls interior: MeshBuilder reports it
    if (partner[first_use[f]] < 0 && face_patch[first_use[f]] == kInteriorFace) return false;
  // Nodes: those some face references, in their order.
  std::vector<int32_t> new_id(points.size(), -1);
  for (int32_t v : cells.nodes) new_id[v] = 0;
  PolyMesh m;
  int removed = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (new_id[i] == 0) {
      new_id[i] = static_cast<int32_t>(m.nodes.size());
      m.nodes.push_back(points[i]);
    } else {
      ++removed;
    }
  }
  m.face_node_ptr.assign(static_cast<size_t>(nf) + 1, 0);
  for (int64_t f = 0; f < nf; ++f)
    m.face_node_ptr[f + 1] = m.face_node_ptr[f] + static_cast<int32_t>(fp[first_use[f] + 1] - fp[first_use[f]]);
  m.face_nodes.resize(static_cast<size_t>(m.face_node_ptr[nf]));
  m.face_owner.resize(static_cast<size_t>(nf));
  m.face_neighbour.resize(static_cast<size_t>(nf));
  m.face_patch.resize(static_cast<size_t>(nf));
  parallel_ranges(nf, [&](int64_t b, int64_t e) {
    for (int64_t f = b; f < e; ++f) {
      const int64_t q = first_use[f];
      int32_t* dst = m.face_nodes.data() + m.face_node_ptr[f];
      for (int64_t i = fp[q]; i < fp[q + 1]; ++i) *dst++ = new_id[nodes[i]];
      m.face_owner[f] = cell_of[q];
      m.face_neighbour[f] = partner[q] >= 0 ? cell_of[partner[q]] : -1;
      m.face_patch[f] = partner[q] >= 0 ? kInteriorFace : face_patch[q];
    }
  });
  m.cell_face_ptr.resize(static_cast<size_t>(nc) + 1);
  for (int64_t c = 0; c <= nc; ++c) m.cell_face_ptr[c] = static_cast<int32_t>(cells.cell_ptr[c]);
  m.cell_faces = std::move(face_id);
  const CellAttributes none{};
  m.cell_region.assign(static_cast<size_t>(nc), none.region);
  m.cell_fv_center.assign(static_cast<size_t>(nc), none.fv_center);
  m.cell_ijk.assign(static_cast<size_t>(nc), none.ijk);
  m.cell_perm.assign(static_cast<size_t>(nc), none.perm);
  m.cell_porosity.assign(static_cast<size_t>(nc), none.porosity);
  m.cell_radial.assign(static_cast<size_t>(nc), none.radial);
  *out = std::move(m);
  *report = BuildReport{};
  report->removed_unused_nodes = removed;
  return true;
}

// MeshBuilder's mesh of the file's cells, face by face (every file, and the one that reports
// the problems of an irregular file).
void build_with_mesh_builder(Parsed& in, ReadResult& res) {
  const RawCells& cells = in.cells;
  std::vector<int32_t> f;  // one face's point ids
  auto load_face = [&](int64_t q) {
    f.assign(cells.nodes.begin() + cells.face_ptr[q], cells.nodes.begin() + cells.face_ptr[q + 1]);
  };
  std::map<std::vector<int32_t>, int> uses;
  if (!res.has_face_patch)
    for (int64_t q = 0; q < cells.faces(); ++q) {
      load_face(q);
      if (f.size() >= 3) ++uses[canonical_cycle(f, nullptr)];
    }
  MeshBuilder mb;
  for (const Vec3& p : in.points) mb.add_node(p);
  in.points = {};
  std::vector<CellFace> cf;  // reused from cell to cell
  for (int64_t c = 0; c < cells.size(); ++c) {
    cf.resize(static_cast<size_t>(cells.cell_ptr[c + 1] - cells.cell_ptr[c]));
    for (int64_t q = cells.cell_ptr[c]; q < cells.cell_ptr[c + 1]; ++q) {
      load_face(q);
      CellFace& face = cf[static_cast<size_t>(q - cells.cell_ptr[c])];
      face.nodes.assign(f.begin(), f.end());
      if (res.has_face_patch) {
        face.patch = in.face_patch[q];
      } else {
        auto it = f.size() >= 3 ? uses.find(canonical_cycle(f, nullptr)) : uses.end();
        face.patch = it != uses.end() && it->second >= 2 ? kInteriorFace : kOuterBoundary;
      }
    }
    mb.add_cell(cf, CellAttributes{});
  }
  in.cells = RawCells{};
  in.face_patch = {};
  res.mesh = mb.finish(&res.build);
}

// The file's face multipliers (one per cell face, both sides of a face alike) on the mesh's faces.
void place_face_multipliers(const std::vector<double>& per_use, PolyMesh& m) {
  if (m.cell_faces.size() != per_use.size()) fail("face_trans_mult does not match the assembled faces");
  m.face_trans_mult.assign(static_cast<size_t>(m.n_faces()), -1.0);
  for (size_t q = 0; q < per_use.size(); ++q) {
    double& v = m.face_trans_mult[m.cell_faces[q]];
    if (v >= 0 && v != per_use[q])
      fail("face_trans_mult: the two sides of face " + std::to_string(m.cell_faces[q]) + " differ");
    v = per_use[q];
  }
}

ReadResult convert(const Source& src, Parsed&& in, VtuAssembly assembly) {
  ReadResult res;
  res.has_face_patch = in.has_face_patch;
  if (assembly == VtuAssembly::Parallel && res.has_face_patch &&
      build_regular_mesh(in.cells, in.points, in.face_patch, &res.mesh, &res.build)) {
    res.assembled_in_parallel = true;
    in.points = {};
    in.cells = RawCells{};
    in.face_patch = {};
  } else {
    build_with_mesh_builder(in, res);
  }
  if (!in.face_mult.empty()) place_face_multipliers(in.face_mult, res.mesh);
  res.mesh.reservoir_cells_are_model = in.reservoir_cells_are_model;
  res.mesh.nnc_cells = std::move(in.nnc_cells);
  res.mesh.nnc_trans = std::move(in.nnc_trans);
  read_cell_data(src, in);  // now: the file's cells no longer take memory
  res.warnings = std::move(in.warnings);
  PolyMesh& m = res.mesh;
  for (Array& a : in.cell_data) {  // as doubles; a Float64 array is moved, not copied
    std::vector<double> v;
    if (a.is_int) {
      v.resize(a.size());
      parallel_ranges(static_cast<int64_t>(a.size()), [&](int64_t b, int64_t e) {
        for (int64_t q = b; q < e; ++q) v[q] = static_cast<double>(a.i[q]);
      });
    } else {
      v = std::move(a.d);
    }
    res.cell_arrays.push_back(VtuCellArray::real(std::move(a.name), a.components, std::move(v)));
    a = Array{};
  }
  const RestoredArrays restored = restore_mesh_cell_arrays(res.cell_arrays, m);
  if (!restored.error.empty()) fail(restored.error);
  res.missing_mesh_arrays = restored.missing;
  res.has_region = restored.has("region");
  res.has_fv_center = restored.has("fv_center");
  res.has_radial = restored.has("radial_well");
  if (!res.has_fv_center) {
    const MeshGeometry geo = compute_geometry(m);
    for (int c = 0; c < m.n_cells(); ++c) m.cell_fv_center[c] = geo.cell_centroid[c];
  }
  res.ok = true;
  return res;
}

// Parses the stream with VTK's vtkXMLDataParser and converts it; VTK's first error message
// becomes ours, and VTK prints nothing.
ReadResult read_stream(std::istream& in, uint64_t file_bytes, VtuAssembly assembly) {
  QuietVtk quiet;
  vtkNew<MessageCatcher> catcher;
  vtkNew<vtkXMLDataParser> parser;
  parser->AddObserver(vtkCommand::ErrorEvent, catcher);
  parser->AddObserver(vtkCommand::WarningEvent, catcher);
  parser->SetStream(&in);
  ReadResult r;
  try {
    const int parsed = parser->Parse();
    if (!catcher->errors.empty()) fail(catcher->errors.front());
    if (!parsed) fail("not a well-formed XML file");
    Source src;
    src.parser = parser;
    src.stream = &in;
    // Compressed blocks can expand ~1000-fold (zlib) and more (LZMA on constant data): bound
    // every array by what a file of this size could possibly hold, so that a forged count
    // cannot allocate without limit.
    src.max_words = std::min<uint64_t>(4096 * (file_bytes + 64), uint64_t(1) << 34);
    src.file_bytes = file_bytes;
    Parsed doc = parse_document(src);
    if (!catcher->errors.empty()) fail(catcher->errors.front());
    r = convert(src, std::move(doc), assembly);
    if (!catcher->errors.empty()) fail(catcher->errors.front());
  } catch (const VtuError& e) {
    r = ReadResult{};
    r.error = e.what;
  } catch (const std::bad_alloc&) {
    r = ReadResult{};
    r.error = "out of memory (declared sizes too large?)";
  }
  if (r.ok) {
    for (const std::string& w : catcher->warnings) r.warnings.push_back("VTK: " + w);
  } else if (r.error.empty()) {
    r.error = "unreadable file";
  }
  (void)quiet;
  return r;
}

}  // namespace

ReadResult read_vtu_buffer(const std::string& bytes, VtuAssembly assembly) {
  if (bytes.empty()) {
    ReadResult r;
    r.error = "empty file";
    return r;
  }
  std::istringstream in(bytes);
  return read_stream(in, bytes.size(), assembly);
}

ReadResult read_vtu(const std::string& path, VtuAssembly assembly) {
  std::error_code ec;
  ReadResult r;
  if (std::filesystem::is_directory(path, ec)) {
    r.error = "cannot read " + path + ": is a directory";
    return r;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    r.error = "cannot open " + path + ": " + std::strerror(errno);
    return r;
  }
  const uint64_t size = std::filesystem::file_size(path, ec);
  if (ec || size == 0) {
    r.error = path + ": empty file";
    return r;
  }
  r = read_stream(in, size, assembly);
  if (!r.ok) r.error = path + ": " + r.error;
  return r;
}

}  // namespace hm
