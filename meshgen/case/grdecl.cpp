#include "meshgen/case/grdecl.hpp"

#include <opm/input/eclipse/Deck/Deck.hpp>
#include <opm/input/eclipse/Deck/DeckItem.hpp>
#include <opm/input/eclipse/Deck/DeckKeyword.hpp>
#include <opm/input/eclipse/Deck/DeckRecord.hpp>
#include <opm/input/eclipse/EclipseState/EclipseState.hpp>
#include <opm/input/eclipse/EclipseState/Grid/EclipseGrid.hpp>
#include <opm/input/eclipse/EclipseState/Grid/FieldPropsManager.hpp>
#include <opm/input/eclipse/EclipseState/Grid/FaceDir.hpp>
#include <opm/input/eclipse/EclipseState/Grid/MapAxes.hpp>
#include <opm/input/eclipse/EclipseState/Grid/NNC.hpp>
#include <opm/input/eclipse/EclipseState/Grid/TransMult.hpp>
#include <opm/input/eclipse/Parser/ErrorGuard.hpp>
#include <opm/input/eclipse/Parser/ParseContext.hpp>
#include <opm/input/eclipse/Parser/Parser.hpp>
#include <opm/input/eclipse/Units/UnitSystem.hpp>
#include <opm/input/eclipse/Units/Units.hpp>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <set>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "meshgen/case/case.hpp"
#include "meshgen/case/minpv.hpp"

namespace hm {

int CornerPointModel::n_active() const {
  int n = 0;
  for (int a : actnum) n += a != 0;
  return n;
}

namespace {

std::string cell_name(int c, int nx, int ny) {
  std::ostringstream os;
  os << "cell (" << c % nx + 1 << ", " << (c / nx) % ny + 1 << ", " << c / (nx * ny) + 1 << ")";
  return os.str();
}

// OPM's EclipseState wants a full deck (RUNSPEC ... GRID); a bare GRDECL (SPECGRID, COORD, ...)
// is wrapped in a minimal one that INCLUDEs it.
std::string as_deck(const std::string& path, const std::string& text) {
  if (text.find("RUNSPEC") != std::string::npos) return text;
  return "RUNSPEC\nDIMENS\n 1 1 1 /\nOIL\nWATER\nMETRIC\nGRID\nINCLUDE\n '" + path + "' /\n";
}

}  // namespace

struct RegionMultipliers {
  Opm::TransMult mult;
};

namespace {

// Relative difference below which OPM's pore volume and volume x PORO x NTG are the same number (the
// order of OPM's multiplications).
constexpr double kPoreVolumeRounding = 1e-12;

// MULTREGT: OPM's TransMult (its region multipliers), the records as the deck gives them and the
// region arrays they name, per cell (1 on inactive cells, which no connection reaches).
void read_region_multipliers(const Opm::Deck& deck, const Opm::EclipseState& state, CornerPointModel& m) {
  m.region_mult = std::make_shared<const RegionMultipliers>(RegionMultipliers{state.getTransMult()});
  std::set<std::string> arrays;
  for (const Opm::DeckKeyword& kw : deck["MULTREGT"])
    for (size_t r = 0; r < kw.size(); ++r) {
      const Opm::DeckRecord& rec = kw.getRecord(r);
      std::ostringstream text;
      for (size_t i = 0; i < rec.size(); ++i) {
        const Opm::DeckItem& item = rec.getItem(i);
        text << (i ? " " : "");
        if (item.defaultApplied(0)) text << "1*";
        else if (item.getType() == Opm::type_tag::integer) text << item.get<int>(0);
        else if (item.getType() == Opm::type_tag::fdouble) text << std::setprecision(17) << item.get<double>(0);
        else text << "'" << item.getTrimmedString(0) << "'";
      }
      m.multregt_records.push_back(text.str());
      const Opm::DeckItem& def = rec.getItem("REGION_DEF");
      const std::string letter = def.defaultApplied(0) ? "M" : def.getTrimmedString(0).substr(0, 1);
      arrays.insert(letter == "F" ? "FLUXNUM" : letter == "O" ? "OPERNUM" : "MULTNUM");
    }
  const Opm::FieldPropsManager& fp = state.fieldProps();
  for (const std::string& name : arrays) {
    if (!fp.has_int(name)) continue;
    const std::vector<int>& active = fp.get_int(name);
    std::vector<int>& v = m.region_arrays[name];
    v.assign(m.actnum.size(), 1);
    for (size_t c = 0, a = 0; c < v.size() && a < active.size(); ++c)
      if (m.actnum[c]) v[c] = active[a++];
  }
}

}  // namespace

double region_multiplier(const CornerPointModel& m, int64_t a, int64_t b) {
  if (!m.region_mult) return 1.0;
  const bool refined = !m.parent_cell.empty();
  const int64_t pa = cell_as_read(m, a), pb = cell_as_read(m, b);
  if (pa == pb) return 1.0;
  const int64_t nx = refined ? m.parent_nx : m.nx, ny = refined ? m.parent_ny : m.ny;
  // flow's direction of an intersection: its axis, plus side (EclTransmissibility::update).
  const Opm::FaceDir::DirEnum dir = pa % nx != pb % nx                 ? Opm::FaceDir::XPlus
                                    : (pa / nx) % ny != (pb / nx) % ny ? Opm::FaceDir::YPlus
                                                                       : Opm::FaceDir::ZPlus;
  return m.region_mult->mult.getRegionMultiplier(static_cast<size_t>(pa), static_cast<size_t>(pb), dir);
}

CornerPointModel read_corner_point_model(const std::string& path, const std::string& key) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw InputError(key + ": no such file: " + path);
  CornerPointModel m;
  try {
    Opm::ParseContext context;
    // A model exported from a geomodeller has keywords our steady single-phase use ignores.
    context.update(Opm::InputError::WARN);
    Opm::ErrorGuard errors;
    Opm::Parser parser;
    std::string text;
    {
      std::ifstream in(path, std::ios::binary);
      std::ostringstream os;
      os << in.rdbuf();
      text = os.str();
    }
    const std::string abs = fs::absolute(path).string();
    Opm::Deck deck = text.find("RUNSPEC") != std::string::npos ? parser.parseFile(abs, context, errors)
                                                                : parser.parseString(as_deck(abs, text), context, errors);
    errors.clear();
    const Opm::EclipseState state(deck);
    const Opm::EclipseGrid& grid = state.getInputGrid();
    m.nx = static_cast<int>(grid.getNX());
    m.ny = static_cast<int>(grid.getNY());
    m.nz = static_cast<int>(grid.getNZ());
    const size_t n = grid.getCartesianSize();
    m.actnum.resize(n);
    for (size_t c = 0; c < n; ++c) m.actnum[c] = grid.cellActive(c) ? 1 : 0;
    // The corners are computed from these (corner: getCornerPos's arithmetic), not stored.
    m.coord = grid.getCOORD();
    m.zcorn = grid.getZCORN();
    m.opm_volume.resize(n);
    for (size_t c = 0; c < n; ++c) m.opm_volume[c] = grid.getCellVolume(c);
    const Opm::TransMult& mult = state.getTransMult();
    const Opm::FaceDir::DirEnum dirs[6] = {Opm::FaceDir::XPlus, Opm::FaceDir::XMinus, Opm::FaceDir::YPlus,
                                           Opm::FaceDir::YMinus, Opm::FaceDir::ZPlus, Opm::FaceDir::ZMinus};
    for (int d = 0; d < 6; ++d) {
      m.trans_mult[d].resize(n);
      for (size_t c = 0; c < n; ++c) m.trans_mult[d][c] = mult.getMultiplier(c, dirs[d]);
    }
    if (m.coord.size() != 6 * size_t(m.nx + 1) * (m.ny + 1) || m.zcorn.size() != 8 * n)
      throw InputError(key + ": the grid is not given as COORD/ZCORN (or SPECGRID does not match them)");
    const Opm::FieldPropsManager& fp = state.fieldProps();
    for (const char* kw : {"PERMX", "PORO"})
      if (!fp.has_double(kw)) throw InputError(key + ": the model has no " + std::string(kw));
    // Field properties come per active cell in SI units; the case works in mD on every cell.
    const double md = Opm::prefix::milli * Opm::unit::darcy;
    auto global = [&](const std::vector<double>& active, double scale, double fill) {
      std::vector<double> out(n, fill);
      for (size_t c = 0, a = 0; c < n; ++c)
        if (m.actnum[c]) out[c] = active[a++] / scale;
      return out;
    };
    m.permx = global(fp.get_double("PERMX"), md, 0.0);
    m.permy = fp.has_double("PERMY") ? global(fp.get_double("PERMY"), md, 0.0) : m.permx;
    m.permz = fp.has_double("PERMZ") ? global(fp.get_double("PERMZ"), md, 0.0) : m.permx;
    m.poro = global(fp.get_double("PORO"), 1.0, 0.0);
    m.ntg = fp.has_double("NTG") ? global(fp.get_double("NTG"), 1.0, 1.0) : std::vector<double>(n, 1.0);
    if (deck.hasKeyword("MULTREGT")) read_region_multipliers(deck, state, m);
    {
      const std::vector<double> porv = fp.porv(true);
      const bool minpv = grid.getMinpvMode() != Opm::MinpvMode::ModeEnum::Inactive;
      const std::vector<double>& limit = grid.getMinpvVector();
      for (size_t c = 0; c < n && c < porv.size(); ++c) {
        if (!m.actnum[c]) continue;
        m.active_pore_volume += porv[c];
        if (minpv && c < limit.size() && porv[c] < limit[c]) ++m.below_minpv, m.below_minpv_pore_volume += porv[c];
        // The same doubles OPM multiplies (EclipseGrid volume, PORO, NTG): a relative 1e-12 is rounding.
        const double ours = m.opm_volume[c] * m.poro[c] * m.ntg[c];
        if (std::abs(porv[c] - ours) > kPoreVolumeRounding * std::max(std::abs(ours), std::abs(porv[c]))) {
          ++m.other_pore_volume, m.other_pore_volume_opm += porv[c], m.other_pore_volume_ours += ours;
          if (m.pore_volume_mult.empty()) m.pore_volume_mult.assign(n, 1.0);
          if (ours > 0) m.pore_volume_mult[c] = porv[c] / ours;  // else PORO or NTG is 0: refused by the case
        }
      }
      if (minpv) {
        MinpvInput in;
        in.nx = m.nx, in.ny = m.ny, in.nz = m.nz;
        in.thickness.resize(n);
        for (size_t c = 0; c < n; ++c) in.thickness[c] = grid.getCellThickness(c);
        in.pore_volume = porv;
        in.minpv = limit;
        in.actnum = m.actnum;
        in.z_tolerance = grid.isPinchActive() ? grid.getPinchThresholdThickness() : 0.0;
        in.pinch_nogap = grid.getPinchGapMode() == Opm::PinchMode::ModeEnum::NOGAP;  // as processEclipseFormat
        const MinpvResult removed = opm_minpv(in);
        for (const int64_t c : removed.removed) m.actnum[static_cast<size_t>(c)] = 0;
        // Measured against flow 2022.10 (docs/corner-point.md, "MINPV"): across removed cells of no
        // thickness only, the connection becomes an NNC face of its grid, to which its transmissibility
        // code gives 0 (the cells connect only as PINCH connects them); across a removed cell with
        // thickness, a K face with the cells' own halves.
        const int64_t nxy = int64_t(m.nx) * m.ny;
        for (const auto& [up, low] : removed.connections) {
          bool gap = false;
          for (int64_t c = up + nxy; c < low && !gap; c += nxy) gap = in.thickness[static_cast<size_t>(c)] > 0;
          if (gap) m.minpv_connections.push_back({up, low});
        }
        m.minpv_removed = removed.removed;
      }
    }
    {
      const Opm::NNC& nnc = state.getInputNNC();
      const Opm::UnitSystem metric = Opm::UnitSystem::newMETRIC();
      for (const Opm::NNCdata& e : nnc.input()) {
        const double t = metric.from_si(Opm::UnitSystem::measure::transmissibility, e.trans);
        if (!(std::isfinite(t) && t >= 0))
          throw InputError(key + ": its NNC between cells " + std::to_string(e.cell1) + " and " +
                           std::to_string(e.cell2) + " (natural indices) has the transmissibility " + std::to_string(t) +
                           ": it must be finite and >= 0");
        m.nnc.push_back({static_cast<int64_t>(std::min(e.cell1, e.cell2)), static_cast<int64_t>(std::max(e.cell1, e.cell2)), t});
      }
      m.deck_editnnc = static_cast<int64_t>(nnc.edit().size());
      for (const Opm::NNCdata& e : nnc.edit()) {
        const int64_t a = static_cast<int64_t>(std::min(e.cell1, e.cell2)), b = static_cast<int64_t>(std::max(e.cell1, e.cell2));
        const auto [it, fresh] = m.edit_nnc.emplace(std::make_pair(a, b), e.trans);
        if (!fresh) it->second *= e.trans;
      }
    }
    if (grid.isPinchActive()) {
      m.pinch.active = true;
      m.pinch.threshold = grid.getPinchThresholdThickness();
      m.pinch.nogap = grid.getPinchGapMode() == Opm::PinchMode::ModeEnum::NOGAP;
      m.pinch.pinchout_all = grid.getPinchOption() == Opm::PinchMode::ModeEnum::ALL;
      m.pinch.multz_all = grid.getMultzOption() == Opm::PinchMode::ModeEnum::ALL;
      // Not in EclipseGrid (OPM Flow 2022.10 does not use it): from the keyword, for writing it back.
      m.pinch.max_empty_gap = deck["PINCH"].back().getRecord(0).getItem("MAX_EMPTY_GAP").getSIDouble(0);
    }
    if (deck.hasKeyword("MAPAXES")) {
      const Opm::MapAxes axes(deck);
      m.has_mapaxes = true;
      double x0 = 0, y0 = 0, x1 = 1, y1 = 0, x2 = 0, y2 = 1;
      axes.transform(x0, y0);
      axes.transform(x1, y1);
      axes.transform(x2, y2);
      m.map_origin = {x0, y0};
      m.map_unit_x = {x1 - x0, y1 - y0};
      m.map_unit_y = {x2 - x0, y2 - y0};
    }
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    std::string why = e.what();
    for (char& ch : why)
      if (ch == '\n') ch = ' ';
    throw InputError(key + ": OPM could not read " + path + ": " + why.substr(0, 300));
  }
  if (m.n_active() == 0) throw InputError(key + ": the model has no active cell (ACTNUM, PORO, MINPV, PINCH)");
  return m;
}

namespace {

// Rock per cell as the mesh carries it: NTG folded into the porosity and the horizontal
// permeabilities (OPM's pore volumes and TRANX/TRANY).
void set_rock(const CornerPointModel& m, ReservoirSpec& r) {
  const size_t n = m.n_cells();
  r.cell_permx.resize(n);
  r.cell_permy.resize(n);
  r.cell_poro.resize(n);
  for (size_t c = 0; c < n; ++c) {
    r.cell_permx[c] = m.permx[c] * m.ntg[c];
    r.cell_permy[c] = m.permy[c] * m.ntg[c];
    r.cell_poro[c] = m.poro[c] * m.ntg[c];
  }
  r.cell_permz = m.permz;
  r.cell_pore_volume_mult = m.pore_volume_mult;
}

}  // namespace

size_t zcorn_index(const CornerPointModel& m, int i, int j, int k, int q) {
  const size_t nx = m.nx, ny = m.ny;
  return 2 * size_t(i) + (q & 1) + 2 * nx * (2 * size_t(j) + ((q >> 1) & 1)) +
         4 * nx * ny * (2 * size_t(k) + ((q >> 2) & 1));
}

void resize_cell_arrays(CornerPointModel& r, const CornerPointModel& m) {
  const size_t n = size_t(r.nx) * r.ny * r.nz;
  r.zcorn.assign(8 * n, 0.0);
  r.actnum.resize(n);
  r.parent_cell.resize(n);
  for (auto* v : {&r.permx, &r.permy, &r.permz, &r.poro, &r.ntg}) v->resize(n);
  r.pore_volume_mult.resize(m.pore_volume_mult.empty() ? 0 : n);
  for (int d = 0; d < 6; ++d) r.trans_mult[d].resize(m.trans_mult[d].empty() ? 0 : n);
}

void inherit_cell(CornerPointModel& r, size_t c, const CornerPointModel& m, size_t s) {
  r.actnum[c] = m.actnum[s];
  r.parent_cell[c] = m.parent_cell.empty() ? static_cast<int32_t>(s) : m.parent_cell[s];
  r.permx[c] = m.permx[s], r.permy[c] = m.permy[s], r.permz[c] = m.permz[s];
  r.poro[c] = m.poro[s], r.ntg[c] = m.ntg[s];
  if (!m.pore_volume_mult.empty()) r.pore_volume_mult[c] = m.pore_volume_mult[s];
}

double corner_depth(const CornerPointModel& m, int c, int q) {
  const int i = c % m.nx, j = (c / m.nx) % m.ny, k = c / (m.nx * m.ny);
  return m.zcorn[zcorn_index(m, i, j, k, q)];
}

Vec3 pillar_point(const CornerPointModel& m, int p, double z) {
  // OPM's EclipseGrid::getCellCorners, term for term and in its order, so that a corner equals getCornerPos bit for bit.
  const double* a = &m.coord[6 * size_t(p)];
  const double xt = a[0], yt = a[1], zt = a[2], xb = a[3], yb = a[4], zb = a[5];
  if (zt == zb) return {xt, yt, z};
  return {xt + (xb - xt) / (zt - zb) * (zt - z), yt + (yb - yt) / (zt - zb) * (zt - z), z};
}

Vec3 corner(const CornerPointModel& m, size_t cell, int q) {
  const size_t nx = size_t(m.nx), ny = size_t(m.ny);
  const size_t i = cell % nx, j = cell / nx % ny, k = cell / (nx * ny);
  const int I = static_cast<int>(i) + (q & 1), J = static_cast<int>(j) + ((q >> 1) & 1);
  return pillar_point(m, I + (m.nx + 1) * J,
                      m.zcorn[zcorn_index(m, static_cast<int>(i), static_cast<int>(j), static_cast<int>(k), q)]);
}

std::array<Vec3, 8> cell_corners(const CornerPointModel& m, size_t cell) {
  std::array<Vec3, 8> out;
  for (int q = 0; q < 8; ++q) out[q] = corner(m, cell, q);
  return out;
}

int64_t merge_rounded_depths(CornerPointModel& m) {
  struct Corner {
    double z;
    size_t cell;
    int q;
    bool operator<(const Corner& o) const { return z < o.z || (z == o.z && (cell < o.cell || (cell == o.cell && q < o.q))); }
  };
  int64_t changed = 0;
  std::vector<Corner> at;  // the corners on one pillar
  for (int J = 0; J <= m.ny; ++J)
    for (int I = 0; I <= m.nx; ++I) {
      at.clear();
      for (int a = 0; a < 4; ++a) {
        const int ci = I - 1 + (a & 1), cj = J - 1 + (a >> 1);
        if (ci < 0 || cj < 0 || ci >= m.nx || cj >= m.ny) continue;
        const int q = (a & 1 ? 0 : 1) | (a & 2 ? 0 : 2);  // the corner of column (ci, cj) on this pillar
        for (int k = 0; k < m.nz; ++k)
          for (int side : {0, 4})
            at.push_back({m.zcorn[zcorn_index(m, ci, cj, k, q | side)], ci + size_t(m.nx) * (cj + size_t(m.ny) * k), q | side});
      }
      std::sort(at.begin(), at.end());
      for (size_t b = 0; b < at.size();) {
        size_t e = b + 1;
        const double limit = at[b].z + kSameDepthUlps * std::numeric_limits<double>::epsilon() * std::abs(at[b].z);
        for (; e < at.size() && at[e].z <= limit; ++e) {
          if (at[e].z == at[b].z) continue;
          const Corner& c = at[e];
          m.zcorn[zcorn_index(m, static_cast<int>(c.cell % m.nx), static_cast<int>(c.cell / m.nx % m.ny),
                              static_cast<int>(c.cell / (size_t(m.nx) * m.ny)), c.q)] = at[b].z;
          ++changed;
        }
        b = e;
      }
    }
  return changed;
}

double edit_nnc_multiplier(const CornerPointModel& m, int64_t a, int64_t b) {
  if (m.edit_nnc.empty()) return 1.0;
  const int64_t pa = cell_as_read(m, a), pb = cell_as_read(m, b);
  const auto it = m.edit_nnc.find({std::min(pa, pb), std::max(pa, pb)});
  return it == m.edit_nnc.end() ? 1.0 : it->second;
}

bool has_transmissibility_multipliers(const CornerPointModel& m) {
  if (m.region_mult || !m.edit_nnc.empty()) return true;
  for (const std::vector<double>& v : m.trans_mult)
    if (std::any_of(v.begin(), v.end(), [](double x) { return x != 1.0; })) return true;
  return false;
}

bool is_rectilinear(const CornerPointModel& m) {
  try {
    rectilinear_reservoir(m, "");
    return true;
  } catch (const InputError&) {
    return false;
  }
}

void check_corner_point_geometry(const CornerPointModel& m, const std::string& key) {
  const int nx = m.nx, ny = m.ny;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      int above = -1;  // the previous active cell of the column
      for (int k = 0; k < m.nz; ++k) {
        const int c = i + nx * (j + ny * k);
        if (!m.actnum[c]) continue;
        for (int q = 0; q < 4; ++q) {
          const double top = corner_depth(m, c, q), bottom = corner_depth(m, c, q + 4);
          if (!(top <= bottom))
            throw InputError(key + ": " + cell_name(c, nx, ny) + ": its top corner lies below its bottom corner on pillar " +
                             std::to_string(q) + " (ZCORN " + std::to_string(top) + " > " + std::to_string(bottom) + ")");
          if (above >= 0 && !(corner_depth(m, above, q + 4) <= top))
            throw InputError(key + ": " + cell_name(c, nx, ny) + " overlaps the active cell above it (" +
                             cell_name(above, nx, ny) + ") on one of its pillars: cells of a column must not overlap");
        }
        above = c;
      }
    }
}

ReservoirSpec corner_point_reservoir(std::shared_ptr<const CornerPointModel> model, const std::string& key) {
  const CornerPointModel& m = *model;
  check_corner_point_geometry(m, key);
  ReservoirSpec r;
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (size_t c = 0; c < m.n_cells(); ++c)
    if (m.actnum[c])
      for (const Vec3& p : cell_corners(m, c)) {
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
      }
  auto axis = [](double a, double b, int n) {
    std::vector<double> v(n + 1);
    for (int i = 0; i <= n; ++i) v[i] = i == n ? b : a + (b - a) * i / n;
    return v;
  };
  r.x = axis(lo.x, hi.x, m.nx);
  r.y = axis(lo.y, hi.y, m.ny);
  r.z = axis(lo.z, hi.z, m.nz);
  for (const auto* a : {&r.x, &r.y, &r.z})
    for (size_t i = 1; i < a->size(); ++i)
      if (!((*a)[i] > (*a)[i - 1])) throw InputError(key + ": the model's active cells have no extent in x, y or z");
  set_rock(m, r);
  r.corner_point = std::move(model);
  return r;
}

CornerPointModel translated_model(const CornerPointModel& m, Vec3 shift) {
  CornerPointModel out = m;
  for (size_t p = 0; p < out.coord.size(); p += 3) {
    out.coord[p] += shift.x;
    out.coord[p + 1] += shift.y;
    out.coord[p + 2] += shift.z;
  }
  for (double& z : out.zcorn) z += shift.z;
  return out;
}

ReservoirSpec rectilinear_reservoir(const CornerPointModel& m, const std::string& key) {
  ReservoirSpec r;
  const int nx = m.nx, ny = m.ny;
  auto idx = [&](int i, int j, int k) { return i + nx * (j + ny * k); };
  // Axes from the cells along the grid's three edges, then every corner must sit on them.
  for (int i = 0; i < nx; ++i) r.x.push_back(corner(m, idx(i, 0, 0), 0).x);
  r.x.push_back(corner(m, idx(nx - 1, 0, 0), 1).x);
  for (int j = 0; j < ny; ++j) r.y.push_back(corner(m, idx(0, j, 0), 0).y);
  r.y.push_back(corner(m, idx(0, ny - 1, 0), 2).y);
  for (int k = 0; k < m.nz; ++k) r.z.push_back(corner(m, idx(0, 0, k), 0).z);
  r.z.push_back(corner(m, idx(0, 0, m.nz - 1), 4).z);
  const size_t n = m.n_cells();
  for (size_t c = 0; c < n; ++c) {
    const int i = c % nx, j = (c / nx) % ny, k = c / (size_t(nx) * ny);
    if (!m.actnum[c])
      throw InputError(key + ": " + cell_name(c, nx, ny) + " is inactive; inactive cells are not meshed yet");
    const std::array<Vec3, 8> corners = cell_corners(m, c);
    for (int q = 0; q < 8; ++q) {
      const Vec3 p = corners[q];
      const Vec3 want{r.x[i + (q & 1)], r.y[j + ((q >> 1) & 1)], r.z[k + ((q >> 2) & 1)]};
      if (!(p == want))
        throw InputError(key + ": " + cell_name(c, nx, ny) +
                         " is not a rectilinear box (sloping layers, inclined pillars or faults): corner-point "
                         "geometry is not meshed yet, only models whose cells are axis-aligned boxes");
    }
  }
  for (size_t a = 1; a < r.x.size(); ++a)
    if (!(r.x[a] > r.x[a - 1])) throw InputError(key + ": grid x not increasing along i (GDORIENT?)");
  for (size_t a = 1; a < r.y.size(); ++a)
    if (!(r.y[a] > r.y[a - 1])) throw InputError(key + ": grid y not increasing along j (GDORIENT?)");
  for (size_t a = 1; a < r.z.size(); ++a)
    if (!(r.z[a] > r.z[a - 1])) throw InputError(key + ": layer " + std::to_string(a) + " has zero thickness");
  set_rock(m, r);
  return r;
}

}  // namespace hm
