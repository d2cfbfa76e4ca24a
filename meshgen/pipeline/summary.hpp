// summary.json of a meshing run (docs/output-formats.md#summary).
#pragma once
#include <nlohmann/json.hpp>

#include "hybrid_mesh.hpp"

namespace hm {

/// Counts, cavities, notes, transition reports and timings of a finished run.
nlohmann::json make_summary(const CaseSpec& cs, const HybridMesh& hm);

/// The paper's Table 1 and 2 quantities for the transition cells of a mesh: distinct
/// vertices and faces of the transition cells, the cell count, and min/max/mean of Q_S
/// (with h = cell_h_ref), Q_O(V) and Q_P(V).
nlohmann::json transition_quality(const PolyMesh& mesh, const MeshGeometry& geo, const std::vector<double>& h_ref);

}  // namespace hm
