#include "mesh_positions.hpp"

#include <algorithm>

namespace hm {

void round_to_written_frame(PolyMesh& mesh, Vec3 origin) {
  if (origin == Vec3{}) return;
  for (Vec3& p : mesh.nodes) p = as_written(p, origin);
  for (Vec3& p : mesh.cell_fv_center) p = as_written(p, origin);
  for (RadialCellInfo& r : mesh.cell_radial)
    if (r.band >= 0) r.cap_center = as_written(r.cap_center, origin);
}

Vec3 plan_origin(const PolyMesh& mesh) {
  if (mesh.nodes.empty()) return {};
  Vec3 o{mesh.nodes[0].x, mesh.nodes[0].y, 0};
  for (const Vec3& p : mesh.nodes) o = {std::min(o.x, p.x), std::min(o.y, p.y), 0};
  return o;
}

void translate_mesh(PolyMesh& mesh, Vec3 shift) {
  for (Vec3& p : mesh.nodes) p += shift;
  for (Vec3& p : mesh.cell_fv_center) p += shift;
  for (RadialCellInfo& r : mesh.cell_radial)
    if (r.band >= 0) r.cap_center += shift;
}

}  // namespace hm
