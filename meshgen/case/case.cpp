// YAML case-file loader (docs/case-format.md). Every problem with the input becomes one
// hm::InputError "key.path: reason"; yaml-cpp is only used to get a node tree, all
// conversions are done here so that the accepted syntax and the messages are ours.
#include "meshgen/case/case.hpp"

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <numeric>
#include <optional>
#include <sstream>
#include <utility>

#include "meshgen/case/case_limits.hpp"
#include "meshgen/case/near_well_layers.hpp"
#include "meshgen/case/corner_point_fault_steps.hpp"
#include "meshgen/case/corner_point_path.hpp"
#include "meshgen/case/corner_point_refine.hpp"
#include "meshgen/case/corner_point_straighten.hpp"
#include "meshgen/case/grdecl.hpp"
#include "meshgen/case/meshed_trajectory.hpp"
#include "meshgen/case/permeability_metric.hpp"
#include "meshgen/case/segment_distance.hpp"
#include "meshgen/case/survey.hpp"
#include "meshgen/core/polymesh.hpp"

namespace hm {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& reason) { throw InputError(path + ": " + reason); }

std::string key_path(const std::string& parent, const std::string& key) {
  return parent.empty() ? key : parent + "." + key;
}
std::string index_path(const std::string& parent, size_t i) { return parent + "[" + std::to_string(i) + "]"; }

// Length in bytes of the well-formed UTF-8 sequence starting at s[i], or 0 if it is not one.
size_t utf8_sequence_length(const std::string& s, size_t i) {
  const auto lead = static_cast<unsigned char>(s[i]);
  size_t n = 0;
  if (lead >= 0xC2 && lead <= 0xDF) n = 2;
  else if (lead >= 0xE0 && lead <= 0xEF) n = 3;
  else if (lead >= 0xF0 && lead <= 0xF4) n = 4;
  else return 0;
  if (i + n > s.size()) return 0;
  for (size_t k = 1; k < n; ++k)
    if ((static_cast<unsigned char>(s[i + k]) & 0xC0) != 0x80) return 0;
  return n;
}

// User text echoed in a message: one line, control bytes and malformed UTF-8 escaped,
// long text cut (messages must stay a single readable line).
std::string printable(const std::string& s, size_t max_chars = 40) {
  std::string out;
  size_t chars = 0;
  for (size_t i = 0; i < s.size(); ++chars) {
    if (chars == max_chars) return out + "...";
    const auto c = static_cast<unsigned char>(s[i]);
    if (c >= 0x20 && c < 0x7F) {
      out += s[i++];
    } else if (const size_t n = c >= 0x80 ? utf8_sequence_length(s, i) : 0; n > 0) {
      out += s.substr(i, n);
      i += n;
    } else {
      static const char* hex = "0123456789abcdef";
      out += c == '\n' ? std::string("\\n") : c == '\t' ? std::string("\\t")
                                                         : std::string("\\x") + hex[c >> 4] + hex[c & 15];
      ++i;
    }
  }
  return out;
}
std::string quoted(const std::string& s, size_t max_chars = 40) { return "'" + printable(s, max_chars) + "'"; }

// Shortest text that reads back as v (echoes user values as written).
std::string fmt(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}
// Computed values (distances): 6 significant digits.
std::string fmt6(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 6);
  return std::string(buf, r.ptr);
}
void require_coordinate(double v, const std::string& path) {
  if (!(std::abs(v) <= kMaxAbsCoordinate))
    fail(path, "coordinates must be within +-" + fmt(kMaxAbsCoordinate) + " m (docs/case-format.md, Limits)");
}
std::string fmt_count(double v) {
  return v < 1e15 ? std::to_string(static_cast<long long>(v)) : fmt6(v);
}

// Decimal number grammar accepted for numbers: [-+]? (d+ .? d* | . d+) ([eE] [-+]? d+)?
// (no hex, no .inf/.nan, no digit separators). Returns the text without a leading '+'.
std::optional<std::string> decimal_text(const std::string& s) {
  size_t i = 0;
  if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
  const size_t mantissa_begin = i;
  size_t digits = 0;
  while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i]))) ++i, ++digits;
  if (i < s.size() && s[i] == '.') {
    ++i;
    while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i]))) ++i, ++digits;
  }
  if (digits == 0 || i == mantissa_begin) return std::nullopt;
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
    size_t exp_digits = 0;
    while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i]))) ++i, ++exp_digits;
    if (exp_digits == 0) return std::nullopt;
  }
  if (i != s.size()) return std::nullopt;
  return s[0] == '+' ? s.substr(1) : s;
}

bool is_integer_text(const std::string& s) {
  size_t i = (!s.empty() && (s[0] == '+' || s[0] == '-')) ? 1 : 0;
  if (i == s.size()) return false;
  for (; i < s.size(); ++i)
    if (!std::isdigit(static_cast<unsigned char>(s[i]))) return false;
  return true;
}

// A quoted scalar ('5', "5", block scalars) or one tagged !!str is a string, never a number.
bool is_string_scalar(const YAML::Node& n) { return n.Tag() == "!" || n.Tag() == "tag:yaml.org,2002:str"; }

// What the user wrote, for "expected ..., got <describe>": numbers bare, other text quoted.
std::string describe(const YAML::Node& n) {
  switch (n.Type()) {
    case YAML::NodeType::Sequence: return "a list";
    case YAML::NodeType::Map: return "a map";
    case YAML::NodeType::Scalar:
      if (!decimal_text(n.Scalar())) return quoted(n.Scalar());
      return is_string_scalar(n) ? "a quoted string " + quoted(n.Scalar()) : printable(n.Scalar());
    default: return "null";
  }
}

double read_number(const YAML::Node& n, const std::string& path) {
  if (!n.IsScalar() || is_string_scalar(n)) fail(path, "expected a number, got " + describe(n));
  const auto text = decimal_text(n.Scalar());
  if (!text) fail(path, "expected a number, got " + describe(n));
  double v = 0;
  const auto r = std::from_chars(text->data(), text->data() + text->size(), v);
  if (r.ec != std::errc() || r.ptr != text->data() + text->size() || !std::isfinite(v))
    fail(path, "expected a finite number, got " + describe(n));
  return v;
}

int read_int(const YAML::Node& n, const std::string& path) {
  if (!n.IsScalar() || is_string_scalar(n) || !is_integer_text(n.Scalar()))
    fail(path, "expected an integer, got " + describe(n));
  const std::string& s = n.Scalar();
  const char* begin = s.data() + (s[0] == '+' ? 1 : 0);
  long long v = 0;
  const auto r = std::from_chars(begin, s.data() + s.size(), v);
  if (r.ec != std::errc() || v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
    fail(path, "integer out of range, got " + describe(n));
  return static_cast<int>(v);
}

bool read_bool(const YAML::Node& n, const std::string& path) {
  if (n.IsScalar() && !is_string_scalar(n)) {
    const std::string& s = n.Scalar();
    if (s == "true" || s == "True" || s == "TRUE") return true;
    if (s == "false" || s == "False" || s == "FALSE") return false;
  }
  fail(path, "expected true or false, got " + describe(n));
}

std::string read_string(const YAML::Node& n, const std::string& path) {
  if (!n.IsScalar()) fail(path, "expected a string, got " + describe(n));
  return n.Scalar();
}

bool matches_name_charset(const std::string& s) {
  if (s.empty()) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-')) return false;
  return true;
}

// A map's entries by key, checked: only `allowed` keys, each at most once, keys are plain names.
class Fields {
 public:
  Fields(const YAML::Node& map, const std::string& path, std::initializer_list<const char*> allowed) : path_(path) {
    if (!map.IsMap()) fail(path, "expected a map, got " + describe(map));
    for (auto it = map.begin(); it != map.end(); ++it) {
      // Copies: it-> returns a temporary proxy, a reference into it would dangle.
      const YAML::Node key = it->first;
      const YAML::Node value = it->second;
      if (!key.IsScalar()) fail(path.empty() ? "case file" : path, "expected a key name, got " + describe(key));
      const std::string& name = key.Scalar();
      if (std::find_if(allowed.begin(), allowed.end(), [&](const char* a) { return name == a; }) == allowed.end()) {
        std::string expected;
        for (const char* a : allowed) expected += (expected.empty() ? "" : ", ") + std::string(a);
        // A key that is not a plain name (empty, or holding ": " or control bytes) is quoted, so that the
        // message still reads 'key.path: reason'.
        fail(key_path(path, matches_name_charset(name) ? name : quoted(name)),
             "unknown key (expected one of: " + expected + ")");
      }
      for (const auto& e : entries_)
        if (e.first == name) fail(key_path(path, name), "duplicate key");
      entries_.emplace_back(name, value);
    }
  }
  std::optional<YAML::Node> get(const std::string& key) const {
    for (const auto& e : entries_)
      if (e.first == key) return e.second;
    return std::nullopt;
  }
  YAML::Node required(const std::string& key) const {
    auto n = get(key);
    if (!n) fail(path(key), "required key is missing");
    return *n;
  }
  std::string path(const std::string& key) const { return key_path(path_, key); }

  // Optional scalar fields: keep `value` (the case.hpp default) when the key is absent.
  void number(const std::string& key, double& value) const {
    if (auto n = get(key)) value = read_number(*n, path(key));
  }
  void integer(const std::string& key, int& value) const {
    if (auto n = get(key)) value = read_int(*n, path(key));
  }
  void boolean(const std::string& key, bool& value) const {
    if (auto n = get(key)) value = read_bool(*n, path(key));
  }

 private:
  std::string path_;
  std::vector<std::pair<std::string, YAML::Node>> entries_;
};

// Exactly three numbers, e.g. permeability [kx, ky, kz].
std::array<double, 3> read_triple(const YAML::Node& n, const std::string& path, const char* shape) {
  if (!n.IsSequence()) fail(path, std::string("expected a list of 3 numbers ") + shape + ", got " + describe(n));
  if (n.size() != 3) fail(path, std::string("expected 3 values ") + shape + ", got " + std::to_string(n.size()));
  std::array<double, 3> v{};
  for (size_t i = 0; i < 3; ++i) v[i] = read_number(n[i], index_path(path, i));
  return v;
}

std::vector<double> read_axis(const YAML::Node& n, const std::string& path) {
  if (!n.IsSequence()) fail(path, "expected a list of numbers, got " + describe(n));
  if (n.size() < 2) fail(path, "needs at least 2 values");
  if (n.size() > kMaxAxisValues)
    fail(path, "at most " + std::to_string(kMaxAxisValues) + " values (got " + std::to_string(n.size()) + ")");
  std::vector<double> v;
  v.reserve(n.size());
  for (size_t i = 0; i < n.size(); ++i) {
    v.push_back(read_number(n[i], index_path(path, i)));
    require_coordinate(v.back(), index_path(path, i));
    if (i > 0 && !(v[i] > v[i - 1])) fail(path, "not strictly increasing at index " + std::to_string(i));
  }
  return v;
}

void require(bool ok, const std::string& path, const std::string& reason) {
  if (!ok) fail(path, reason);
}
// v in [lo, hi] (lo_open: (lo, hi]); the message gives the range with its unit.
void require_range(double v, double lo, double hi, bool lo_open, const std::string& path, const char* unit) {
  require(lo_open ? v > lo : v >= lo, path,
          std::string("must be ") + (lo_open ? "> " : ">= ") + fmt(lo) + (lo == 0 ? std::string() : " " + std::string(unit)));
  require(v <= hi, path, "must be <= " + fmt(hi) + " " + unit + " (docs/case-format.md, Limits)");
}

// Why cell c of a model's reservoir cannot be meshed: its rock or pore volume out of range (empty: it can).
std::string rock_problem(const ReservoirSpec& r, size_t c) {
  if (!(r.cell_poro[c] > 0 && r.cell_poro[c] <= 1)) return "porosity x NTG must be in (0, 1], got " + fmt(r.cell_poro[c]);
  if (!r.cell_pore_volume_mult.empty() && !(std::isfinite(r.cell_pore_volume_mult[c]) && r.cell_pore_volume_mult[c] > 0))
    return "its pore volume in OPM (MULTPV, PORV) is " + fmt(r.cell_pore_volume_mult[c]) +
           " x volume x PORO x NTG: must be > 0";
  if (!(r.cell_permx[c] > 0 && r.cell_permy[c] > 0 && r.cell_permz[c] > 0)) return "permeability must be > 0";
  for (double k : {r.cell_permx[c], r.cell_permy[c], r.cell_permz[c]})
    if (!(k >= kMinPermeability && k <= kMaxPermeability))
      return "permeability must be in [" + fmt(kMinPermeability) + ", " + fmt(kMaxPermeability) + "] mD, got " + fmt(k) +
             " (docs/case-format.md, Limits)";
  return {};
}

// reservoir.grdecl: a model file read by OPM instead of the x/y/z axes and the uniform rock.
ReservoirSpec read_grdecl_reservoir(const Fields& f, const std::string& base_dir, std::vector<std::string>& notes) {
  for (const char* k : {"x", "y", "z", "permeability", "porosity"})
    if (f.get(k)) fail(f.path(k), "not with reservoir.grdecl (the model gives the grid and its rock)");
  std::string path = read_string(f.required("grdecl"), f.path("grdecl"));
  if (!base_dir.empty() && !path.empty() && path[0] != '/') path = base_dir + "/" + path;
  CornerPointModel as_read = read_corner_point_model(path, f.path("grdecl"));
  if (const int64_t merged = merge_rounded_depths(as_read); merged > 0)
    notes.push_back(f.path("grdecl") + ": " + std::to_string(merged) +
                    " corner depths within a rounding of another corner's on the same pillar made one (a fault whose "
                    "throw is a whole number of layers, written with rounding): one node there, not a fault of "
                    "1e-13 m (docs/corner-point.md, \"Depths equal up to a rounding\")");
  auto shared = std::make_shared<const CornerPointModel>(std::move(as_read));
  const CornerPointModel& model = *shared;
  if (model.below_minpv > 0) {
    char pv[160];
    std::snprintf(pv, sizeof pv, "%.6g rm3, %.3g %% of the active pore volume", model.below_minpv_pore_volume,
                  100 * model.below_minpv_pore_volume / model.active_pore_volume);
    notes.push_back(f.path("grdecl") + ": " + std::to_string(model.below_minpv) +
                    " active cells have a pore volume below the model's MINPV (" + pv +
                    "): removed as OPM Flow removes them, and " + std::to_string(model.minpv_connections.size()) +
                    " pairs of cells above and below connected across them as flow connects them (docs/corner-point.md, "
                    "\"MINPV\")");
  }
  if (model.other_pore_volume > 0) {
    char pv[200];
    std::snprintf(pv, sizeof pv, "%.6g rm3 in OPM against %.6g", model.other_pore_volume_opm, model.other_pore_volume_ours);
    notes.push_back(f.path("grdecl") + ": " + std::to_string(model.other_pore_volume) +
                    " active cells have a pore volume other than volume x PORO x NTG (MULTPV or PORV in the deck; " + pv +
                    "): the mesh carries it as their pore-volume multiplier, and the near-well cells take the "
                    "multiplier of the model cell they lie in (docs/corner-point.md, \"Pore volumes\")");
  }
  // Axis-aligned boxes, all active, no multiplier: the rectilinear grid (the same mesh as the box
  // form); else the model's own cells (meshgen/grids/corner_point_grid.hpp), which carry multipliers.
  ReservoirSpec r = is_rectilinear(model) && !has_transmissibility_multipliers(model) && model.nnc.empty()
                       ? rectilinear_reservoir(model, f.path("grdecl"))
                       : corner_point_reservoir(shared, f.path("grdecl"));
  for (size_t c = 0; c < r.cell_poro.size(); ++c) {
    if (!model.actnum[c]) continue;  // inactive cells carry no rock
    const std::string problem = rock_problem(r, c);
    require(problem.empty(), f.path("grdecl") + ": cell " + std::to_string(c), problem);
  }
  for (const auto* axis : {&r.x, &r.y, &r.z})
    for (double v : *axis) require_coordinate(v, f.path("grdecl"));
  r.grdecl = path;
  if (model.has_mapaxes) {
    r.has_map_axes = true;
    r.map_origin = {model.map_origin[0], model.map_origin[1], 0};
    r.map_unit_x = {model.map_unit_x[0], model.map_unit_x[1], 0};
    r.map_unit_y = {model.map_unit_y[0], model.map_unit_y[1], 0};
    const double det = r.map_unit_x.x * r.map_unit_y.y - r.map_unit_x.y * r.map_unit_y.x;
    require(std::isfinite(det) && det != 0, f.path("grdecl"), "MAPAXES: the grid axes are parallel");
  }
  return r;
}

// reservoir.near_well_cell_size: auto (0), off (-1) or a size in metres.
double read_near_well_cell_size(const YAML::Node& n, const std::string& path) {
  if (n.IsScalar() && n.Scalar() == "auto") return 0;
  if (n.IsScalar() && n.Scalar() == "off") return -1;
  if (!n.IsScalar() || !decimal_text(n.Scalar())) fail(path, "expected auto, off or a size in m, got " + describe(n));
  const double v = read_number(n, path);
  require(v > 0, path, "must be > 0");
  return v;
}

// Wells in a corner-point model: the part of each path inside the model's active cells is meshed
// (meshgen/case/corner_point_path.hpp), clipped from the path as the user gave it (`as_given`, grid
// frame); with `note` the case says so in its notes.
void clip_paths_to_model(CaseSpec& cs, const std::vector<WellSpec>& as_given, SurfaceGapRule rule, bool note) {
  if (!cs.reservoir.corner_point) return;
  for (size_t i = 0; i < cs.wells.size(); ++i) {
    WellSpec& w = cs.wells[i];
    const std::string key = index_path("wells", i);
    const ClippedPath path = clip_path_to_model(*cs.reservoir.corner_point, as_given[i], key, rule);
    if (!path.clipped()) continue;
    if (w.end_caps == EndCaps::Hemisphere && !w.end_caps_fallback)
      fail(key + ".end_caps", "hemisphere caps need both ends of the path inside the corner-point model; this well "
                              "crosses the model's surface (use flat or auto)");
    w.end_caps = EndCaps::Flat;
    w.end_caps_fallback = false;
    w.trajectory = path.points;
    w.trajectory_md = path.md;
    if (!note) continue;
    std::string gaps;
    for (int e = 0; e < 2; ++e)
      if (path.cut[e] > 0)
        gaps += std::string(gaps.empty() ? "" : ", ") + (e == 0 ? "start " : "end ") + fmt6(path.gap[e]) + " m (" +
                fmt6(path.gap[e] / w.drainage_radius) + " x drainage_radius)";
    const bool crosses = path.crosses[0] || path.crosses[1];
    const bool near = (path.cut[0] > 0 && !path.crosses[0]) || (path.cut[1] > 0 && !path.crosses[1]);
    const std::string where = crosses && near ? "crosses the corner-point model's surface and ends near it"
                              : crosses       ? "crosses the corner-point model's surface"
                                              : "ends near the corner-point model's surface";
    std::string text = key + " (" + w.name + "): its path " + where + "; the radial block is "
                       "built from measured depth " + fmt6(path.md.front()) + " to " + fmt6(path.md.back()) +
                       " m (flat ends that keep " + gaps + " from the surface) and the transition fills the rest to "
                       "the surface";
    bool open_outside = false;
    for (const auto& iv : w.perforations) open_outside = open_outside || iv[0] < path.md.front() || iv[1] > path.md.back();
    if (w.perforations.empty())
      text += near ? "; the path beyond the block's ends has no wellbore connection"
                   : "; the path between the surface and the block has no wellbore connection";
    if (open_outside) text += "; perforated depths outside that range have no wellbore connection";
    cs.notes.push_back(text);
  }
}

// Each corner-point well's block with outer faces small enough for the model's surface near its path
// (fit_outer_faces); a well whose faces cannot be made so is left as it is, for the cavity's Gabriel
// test to refuse, naming the cell.
void fit_blocks_to_the_surface(CaseSpec& cs) {
  if (!cs.reservoir.corner_point) return;
  for (size_t i = 0; i < cs.wells.size(); ++i) {
    WellSpec& w = cs.wells[i];
    const double clearance = surface_clearance(*cs.reservoir.corner_point, w);
    const OuterFaceFit fit = fit_outer_faces(w, clearance);
    if (!fit.fits || (fit.sectors == w.sectors && fit.segment_length == w.segment_length)) continue;
    std::string change;
    if (fit.sectors != w.sectors) change = "sectors " + std::to_string(w.sectors) + " -> " + std::to_string(fit.sectors);
    if (fit.segment_length != w.segment_length)
      change += (change.empty() ? "" : ", ") + std::string("segment_length ") + fmt6(w.segment_length) + " -> " +
                fmt6(fit.segment_length) + " m";
    cs.notes.push_back(index_path("wells", i) + " (" + w.name + "): " + change + ": its block passes " +
                       fmt6(clearance) + " m from the corner-point model's surface, so its outer faces are made "
                       "smaller than that (their diametral spheres must not hold the surface's nodes, paper 5.1)");
    w.sectors = fit.sectors;
    w.segment_length = fit.segment_length;
  }
}

// The case's reservoir becomes `model` (its axes and per-cell rock as corner_point_reservoir gives them).
void use_model(ReservoirSpec& r, std::shared_ptr<const CornerPointModel> model) {
  const ReservoirSpec grid = corner_point_reservoir(std::move(model), "reservoir.grdecl");
  r.x = grid.x;
  r.y = grid.y;
  r.z = grid.z;
  r.cell_permx = grid.cell_permx;
  r.cell_permy = grid.cell_permy;
  r.cell_permz = grid.cell_permz;
  r.cell_poro = grid.cell_poro;
  r.cell_pore_volume_mult = grid.cell_pore_volume_mult;
  r.corner_point = grid.corner_point;
}

// Whether a cell (its 8 corners' box) lies within kMinpvKeptRadii drainage radii of a well's path, sampled
// every quarter radius.
constexpr double kMinpvKeptRadii = 3.0;
bool near_a_well(const std::array<Vec3, 8>& corners, const std::vector<WellSpec>& wells) {
  Vec3 lo = corners[0], hi = lo;
  for (const Vec3& p : corners) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  for (const WellSpec& w : wells) {
    const double reach = kMinpvKeptRadii * w.drainage_radius, step = w.drainage_radius / 4;
    for (size_t k = 0; k + 1 < w.trajectory.size(); ++k) {
      const Vec3 a = w.trajectory[k], b = w.trajectory[k + 1];
      const int n = 1 + static_cast<int>(norm(b - a) / step);
      for (int q = 0; q <= n; ++q) {
        const Vec3 p = a + (b - a) * (double(q) / n);
        const Vec3 d{std::max({lo.x - p.x, p.x - hi.x, 0.0}), std::max({lo.y - p.y, p.y - hi.y, 0.0}),
                     std::max({lo.z - p.z, p.z - hi.z, 0.0})};
        if (norm(d) <= reach) return true;
      }
    }
  }
  return false;
}

// Cells that MINPV removes near a well stay cells: the near-well cells replace the model's cells there,
// and a removed cell on a well's path would cut the path (docs/corner-point.md, "MINPV"); only cells whose
// rock can be meshed (rock_problem). The connections MINPV makes across a kept cell are dropped (the cells
// connect through it).
void keep_minpv_cells_near_wells(CaseSpec& cs) {
  ReservoirSpec& r = cs.reservoir;
  if (!r.corner_point || r.corner_point->minpv_removed.empty() || cs.wells.empty()) return;
  const CornerPointModel& m = *r.corner_point;
  std::vector<int64_t> kept;
  for (const int64_t c : m.minpv_removed) {
    const size_t i = static_cast<size_t>(c);
    if (m.opm_volume[i] > 0 && rock_problem(r, i).empty() && near_a_well(cell_corners(m, i), cs.wells)) kept.push_back(c);
  }
  if (kept.empty()) return;
  auto model = std::make_shared<CornerPointModel>(m);
  const int64_t nxy = int64_t(m.nx) * m.ny;
  std::vector<std::pair<int64_t, int64_t>> connections;
  for (const auto& [up, low] : m.minpv_connections) {
    bool across_kept = false;
    for (const int64_t c : kept) across_kept = across_kept || (c % nxy == up % nxy && c > up && c < low);
    if (!across_kept) connections.push_back({up, low});
  }
  for (const int64_t c : kept) model->actnum[static_cast<size_t>(c)] = 1;
  model->minpv_connections = std::move(connections);
  model->minpv_removed.erase(std::remove_if(model->minpv_removed.begin(), model->minpv_removed.end(),
                                            [&](int64_t c) { return std::count(kept.begin(), kept.end(), c) > 0; }),
                             model->minpv_removed.end());
  cs.notes.push_back("reservoir.grdecl: " + std::to_string(kept.size()) + " of the cells below MINPV lie within " +
                     fmt6(kMinpvKeptRadii) + " drainage radii of a well: kept as cells (the near-well cells replace "
                     "the model's cells there), the other " + std::to_string(model->minpv_removed.size()) +
                     " removed (docs/corner-point.md, \"MINPV\")");
  use_model(r, std::move(model));
}

// A corner-point model with wells: its columns near the wells split to the wells' scale
// (meshgen/case/corner_point_refine.hpp); the case's reservoir becomes the refined model.
void refine_near_wells(CaseSpec& cs) {
  ReservoirSpec& r = cs.reservoir;
  if (!r.corner_point || cs.wells.empty() || r.near_well_cell_size < 0) return;
  std::vector<RefinementRequest> requests;
  for (const WellSpec& w : cs.wells) {
    const double size = r.near_well_cell_size > 0 ? r.near_well_cell_size : w.drainage_radius;
    const bool automatic = r.near_well_cell_size == 0;
    requests.push_back({w.trajectory, size, cs.transition.dilation * w.drainage_radius + 2 * size, automatic,
                        automatic, r.near_well_grading});
  }
  std::vector<StraightenRequest> upright;
  for (const RefinementRequest& q : requests)
    upright.push_back({q.path, q.reach + 2 * q.cell_size, r.upright_pillars == ReservoirSpec::Upright::On});
  std::optional<CornerPointModel> refined_m;
  std::vector<StraightenOutcome> outcomes;
  auto refine_and_turn = [&] {
    refined_m.reset();
    const ColumnSplits splits = near_well_splits(*r.corner_point, requests);
    // Refused before the model is built: a refinement past the limit would not fit in memory.
    const double cells = splits.cells(r.corner_point->nz);
    if (cells > kMaxCells)
      fail("reservoir.near_well_cell_size", "refining the model near the wells gives " + fmt_count(cells) +
                                                " cells > " + fmt_count(kMaxCells) + ": give a larger size, or off");
    if (splits.refines()) refined_m = refined_model(*r.corner_point, splits);
    outcomes.clear();
    if (r.upright_pillars == ReservoirSpec::Upright::Off) return;
    CornerPointModel turned = straightened_model(refined_m ? *refined_m : *r.corner_point, upright, &outcomes);
    if (std::any_of(outcomes.begin(), outcomes.end(), [](const StraightenOutcome& o) { return o.straightened; }))
      refined_m = std::move(turned);
  };
  refine_and_turn();
  // Where the pillars lean obliquely (turned upright, or refused) the columns are split into equal
  // children: graded ones failed there (Reek's OP_2, whose turn graded children also refuse;
  // docs/corner-point.md, "Graded children"). Pillars turned upright no longer lean.
  bool regrade = false;
  for (size_t w = 0; w < outcomes.size(); ++w) {
    const bool oblique = outcomes[w].straightened || outcomes[w].wall_angle_deg < kStraightenWallAngleBelow;
    if (oblique && requests[w].graded) requests[w].graded = false, regrade = true;
    if (outcomes[w].straightened && requests[w].limit_by_lean) requests[w].limit_by_lean = false, regrade = true;
  }
  if (regrade) refine_and_turn();
  for (size_t w = 0; w < outcomes.size(); ++w) {
    const StraightenOutcome& o = outcomes[w];
    const std::string well = "wells[" + std::to_string(w) + "] (" + cs.wells[w].name + ")";
    if (o.straightened)
      cs.notes.push_back("reservoir: the model's pillars within " + fmt6(upright[w].reach) + " m of " + well +
                         " lean up to " + fmt6(o.max_lean_deg) + " degrees obliquely to the grid (column walls at " +
                         fmt6(o.wall_angle_deg) + " degrees): " + std::to_string(o.pillars) +
                         " pillars turned upright, blending back to the model's over " + fmt6(o.blend) +
                         " m, the columns there split into equal children (reservoir.upright_pillars; docs/corner-point.md, "
                         "\"Upright pillars near wells\")");
    else if (!o.refused.empty())
      cs.notes.push_back("reservoir: the model's pillars near " + well + " lean up to " + fmt6(o.max_lean_deg) +
                         " degrees obliquely to the grid (column walls at " + fmt6(o.wall_angle_deg) +
                         " degrees) and are kept as they are: " + o.refused + " (docs/corner-point.md, \"Upright "
                         "pillars near wells\")");
  }
  if (!refined_m) return;
  use_model(r, std::make_shared<const CornerPointModel>(std::move(*refined_m)));
}

// Each well's path and the reach within which a fault step counts for it: its cavity's, (dilation + 2)
// drainage radii, times kFaultStepReach.
std::vector<FaultStepRequest> fault_step_requests(const CaseSpec& cs) {
  std::vector<FaultStepRequest> requests;
  for (const WellSpec& w : cs.wells)
    requests.push_back({w.trajectory, kFaultStepReach * (cs.transition.dilation + 2) * w.drainage_radius});
  return requests;
}

// Fault steps too thin to split, moved onto the other side's layer boundary near the wells
// (snap_thin_fault_steps). In the model the wells are meshed in: the refinement's pillars between a
// pillar near a well and one beyond would otherwise keep a part of the step.
void snap_fault_steps_near_wells(CaseSpec& cs) {
  ReservoirSpec& r = cs.reservoir;
  if (!r.corner_point || cs.wells.empty()) return;
  CornerPointModel snapped = *r.corner_point;
  const SnappedSteps snaps = snap_thin_fault_steps(snapped, fault_step_requests(cs));
  if (snaps.corners == 0) return;
  cs.notes.push_back("reservoir: " + std::to_string(snaps.corners) + " cell corners on faults near the wells moved by "
                     "at most " + fmt6(snaps.largest) + " m (under " + fmt6(100 * kMinStepFraction) +
                     " % of their cells' thickness) onto the other side's layer boundary, so that the faults' two "
                     "sides meet face to face there (docs/corner-point.md, \"Fault steps\")");
  use_model(r, std::make_shared<const CornerPointModel>(std::move(snapped)));
}

// A corner-point model whose faults step by a fraction of a layer near a well: its layers split there
// (meshgen/case/corner_point_fault_steps.hpp) so that the two sides meet face to face in the cavities.
void split_fault_steps_near_wells(CaseSpec& cs) {
  ReservoirSpec& r = cs.reservoir;
  if (!r.corner_point || cs.wells.empty()) return;
  const FaultStepSplit split = fault_step_children(*r.corner_point, fault_step_requests(cs));
  if (!split.splits()) return;
  const double cells = double(r.corner_point->nx) * r.corner_point->ny *
                       std::accumulate(split.children.begin(), split.children.end(), 0.0);
  if (cells > kMaxCells)
    fail("reservoir.grdecl", "splitting the layers at the fault steps near the wells gives " + fmt_count(cells) +
                                 " cells > " + fmt_count(kMaxCells));
  auto model = std::make_shared<const CornerPointModel>(layers_split_at_fault_steps(*r.corner_point, split));
  int split_layers = 0;
  for (int n : split.children) split_layers += n > 1;
  cs.notes.push_back("reservoir: " + std::to_string(split.steps) + " cell corners on faults near the wells step by a "
                     "fraction of a layer: " + std::to_string(split_layers) + " layers split there, " +
                     std::to_string(r.corner_point->nz) + " -> " + std::to_string(model->nz) +
                     " layers, so that the faults' two sides meet face to face (docs/corner-point.md, \"Fault steps\")");
  use_model(r, model);
}

// A corner-point model meshed in a permeability frame that stretches its layers against its columns:
// the layers near the wells split so that their scaled cells there are at most
// reservoir.near_well_layer_aspect times taller than wide, the two sides of a fault face to face
// (frame_layer_children). The reach is the fault steps' in the frame: a scaled distance is up to
// max(s) physical metres.
void split_corner_point_layers_for_the_frame(CaseSpec& cs) {
  ReservoirSpec& r = cs.reservoir;
  if (!r.corner_point || cs.wells.empty() || cs.metric != MeshMetric::Permeability || !(r.near_well_layer_aspect > 0))
    return;
  const PermeabilityFrame frame = permeability_frame(cs);
  if (frame.identity()) return;
  const Vec3 s = frame.scale;
  std::vector<FaultStepRequest> requests = fault_step_requests(cs);
  for (FaultStepRequest& q : requests) q.reach *= std::max({s.x, s.y, s.z});
  const FaultStepSplit split = frame_layer_children(*r.corner_point, requests, s, r.near_well_layer_aspect);
  if (!split.splits()) return;
  const double cells = double(r.corner_point->nx) * r.corner_point->ny *
                       std::accumulate(split.children.begin(), split.children.end(), 0.0);
  if (cells > kMaxCells)
    fail("reservoir.near_well_layer_aspect", "splitting the layers near the wells for the permeability frame gives " +
                                                 fmt_count(cells) + " cells > " + fmt_count(kMaxCells) +
                                                 ": give a larger aspect, 0 (off), or metric: euclidean");
  auto model = std::make_shared<const CornerPointModel>(layers_split_at_fault_steps(*r.corner_point, split));
  std::ostringstream note;
  note << "reservoir: layers near the wells split for the permeability frame (children at most "
       << fmt6(split.child_thickness) << " m thick there: scaled, at most " << r.near_well_layer_aspect
       << " x taller than the narrowest near-well cell is wide; reservoir.near_well_layer_aspect, faults face to face):";
  for (size_t k = 0; k < split.children.size(); ++k)
    if (split.children[k] > 1) note << " k" << k + 1 << " x" << split.children[k];
  note << "; the mesh and the deck have " << model->nz << " layers instead of " << r.corner_point->nz;
  cs.notes.push_back(note.str());
  use_model(r, model);
}

ReservoirSpec read_reservoir(const YAML::Node& n, const std::string& base_dir, std::vector<std::string>& notes) {
  const Fields f(n, "reservoir",
                 {"x", "y", "z", "grdecl", "permeability", "porosity", "initial_pressure", "near_well_cell_size",
                  "near_well_layer_aspect", "upright_pillars", "near_well_grading"});
  ReservoirSpec r;
  if (f.get("grdecl")) {
    r = read_grdecl_reservoir(f, base_dir, notes);
    if (auto s = f.get("near_well_cell_size")) r.near_well_cell_size = read_near_well_cell_size(*s, f.path("near_well_cell_size"));
    if (auto s = f.get("upright_pillars")) {
      const std::string v = s->IsScalar() ? s->Scalar() : "";
      if (v != "auto" && v != "on" && v != "off") fail(f.path("upright_pillars"), "expected auto, on or off, got " + describe(*s));
      r.upright_pillars = v == "on" ? ReservoirSpec::Upright::On : v == "off" ? ReservoirSpec::Upright::Off : ReservoirSpec::Upright::Auto;
    }
    if (auto s = f.get("near_well_grading")) {
      const std::string v = s->IsScalar() ? s->Scalar() : "";
      if (v != "on" && v != "off") fail(f.path("near_well_grading"), "expected on or off, got " + describe(*s));
      r.near_well_grading = v == "on";
    }
  } else {
    if (f.get("near_well_cell_size")) fail(f.path("near_well_cell_size"), "only with reservoir.grdecl (a corner-point model)");
    if (f.get("upright_pillars")) fail(f.path("upright_pillars"), "only with reservoir.grdecl (a corner-point model)");
    if (f.get("near_well_grading")) fail(f.path("near_well_grading"), "only with reservoir.grdecl (a corner-point model)");
    r.x = read_axis(f.required("x"), f.path("x"));
    r.y = read_axis(f.required("y"), f.path("y"));
    r.z = read_axis(f.required("z"), f.path("z"));
  }
  const double cells = double(r.x.size() - 1) * double(r.y.size() - 1) * double(r.z.size() - 1);
  if (cells > kMaxCells)
    fail("reservoir", "too many cells (" + std::to_string(r.x.size() - 1) + " x " + std::to_string(r.y.size() - 1) +
                          " x " + std::to_string(r.z.size() - 1) + " = " + fmt_count(cells) + " > " +
                          fmt_count(kMaxCells) + ")");
  if (auto k = f.get("permeability")) {
    const auto v = read_triple(*k, f.path("permeability"), "[kx, ky, kz]");
    for (size_t i = 0; i < 3; ++i) require(v[i] > 0, index_path(f.path("permeability"), i), "must be > 0");
    for (size_t i = 0; i < 3; ++i)
      require_range(v[i], kMinPermeability, kMaxPermeability, false, index_path(f.path("permeability"), i), "mD");
    r.permeability = {v[0], v[1], v[2]};
  }
  f.number("porosity", r.porosity);
  require(r.porosity > 0 && r.porosity <= 1, f.path("porosity"), "must be in (0, 1]");
  f.number("initial_pressure", r.initial_pressure);
  require_range(r.initial_pressure, 0, kMaxPressure, true, f.path("initial_pressure"), "bar");
  f.number("near_well_layer_aspect", r.near_well_layer_aspect);
  require(r.near_well_layer_aspect == 0 || (r.near_well_layer_aspect >= 0.5 && r.near_well_layer_aspect <= 100),
          f.path("near_well_layer_aspect"), "must be 0 (off) or in [0.5, 100]");
  return r;
}

TransitionSpec read_transition(const YAML::Node& n) {
  TransitionSpec t;
  if (n.IsNull()) return t;
  const Fields f(n, "transition", {"dilation", "optimize", "gamma", "omega_o", "omega_p", "expansion"});
  f.number("dilation", t.dilation);
  require(t.dilation >= 1, f.path("dilation"), "must be >= 1");
  f.boolean("optimize", t.optimize);
  if (auto g = f.get("gamma")) t.gamma = read_triple(*g, f.path("gamma"), "[G1, G2, G3]");
  require(0 < t.gamma[0] && t.gamma[0] <= t.gamma[1] && t.gamma[1] <= t.gamma[2] && t.gamma[2] <= 0.5,
          f.path("gamma"), "must satisfy 0 < G1 <= G2 <= G3 <= 0.5");
  f.number("omega_o", t.omega_o);
  require(t.omega_o >= 80 && t.omega_o <= 90, f.path("omega_o"), "must be in [80, 90] degrees");
  f.number("omega_p", t.omega_p);
  require(t.omega_p >= 0 && t.omega_p <= 10, f.path("omega_p"), "must be in [0, 10] degrees");
  f.number("expansion", t.expansion);
  require(t.expansion > 1 && t.expansion <= 1.1, f.path("expansion"), "must be in (1, 1.1]");
  return t;
}

FluidSpec read_fluid(const YAML::Node& n) {
  FluidSpec fl;
  if (n.IsNull()) return fl;
  const Fields f(n, "fluid", {"viscosity", "density", "compressibility"});
  f.number("viscosity", fl.viscosity);
  require(fl.viscosity > 0, f.path("viscosity"), "must be > 0");
  require_range(fl.viscosity, kMinViscosity, kMaxViscosity, false, f.path("viscosity"), "cP");
  f.number("density", fl.density);
  require(fl.density > 0, f.path("density"), "must be > 0");
  require_range(fl.density, kMinDensity, kMaxDensity, false, f.path("density"), "kg/m3");
  f.number("compressibility", fl.compressibility);
  require(fl.compressibility >= 0, f.path("compressibility"), "must be >= 0");
  require_range(fl.compressibility, 0, kMaxCompressibility, false, f.path("compressibility"), "1/bar");
  return fl;
}

std::vector<Vec3> read_trajectory(const YAML::Node& n, const std::string& path, size_t& points_budget) {
  if (!n.IsSequence()) fail(path, "expected a list of points [[x, y, z], ...], got " + describe(n));
  if (n.size() < 2) fail(path, "needs at least 2 points");
  if (n.size() > points_budget)
    fail(path, "too many points (at most " + std::to_string(kMaxTrajectoryPoints) + " over all wells)");
  points_budget -= n.size();
  std::vector<Vec3> pts;
  pts.reserve(n.size());
  for (size_t i = 0; i < n.size(); ++i) {
    const std::string p = index_path(path, i);
    if (!n[i].IsSequence()) fail(p, "expected a point [x, y, z], got " + describe(n[i]));
    const auto v = read_triple(n[i], p, "[x, y, z]");
    for (size_t d = 0; d < 3; ++d) require_coordinate(v[d], index_path(p, d));
    pts.push_back({v[0], v[1], v[2]});
    if (i > 0 && pts[i] == pts[i - 1]) fail(p, "repeats the previous point");
  }
  return pts;
}

// survey: {head: [x, y, z], stations: [[md, inclination, azimuth], ...]} -> the station
// positions by minimum curvature (meshgen/case/survey.hpp).
std::vector<Vec3> read_survey(const YAML::Node& n, const std::string& path, size_t& points_budget,
                              std::vector<double>& md) {
  if (!n.IsMap()) fail(path, "expected a map {head: [x, y, z], stations: [[md, inclination, azimuth], ...]}, got " +
                                 describe(n));
  const Fields f(n, path, {"head", "stations"});
  const auto h = read_triple(f.required("head"), f.path("head"), "[x, y, z]");
  const YAML::Node st = f.required("stations");
  const std::string sp = f.path("stations");
  if (!st.IsSequence()) fail(sp, "expected a list of stations [[md, inclination, azimuth], ...], got " + describe(st));
  if (st.size() < 1) fail(sp, "needs at least 1 station");
  if (st.size() + 1 > points_budget)
    fail(sp, "too many stations (at most " + std::to_string(kMaxTrajectoryPoints) + " points over all wells)");
  points_budget -= st.size() + 1;
  std::vector<SurveyStation> stations;
  for (size_t i = 0; i < st.size(); ++i) {
    const std::string p = index_path(sp, i);
    if (!st[i].IsSequence()) fail(p, "expected a station [md, inclination, azimuth], got " + describe(st[i]));
    const auto v = read_triple(st[i], p, "[md, inclination, azimuth]");
    const SurveyStation s{v[0], v[1], v[2]};
    const double prev_md = stations.empty() ? 0.0 : stations.back().md;
    require(s.md > prev_md, p, "md must be greater than the previous station's (" + fmt(prev_md) + " m)");
    require(s.inclination_deg >= 0 && s.inclination_deg <= 180, p, "inclination must be in [0, 180] degrees");
    require(s.azimuth_deg >= 0 && s.azimuth_deg < 360, p, "azimuth must be in [0, 360) degrees");
    if (!stations.empty())
      require(survey_dogleg(stations.back(), s) <= kMaxSurveyDoglegDeg * kDegreesToRadians, p,
              "turns by more than " + fmt(kMaxSurveyDoglegDeg) + " degrees from the previous station");
    stations.push_back(s);
  }
  md.assign(1, 0.0);
  for (const SurveyStation& s : stations) md.push_back(s.md);
  return minimum_curvature_positions({h[0], h[1], h[2]}, stations);
}

// perforations: [[md_from, md_to], ...], sorted, disjoint, on the path [0, md_end].
std::vector<std::array<double, 2>> read_perforations(const YAML::Node& n, const std::string& path, double md_end) {
  if (!n.IsSequence() || n.size() == 0)
    fail(path, "expected a non-empty list of intervals [[md_from, md_to], ...], got " + describe(n));
  std::vector<std::array<double, 2>> out;
  for (size_t i = 0; i < n.size(); ++i) {
    const std::string p = index_path(path, i);
    if (!n[i].IsSequence() || n[i].size() != 2) fail(p, "expected an interval [md_from, md_to], got " + describe(n[i]));
    const double from = read_number(n[i][0], p + "[0]"), to = read_number(n[i][1], p + "[1]");
    require(from >= 0, p, "md_from must be >= 0 (the path starts at md 0)");
    require(to > from, p, "md_to must be greater than md_from");
    require(to <= md_end * (1 + kMeasuredDepthTolerance), p,
            "md_to is beyond the end of the path (md " + fmt(md_end) + " m)");
    if (!out.empty())
      require(from >= out.back()[1], p, "overlaps or precedes the previous interval (ends at md " + fmt(out.back()[1]) + " m)");
    out.push_back({from, to});
  }
  return out;
}

WellSpec read_well(const YAML::Node& n, const std::string& path, size_t& points_budget) {
  const Fields f(n, path,
                 {"name", "type", "trajectory", "survey", "radius", "drainage_radius", "rings", "sectors",
                  "segment_length", "bhp", "end_caps", "perforations"});
  WellSpec w;
  w.name = read_string(f.required("name"), f.path("name"));
  require(matches_name_charset(w.name), f.path("name"), "must match [A-Za-z0-9_-]+");
  require(w.name.size() <= kMaxWellNameLength, f.path("name"),
          "at most " + std::to_string(kMaxWellNameLength) + " characters (Eclipse well names)");
  if (auto t = f.get("type")) {
    const std::string s = t->IsScalar() ? t->Scalar() : std::string();
    if (t->IsScalar() && s == "producer") w.type = WellType::Producer;
    else if (t->IsScalar() && s == "injector") w.type = WellType::Injector;
    else fail(f.path("type"), "expected producer or injector, got " + describe(*t));
  }
  const auto survey = f.get("survey");
  if (survey && f.get("trajectory")) fail(f.path("survey"), "give either trajectory or survey, not both");
  w.trajectory = survey ? read_survey(*survey, f.path("survey"), points_budget, w.trajectory_md)
                        : read_trajectory(f.required("trajectory"), f.path("trajectory"), points_budget);
  if (auto pf = f.get("perforations"))
    w.perforations = read_perforations(*pf, f.path("perforations"), well_measured_depths(w).back());
  w.radius = read_number(f.required("radius"), f.path("radius"));
  require(w.radius > 0, f.path("radius"), "must be > 0");
  require_range(w.radius, kMinWellRadius, kMaxWellRadius, false, f.path("radius"), "m");
  w.drainage_radius = read_number(f.required("drainage_radius"), f.path("drainage_radius"));
  require(w.drainage_radius > w.radius, f.path("drainage_radius"), "must be > radius (" + fmt(w.radius) + ")");
  require(w.drainage_radius <= kMaxDrainageRadius, f.path("drainage_radius"),
          "must be <= " + fmt(kMaxDrainageRadius) + " m (docs/case-format.md, Limits)");
  f.integer("rings", w.rings);
  require(w.rings >= 1, f.path("rings"), "must be >= 1");
  f.integer("sectors", w.sectors);
  require(w.sectors >= 3, f.path("sectors"), "must be >= 3");
  f.number("segment_length", w.segment_length);
  require(w.segment_length > 0, f.path("segment_length"), "must be > 0");
  require(w.segment_length <= kMaxSegmentLength, f.path("segment_length"),
          "must be <= " + fmt(kMaxSegmentLength) + " m (docs/case-format.md, Limits)");
  w.bhp = read_number(f.required("bhp"), f.path("bhp"));
  require_range(w.bhp, 0, kMaxPressure, true, f.path("bhp"), "bar");
  if (auto e = f.get("end_caps")) {
    const std::string s = e->IsScalar() ? e->Scalar() : std::string();
    w.end_caps_fallback = false;
    if (e->IsScalar() && s == "flat") w.end_caps = EndCaps::Flat;
    else if (e->IsScalar() && s == "hemisphere") w.end_caps = EndCaps::Hemisphere;
    else if (e->IsScalar() && s == "auto") w.end_caps_fallback = true;
    else fail(f.path("end_caps"), "expected auto, hemisphere or flat, got " + describe(*e));
  }
  return w;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// Cross-field checks that need the whole case: wells inside the box, unique names,
// radial grids apart, bounded total size.
void check_wells(const CaseSpec& cs) {
  const ReservoirSpec& r = cs.reservoir;
  std::vector<std::vector<Vec3>> meshed;  // the parts of the trajectories inside the box
  double total_cells = double(r.x.size() - 1) * double(r.y.size() - 1) * double(r.z.size() - 1);

  for (size_t a = 0; a < cs.wells.size(); ++a) {
    const WellSpec& w = cs.wells[a];
    const std::string path = index_path("wells", a);
    // The part inside the box is meshed; its radial block must fit (meshed_trajectory.hpp).
    meshed.push_back(meshed_trajectory(r, w, path).points);
    check_bend_limit(meshed.back(), path, kMaxBendDegrees);
    for (size_t b = 0; b < a; ++b) {
      if (cs.wells[b].name == w.name) fail(path + ".name", "duplicate of " + index_path("wells", b) + ".name");
      if (lower(cs.wells[b].name) == lower(w.name))
        fail(path + ".name", "duplicate of " + index_path("wells", b) +
                                 ".name (names are compared ignoring case, as in Eclipse decks)");
    }
    double segments = 0;
    for (size_t i = 0; i + 1 < w.trajectory.size(); ++i)
      segments += std::max(1.0, std::ceil(norm(w.trajectory[i + 1] - w.trajectory[i]) / w.segment_length));
    if (w.end_caps == EndCaps::Hemisphere)
      segments += 2.0 * (hemisphere_cap_bands(w.sectors) + static_cast<double>(hemisphere_end_grading(w).size()));
    const double cells = double(w.rings) * double(w.sectors) * segments;
    total_cells += cells;
    if (total_cells > kMaxCells)
      fail(path, "too many cells (" + std::to_string(w.rings) + " x " + std::to_string(w.sectors) + " x " +
                     fmt_count(segments) + " = " + fmt_count(cells) +
                     " rings x sectors x segments; at most " + fmt_count(kMaxCells) + " in the whole case)");
  }

  // Two radial grids may not overlap: polylines at least the sum of the drainage radii apart
  // (stronger than "a block does not reach the other wellbore").
  for (size_t b = 1; b < cs.wells.size(); ++b) {
    for (size_t a = 0; a < b; ++a) {
      const double limit = cs.wells[a].drainage_radius + cs.wells[b].drainage_radius;
      const double d = polyline_distance(meshed[a], meshed[b], limit);
      if (d < limit)
        fail(index_path("wells", b) + ".trajectory",
             "too close to " + index_path("wells", a) + " (distance " + fmt6(d) + " m < " + fmt6(limit) +
                 " m = sum of drainage radii; radial grids may not overlap)");
    }
  }
}

CaseSpec read_case(const YAML::Node& root, const std::string& base_dir) {
  if (!root.IsMap()) fail("case file", "expected a map with keys name, reservoir, ..., got " + describe(root));
  const Fields f(root, "", {"name", "metric", "reservoir", "wells", "transition", "fluid"});
  CaseSpec cs;
  cs.name = read_string(f.required("name"), "name");
  require(matches_name_charset(cs.name), "name", "must match [A-Za-z0-9_-]+");
  require(cs.name.size() <= kMaxCaseNameLength, "name",
          "at most " + std::to_string(kMaxCaseNameLength) + " characters");
  if (auto m = f.get("metric")) {
    const std::string s = m->IsScalar() ? m->Scalar() : std::string();
    if (m->IsScalar() && s == "permeability") cs.metric = MeshMetric::Permeability;
    else if (m->IsScalar() && s == "euclidean") cs.metric = MeshMetric::Euclidean;
    else fail("metric", "expected permeability or euclidean, got " + describe(*m));
  }
  cs.reservoir = read_reservoir(f.required("reservoir"), base_dir, cs.notes);
  if (auto t = f.get("transition")) cs.transition = read_transition(*t);
  if (auto fl = f.get("fluid")) cs.fluid = read_fluid(*fl);
  if (auto wells = f.get("wells"); wells && !wells->IsNull()) {
    if (!wells->IsSequence()) fail("wells", "expected a list of wells, got " + describe(*wells));
    if (wells->size() > kMaxWells)
      fail("wells", "at most " + std::to_string(kMaxWells) + " wells (got " + std::to_string(wells->size()) + ")");
    size_t points_budget = kMaxTrajectoryPoints;
    for (size_t i = 0; i < wells->size(); ++i) cs.wells.push_back(read_well((*wells)[i], index_path("wells", i), points_budget));
  }
  for (WellSpec& w : cs.wells)
    for (Vec3& p : w.trajectory) p = map_to_grid(cs.reservoir, p);
  // The path's part inside the model, ended kSurfaceGapMin x R inside the surface: the refinement
  // follows it. Then, in the refined model, ended where the surface's faces near each end allow
  // (surface_gap, at least that much).
  keep_minpv_cells_near_wells(cs);
  const std::vector<WellSpec> as_given = cs.wells;
  clip_paths_to_model(cs, as_given, SurfaceGapRule::Least, false);
  check_wells(cs);
  split_fault_steps_near_wells(cs);
  refine_near_wells(cs);
  snap_fault_steps_near_wells(cs);
  split_corner_point_layers_for_the_frame(cs);
  clip_paths_to_model(cs, as_given, SurfaceGapRule::SurfaceFaces, true);
  fit_blocks_to_the_surface(cs);
  check_wells(cs);
  split_layers_near_wells(cs);
  return cs;
}

}  // namespace

Vec3 map_to_grid(const ReservoirSpec& r, Vec3 p) {
  if (!r.has_map_axes) return p;
  // p = origin + gx unit_x + gy unit_y, solved by Cramer's rule.
  const Vec3 ux = r.map_unit_x, uy = r.map_unit_y;
  const double dx = p.x - r.map_origin.x, dy = p.y - r.map_origin.y;
  const double det = ux.x * uy.y - ux.y * uy.x;
  return {(dx * uy.y - dy * uy.x) / det, (ux.x * dy - ux.y * dx) / det, p.z};
}

int reservoir_cell_at(const ReservoirSpec& r, Vec3 p) {
  auto slot = [](const std::vector<double>& axis, double v) {
    const auto it = std::upper_bound(axis.begin(), axis.end(), v);
    const long k = static_cast<long>(it - axis.begin()) - 1;
    return static_cast<int>(std::clamp<long>(k, 0, static_cast<long>(axis.size()) - 2));
  };
  const int nx = static_cast<int>(r.x.size()) - 1, ny = static_cast<int>(r.y.size()) - 1;
  return slot(r.x, p.x) + nx * (slot(r.y, p.y) + ny * slot(r.z, p.z));
}

Vec3 reservoir_permeability(const ReservoirSpec& r, int c) {
  if (r.cell_permx.empty()) return r.permeability;
  return {r.cell_permx[c], r.cell_permy[c], r.cell_permz[c]};
}

double reservoir_porosity(const ReservoirSpec& r, int c) { return r.cell_poro.empty() ? r.porosity : r.cell_poro[c]; }

void assign_reservoir_rock(const ReservoirSpec& r, int c, CellAttributes& at) {
  at.perm = reservoir_permeability(r, c);
  at.porosity = reservoir_porosity(r, c);
  at.pore_volume_mult = r.cell_pore_volume_mult.empty() ? 1.0 : r.cell_pore_volume_mult[c];
}

std::vector<double> well_measured_depths(const WellSpec& ws) {
  if (ws.trajectory_md.size() == ws.trajectory.size()) return ws.trajectory_md;
  std::vector<double> md(ws.trajectory.size(), 0.0);
  for (size_t i = 1; i < md.size(); ++i) md[i] = md[i - 1] + norm(ws.trajectory[i] - ws.trajectory[i - 1]);
  return md;
}

std::vector<double> ring_radii(const WellSpec& ws) {
  std::vector<double> radii(ws.rings + 1);
  const double ratio = ws.drainage_radius / ws.radius;
  for (int i = 0; i <= ws.rings; ++i) radii[i] = ws.radius * std::pow(ratio, static_cast<double>(i) / ws.rings);
  radii[0] = ws.radius;
  radii[ws.rings] = ws.drainage_radius;
  return radii;
}

std::vector<double> hemisphere_end_grading(const WellSpec& ws) {
  std::vector<double> g;
  if (ws.end_caps != EndCaps::Hemisphere || !(ws.drainage_radius > ws.radius) || ws.rings < 1) return g;
  const double ratio = std::pow(ws.drainage_radius / ws.radius, 1.0 / ws.rings);
  double r = ws.radius;
  while (static_cast<int>(g.size()) < ws.rings && r * ratio - r < ws.segment_length &&
         r * ratio - ws.radius <= 3 * ws.segment_length) {
    r *= ratio;
    g.push_back(r - ws.radius);
  }
  return g;
}

namespace {

/// Start marks of the documents of a YAML stream (yaml-cpp's event parser; no nodes built).
class DocumentStarts : public YAML::EventHandler {
 public:
  std::vector<YAML::Mark> starts;
  void OnDocumentStart(const YAML::Mark& mark) override { starts.push_back(mark); }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t, const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}
};

/// Number of documents in the stream. yaml-cpp 0.7's LoadAll loops forever, allocating a null
/// document per turn, on a token that starts no node (a ',' outside [ ] or { }: jbeder/yaml-cpp#1040,
/// fixed upstream by PR #1319; found by tests/fuzz/fuzz_case): a document that starts where the
/// previous one started made no progress, and is refused.
size_t count_documents(const std::string& yaml_text) {
  std::istringstream in(yaml_text);
  YAML::Parser parser(in);
  DocumentStarts docs;
  while (parser.HandleNextDocument(docs)) {
    const size_t n = docs.starts.size();
    if (n >= 2 && docs.starts[n - 1].pos == docs.starts[n - 2].pos) {
      const YAML::Mark& m = docs.starts[n - 1];
      fail("case file", "YAML error at line " + std::to_string(m.line + 1) + ", column " + std::to_string(m.column + 1) +
                            ": unexpected token (a ',' outside a [ ] or { } list?)");
    }
  }
  return docs.starts.size();
}

}  // namespace

CaseSpec parse_case(const std::string& yaml_text, const std::string& base_dir) {
  try {
    const size_t n_docs = count_documents(yaml_text);
    if (n_docs > 1) fail("case file", "expected one YAML document, got " + std::to_string(n_docs));
    const YAML::Node doc = YAML::Load(yaml_text);
    if (n_docs == 0 || doc.IsNull()) fail("case file", "empty document");
    return read_case(doc, base_dir);
  } catch (const YAML::DeepRecursion& e) {
    // yaml-cpp reports its nesting limit as "bad file"; say what happened.
    fail("case file", "YAML error at line " + std::to_string(e.mark.line + 1) + ", column " +
                          std::to_string(e.mark.column + 1) + ": nested too deeply (" + std::to_string(e.depth()) +
                          " levels)");
  } catch (const YAML::Exception& e) {
    if (e.mark.is_null()) fail("case file", "YAML error: " + printable(e.msg, 200));
    fail("case file", "YAML error at line " + std::to_string(e.mark.line + 1) + ", column " +
                          std::to_string(e.mark.column + 1) + ": " + printable(e.msg, 200));
  }
}

CaseSpec load_case(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail("case file", "cannot open " + quoted(path, 300));
  std::string text;
  char buf[65536];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    text.append(buf, static_cast<size_t>(in.gcount()));
    if (text.size() > kMaxCaseFileBytes)
      fail("case file", quoted(path, 300) + " is larger than " + std::to_string(kMaxCaseFileBytes >> 20) + " MiB");
  }
  if (in.bad()) fail("case file", "cannot read " + quoted(path, 300));
  const std::string dir = std::filesystem::path(path).parent_path().string();
  return parse_case(text, dir.empty() ? "." : dir);
}

}  // namespace hm
