// Helpers of the tests that write synthetic corner-point models (GRDECL text).
#pragma once
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

}  // namespace hmtest
