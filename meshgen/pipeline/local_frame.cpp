#include "local_frame.hpp"

#include "meshgen/case/grdecl.hpp"

namespace hm {

// z (depth) stays: depths are below 1e4 m, where a double resolves 2e-12 m, and keeping them
// keeps every mesh of a case whose reservoir starts at x = y = 0 bit-identical to the mesh of
// the case as given (the shipped examples' figures hold unchanged).
Vec3 case_origin(const CaseSpec& cs) { return {cs.reservoir.x.front(), cs.reservoir.y.front(), 0.0}; }

CaseSpec translated_case(const CaseSpec& cs, Vec3 shift) {
  CaseSpec out = cs;
  for (double& v : out.reservoir.x) v += shift.x;
  for (double& v : out.reservoir.y) v += shift.y;
  for (double& v : out.reservoir.z) v += shift.z;
  if (cs.reservoir.corner_point)
    out.reservoir.corner_point = std::make_shared<const CornerPointModel>(translated_model(*cs.reservoir.corner_point, shift));
  for (WellSpec& w : out.wells)
    for (Vec3& p : w.trajectory) p += shift;
  return out;
}

void translate_mesh(PolyMesh& mesh, Vec3 shift) {
  for (Vec3& p : mesh.nodes) p += shift;
  for (Vec3& p : mesh.cell_fv_center) p += shift;
  for (RadialCellInfo& r : mesh.cell_radial)
    if (r.band >= 0) r.cap_center += shift;
}

}  // namespace hm
