// build_hybrid_mesh: the Euclidean job, run in the case's permeability frame when it has one.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>

#include "hybrid_mesh.hpp"
#include "meshgen/case/grdecl.hpp"
#include "meshgen/grids/corner_point_grid.hpp"
#include "meshgen/pipeline/local_frame.hpp"
#include "meshgen/pipeline/permeability_frame.hpp"

namespace hm {

namespace {

std::string fmt_scale(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// Relative to the model's extent: how far a model node built in the scaled frame may lie from the
// scaled image of the same node built from the physical model (rounding of the two computations).
constexpr double kModelNodeAgreement = 1e-12;

// In a corner-point model the builder's first nodes are the model's (corner_point_mesh.cpp adds them
// first) and the mesh keeps the used ones in their order. They get their coordinates as the physical
// model gives them (what the Euclidean job writes, and what the deck's COORD/ZCORN say), not the scaled
// positions mapped back, off by ulps.
struct PhysicalModelNodes {
  std::vector<Vec3> builder;                      ///< the model's builder nodes, physical
  std::vector<std::pair<int32_t, Vec3>> in_mesh;  ///< (mesh node, physical position) of those the mesh uses
};

// Throws when the model's nodes built in the scaled frame do not correspond to the physical model's.
PhysicalModelNodes physical_model_nodes(const PolyMesh& scaled_mesh, const std::vector<Vec3>& scaled_builder_nodes,
                                        const CornerPointModel& physical, const PermeabilityFrame& f) {
  PhysicalModelNodes out;
  {
    MeshBuilder builder;
    corner_point_cell_faces(physical, std::vector<char>(physical.actnum.size(), 1), builder);
    out.builder.resize(builder.n_nodes());
    for (int32_t i = 0; i < builder.n_nodes(); ++i) out.builder[i] = builder.node(i);
  }
  const size_t n = out.builder.size();
  double extent = 0;
  for (size_t i = 1; i < n; ++i) extent = std::max(extent, norm(out.builder[i] - out.builder[0]));
  bool agree = n <= scaled_builder_nodes.size();
  for (size_t i = 0; i < n && agree; ++i)
    agree = norm(to_scaled(f, out.builder[i]) - scaled_builder_nodes[i]) <= kModelNodeAgreement * extent;
  if (!agree)
    throw MeshingError("permeability frame", {},
                       "permeability frame: the corner-point model's nodes built in the scaled frame do not correspond to "
                       "the physical model's (" + std::to_string(n) + " physical, " +
                           std::to_string(scaled_builder_nodes.size()) + " in the frame with the wells')");
  size_t i = 0;
  for (int32_t j = 0; j < scaled_mesh.n_nodes() && i < n; ++j) {
    while (i < n && !(scaled_builder_nodes[i] == scaled_mesh.nodes[j])) ++i;
    if (i < n) out.in_mesh.push_back({j, out.builder[i++]});
  }
  return out;
}

}  // namespace

HybridMesh build_hybrid_mesh(const CaseSpec& cs, const PipelineOptions& opts) {
  const bool corner_point = cs.reservoir.corner_point != nullptr;
  // A corner-point model without wells is meshed as its own cells: there is nothing to make K-orthogonal.
  if (corner_point && cs.wells.empty()) return build_corner_point_mesh(cs, opts);
  const PermeabilityFrame frame = permeability_frame(cs);
  auto build = [&](const CaseSpec& c, const PipelineOptions& o) {
    return corner_point ? build_corner_point_mesh(c, o) : build_hybrid_mesh_euclidean(c, o);
  };
  if (frame.identity()) {
    HybridMesh out = build(cs, opts);
    out.frame = frame;
    return out;
  }
  PipelineOptions scaled_opts = opts;
  scaled_opts.written_origin = Vec3{};  // the scaled frame's positions are not the written ones
  scaled_opts.frame = frame;
  scaled_opts.frame_written_origin = opts.written_origin;
  HybridMesh out;
  try {
    out = build(scaled_case(cs, frame), scaled_opts);
  } catch (const MeshingError& e) {
    // The frame stretches a corner-point model's layers against its columns, split near the wells only
    // as far as reservoir.near_well_layer_aspect asks (docs/anisotropy.md, "Corner-point models"): the
    // transition's refusals there say so, and what meshes without the stretch.
    if (!corner_point || e.stage != "transition") throw;
    const double aspect = cs.reservoir.near_well_layer_aspect;
    const std::string split = aspect > 0 ? "split near the wells to cells at most " + fmt_scale(aspect) +
                                               " times taller than wide (reservoir.near_well_layer_aspect)"
                                         : "not split for it (reservoir.near_well_layer_aspect: 0)";
    throw MeshingError(e.stage, e.wells,
                       std::string(e.what()) + "; metric: permeability stretches the model's layers " +
                           fmt_scale(frame.scale.x / frame.scale.z) + " times against its columns, " + split +
                           ": metric: euclidean meshes without the stretch (docs/anisotropy.md, \"Corner-point models\")");
  }
  const auto t0 = std::chrono::steady_clock::now();
  out.frame = frame;
  PhysicalModelNodes model_nodes;
  if (corner_point) model_nodes = physical_model_nodes(out.mesh, out.cavity_node_coords, *cs.reservoir.corner_point, frame);
  const FrameUnmapper unmap(frame, cs.reservoir);
  unscale_mesh(out.mesh, unmap);
  for (const auto& [node, p] : model_nodes.in_mesh) out.mesh.nodes[node] = p;
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
  std::copy(model_nodes.builder.begin(), model_nodes.builder.end(), out.cavity_node_coords.begin());
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
