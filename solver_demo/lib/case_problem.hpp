// The flow problem of a case as its exported Eclipse deck states it (docs/export-eclipse.md):
// what `solver_demo CASE` solves and what the Flow comparisons of the tests solve.
#pragma once
#include "meshgen/case/case.hpp"
#include "tpfa.hpp"

namespace hm {

/// Viscosity, surface density, gravity on; the deck's PVTW water (Pref = initial pressure, B_ref = 1,
/// Cw raised to 1e-8 /bar as the exporter writes it); every well under BHP control at the depth of its
/// first trajectory point (WELSPECS item 5). `mesh` and `geo` are referenced, not copied.
FlowProblem deck_flow_problem(const CaseSpec& cs, const PolyMesh& mesh, const MeshGeometry& geo);

}  // namespace hm
