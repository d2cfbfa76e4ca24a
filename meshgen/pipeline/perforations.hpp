// Perforated intervals (wells[i].perforations, docs/case-format.md): wellbore faces outside them
// become closed walls, so the deck, the solver, fvcheck and OpenFOAM see no connection there.
#pragma once
#include <vector>

#include "meshgen/case/case.hpp"
#include "meshgen/core/geometry.hpp"

namespace hm {

/// Measured depth of the point of `ws`'s trajectory closest to p (the first such point on a tie),
/// interpolated linearly between the measured depths of the polyline's points.
double measured_depth_at(const WellSpec& ws, const std::vector<double>& md, Vec3 p);

/// Moves each wellbore face of a well with perforation intervals whose centroid's measured depth
/// lies outside all of them to closed_wellbore_patch(w). Returns the faces left open per well.
/// Throws InputError (wells[i].perforations) when a well keeps no open face.
std::vector<int> close_unperforated_wellbore(PolyMesh& mesh, const MeshGeometry& geo, const CaseSpec& cs);

}  // namespace hm
