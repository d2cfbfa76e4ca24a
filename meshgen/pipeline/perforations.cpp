#include "perforations.hpp"

#include <algorithm>
#include <limits>
#include <string>

namespace hm {

double measured_depth_at(const WellSpec& ws, const std::vector<double>& md, Vec3 p) {
  double best = std::numeric_limits<double>::infinity(), best_md = md.empty() ? 0.0 : md.front();
  for (size_t i = 0; i + 1 < ws.trajectory.size(); ++i) {
    const Vec3 a = ws.trajectory[i], ab = ws.trajectory[i + 1] - a;
    const double t = std::clamp(dot(p - a, ab) / dot(ab, ab), 0.0, 1.0);
    const double d = norm(p - (a + t * ab));
    if (d < best) best = d, best_md = md[i] + t * (md[i + 1] - md[i]);
  }
  return best_md;
}

namespace {
bool perforated(const WellSpec& ws, double md) {
  for (const auto& iv : ws.perforations)
    if (md >= iv[0] && md <= iv[1]) return true;
  return false;
}
}  // namespace

std::vector<int> close_unperforated_wellbore(PolyMesh& mesh, const MeshGeometry& geo, const CaseSpec& cs) {
  const int nw = static_cast<int>(cs.wells.size());
  std::vector<int> open(nw, 0);
  std::vector<std::vector<double>> md(nw);
  for (int w = 0; w < nw; ++w) md[w] = well_measured_depths(cs.wells[w]);
  for (int f = 0; f < mesh.n_faces(); ++f) {
    const int32_t p = mesh.face_patch[f];
    if (mesh.face_neighbour[f] >= 0 || !is_wellbore_patch(p) || well_of_patch(p) >= nw) continue;
    const int w = well_of_patch(p);
    const WellSpec& ws = cs.wells[w];
    if (ws.perforations.empty() || perforated(ws, measured_depth_at(ws, md[w], geo.face_centroid[f])))
      ++open[w];
    else
      mesh.face_patch[f] = closed_wellbore_patch(w);
  }
  for (int w = 0; w < nw; ++w)
    if (open[w] == 0)
      throw InputError("wells[" + std::to_string(w) + "].perforations: no perforated interval reaches the part of " +
                       cs.wells[w].name + " inside the reservoir (every wellbore face would be closed)");
  return open;
}

}  // namespace hm
