// Helpers of the tests that write synthetic corner-point models (GRDECL text).
#pragma once
#include <cmath>
#include <cstdio>
#include <functional>
#include <sstream>
#include <string>

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

/// Planar layers (depth 1000 + dz k + tan(dip) x + 0.01 y at pillar (x, y) = (dx I, dy J)) on
/// parallel straight pillars inclined `pillar_deg` from the vertical toward azimuth `pillar_azimuth_deg`
/// (0: +x, 90: +y), so every cell face is
/// planar; an optional fault on pillar line I = fault_i (columns i >= fault_i down by throw_m).
/// PERMX varies by cell; PERMY 120, PERMZ 12 mD; PORO 0.2.
struct LayeredModel {
  int nx = 7, ny = 7, nz = 40, fault_i = -1;
  double dx = 100, dy = 100, dz = 3, dip_deg = 5, pillar_deg = 0, pillar_azimuth_deg = 0, throw_m = 0;

  double depth(int i_col, int I, int J, int k) const {
    double z = 1000 + dz * k + std::tan(dip_deg * M_PI / 180) * dx * I + 0.01 * dy * J;
    if (fault_i > 0 && i_col >= fault_i) z += throw_m;
    return z;
  }
  std::string text() const {
    std::ostringstream o;
    const double lean = std::tan(pillar_deg * M_PI / 180), az = pillar_azimuth_deg * M_PI / 180;
    const double lx = lean * std::cos(az), ly = lean * std::sin(az);
    o << "SPECGRID\n " << nx << " " << ny << " " << nz << " 1 F /\nCOORD\n";
    for (int J = 0; J <= ny; ++J)
      for (int I = 0; I <= nx; ++I) {
        const double x = dx * I, y = dy * J;  // the pillar's point at depth 1000
        o << grdecl_number(x - 100 * lx) << " " << grdecl_number(y - 100 * ly) << " 900 " << grdecl_number(x + 300 * lx)
          << " " << grdecl_number(y + 300 * ly) << " 1300\n";
      }
    o << "/\nZCORN\n";
    write_zcorn(o, nx, ny, nz, [&](int i, int I, int J, int k) { return depth(i, I, J, k); });
    const int n = nx * ny * nz;
    o << "/\nPERMX\n";
    for (int c = 0; c < n; ++c) o << 50 + (c % 7) * 30 << "\n";
    o << "/\nPERMY\n" << n << "*120 /\nPERMZ\n" << n << "*12 /\nPORO\n" << n << "*0.2 /\n";
    return o.str();
  }
};

}  // namespace hmtest
