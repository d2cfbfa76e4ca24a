// build_hybrid_mesh: the Euclidean job, run in the case's permeability frame when it has one.
#include <chrono>
#include <cstdio>
#include <string>

#include "hybrid_mesh.hpp"
#include "meshgen/pipeline/local_frame.hpp"
#include "meshgen/pipeline/permeability_frame.hpp"

namespace hm {

namespace {

std::string fmt_scale(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

}  // namespace

HybridMesh build_hybrid_mesh(const CaseSpec& cs, const PipelineOptions& opts) {
  if (cs.reservoir.corner_point) return build_corner_point_mesh(cs, opts);
  const PermeabilityFrame frame = permeability_frame(cs);
  if (frame.identity()) {
    HybridMesh out = build_hybrid_mesh_euclidean(cs, opts);
    out.frame = frame;
    return out;
  }
  PipelineOptions scaled_opts = opts;
  scaled_opts.written_origin = Vec3{};  // the scaled frame's positions are not the written ones
  scaled_opts.frame = frame;
  scaled_opts.frame_written_origin = opts.written_origin;
  HybridMesh out = build_hybrid_mesh_euclidean(scaled_case(cs, frame), scaled_opts);
  const auto t0 = std::chrono::steady_clock::now();
  out.frame = frame;
  const FrameUnmapper unmap(frame, cs.reservoir);
  unscale_mesh(out.mesh, unmap);
  round_to_written_frame(out.mesh, opts.written_origin);
  out.geometry = compute_geometry(out.mesh);
  // The self-check above judged the scaled frame's positions, which no file holds: the mesh is
  // judged again as written (physical, rounded to the user's frame; orthogonality in the K metric,
  // as fvcheck measures it), so that the way back cannot make a mesh that fails fvcheck.
  if (opts.build_transition) {
    std::vector<std::vector<int>> cavity_wells;
    for (const Cavity& c : out.cavities.cavities) cavity_wells.push_back(c.wells);
    out.self_check = self_check(out.mesh, out.geometry, out.build_report, out.cell_cavity, cavity_wells, cs);
    if (!out.self_check.ok())
      throw MeshingError("self-check", out.self_check.wells,
                         out.self_check.message + " (as written, back from the permeability frame)");
  }
  out.grid = make_reservoir_grid(cs.reservoir);
  for (Vec3& p : out.cavity_node_coords) p = unmap(p);
  for (WellBlock& b : out.blocks) {
    for (Vec3& p : b.nodes) p = unmap(p);
    for (Vec3& p : b.layer_center) p = unmap(p);
    for (Vec3& p : b.trajectory) p = unmap(p);
    for (int e = 0; e < 2; ++e)
      if (b.boundary_axis[e] >= 0) {
        Vec3 p;
        p[b.boundary_axis[e]] = b.boundary_value[e];
        b.boundary_value[e] = unmap(p)[b.boundary_axis[e]];
      }
  }
  out.notes.push_back("metric: permeability: meshed in the frame x' = S^-1 x, S = diag(" + fmt_scale(frame.scale.x) +
                      ", " + fmt_scale(frame.scale.y) + ", " + fmt_scale(frame.scale.z) + ") of K = (" +
                      fmt_scale(frame.k.x) + ", " + fmt_scale(frame.k.y) + ", " + fmt_scale(frame.k.z) +
                      ") mD (docs/anisotropy.md)");
  out.timings_s.push_back({"permeability_frame", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()});
  return out;
}

}  // namespace hm
