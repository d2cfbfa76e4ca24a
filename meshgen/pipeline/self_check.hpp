// meshgen's check of its own mesh before anything is written (docs/architecture.md,
// "Self-check"): fvcheck's checks (fvcheck/lib, the one implementation) plus finite numbers
// everywhere a file takes them from. A mesh that fails is not written: meshgen exits 1 naming
// the check, the cells and the wells they belong to.
#pragma once
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "fvcheck/lib/checks.hpp"
#include "meshgen/case/case.hpp"
#include "meshgen/core/geometry.hpp"
#include "meshgen/core/polymesh.hpp"

namespace hm {

struct SelfCheckFailure {
  std::string check;           ///< fvcheck's check name ("convexity", ...), "structure" or "finite"
  int64_t violations = 0;      ///< cells (or faces, for the per-face checks) that fail it
  std::vector<int32_t> cells;  ///< up to 10 failing cells, worst first (a face's owner for per-face checks)
  double worst = 0;            ///< the check's worst value (fvcheck's meaning: degrees for orthogonality)
  bool per_face = false;       ///< the check named faces (else cells: a corner-point model's near-well cells judged alone)
  int32_t neighbour = -1;      ///< per_face: the worst face's other cell (-1: a boundary face)
  std::vector<std::pair<std::string, int64_t>> counts;  ///< the check's non-zero named sub-counts
};

struct SelfCheck {
  std::vector<SelfCheckFailure> failures;  ///< one per failing check, in fvcheck's order
  std::vector<int> wells;  ///< wells of the failing cells (radial cells' well, transition cells' cavity wells)
  std::string message;     ///< one line naming the checks, cells and wells; empty when ok
  bool ok() const { return failures.empty(); }
};

/// Runs the checks on `mesh` (geo = compute_geometry(mesh); build = the builder's report).
/// cell_cavity[c] (-1 or a cavity index) and cavity_wells[k] name the wells of transition cells.
/// The checks: CSR structure, convexity, conformity (with orientation and the builder's
/// problems), closure, positive volume, orthogonality, auto-centering, planarity at fvcheck's
/// defaults (CheckOptions{}), and finite nodes, FV centres, permeability, porosity, volumes,
/// face areas and two-point transmissibilities.
SelfCheck self_check(const PolyMesh& mesh, const MeshGeometry& geo, const BuildReport& build,
                     const std::vector<int32_t>& cell_cavity, const std::vector<std::vector<int>>& cavity_wells,
                     const CaseSpec& cs);

}  // namespace hm
