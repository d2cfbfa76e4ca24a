// The cells of a corner-point model meshed alone (no wells), for tests that compare a derived model
// (refined, split at fault steps) with its parent.
#pragma once
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "meshgen/case/grdecl.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"

namespace hmtest {

/// Mesh volume per model cell (natural order; 0 for a cell not meshed).
inline std::vector<double> model_cell_volumes(const hm::CornerPointModel& m) {
  hm::CaseSpec cs;
  cs.name = "m";
  cs.reservoir = hm::corner_point_reservoir(std::make_shared<const hm::CornerPointModel>(m), "reservoir.grdecl");
  const hm::HybridMesh out = hm::build_hybrid_mesh(cs);
  EXPECT_TRUE(out.build_report.ok);
  std::vector<double> v(m.n_cells(), 0.0);
  for (int c = 0; c < out.mesh.n_cells(); ++c) {
    const auto& ijk = out.mesh.cell_ijk[c];
    v[ijk[0] + m.nx * (ijk[1] + m.ny * ijk[2])] = out.geometry.cell_volume[c];
  }
  return v;
}

}  // namespace hmtest
