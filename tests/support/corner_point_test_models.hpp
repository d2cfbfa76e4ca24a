// Helpers of the tests that write synthetic corner-point models (GRDECL text): shared by the
// pipeline's corner-point tests and the exporters' Flow tests.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace hmtest {

/// A double as the shortest text that reads back as the same value (%.17g).
inline std::string grdecl_number(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

/// The ZCORN values in Eclipse order: per layer k its top then bottom surface, per row j the -j
/// then +j corners, per column i the -i then +i corner; depth(i_col, I, J, surface) gives the depth
/// of the corner of column i_col on pillar (I, J) at surface k (top) or k + 1 (bottom).
inline void write_zcorn(std::ostringstream& o, int nx, int ny, int nz,
                        const std::function<double(int, int, int, int)>& depth) {
  for (int k = 0; k < nz; ++k)
    for (int c = 0; c < 2; ++c)
      for (int j = 0; j < ny; ++j)
        for (int b = 0; b < 2; ++b)
          for (int i = 0; i < nx; ++i)
            for (int a = 0; a < 2; ++a) o << grdecl_number(depth(i, i + a, j + b, k + c)) << "\n";
}

/// The COORD lines of (nx + 1)(ny + 1) pillars, I fastest: pillar(I, J) gives its top and bottom x, y
/// {x_top, y_top, x_bottom, y_bottom}, at depths z_top and z_bottom.
inline void write_pillars(std::ostringstream& o, int nx, int ny, double z_top, double z_bottom,
                          const std::function<std::array<double, 4>(int, int)>& pillar) {
  for (int J = 0; J <= ny; ++J)
    for (int I = 0; I <= nx; ++I) {
      const std::array<double, 4> p = pillar(I, J);
      o << grdecl_number(p[0]) << " " << grdecl_number(p[1]) << " " << grdecl_number(z_top) << " " << grdecl_number(p[2])
        << " " << grdecl_number(p[3]) << " " << grdecl_number(z_bottom) << "\n";
    }
}

/// Vertical pillars every dx, dy; layers of thickness dz dipping `dip_deg` in x, 1 % in y, with a
/// twist (x y term: the top and bottom faces are not planar); a fault on pillar line I = fault_i
/// (the +i side down by `throw_m`) when fault_i > 0. PERMX and PORO vary by cell
/// (docs/corner-point.md, "Measured").
struct TiltedModel {
  int nx = 9, ny = 9, nz = 16, fault_i = -1;
  double dx = 20, dy = 20, dz = 4.5, dip_deg = 5, throw_m = 0;
  bool inclined_pillars = false;  // non-parallel pillars: the column faces are not planar either
  double pillar_twist = 0;        // inclined pillars whose slope also varies along the model's sides (bent sides)
  std::vector<int> inactive;      // cells with ACTNUM 0 (natural index)
  std::string keywords;           // GRDECL text appended (multipliers, FAULTS; multiplier_keywords)
  int pinch_k = -1;               // a layer that thins from dz to 0 over 2 dx toward pinch_x and is 0 beyond
  double pinch_x = 100;
  double kv_kh = 0;               // > 0: PERMY = PERMX and PERMZ = kv_kh PERMX in every cell (one anisotropy)

  double depth(int i_col, int I, int J, int k) const {
    const double x = dx * I, y = dy * J;
    double z = 1000 + std::tan(dip_deg * M_PI / 180) * x + 0.01 * y + 1e-4 * x * y + dz * k;
    if (pinch_k >= 0 && k > pinch_k) z -= dz * (1 - std::clamp((pinch_x - x) / (2 * dx), 0.0, 1.0));
    if (fault_i > 0 && i_col >= fault_i) z += throw_m;
    return z;
  }
  /// The model as GRDECL text (SPECGRID, COORD, ZCORN, PERMX/Y/Z, PORO).
  std::string text() const {
    std::ostringstream o;
    o << "SPECGRID\n " << nx << " " << ny << " " << nz << " 1 F /\nCOORD\n";
    write_pillars(o, nx, ny, 900, 1200, [&](int I, int J) {
      const double x = dx * I, y = dy * J;
      return inclined_pillars ? std::array<double, 4>{x, y, x + 6 + 0.01 * x + pillar_twist * y,
                                                      y + 3 - 0.005 * y + pillar_twist * x}
                              : std::array<double, 4>{x, y, x, y};
    });
    o << "/\nZCORN\n";
    write_zcorn(o, nx, ny, nz, [&](int i, int I, int J, int k) { return depth(i, I, J, k); });
    const int n = nx * ny * nz;
    if (!inactive.empty()) {
      o << "/\nACTNUM\n";
      for (int c = 0; c < n; ++c) o << (std::find(inactive.begin(), inactive.end(), c) == inactive.end() ? 1 : 0) << "\n";
    }
    o << "/\nPERMX\n";
    for (int c = 0; c < n; ++c) o << 50 + (c % 7) * 30 << "\n";
    if (kv_kh > 0) {
      o << "/\nPERMY\n";
      for (int c = 0; c < n; ++c) o << 50 + (c % 7) * 30 << "\n";
      o << "/\nPERMZ\n";
      for (int c = 0; c < n; ++c) o << kv_kh * (50 + (c % 7) * 30) << "\n";
      o << "/\nPORO\n";
    } else {
      o << "/\nPERMY\n" << n << "*120 /\nPERMZ\n" << n << "*12 /\nPORO\n";
    }
    for (int c = 0; c < n; ++c) o << 0.15 + 0.01 * (c % 5) << "\n";
    o << "/\n" << keywords;
    return o.str();
  }
};

/// Transmissibility multipliers of a TiltedModel (GRDECL text for TiltedModel::keywords): MULTX by cell
/// (0.3 to 1.0), MULTY- 0.5 on every third cell, MULTZ 0.02 on layer `barrier_k` (0-based; its face
/// toward the layer below) and 0.5 to 0.7 on the others, and, when the model has a fault, FAULTS 'F1'
/// on its pillar line (faces +I of the cells just before it) with MULTFLT 0.05.
inline std::string multiplier_keywords(const TiltedModel& g, int barrier_k) {
  std::ostringstream o;
  const int n = g.nx * g.ny * g.nz;
  o << "MULTX\n";
  for (int c = 0; c < n; ++c) o << 0.3 + 0.1 * (c % 8) << "\n";
  o << "/\nMULTY-\n";
  for (int c = 0; c < n; ++c) o << (c % 3 == 0 ? 0.5 : 1.0) << "\n";
  o << "/\nMULTZ\n";
  for (int c = 0; c < n; ++c) {
    const int k = c / (g.nx * g.ny);
    o << (k == barrier_k ? 0.02 : 0.5 + 0.05 * (k % 5)) << "\n";
  }
  o << "/\n";
  if (g.fault_i > 0)
    o << "FAULTS\n 'F1' " << g.fault_i << " " << g.fault_i << " 1 " << g.ny << " 1 " << g.nz << " 'X' /\n/\n"
      << "MULTFLT\n 'F1' 0.05 /\n/\n";
  return o.str();
}

/// Pore volumes other than the rock's: MULTPV 1000 on the column i = 0 (an aquifer, as geomodellers attach
/// one) and 2.5 on every seventh other cell, 1 elsewhere.
inline std::string pore_volume_keywords(const TiltedModel& g) {
  std::ostringstream o;
  o << "MULTPV\n";
  for (int c = 0; c < g.nx * g.ny * g.nz; ++c) o << (c % g.nx == 0 ? 1000.0 : c % 7 == 0 ? 2.5 : 1.0) << "\n";
  o << "/\n";
  return o.str();
}

/// An EDIT section with EDITNNC on the connections across the fault (fault_i > 0, throw_m between one and
/// two layers): cell (fault_i, J, K) with (fault_i + 1, J, K - 1) x 0.1 and with (fault_i + 1, J, K - 2) x 0.5
/// (1-based), pairs flow connects across the fault and OPM keeps in NNC::edit(). Append it last.
inline std::string edit_nnc_keywords(const TiltedModel& g) {
  std::ostringstream o;
  o << "EDIT\nEDITNNC\n";
  for (int J = 1; J <= g.ny; ++J)
    for (int K = 2; K <= g.nz; ++K) {
      o << " " << g.fault_i << " " << J << " " << K << " " << g.fault_i + 1 << " " << J << " " << K - 1 << " 0.1 /\n";
      if (K > 2) o << " " << g.fault_i << " " << J << " " << K << " " << g.fault_i + 1 << " " << J << " " << K - 2 << " 0.5 /\n";
    }
  o << "/\n";
  return o.str();
}

/// NNC records (GRID section) between cells that share no face, away from the wells of the flow tests
/// (P1 in column (5, 5), I1 in (3, 7), 1-based): a strong conduit between the two wells' surroundings and
/// weaker ones between the model's corners. {I1 J1 K1 I2 J2 K2 T}, T in cP.rm3/day/bar.
inline const std::vector<std::array<double, 7>>& nnc_records() {
  static const std::vector<std::array<double, 7>> r{
      {1, 9, 8, 8, 2, 8, 20}, {1, 1, 2, 9, 9, 15, 5}, {9, 1, 4, 1, 9, 12, 2}, {2, 2, 14, 8, 8, 3, 0.75}};
  return r;
}
inline std::string nnc_keywords() {
  std::ostringstream o;
  o << "NNC\n";
  for (const auto& r : nnc_records())
    o << " " << r[0] << " " << r[1] << " " << r[2] << " " << r[3] << " " << r[4] << " " << r[5] << " " << r[6] << " /\n";
  o << "/\n";
  return o.str();
}

/// MULTNUM regions 1 (i < 4), 2 (i >= 4, k < 8) and 3 (i >= 4, k >= 8) and MULTREGT records between them:
/// 1-2 x 0.1 in every direction, 2-3 x 0.02 in Z only (flow applies neither to an X connection of 2-3).
inline std::string region_multiplier_keywords(const TiltedModel& g) {
  std::ostringstream o;
  o << "MULTNUM\n";
  for (int c = 0; c < g.nx * g.ny * g.nz; ++c) {
    const int i = c % g.nx, k = c / (g.nx * g.ny);
    o << (i < 4 ? 1 : k < 8 ? 2 : 3) << "\n";
  }
  o << "/\nMULTREGT\n 1 2 0.1 XYZ 1* M /\n 2 3 0.02 Z 1* M /\n/\n";
  return o.str();
}

/// Planar layers (depth 1000 + dz k + tan(dip) x + 0.01 y at pillar (x, y) = (dx I, dy J)) on
/// parallel straight pillars inclined `pillar_deg` from the vertical toward azimuth `pillar_azimuth_deg`
/// (0: +x, 90: +y), so every cell face is
/// planar; an optional fault on pillar line I = fault_i (columns i >= fault_i down by throw_m).
/// PERMX varies by cell; PERMY 120, PERMZ 12 mD; PORO 0.2. Optionally a model as a geomodeller
/// exports it: in field coordinates (`x_origin`, `y_origin` added to COORD; or, with `map_axes`, COORD
/// in the grid's own frame and MAPAXES placing it there turned `map_turn_deg` counter-clockwise) and
/// with `rock` (per-cell rock: a log-normal PERMX = PERMY about a mean of its own per layer, PERMZ =
/// kv_kh PERMX, PORO rising with log PERMX; drawn from `rock_seed`).
struct LayeredModel {
  int nx = 7, ny = 7, nz = 40, fault_i = -1;
  double dx = 100, dy = 100, dz = 3, dip_deg = 5, pillar_deg = 0, pillar_azimuth_deg = 0, throw_m = 0;
  double x_origin = 0, y_origin = 0, map_turn_deg = 0, kv_kh = 0.1;
  double dz_beyond_fault = 0;  ///< > 0: the layers' thickness in the columns beyond the fault (a growth fault)
  bool map_axes = false, rock = false;
  unsigned rock_seed = 1;

  /// Map position of point (x, y) of the model's own frame (pillar (I, J) at depth 1000 is (dx I, dy J)).
  std::array<double, 2> to_map(double x, double y) const {
    if (!map_axes) return {x_origin + x, y_origin + y};
    const double c = std::cos(map_turn_deg * M_PI / 180), s = std::sin(map_turn_deg * M_PI / 180);
    return {x_origin + c * x - s * y, y_origin + s * x + c * y};
  }
  /// Depth of the top of layer k (of the columns before the fault) at grid-frame plan point (x, y): the
  /// layer's surface is a plane through the leaning pillars.
  double layer_top(int k, double x, double y) const {
    const double lean = std::tan(pillar_deg * M_PI / 180), az = pillar_azimuth_deg * M_PI / 180;
    const double sx = std::tan(dip_deg * M_PI / 180), sy = 0.01;
    return 1000 + dz * k + (sx * x + sy * y) / (1 + sx * lean * std::cos(az) + sy * lean * std::sin(az));
  }

  double depth(int i_col, int I, int J, int k) const {
    const double thickness = fault_i > 0 && i_col >= fault_i && dz_beyond_fault > 0 ? dz_beyond_fault : dz;
    double z = 1000 + thickness * k + std::tan(dip_deg * M_PI / 180) * dx * I + 0.01 * dy * J;
    if (fault_i > 0 && i_col >= fault_i) z += throw_m;
    return z;
  }
  std::string text() const {
    std::ostringstream o;
    const double lean = std::tan(pillar_deg * M_PI / 180), az = pillar_azimuth_deg * M_PI / 180;
    const double lx = lean * std::cos(az), ly = lean * std::sin(az);
    o << "SPECGRID\n " << nx << " " << ny << " " << nz << " 1 F /\nCOORD\n";
    const double ox = map_axes ? 0 : x_origin, oy = map_axes ? 0 : y_origin;
    write_pillars(o, nx, ny, 900, 1300, [&](int I, int J) {
      const double x = ox + dx * I, y = oy + dy * J;  // the pillar's point at depth 1000
      return std::array<double, 4>{x - 100 * lx, y - 100 * ly, x + 300 * lx, y + 300 * ly};
    });
    o << "/\nZCORN\n";
    write_zcorn(o, nx, ny, nz, [&](int i, int I, int J, int k) { return depth(i, I, J, k); });
    if (map_axes) {
      const std::array<double, 2> y1 = to_map(0, 1), o0 = to_map(0, 0), x1 = to_map(1, 0);
      o << "/\nMAPUNITS\n 'METRES' /\nMAPAXES\n " << grdecl_number(y1[0]) << " " << grdecl_number(y1[1]) << " "
        << grdecl_number(o0[0]) << " " << grdecl_number(o0[1]) << " " << grdecl_number(x1[0]) << " "
        << grdecl_number(x1[1]) << "\n";
    }
    const int n = nx * ny * nz;
    if (rock) {
      std::vector<double> permx(n);
      std::mt19937 rng(rock_seed);
      std::uniform_real_distribution<double> layer_mean(-1, 3.5);
      std::normal_distribution<double> noise(0, 0.3);
      for (int k = 0; k < nz; ++k) {
        const double m = layer_mean(rng);
        for (int c = k * nx * ny; c < (k + 1) * nx * ny; ++c) permx[c] = std::pow(10.0, std::clamp(m + noise(rng), -2.0, 4.0));
      }
      auto write = [&](const char* key, auto value) {
        o << "/\n" << key << "\n";
        for (int c = 0; c < n; ++c) o << grdecl_number(value(c)) << "\n";
      };
      write("PERMX", [&](int c) { return permx[c]; });
      write("PERMY", [&](int c) { return permx[c]; });
      write("PERMZ", [&](int c) { return kv_kh * permx[c]; });
      write("PORO", [&](int c) { return std::clamp(0.12 + 0.05 * std::log10(permx[c]), 0.03, 0.35); });
      o << "/\n";
      return o.str();
    }
    o << "/\nPERMX\n";
    for (int c = 0; c < n; ++c) o << 50 + (c % 7) * 30 << "\n";
    o << "/\nPERMY\n" << n << "*120 /\nPERMZ\n" << n << "*12 /\nPORO\n" << n << "*0.2 /\n";
    return o.str();
  }
};

/// A case's `wells:` block with one vertical producer P1 at (x, y) from z0 to z1 (R = 5 m, 4 rings,
/// 12 sectors, flat ends, BHP 150 bar).
inline std::string vertical_well_yaml(double x, double y, double z0, double z1) {
  return "wells:\n  - {name: P1, trajectory: [[" + grdecl_number(x) + ", " + grdecl_number(y) + ", " +
         grdecl_number(z0) + "], [" + grdecl_number(x) + ", " + grdecl_number(y) + ", " + grdecl_number(z1) +
         "]], radius: 0.1, drainage_radius: 5, rings: 4, sectors: 12, segment_length: 4, end_caps: flat, bhp: 150}\n";
}

/// A `wells:` entry (no header) with a vertical injector I1 at (x, y) from z0 to z1, the producer's
/// block parameters, BHP 250 bar.
inline std::string injector_yaml(double x, double y, double z0, double z1) {
  return "  - {name: I1, type: injector, trajectory: [[" + grdecl_number(x) + ", " + grdecl_number(y) + ", " +
         grdecl_number(z0) + "], [" + grdecl_number(x) + ", " + grdecl_number(y) + ", " + grdecl_number(z1) +
         "]], radius: 0.1, drainage_radius: 5, rings: 4, sectors: 12, segment_length: 4, end_caps: flat, bhp: 250}\n";
}

/// The deviated producer P1 of the inclined-pillar case: (90, 90, 1055) to (110, 90, 1068).
inline std::string deviated_well_yaml() {
  return "wells:\n  - {name: P1, trajectory: [[90, 90, 1055], [110, 90, 1068]], radius: 0.1, "
         "drainage_radius: 5, rings: 4, sectors: 12, segment_length: 4, end_caps: flat, bhp: 150}\n";
}

}  // namespace hmtest
