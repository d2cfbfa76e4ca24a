#include "case_problem.hpp"

#include <algorithm>

namespace hm {

FlowProblem deck_flow_problem(const CaseSpec& cs, const PolyMesh& mesh, const MeshGeometry& geo) {
  FlowProblem pb;
  pb.mesh = &mesh;
  pb.geo = &geo;
  pb.viscosity_cp = cs.fluid.viscosity;
  pb.density = cs.fluid.density;
  pb.gravity = true;
  // The deck's PVTW: Pref = initial pressure, B_ref = 1, Cw raised to 1e-8 /bar as the exporter does.
  pb.compressibility = std::max(cs.fluid.compressibility, 1e-8);
  pb.reference_pressure = cs.reservoir.initial_pressure;
  pb.formation_volume_factor = 1.0;
  for (int w = 0; w < static_cast<int>(cs.wells.size()); ++w)
    pb.wells.push_back({w, cs.wells[w].bhp, cs.wells[w].trajectory.front().z});
  return pb;
}

}  // namespace hm
