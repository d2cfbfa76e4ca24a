// summary.json of a meshing run (docs/output-formats.md#summary).
#pragma once
#include <nlohmann/json.hpp>

#include "hybrid_mesh.hpp"

namespace hm {

/// Counts, cavities, notes, transition reports and timings of a finished run.
nlohmann::json make_summary(const CaseSpec& cs, const HybridMesh& hm);

/// JSON form of the paper's Table 1 and 2 quantities (TransitionQuality).
nlohmann::json to_json(const TransitionQuality& q);

}  // namespace hm
