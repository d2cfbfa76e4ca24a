#include "vtu_reader.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>

#include "meshgen/core/geometry.hpp"

namespace hm {

namespace {

// Internal failure: caught in read_vtu_buffer and turned into ReadResult::error.
struct VtuError {
  std::string what;
};
[[noreturn]] void fail(const std::string& what) { throw VtuError{what}; }

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

// ---------------------------------------------------------------- XML scanner
// Enough XML for VTK files: elements, attributes, text, comments, declarations. The
// appended data section is binary: scanning stops at <AppendedData ...>.
struct XmlNode {
  std::string name;
  std::vector<std::pair<std::string, std::string>> attrs;
  size_t text_begin = 0, text_end = 0;  // first text chunk inside the element
  bool has_text = false;
  std::vector<int> children;
  int parent = -1;

  const std::string* attr(const std::string& key) const {
    for (const auto& [k, v] : attrs)
      if (k == key) return &v;
    return nullptr;
  }
};

struct XmlDoc {
  std::vector<XmlNode> nodes;
  int appended = -1;           // index of the AppendedData node, -1 if none
  size_t appended_begin = 0;   // first byte after '_' of the appended section
};

std::string decode_entities(const std::string& s) {
  std::string o;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] != '&') {
      o += s[i];
      continue;
    }
    static const std::pair<const char*, char> ents[] = {{"&amp;", '&'}, {"&lt;", '<'}, {"&gt;", '>'},
                                                        {"&quot;", '"'}, {"&apos;", '\''}};
    bool done = false;
    for (const auto& [e, ch] : ents)
      if (s.compare(i, std::strlen(e), e) == 0) {
        o += ch;
        i += std::strlen(e) - 1;
        done = true;
        break;
      }
    if (!done) o += '&';
  }
  return o;
}

bool is_name_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == ':' ||
         c == '.' || c == '-';
}

XmlDoc parse_xml(const std::string& buf) {
  XmlDoc doc;
  std::vector<int> stack;
  const size_t n = buf.size();
  size_t pos = 0;
  while (pos < n) {
    const size_t lt = buf.find('<', pos);
    const size_t text_end = lt == std::string::npos ? n : lt;
    if (!stack.empty() && text_end > pos) {
      XmlNode& top = doc.nodes[stack.back()];
      if (!top.has_text) {
        top.has_text = true;
        top.text_begin = pos;
        top.text_end = text_end;
      }
    }
    if (lt == std::string::npos) break;
    pos = lt;
    auto skip_to = [&](const char* term, const char* what) {
      const size_t e = buf.find(term, pos);
      if (e == std::string::npos) fail(std::string("truncated XML: unterminated ") + what);
      pos = e + std::strlen(term);
    };
    if (buf.compare(pos, 4, "<!--") == 0) { skip_to("-->", "comment"); continue; }
    if (buf.compare(pos, 2, "<?") == 0) { skip_to("?>", "declaration"); continue; }
    if (buf.compare(pos, 9, "<![CDATA[") == 0) fail("XML CDATA sections are not supported");
    if (buf.compare(pos, 2, "<!") == 0) { skip_to(">", "declaration"); continue; }
    if (buf.compare(pos, 2, "</") == 0) {
      size_t p = pos + 2;
      const size_t b = p;
      while (p < n && is_name_char(buf[p])) ++p;
      const std::string name = buf.substr(b, p - b);
      while (p < n && is_space(buf[p])) ++p;
      if (p >= n || buf[p] != '>') fail("malformed XML end tag </" + name + ">");
      if (stack.empty() || doc.nodes[stack.back()].name != name)
        fail("malformed XML: unexpected </" + name + ">");
      stack.pop_back();
      pos = p + 1;
      continue;
    }
    // Start tag.
    size_t p = pos + 1;
    const size_t b = p;
    while (p < n && is_name_char(buf[p])) ++p;
    if (p == b) fail("malformed XML near byte " + std::to_string(pos));
    XmlNode node;
    node.name = buf.substr(b, p - b);
    bool self_closing = false;
    for (;;) {
      while (p < n && is_space(buf[p])) ++p;
      if (p >= n) fail("truncated XML inside <" + node.name + ">");
      if (buf[p] == '>') { ++p; break; }
      if (buf[p] == '/') {
        if (p + 1 >= n || buf[p + 1] != '>') fail("malformed XML tag <" + node.name + ">");
        self_closing = true;
        p += 2;
        break;
      }
      const size_t kb = p;
      while (p < n && is_name_char(buf[p])) ++p;
      if (p == kb) fail("malformed attribute in <" + node.name + ">");
      std::string key = buf.substr(kb, p - kb);
      while (p < n && is_space(buf[p])) ++p;
      if (p >= n || buf[p] != '=') fail("malformed attribute " + key + " in <" + node.name + ">");
      ++p;
      while (p < n && is_space(buf[p])) ++p;
      if (p >= n || (buf[p] != '"' && buf[p] != '\'')) fail("malformed attribute " + key + " in <" + node.name + ">");
      const char q = buf[p++];
      const size_t vb = p;
      while (p < n && buf[p] != q) ++p;
      if (p >= n) fail("truncated XML inside <" + node.name + ">");
      node.attrs.emplace_back(std::move(key), decode_entities(buf.substr(vb, p - vb)));
      ++p;
    }
    node.parent = stack.empty() ? -1 : stack.back();
    const int id = static_cast<int>(doc.nodes.size());
    if (node.parent >= 0) doc.nodes[node.parent].children.push_back(id);
    const bool appended = node.name == "AppendedData";
    doc.nodes.push_back(std::move(node));
    pos = p;
    if (appended && !self_closing) {
      // Binary from here on: the section starts after the first non-blank character '_'.
      while (pos < n && is_space(buf[pos])) ++pos;
      if (pos >= n || buf[pos] != '_') fail("AppendedData does not start with '_'");
      doc.appended = id;
      doc.appended_begin = pos + 1;
      return doc;
    }
    if (!self_closing) stack.push_back(id);
  }
  if (!stack.empty()) fail("truncated XML: <" + doc.nodes[stack.back()].name + "> is not closed");
  return doc;
}

// ---------------------------------------------------------------- numbers and base64
int64_t parse_count(const std::string* s, const std::string& what, int64_t max_value) {
  if (!s) fail("missing attribute " + what);
  int64_t v = -1;
  const char* b = s->data();
  const char* e = b + s->size();
  while (b < e && is_space(*b)) ++b;
  auto r = std::from_chars(b, e, v);
  if (r.ec != std::errc() || v < 0 || v > max_value) fail("bad value of " + what + ": '" + *s + "'");
  for (const char* q = r.ptr; q < e; ++q)
    if (!is_space(*q)) fail("bad value of " + what + ": '" + *s + "'");
  return v;
}

int b64_value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

// Decodes base64 group by group; padding may appear mid-stream (VTK may encode the header
// and the data as separate blocks), which group-wise decoding handles transparently.
class Base64Cursor {
 public:
  Base64Cursor(const char* p, const char* end) : p_(p), end_(end) {}
  // Appends decoded bytes to out until it holds at least `want` bytes. False at the end of
  // the text or on an invalid character.
  bool fill(std::string& out, size_t want) {
    while (out.size() < want) {
      int vals[4];
      int got = 0, pad = 0;
      while (got < 4) {
        while (p_ < end_ && is_space(*p_)) ++p_;
        if (p_ >= end_) return false;
        const char c = *p_++;
        if (c == '=') {
          vals[got++] = 0;
          ++pad;
          continue;
        }
        const int v = b64_value(c);
        if (v < 0 || pad > 0) return false;
        vals[got++] = v;
      }
      if (pad > 2) return false;
      const uint32_t w = (uint32_t(vals[0]) << 18) | (uint32_t(vals[1]) << 12) | (uint32_t(vals[2]) << 6) | uint32_t(vals[3]);
      out += static_cast<char>((w >> 16) & 0xff);
      if (pad < 2) out += static_cast<char>((w >> 8) & 0xff);
      if (pad < 1) out += static_cast<char>(w & 0xff);
    }
    return true;
  }
  size_t remaining_chars() const { return static_cast<size_t>(end_ - p_); }

 private:
  const char* p_;
  const char* end_;
};

// ---------------------------------------------------------------- data arrays
struct Array {
  std::string name;
  int components = 1;
  bool is_int = false;
  std::vector<int64_t> i;  // when is_int
  std::vector<double> d;   // when !is_int
  size_t size() const { return is_int ? i.size() : d.size(); }
  double as_double(size_t k) const { return is_int ? static_cast<double>(i[k]) : d[k]; }
};

struct FileInfo {
  bool swap = false;        // file byte order differs from the host's
  int header_bytes = 4;     // UInt32 or UInt64
  const std::string* buf = nullptr;
  const XmlDoc* doc = nullptr;
  bool appended_base64 = false;
};

struct TypeInfo {
  int size;
  bool is_int, is_signed;
};
TypeInfo type_info(const std::string& t, const std::string& array) {
  if (t == "Int8") return {1, true, true};
  if (t == "UInt8") return {1, true, false};
  if (t == "Int16") return {2, true, true};
  if (t == "UInt16") return {2, true, false};
  if (t == "Int32") return {4, true, true};
  if (t == "UInt32") return {4, true, false};
  if (t == "Int64") return {8, true, true};
  if (t == "UInt64") return {8, true, false};
  if (t == "Float32") return {4, false, true};
  if (t == "Float64") return {8, false, true};
  fail("array " + array + ": unsupported type '" + t + "'");
}

bool host_little_endian() {
  const uint16_t one = 1;
  unsigned char b;
  std::memcpy(&b, &one, 1);
  return b == 1;
}

uint64_t read_header(const char* p, int bytes, bool swap) {
  unsigned char tmp[8];
  std::memcpy(tmp, p, bytes);
  if (swap) std::reverse(tmp, tmp + bytes);
  if (bytes == 4) {
    uint32_t v;
    std::memcpy(&v, tmp, 4);
    return v;
  }
  uint64_t v;
  std::memcpy(&v, tmp, 8);
  return v;
}

void convert_binary(const char* p, size_t count, const TypeInfo& ti, bool swap, Array& a) {
  const size_t n = count / ti.size;
  if (ti.is_int) a.i.resize(n);
  else a.d.resize(n);
  unsigned char tmp[8];
  for (size_t k = 0; k < n; ++k) {
    std::memcpy(tmp, p + k * ti.size, ti.size);
    if (swap) std::reverse(tmp, tmp + ti.size);
    if (!ti.is_int) {
      if (ti.size == 4) {
        float f;
        std::memcpy(&f, tmp, 4);
        a.d[k] = f;
      } else {
        std::memcpy(&a.d[k], tmp, 8);
      }
      continue;
    }
    int64_t v = 0;
    switch (ti.size) {
      case 1: v = ti.is_signed ? int64_t(int8_t(tmp[0])) : int64_t(tmp[0]); break;
      case 2: {
        uint16_t u;
        std::memcpy(&u, tmp, 2);
        v = ti.is_signed ? int64_t(int16_t(u)) : int64_t(u);
        break;
      }
      case 4: {
        uint32_t u;
        std::memcpy(&u, tmp, 4);
        v = ti.is_signed ? int64_t(int32_t(u)) : int64_t(u);
        break;
      }
      default: {
        uint64_t u;
        std::memcpy(&u, tmp, 8);
        if (!ti.is_signed && u > static_cast<uint64_t>(std::numeric_limits<int64_t>::max()))
          fail("array " + a.name + ": UInt64 value out of range");
        v = static_cast<int64_t>(u);
      }
    }
    a.i[k] = v;
  }
}

// Decodes one <DataArray>. expected_values < 0: any count (a multiple of components).
Array read_array(const FileInfo& fi, const XmlNode& node, int64_t expected_values) {
  Array a;
  const std::string* nm = node.attr("Name");
  a.name = nm ? *nm : std::string("(unnamed)");
  const std::string* ty = node.attr("type");
  if (!ty) fail("array " + a.name + ": missing type");
  const TypeInfo ti = type_info(*ty, a.name);
  a.is_int = ti.is_int;
  if (const std::string* nc = node.attr("NumberOfComponents"))
    a.components = static_cast<int>(parse_count(nc, "NumberOfComponents of " + a.name, 1 << 20));
  if (a.components < 1) fail("array " + a.name + ": NumberOfComponents must be >= 1");
  const std::string* fmt = node.attr("format");
  const std::string format = fmt ? *fmt : std::string("ascii");
  const std::string& buf = *fi.buf;

  if (format == "ascii") {
    const char* p = buf.data() + (node.has_text ? node.text_begin : 0);
    const char* e = buf.data() + (node.has_text ? node.text_end : 0);
    while (p < e) {
      while (p < e && is_space(*p)) ++p;
      if (p >= e) break;
      if (expected_values >= 0 && static_cast<int64_t>(a.size()) >= expected_values)
        fail("array " + a.name + ": more values than expected (" + std::to_string(expected_values) + ")");
      std::from_chars_result r;
      if (ti.is_int) {
        int64_t v = 0;
        r = std::from_chars(p, e, v);
        a.i.push_back(v);
      } else {
        double v = 0;
        r = std::from_chars(p, e, v);
        a.d.push_back(v);
      }
      if (r.ec != std::errc() || (r.ptr < e && !is_space(*r.ptr)))
        fail("array " + a.name + ": bad ascii number at value " + std::to_string(a.size() - 1));
      p = r.ptr;
    }
  } else if (format == "binary" || format == "appended") {
    std::string bytes;  // header + data for base64 input
    const char* data = nullptr;
    uint64_t count = 0;
    if (format == "appended" && !fi.appended_base64) {
      if (fi.doc->appended < 0) fail("array " + a.name + ": appended format but no AppendedData section");
      const uint64_t off = static_cast<uint64_t>(parse_count(node.attr("offset"), "offset of " + a.name,
                                                             std::numeric_limits<int64_t>::max()));
      const uint64_t avail = buf.size() - fi.doc->appended_begin;
      if (off > avail || avail - off < static_cast<uint64_t>(fi.header_bytes))
        fail("array " + a.name + ": offset " + std::to_string(off) + " beyond the end of the appended data");
      const char* p = buf.data() + fi.doc->appended_begin + off;
      count = read_header(p, fi.header_bytes, fi.swap);
      if (count > avail - off - fi.header_bytes)
        fail("array " + a.name + ": " + std::to_string(count) + " bytes declared but the file ends first (truncated?)");
      data = p + fi.header_bytes;
    } else {
      const char *p, *e;
      if (format == "binary") {
        p = buf.data() + (node.has_text ? node.text_begin : 0);
        e = buf.data() + (node.has_text ? node.text_end : 0);
      } else {
        if (fi.doc->appended < 0) fail("array " + a.name + ": appended format but no AppendedData section");
        const uint64_t off = static_cast<uint64_t>(parse_count(node.attr("offset"), "offset of " + a.name,
                                                               std::numeric_limits<int64_t>::max()));
        const uint64_t avail = buf.size() - fi.doc->appended_begin;
        if (off >= avail) fail("array " + a.name + ": offset beyond the end of the appended data");
        p = buf.data() + fi.doc->appended_begin + off;
        e = buf.data() + buf.size();
      }
      Base64Cursor cur(p, e);
      if (!cur.fill(bytes, fi.header_bytes)) fail("array " + a.name + ": bad or truncated base64 header");
      count = read_header(bytes.data(), fi.header_bytes, fi.swap);
      if (count / 3 > cur.remaining_chars() / 4 + 1)
        fail("array " + a.name + ": " + std::to_string(count) + " bytes declared but the data ends first (truncated?)");
      bytes.reserve(fi.header_bytes + count);
      if (!cur.fill(bytes, fi.header_bytes + count))
        fail("array " + a.name + ": bad or truncated base64 data");
      data = bytes.data() + fi.header_bytes;
    }
    if (count % ti.size != 0) fail("array " + a.name + ": byte count is not a multiple of the value size");
    if (expected_values >= 0 && count / ti.size != static_cast<uint64_t>(expected_values))
      fail("array " + a.name + ": " + std::to_string(count / ti.size) + " values, expected " +
           std::to_string(expected_values));
    convert_binary(data, count, ti, fi.swap, a);
  } else {
    fail("array " + a.name + ": unsupported format '" + format + "'");
  }
  if (expected_values >= 0 && static_cast<int64_t>(a.size()) != expected_values)
    fail("array " + a.name + ": " + std::to_string(a.size()) + " values, expected " + std::to_string(expected_values));
  if (a.size() % a.components != 0) fail("array " + a.name + ": value count is not a multiple of NumberOfComponents");
  return a;
}

const XmlNode* child(const XmlDoc& doc, const XmlNode& parent, const std::string& name) {
  for (int c : parent.children)
    if (doc.nodes[c].name == name) return &doc.nodes[c];
  return nullptr;
}

const XmlNode* data_array(const XmlDoc& doc, const XmlNode& parent, const std::string& name) {
  for (int c : parent.children) {
    const XmlNode& n = doc.nodes[c];
    if (n.name != "DataArray") continue;
    const std::string* nm = n.attr("Name");
    if (nm && *nm == name) return &n;
  }
  return nullptr;
}

// Faces of the linear VTK cells, as local point indices (orientation fixed later).
const std::vector<std::vector<int>>* standard_faces(int type, int* npts) {
  static const std::vector<std::vector<int>> tet{{0, 1, 3}, {1, 2, 3}, {2, 0, 3}, {0, 2, 1}};
  static const std::vector<std::vector<int>> voxel{{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                                                   {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
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

struct RawCell {
  std::vector<std::vector<int32_t>> faces;
};

}  // namespace

int orient_cell_faces(std::vector<std::vector<int32_t>>& faces, const std::vector<Vec3>& pts, bool* consistent) {
  if (consistent) *consistent = true;
  const int nf = static_cast<int>(faces.size());
  struct E {
    int32_t lo, hi;
    int face;
    bool fwd;
  };
  std::vector<E> edges;
  for (int f = 0; f < nf; ++f) {
    const size_t k = faces[f].size();
    for (size_t i = 0; i < k; ++i) {
      const int32_t a = faces[f][i], b = faces[f][(i + 1) % k];
      if (a == b) continue;
      edges.push_back({std::min(a, b), std::max(a, b), f, a < b});
    }
  }
  std::sort(edges.begin(), edges.end(), [](const E& x, const E& y) { return x.lo != y.lo ? x.lo < y.lo : x.hi < y.hi; });
  // Faces sharing an edge (used by exactly two faces) must traverse it in opposite directions.
  std::vector<std::vector<std::pair<int, bool>>> adj(nf);  // (other face, must have a different flip)
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    while (j < edges.size() && edges[j].lo == edges[i].lo && edges[j].hi == edges[i].hi) ++j;
    if (j - i == 2 && edges[i].face != edges[i + 1].face) {
      const bool same_dir = edges[i].fwd == edges[i + 1].fwd;
      adj[edges[i].face].emplace_back(edges[i + 1].face, same_dir);
      adj[edges[i + 1].face].emplace_back(edges[i].face, same_dir);
    }
    i = j;
  }
  std::vector<int> flip(nf, -1), comp(nf, -1);
  int ncomp = 0;
  for (int s = 0; s < nf; ++s) {
    if (flip[s] >= 0) continue;
    flip[s] = 0;
    comp[s] = ncomp;
    std::vector<int> queue{s};
    while (!queue.empty()) {
      const int f = queue.back();
      queue.pop_back();
      for (auto [g, differ] : adj[f]) {
        const int want = differ ? 1 - flip[f] : flip[f];
        if (flip[g] < 0) {
          flip[g] = want;
          comp[g] = ncomp;
          queue.push_back(g);
        } else if (flip[g] != want && consistent) {
          *consistent = false;
        }
      }
    }
    ++ncomp;
  }
  // Outward: each component's signed volume about the mean node must be positive.
  Vec3 x0;
  size_t cnt = 0;
  for (const auto& f : faces)
    for (int32_t v : f) x0 += pts[v], ++cnt;
  if (cnt > 0) x0 = x0 / static_cast<double>(cnt);
  std::vector<double> vol(ncomp, 0.0);
  for (int f = 0; f < nf; ++f) {
    const size_t k = faces[f].size();
    if (k < 3) continue;
    Vec3 g;
    for (int32_t v : faces[f]) g += pts[v];
    g = g / static_cast<double>(k);
    double v6 = 0;
    for (size_t i = 0; i < k; ++i)
      v6 += dot(g - x0, cross(pts[faces[f][i]] - x0, pts[faces[f][(i + 1) % k]] - x0));
    vol[comp[f]] += flip[f] ? -v6 : v6;
  }
  int flipped = 0;
  for (int f = 0; f < nf; ++f) {
    const bool reverse = (flip[f] == 1) != (vol[comp[f]] < 0);
    if (reverse) {
      std::reverse(faces[f].begin(), faces[f].end());
      ++flipped;
    }
  }
  return flipped;
}

ReadResult read_vtu_buffer(const std::string& buf) {
  ReadResult res;
  try {
    if (buf.empty()) fail("empty file");
    const XmlDoc doc = parse_xml(buf);
    if (doc.nodes.empty() || doc.nodes[0].name != "VTKFile") fail("not a VTK XML file (no <VTKFile> root)");
    const XmlNode& root = doc.nodes[0];
    const std::string* type = root.attr("type");
    if (!type || *type != "UnstructuredGrid")
      fail("not an UnstructuredGrid file (type=\"" + (type ? *type : std::string()) + "\")");
    FileInfo fi;
    fi.buf = &buf;
    fi.doc = &doc;
    if (const std::string* comp = root.attr("compressor"); comp && !comp->empty())
      fail("compressed data (" + *comp + ") is not supported; write the file uncompressed");
    const std::string* bo = root.attr("byte_order");
    const bool file_le = !bo || *bo == "LittleEndian";
    if (bo && *bo != "LittleEndian" && *bo != "BigEndian") fail("unknown byte_order '" + *bo + "'");
    fi.swap = file_le != host_little_endian();
    if (const std::string* ht = root.attr("header_type")) {
      if (*ht == "UInt64") fi.header_bytes = 8;
      else if (*ht == "UInt32") fi.header_bytes = 4;
      else fail("unsupported header_type '" + *ht + "'");
    }
    if (doc.appended >= 0) {
      const std::string* enc = doc.nodes[doc.appended].attr("encoding");
      if (!enc || *enc == "raw") fi.appended_base64 = false;
      else if (*enc == "base64") fi.appended_base64 = true;
      else fail("unsupported AppendedData encoding '" + *enc + "'");
    }
    const XmlNode* grid = child(doc, root, "UnstructuredGrid");
    if (!grid) fail("no <UnstructuredGrid> element");

    std::vector<Vec3> points;
    std::vector<RawCell> cells;
    std::vector<Array> cell_data;  // concatenated over pieces
    std::vector<std::string> dropped;
    int pieces = 0;
    for (int ci : grid->children) {
      const XmlNode& piece = doc.nodes[ci];
      if (piece.name != "Piece") continue;
      ++pieces;
      const int64_t np = parse_count(piece.attr("NumberOfPoints"), "NumberOfPoints", kMaxIds);
      const int64_t nc = parse_count(piece.attr("NumberOfCells"), "NumberOfCells", kMaxIds);
      const int64_t base = static_cast<int64_t>(points.size());
      if (base + np > kMaxIds || static_cast<int64_t>(cells.size()) + nc > kMaxIds) fail("too many points or cells");
      // Points.
      if (np > 0) {
        const XmlNode* pts = child(doc, piece, "Points");
        if (!pts) fail("piece without <Points>");
        const XmlNode* arr = nullptr;
        for (int c : pts->children)
          if (doc.nodes[c].name == "DataArray") { arr = &doc.nodes[c]; break; }
        if (!arr) fail("<Points> without a DataArray");
        Array p = read_array(fi, *arr, 3 * np);
        if (p.components != 3) fail("Points must have 3 components");
        for (int64_t i = 0; i < np; ++i) {
          const Vec3 x{p.as_double(3 * i), p.as_double(3 * i + 1), p.as_double(3 * i + 2)};
          if (!std::isfinite(x.x) || !std::isfinite(x.y) || !std::isfinite(x.z))
            fail("point " + std::to_string(base + i) + " has a non-finite coordinate");
          points.push_back(x);
        }
      }
      // Cells.
      if (nc > 0) {
        const XmlNode* cx = child(doc, piece, "Cells");
        if (!cx) fail("piece without <Cells>");
        const XmlNode* n_types = data_array(doc, *cx, "types");
        const XmlNode* n_offsets = data_array(doc, *cx, "offsets");
        const XmlNode* n_conn = data_array(doc, *cx, "connectivity");
        if (!n_types || !n_offsets || !n_conn) fail("<Cells> needs connectivity, offsets and types");
        const Array types = read_array(fi, *n_types, nc);
        const Array offsets = read_array(fi, *n_offsets, nc);
        const Array conn = read_array(fi, *n_conn, -1);
        if (!types.is_int || !offsets.is_int || !conn.is_int) fail("connectivity, offsets and types must be integer arrays");
        Array faces, faceoffsets;
        bool any_poly = false;
        for (int64_t v : types.i) any_poly = any_poly || v == 42;
        if (any_poly) {
          const XmlNode* n_faces = data_array(doc, *cx, "faces");
          const XmlNode* n_fo = data_array(doc, *cx, "faceoffsets");
          if (!n_faces || !n_fo) fail("polyhedral cells need the faces and faceoffsets arrays");
          faces = read_array(fi, *n_faces, -1);
          faceoffsets = read_array(fi, *n_fo, nc);
          if (!faces.is_int || !faceoffsets.is_int) fail("faces and faceoffsets must be integer arrays");
        }
        auto point_id = [&](int64_t v, int64_t cell) {
          if (v < 0 || v >= np)
            fail("cell " + std::to_string(cell) + ": point id " + std::to_string(v) + " out of range [0, " +
                 std::to_string(np) + ")");
          return static_cast<int32_t>(base + v);
        };
        int64_t prev_conn_end = 0, prev_face_end = 0;
        for (int64_t c = 0; c < nc; ++c) {
          const int64_t cid = static_cast<int64_t>(cells.size());
          const int64_t cend = offsets.i[c];
          if (cend < prev_conn_end || cend > static_cast<int64_t>(conn.i.size()))
            fail("cell " + std::to_string(cid) + ": bad offsets entry " + std::to_string(cend));
          RawCell rc;
          const int64_t t = types.i[c];
          if (t == 42) {
            const int64_t fend = faceoffsets.i[c];
            const int64_t fbeg = prev_face_end;
            if (fend < fbeg || fend > static_cast<int64_t>(faces.i.size()))
              fail("cell " + std::to_string(cid) + ": bad faceoffsets entry " + std::to_string(fend));
            int64_t p = fbeg;
            if (p >= fend) fail("cell " + std::to_string(cid) + ": empty face list");
            const int64_t nfaces = faces.i[p++];
            if (nfaces < 1 || nfaces > fend - p)
              fail("cell " + std::to_string(cid) + ": bad number of faces " + std::to_string(nfaces));
            for (int64_t k = 0; k < nfaces; ++k) {
              if (p >= fend) fail("cell " + std::to_string(cid) + ": face list ends early");
              const int64_t nv = faces.i[p++];
              if (nv < 0 || nv > fend - p)
                fail("cell " + std::to_string(cid) + ": bad face size " + std::to_string(nv));
              std::vector<int32_t> fv;
              for (int64_t q = 0; q < nv; ++q) fv.push_back(point_id(faces.i[p++], cid));
              rc.faces.push_back(std::move(fv));
            }
            if (p != fend)
              fail("cell " + std::to_string(cid) + ": faces stream has " + std::to_string(fend - p) + " extra entries");
            prev_face_end = fend;
          } else {
            int npts = 0;
            const std::vector<std::vector<int>>* tmpl = standard_faces(static_cast<int>(std::clamp<int64_t>(t, -1, 1000)), &npts);
            if (!tmpl) fail("cell " + std::to_string(cid) + ": unsupported VTK cell type " + std::to_string(t));
            if (cend - prev_conn_end != npts)
              fail("cell " + std::to_string(cid) + ": type " + std::to_string(t) + " needs " + std::to_string(npts) +
                   " points, got " + std::to_string(cend - prev_conn_end));
            for (const auto& lf : *tmpl) {
              std::vector<int32_t> fv;
              for (int k : lf) fv.push_back(point_id(conn.i[prev_conn_end + k], cid));
              rc.faces.push_back(std::move(fv));
            }
          }
          prev_conn_end = cend;
          cells.push_back(std::move(rc));
        }
      }
      // Cell data.
      std::vector<Array> piece_data;
      if (const XmlNode* cd = child(doc, piece, "CellData"))
        for (int c : cd->children)
          if (doc.nodes[c].name == "DataArray") {
            const XmlNode& an = doc.nodes[c];
            int comps = 1;
            if (const std::string* s = an.attr("NumberOfComponents"))
              comps = static_cast<int>(parse_count(s, "NumberOfComponents", 1 << 20));
            piece_data.push_back(read_array(fi, an, nc * comps));
          }
      if (pieces == 1) {
        cell_data = std::move(piece_data);
      } else {
        std::vector<Array> merged;
        for (Array& a : cell_data) {
          auto it = std::find_if(piece_data.begin(), piece_data.end(), [&](const Array& b) {
            return b.name == a.name && b.components == a.components && b.is_int == a.is_int;
          });
          if (it == piece_data.end()) {
            dropped.push_back(a.name);
            continue;
          }
          a.i.insert(a.i.end(), it->i.begin(), it->i.end());
          a.d.insert(a.d.end(), it->d.begin(), it->d.end());
          merged.push_back(std::move(a));
        }
        cell_data = std::move(merged);
      }
    }
    if (pieces == 0) fail("no <Piece> element");
    if (cells.empty()) fail("the file has no cells");
    for (const std::string& d : dropped) res.warnings.push_back("cell array '" + d + "' missing in some piece: ignored");

    // Boundary patches: the writer's face_patch field data, else "used once = outer boundary".
    int64_t total_faces = 0;
    for (const RawCell& rc : cells) total_faces += static_cast<int64_t>(rc.faces.size());
    std::vector<int32_t> face_patch;
    if (const XmlNode* fd = child(doc, *grid, "FieldData"))
      if (const XmlNode* fp = data_array(doc, *fd, "face_patch")) {
        Array a = read_array(fi, *fp, -1);
        if (a.is_int && static_cast<int64_t>(a.i.size()) == total_faces && pieces == 1) {
          for (int64_t v : a.i) face_patch.push_back(static_cast<int32_t>(std::clamp<int64_t>(v, -1, 1 << 30)));
          res.has_face_patch = true;
        } else {
          res.warnings.push_back("field data face_patch does not match the faces: ignored");
        }
      }

    // Orient every cell's faces outward.
    for (size_t c = 0; c < cells.size(); ++c) {
      bool consistent = true;
      res.flipped_faces += orient_cell_faces(cells[c].faces, points, &consistent);
      if (!consistent) ++res.unorientable_cells;
    }
    std::map<std::vector<int32_t>, int> uses;
    if (!res.has_face_patch)
      for (const RawCell& rc : cells)
        for (const auto& f : rc.faces)
          if (f.size() >= 3) ++uses[canonical_cycle(f, nullptr)];

    MeshBuilder mb;
    for (const Vec3& p : points) mb.add_node(p);
    size_t k = 0;
    for (const RawCell& rc : cells) {
      std::vector<CellFace> cf;
      for (const auto& f : rc.faces) {
        CellFace face;
        face.nodes = f;
        if (res.has_face_patch) {
          face.patch = face_patch[k];
        } else {
          auto it = f.size() >= 3 ? uses.find(canonical_cycle(f, nullptr)) : uses.end();
          face.patch = it != uses.end() && it->second >= 2 ? kInteriorFace : kOuterBoundary;
        }
        ++k;
        cf.push_back(std::move(face));
      }
      mb.add_cell(cf, CellAttributes{});
    }
    res.mesh = mb.finish(&res.build);
    PolyMesh& m = res.mesh;
    const size_t ncell = cells.size();

    // Cell data.
    for (const Array& a : cell_data) {
      VtuCellArray v;
      v.name = a.name;
      v.components = a.components;
      v.values.resize(a.size());
      for (size_t i = 0; i < a.size(); ++i) v.values[i] = a.as_double(i);
      res.cell_arrays.push_back(std::move(v));
    }
    if (const VtuCellArray* r = res.find("region")) {
      for (size_t c = 0; c < ncell; ++c) {
        const double v = r->values[c * r->components];
        if (!(std::fabs(v) < 2e9) || v != std::floor(v)) fail("cell " + std::to_string(c) + ": region is not an integer");
        m.cell_region[c] = static_cast<int32_t>(v);
      }
      res.has_region = true;
    }
    if (const VtuCellArray* fc = res.find("fv_center")) {
      if (fc->components != 3) fail("fv_center must have 3 components");
      for (size_t c = 0; c < ncell; ++c) {
        const Vec3 x{fc->values[3 * c], fc->values[3 * c + 1], fc->values[3 * c + 2]};
        if (!std::isfinite(x.x) || !std::isfinite(x.y) || !std::isfinite(x.z))
          fail("cell " + std::to_string(c) + ": fv_center is not finite");
        m.cell_fv_center[c] = x;
      }
      res.has_fv_center = true;
    } else {
      const MeshGeometry geo = compute_geometry(m);
      for (size_t c = 0; c < ncell; ++c) m.cell_fv_center[c] = geo.cell_centroid[c];
    }
    if (const VtuCellArray* pm = res.find("permeability")) {
      if (pm->components == 3 || pm->components == 1)
        for (size_t c = 0; c < ncell; ++c) {
          const double* v = &pm->values[c * pm->components];
          m.cell_perm[c] = pm->components == 3 ? Vec3{v[0], v[1], v[2]} : Vec3{v[0], v[0], v[0]};
        }
      else
        res.warnings.push_back("permeability must have 1 or 3 components: ignored");
    }
    if (const VtuCellArray* po = res.find("porosity"))
      for (size_t c = 0; c < ncell; ++c) m.cell_porosity[c] = po->values[c * po->components];
    if (const VtuCellArray* ijk = res.find("ijk"); ijk && ijk->components == 3)
      for (size_t c = 0; c < ncell; ++c)
        for (int d = 0; d < 3; ++d) {
          const double v = ijk->values[3 * c + d];
          m.cell_ijk[c][d] = std::fabs(v) < 2e9 ? static_cast<int32_t>(v) : -1;
        }
    if (res.flipped_faces > 0)
      res.warnings.push_back(std::to_string(res.flipped_faces) + " face(s) re-oriented to point out of their cell");
    if (res.unorientable_cells > 0)
      res.warnings.push_back(std::to_string(res.unorientable_cells) + " cell(s) whose faces cannot be oriented consistently");
    res.ok = true;
  } catch (const VtuError& e) {
    res = ReadResult{};
    res.error = e.what;
  } catch (const std::bad_alloc&) {
    res = ReadResult{};
    res.error = "out of memory (declared sizes too large?)";
  }
  return res;
}

ReadResult read_vtu(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    ReadResult r;
    r.error = "cannot read " + path + ": is a directory";
    return r;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    ReadResult r;
    r.error = "cannot open " + path + ": " + std::strerror(errno);
    return r;
  }
  // One buffer of the file's size (no stream copy: mesh files can be large).
  std::string bytes;
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(0, std::ios::beg);
  if (size > 0) {
    bytes.resize(static_cast<size_t>(size));
    in.read(bytes.data(), size);
    bytes.resize(static_cast<size_t>(std::max<std::streamsize>(in.gcount(), 0)));
  }
  if (in.bad()) {
    ReadResult r;
    r.error = "cannot read " + path;
    return r;
  }
  ReadResult r = read_vtu_buffer(bytes);
  if (!r.ok) r.error = path + ": " + r.error;
  return r;
}

}  // namespace hm
