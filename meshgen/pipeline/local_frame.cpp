#include "local_frame.hpp"

#include <cmath>
#include <string>

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

double on_frame_grid(double v) { return std::nearbyint(v / kFrameQuantum) * kFrameQuantum; }

namespace {

void snap_axis(std::vector<double>& axis, const std::string& key) {
  for (size_t i = 0; i < axis.size(); ++i) {
    axis[i] = on_frame_grid(axis[i]);
    if (i > 0 && !(axis[i] > axis[i - 1]))
      throw InputError(key + ": nodes " + std::to_string(i - 1) + " and " + std::to_string(i) +
                       " are closer than the local frame's resolution (2^-20 m)");
  }
}

// The model with its COORD's x and y on the frame's grid; shared when they are there already.
std::shared_ptr<const CornerPointModel> snapped_model(const std::shared_ptr<const CornerPointModel>& m) {
  bool on_grid = true;
  for (size_t p = 0; p < m->coord.size() && on_grid; p += 3)
    on_grid = on_frame_grid(m->coord[p]) == m->coord[p] && on_frame_grid(m->coord[p + 1]) == m->coord[p + 1];
  if (on_grid) return m;
  auto out = std::make_shared<CornerPointModel>(*m);
  for (size_t p = 0; p < out->coord.size(); p += 3)
    out->coord[p] = on_frame_grid(out->coord[p]), out->coord[p + 1] = on_frame_grid(out->coord[p + 1]);
  return out;
}

}  // namespace

CaseSpec local_case(const CaseSpec& cs) {
  CaseSpec out = translated_case(cs, -1.0 * case_origin(cs));
  snap_axis(out.reservoir.x, "reservoir.x");
  snap_axis(out.reservoir.y, "reservoir.y");
  if (out.reservoir.corner_point) out.reservoir.corner_point = snapped_model(out.reservoir.corner_point);
  for (size_t w = 0; w < out.wells.size(); ++w) {
    std::vector<Vec3>& path = out.wells[w].trajectory;
    for (size_t i = 0; i < path.size(); ++i) {
      path[i].x = on_frame_grid(path[i].x), path[i].y = on_frame_grid(path[i].y);
      if (i > 0 && path[i] == path[i - 1])
        throw InputError("wells[" + std::to_string(w) + "].trajectory: points " + std::to_string(i - 1) + " and " +
                         std::to_string(i) + " are closer than the local frame's resolution (2^-20 m)");
    }
  }
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
  const CaseSpec local = local_case(cs);
  std::shared_ptr<const CornerPointModel>& user_model = cs.reservoir.corner_point;
  const bool hold_once = user_model && user_model != local.reservoir.corner_point && user_model.use_count() == 1 &&
                         translation_round_trips(*user_model, -origin);
  std::vector<double> user_coord;  // the local model's is on the frame's grid
  if (hold_once) user_coord = user_model->coord, user_model.reset();
  auto give_back = [&] {
    if (!hold_once) return;
    CornerPointModel back = translated_model(*local.reservoir.corner_point, origin);
    back.coord = std::move(user_coord);
    user_model = std::make_shared<const CornerPointModel>(std::move(back));
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
