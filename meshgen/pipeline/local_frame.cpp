#include "local_frame.hpp"

#include <cmath>

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
  if (cs.reservoir.corner_point && !(shift == Vec3{}))
    out.reservoir.corner_point = std::make_shared<const CornerPointModel>(translated_model(*cs.reservoir.corner_point, shift));
  for (WellSpec& w : out.wells)
    for (Vec3& p : w.trajectory) p += shift;
  return out;
}

bool translation_round_trips(const CornerPointModel& m, Vec3 shift) {
  // Equal and of the same sign: -0 comes back as +0.
  auto back = [](double v, double s) {
    const double w = (v + s) - s;
    return w == v && std::signbit(w) == std::signbit(v);
  };
  for (size_t p = 0; p < m.coord.size(); p += 3)
    if (!back(m.coord[p], shift.x) || !back(m.coord[p + 1], shift.y) || !back(m.coord[p + 2], shift.z)) return false;
  for (double z : m.zcorn)
    if (!back(z, shift.z)) return false;
  return true;  // and so do the corners, computed from COORD and ZCORN
}

HybridMesh build_hybrid_mesh_in_local_frame(CaseSpec& cs, const PipelineOptions& opts) {
  const Vec3 origin = case_origin(cs);
  const CaseSpec local = translated_case(cs, -origin);
  std::shared_ptr<const CornerPointModel>& user_model = cs.reservoir.corner_point;
  const bool hold_once = user_model && user_model != local.reservoir.corner_point && user_model.use_count() == 1 &&
                         translation_round_trips(*user_model, -origin);
  if (hold_once) user_model.reset();
  auto give_back = [&] {
    if (hold_once)
      user_model = std::make_shared<const CornerPointModel>(translated_model(*local.reservoir.corner_point, origin));
  };
  PipelineOptions written = opts;
  written.written_origin = origin;
  try {
    HybridMesh h = build_hybrid_mesh(local, written);
    give_back();
    return h;
  } catch (...) {
    give_back();
    throw;
  }
}

}  // namespace hm
