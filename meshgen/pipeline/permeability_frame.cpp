#include "permeability_frame.hpp"

#include "meshgen/case/case_limits.hpp"
#include "meshgen/case/grdecl.hpp"
#include "meshgen/case/meshed_trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace hm {

namespace {

Vec3 divided(Vec3 v, Vec3 s) { return {v.x / s.x, v.y / s.y, v.z / s.z}; }

// Two unit vectors completing the unit axis t to an orthonormal basis.
void complete_basis(Vec3 t, Vec3* u, Vec3* w) {
  const Vec3 helper = std::fabs(t.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  *u = normalized(cross(t, helper));
  *w = cross(t, *u);
}

// Gram matrix (g11, g22, g12) of [P S^-1 u, P S^-1 w]: the scaled cross-section (normal to the
// scaled axis) of the unit circle about the physical unit axis t; its singular values are the
// semi-axes a, b of that ellipse.
Vec3 cross_section_gram(Vec3 scale, Vec3 t) {
  Vec3 u, w;
  complete_basis(t, &u, &w);
  const Vec3 ts = normalized(divided(t, scale));
  auto project = [&](Vec3 v) { return v - dot(v, ts) * ts; };
  const Vec3 a = project(divided(u, scale)), b = project(divided(w, scale));
  return {dot(a, a), dot(b, b), dot(a, b)};
}

}  // namespace

double equivalent_radius(Vec3 scale, Vec3 t, double r) {
  const Vec3 g = cross_section_gram(scale, t);
  // a + b = sqrt(g11 + g22 + 2 sqrt(det G)).
  const double sum = std::sqrt(g.x + g.y + 2 * std::sqrt(std::max(0.0, g.x * g.y - g.z * g.z)));
  return 0.5 * r * sum;
}

double scaled_block_radius(Vec3 scale, double R) { return R / std::max({scale.x, scale.y, scale.z}); }

double area_block_radius(Vec3 scale, Vec3 t, double R) {
  const Vec3 g = cross_section_gram(scale, t);
  // a b = sqrt(det G).
  return R * std::sqrt(std::sqrt(std::max(0.0, g.x * g.y - g.z * g.z)));
}

namespace {

// Relative gain below which the area radius is not taken: the inscribed block is kept where the
// two nearly agree (a vertical well in kx = ky rock has a circular scaled cross-section, where they
// are equal up to round-off: its mesh stays bit-identical).
constexpr double kAreaRadiusMinGain = 0.01;

// The single-well rule of scaled_case: the area radius when the block keeps, in the scaled box,
// the same fit as with the inscribed radius (no throw, not squeezed, same ends and caps);
// else the inscribed radius.
double fitted_block_radius(const ReservoirSpec& scaled_reservoir, WellSpec w, double inscribed, double area,
                           const std::string& key) {
  if (!(area > inscribed * (1 + kAreaRadiusMinGain))) return inscribed;
  w.drainage_radius = inscribed;
  const MeshedTrajectory small = meshed_trajectory(scaled_reservoir, w, key, false);
  w.drainage_radius = area;
  try {
    const MeshedTrajectory big = meshed_trajectory(scaled_reservoir, w, key, true);
    if (big.drainage_radius == area && big.ends == small.ends && big.caps_fit == small.caps_fit &&
        big.points.size() == small.points.size())
      return area;
  } catch (const InputError&) {
    // The enlarged block does not fit the box: the inscribed one does (the physical checks).
  }
  return inscribed;
}

// The scaling sharpens bends that turn across the axis of low permeability (a 60-degree bend at
// kv/kh 0.01 can pass 120): one the radial block cannot hold is refused here, naming both angles,
// rather than by the block with an angle the user never gave.
void check_scaled_bends(const std::vector<Vec3>& physical, const std::vector<Vec3>& scaled, const PermeabilityFrame& f,
                        const std::string& key) {
  for (size_t k = 1; k + 1 < scaled.size(); ++k) {
    const double deg = bend_degrees(scaled[k] - scaled[k - 1], scaled[k + 1] - scaled[k]);
    if (!(deg > kMaxBlockBendDegrees * (1 + kBendLimitTolerance))) continue;
    char text[512];
    std::snprintf(text, sizeof text,
                  ".trajectory: the bend at point %zu, %.4g degrees as given, is %.4g degrees in the permeability "
                  "frame (metric: permeability, K = %.4g, %.4g, %.4g mD), over the %.4g-degree limit of a radial "
                  "block: smooth the bend (over several block radii), give a smaller drainage_radius, or mesh with "
                  "metric: euclidean (docs/anisotropy.md, \"Bends sharpened by the frame\")",
                  k, bend_degrees(physical[k] - physical[k - 1], physical[k + 1] - physical[k]), deg, f.k.x, f.k.y,
                  f.k.z, kMaxBlockBendDegrees);
    throw InputError(key + text);
  }
}

}  // namespace

std::shared_ptr<const CornerPointModel> scaled_corner_point_model(const CornerPointModel& m, const PermeabilityFrame& f) {
  auto out = std::make_shared<CornerPointModel>(m);
  for (size_t i = 0; i < out->coord.size(); ++i) {
    const int d = static_cast<int>(i % 3);
    out->coord[i] = f.origin[d] + (out->coord[i] - f.origin[d]) / f.scale[d];
  }
  for (double& z : out->zcorn) z = f.origin.z + (z - f.origin.z) / f.scale.z;
  out->pinch.threshold /= f.scale.z;
  out->pinch.max_empty_gap /= f.scale.z;
  return out;
}

CaseSpec scaled_case(const CaseSpec& cs, const PermeabilityFrame& f) {
  CaseSpec out = cs;
  if (f.identity()) return out;
  ReservoirSpec& r = out.reservoir;
  for (double& v : r.x) v = f.origin.x + (v - f.origin.x) / f.scale.x;
  for (double& v : r.y) v = f.origin.y + (v - f.origin.y) / f.scale.y;
  for (double& v : r.z) v = f.origin.z + (v - f.origin.z) / f.scale.z;
  if (r.corner_point) r.corner_point = scaled_corner_point_model(*r.corner_point, f);
  for (size_t i = 0; i < out.wells.size(); ++i) {
    WellSpec& w = out.wells[i];
    double length = 0, scaled_length = 0, radius_sum = 0, area_radius_sum = 0;
    for (size_t j = 0; j + 1 < w.trajectory.size(); ++j) {
      const Vec3 d = w.trajectory[j + 1] - w.trajectory[j];
      const double l = norm(d);
      length += l;
      scaled_length += norm(divided(d, f.scale));
      radius_sum += l * equivalent_radius(f.scale, d / l, w.radius);
      area_radius_sum += l * area_block_radius(f.scale, d / l, w.drainage_radius);
    }
    // Measured depths stay the physical ones (perforations are given in them).
    if (w.trajectory_md.empty()) w.trajectory_md = well_measured_depths(w);
    for (Vec3& p : w.trajectory) p = to_scaled(f, p);
    check_scaled_bends(cs.wells[i].trajectory, w.trajectory, f, "wells[" + std::to_string(i) + "]");
    w.radius = radius_sum / length;
    const double inscribed = scaled_block_radius(f.scale, w.drainage_radius);
    // A corner-point model's paths were fitted to its surface with the physical block: the inscribed
    // block lies inside it. The box's rule for the area radius knows only a box.
    w.drainage_radius = out.wells.size() == 1 && !r.corner_point
                            ? fitted_block_radius(r, w, inscribed, area_radius_sum / length,
                                                  "wells[" + std::to_string(i) + "]")
                            : inscribed;
    w.segment_length *= scaled_length / length;
    if (!(w.radius < w.drainage_radius))
      throw InputError("wells[" + std::to_string(i) + "].drainage_radius: too small for this anisotropy (metric: " +
                       "permeability): the scaled wellbore radius " + std::to_string(w.radius) +
                       " m is not below the scaled block radius " + std::to_string(w.drainage_radius) +
                       " m (docs/anisotropy.md)");
  }
  return out;
}

FrameUnmapper::FrameUnmapper(const PermeabilityFrame& f, const ReservoirSpec& phys) : frame(f), physical(&phys) {
  if (phys.corner_point) return;  // x, y, z only divide its bounding box: no node lies on them
  const std::vector<double>* axes[3] = {&phys.x, &phys.y, &phys.z};
  for (int d = 0; d < 3; ++d)
    for (double v : *axes[d]) scaled_axis[d].push_back(frame.origin[d] + (v - frame.origin[d]) / frame.scale[d]);
}

Vec3 FrameUnmapper::operator()(Vec3 xs) const {
  Vec3 x = to_physical(frame, xs);
  const std::vector<double>* axes[3] = {&physical->x, &physical->y, &physical->z};
  for (int d = 0; d < 3; ++d) {
    const std::vector<double>& a = scaled_axis[d];
    if (a.empty()) continue;
    const auto it = std::lower_bound(a.begin(), a.end(), xs[d]);
    if (it != a.end() && *it == xs[d]) x[d] = (*axes[d])[it - a.begin()];
  }
  return x;
}

void unscale_mesh(PolyMesh& m, const FrameUnmapper& unmap) {
  for (Vec3& p : m.nodes) p = unmap(p);
  for (Vec3& p : m.cell_fv_center) p = unmap(p);
  for (RadialCellInfo& r : m.cell_radial)
    if (r.band >= 0) r.cap_center = unmap(r.cap_center);
  m.metric_scale = unmap.frame.scale;
}

}  // namespace hm
