// Two-point fluxes in the hemispherical end caps of a well block (fvcheck/lib/transmissibility.cpp,
// cap_log_half; docs/transmissibility.md). Near a well's end the field is, to leading order,
// p = C (ln rho + ln(1 + cos psi)) about the end point E: its radial part ln rho must cross every
// cap shell face with its exact flux, which the orthogonal (linear) form misses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "block_mesh.hpp"
#include "fvcheck/lib/transmissibility.hpp"
#include "meshgen/core/geometry.hpp"
#include "meshgen/core/mesh_builder.hpp"
#include "meshgen/grids/well_block.hpp"

using namespace hm;

namespace {

CaseSpec capped_case(std::vector<Vec3> trajectory, int sectors) {
  CaseSpec cs;
  cs.name = "cap";
  cs.reservoir.x = {-1e3, 1e3};
  cs.reservoir.y = {-1e3, 1e3};
  cs.reservoir.z = {-1e3, 1e3};
  cs.reservoir.permeability = {50, 50, 50};
  WellSpec w;
  w.name = "W";
  w.trajectory = std::move(trajectory);
  w.radius = 0.1;
  w.drainage_radius = 8;
  w.rings = 6;
  w.sectors = sectors;
  w.segment_length = 4;
  w.end_caps = EndCaps::Hemisphere;
  cs.wells.push_back(w);
  return cs;
}

// The block alone: its outer-surface faces become boundary faces.
PolyMesh block_mesh(const CaseSpec& cs) {
  WellBlock block = make_well_block(cs, 0, cs.wells[0].sectors);
  for (size_t s = 0; s < block.surface_faces.size(); ++s) {
    std::vector<int32_t> key = block.surface_faces[s];
    std::sort(key.begin(), key.end());
    for (CellFace& f : block.cell_faces[block.surface_cell[s]]) {
      std::vector<int32_t> nodes = f.nodes;
      std::sort(nodes.begin(), nodes.end());
      if (nodes == key) f.patch = kOuterBoundary;
    }
  }
  return hm_test::assemble_block(block);
}

// Flux of grad(ln |x - E|) = (x - E) / |x - E|^2 through face f along n: 7-point Gauss on a fan
// of 32 x 32 sub-triangles per edge (independent of the production quadrature).
double exact_log_flux(const PolyMesh& m, int f, Vec3 n, Vec3 e) {
  static const double w[7] = {0.225, 0.132394152788506, 0.132394152788506, 0.132394152788506,
                              0.125939180544827, 0.125939180544827, 0.125939180544827};
  static const double a[7][2] = {{1.0 / 3, 1.0 / 3},
                                 {0.059715871789770, 0.470142064105115},
                                 {0.470142064105115, 0.059715871789770},
                                 {0.470142064105115, 0.470142064105115},
                                 {0.797426985353087, 0.101286507323456},
                                 {0.101286507323456, 0.797426985353087},
                                 {0.101286507323456, 0.101286507323456}};
  const int k = m.face_size(f), sub = 32;
  Vec3 mid;
  for (const int32_t* v = m.face_begin(f); v != m.face_end(f); ++v) mid += m.nodes[*v];
  mid = mid / static_cast<double>(k);
  double sum = 0;
  auto tri = [&](Vec3 p0, Vec3 p1, Vec3 p2) {
    const double area = 0.5 * norm(cross(p1 - p0, p2 - p0));
    for (int q = 0; q < 7; ++q) {
      const Vec3 x = p0 + a[q][0] * (p1 - p0) + a[q][1] * (p2 - p0);
      sum += area * w[q] * dot(n, x - e) / norm2(x - e);
    }
  };
  for (int i = 0; i < k; ++i) {
    const Vec3 p = m.nodes[m.face_begin(f)[i]], q = m.nodes[m.face_begin(f)[(i + 1) % k]];
    const Vec3 e1 = (p - mid) / sub, e2 = (q - mid) / sub;
    for (int r = 0; r < sub; ++r)
      for (int s = 0; r + s < sub; ++s) {
        const Vec3 b = mid + static_cast<double>(r) * e1 + static_cast<double>(s) * e2;
        tri(b, b + e1, b + e2);
        if (r + s + 1 < sub) tri(b + e1, b + e1 + e2, b + e2);
      }
  }
  return sum;
}

struct ShellFluxErrors {
  int faces = 0;
  double worst = 0;  // max |T dp / exact flux - 1| over the interior cap shell faces
};

ShellFluxErrors shell_flux_errors(const CaseSpec& cs, bool exact_radial) {
  const PolyMesh m = block_mesh(cs);
  const MeshGeometry g = compute_geometry(m);
  TransmissibilityOptions opt;
  opt.exact_radial = exact_radial;
  const Transmissibilities t = compute_transmissibilities(m, g, opt);
  const double k = cs.reservoir.permeability.x * kDarcyMetric;
  ShellFluxErrors out;
  for (int f = 0; f < m.n_faces(); ++f) {
    const int o = m.face_owner[f], nb = m.face_neighbour[f];
    if (nb < 0) continue;
    const RadialCellInfo &ro = m.cell_radial[o], &rn = m.cell_radial[nb];
    if (ro.band < 0 || rn.band != ro.band || rn.segment != ro.segment || rn.sector != ro.sector) continue;
    const Vec3 e = ro.cap_center;
    const double p_o = std::log(norm(m.cell_fv_center[o] - e)), p_n = std::log(norm(m.cell_fv_center[nb] - e));
    const Vec3 n = normalized(g.face_area[f]);  // out of the owner
    const double exact = -k * exact_log_flux(m, f, n, e);  // Darcy flux owner -> neighbour
    out.worst = std::max(out.worst, std::fabs(t.face[f] * (p_o - p_n) / exact - 1));
    ++out.faces;
  }
  return out;
}

}  // namespace

TEST(EndCapTransmissibility, ShellFacesCarryTheExactFluxOfTheTipLogField) {
  for (int sectors : {6, 12, 24}) {
    for (const auto& traj : {std::vector<Vec3>{{0, 0, 0}, {0, 0, 40}}, std::vector<Vec3>{{0, 0, 0}, {30, 10, 25}},
                             std::vector<Vec3>{{0, 0, 0}, {0, 0, 30}, {20, 0, 50}}}) {
      const ShellFluxErrors e = shell_flux_errors(capped_case(traj, sectors), true);
      // 2 caps x 5 interior shells x bands x sectors
      EXPECT_EQ(e.faces, 2 * 5 * hemisphere_cap_bands(sectors) * sectors);
      EXPECT_LT(e.worst, 1e-4) << sectors << " sectors";
      std::printf("[cap shells] %d sectors, %zu points: %d faces, worst flux ratio error %.1e\n", sectors, traj.size(),
                  e.faces, e.worst);
    }
  }
}

// The fail half: without the radial structure (exact_radial = false: the generic two-point form
// on every face of a radial cell) the same faces are several percent off.
TEST(EndCapTransmissibility, GenericFormOnCapShellsIsNotExact) {
  const ShellFluxErrors e = shell_flux_errors(capped_case({{0, 0, 0}, {0, 0, 40}}, 12), false);
  EXPECT_GT(e.worst, 0.02);
  std::printf("[cap shells] generic form: worst flux ratio error %.3f\n", e.worst);
}
