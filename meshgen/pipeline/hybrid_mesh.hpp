// The whole meshing job: case -> reservoir grid + well blocks -> cavities ->
// transition meshes -> one conforming PolyMesh, with a report of every stage.
#pragma once
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "meshgen/case/case.hpp"
#include "meshgen/cavity/cavity.hpp"
#include "meshgen/core/geometry.hpp"
#include "meshgen/core/mesh_builder.hpp"
#include "meshgen/grids/reservoir_grid.hpp"
#include "fvcheck/lib/quality.hpp"
#include "meshgen/grids/well_block.hpp"
#include "meshgen/pipeline/permeability_frame.hpp"
#include "meshgen/pipeline/self_check.hpp"
#include "meshgen/transition/transition.hpp"

namespace hm {

struct PipelineOptions {
  bool build_transition = true;  ///< false: stop after the cavities (the mesh then has open cavity faces)
  bool optimize = true;          ///< run the small-edge optimisation when the case asks for it
  int threads = 0;               ///< cavities built at once (meshgen -j); 0: every core
  /// The origin the writers add back (build_hybrid_mesh_in_local_frame sets it; local_frame.hpp): before
  /// the geometry and the self-check, every position of the mesh is rounded to what it is once moved
  /// there and back (round_to_written_frame), so that the self-check judges the coordinates the files
  /// get. Zero: nothing is rounded.
  Vec3 written_origin;
  /// The permeability frame the case is meshed in (build_hybrid_mesh sets it; identity: none) and the
  /// origin its physical positions are written about (TransitionOptions::frame).
  PermeabilityFrame frame;
  Vec3 frame_written_origin;
  /// Called at the end of each stage of HybridMesh::timings_s with its name (benchmarks
  /// sample memory there); may be empty.
  std::function<void(const std::string& stage)> on_stage;
};

/// The paper's Table 1 and 2 quantities for the transition cells of a mesh.
struct TransitionQuality {
  int vertices = 0;  ///< distinct nodes of the transition cells
  int faces = 0;     ///< distinct faces of the transition cells
  int cells = 0;
  Stats q_s, q_o, q_p;  ///< Q_S (h = cell_h_ref), Q_O(V), Q_P(V) over the transition cells
};
TransitionQuality transition_quality(const PolyMesh& mesh, const MeshGeometry& geo, const std::vector<double>& h_ref);
/// Adds the figures of disjoint sets of transition cells (other cavities) into `total`.
void add_quality(TransitionQuality& total, const TransitionQuality& q);
/// Q_O(V) over the transition cells of the assembled mesh, as fvcheck and the self-check measure it:
/// each face toward its neighbour's FV centre (a boundary face toward its flux point). Unlike
/// transition_quality on a cavity's own submesh, whose constrained polygons are boundary faces
/// measured to their centroid (the paper's Table 2), this is the orthogonality the fluxes get.
Stats transition_orthogonality_in_mesh(const PolyMesh& mesh, const MeshGeometry& geo);

struct HybridMesh {
  PolyMesh mesh;
  MeshGeometry geometry;
  ReservoirGrid grid;
  std::vector<WellBlock> blocks;
  CavitySet cavities;
  std::vector<Vec3> cavity_node_coords;  ///< coordinates of the builder node ids the cavities use
  std::vector<TransitionReport> transition_reports;  ///< one per cavity
  std::vector<int32_t> cell_cavity;  ///< n_cells: cavity index of transition cells, -1 otherwise
  std::vector<double> cell_h_ref;    ///< n_cells: Q_S reference length (transition: mean constrained edge)
  std::vector<int32_t> reservoir_cell_of;  ///< n_cells: linear reservoir index of reservoir cells, -1 otherwise
  BuildReport build_report;
  /// The transition cells before and after the site optimiser, each cavity's cells measured on
  /// their own (transition_submesh: the cavity polygons are boundary faces).
  TransitionQuality transition_before;
  TransitionQuality transition_after;   ///< after optimisation (when optimized)
  Stats transition_q_o_in_mesh;         ///< transition_orthogonality_in_mesh of the finished mesh
  bool optimized = false;
  SiteOptimizeReport optimize_report;   ///< summed over the cavities (rounds: the largest)
  int transition_builds = 0;         ///< transition meshes built, all cavities and rounds (refused ones too)
  SelfCheck self_check;              ///< the checks of the finished mesh (ok, or the job threw)
  std::vector<std::string> notes;    ///< every automatic change made to the input (sectors, dilation, ...)
  std::vector<std::pair<std::string, double>> timings_s;  ///< stage name -> seconds, in stage order
  /// The permeability frame the mesh was built in (identity: Euclidean). Every position above is
  /// physical; the quality figures, the self-check and the radial data are the scaled frame's.
  PermeabilityFrame frame;
};

/// A failure the input did not cause (exit 1): the stage ("cavity", "transition", "assembly",
/// "optimize", "self-check"), the wells concerned (case indices) and, in what(), the cause and
/// what the user can change.
class MeshingError : public std::runtime_error {
 public:
  MeshingError(std::string stage_name, std::vector<int> wells_concerned, const std::string& what)
      : std::runtime_error(what), stage(std::move(stage_name)), wells(std::move(wells_concerned)) {}
  std::string stage;
  std::vector<int> wells;
};

/// Runs the job in the case's own frame (meshgen moves the case to a local frame first,
/// local_frame.hpp). Throws InputError for bad input, MeshingError for a meshing failure,
/// including a mesh that fails the self-check (self_check.hpp) that ends the job.
/// With `metric: permeability` and anisotropic rock the job meshes scaled_case(cs, frame) and
/// maps the mesh back (permeability_frame.hpp, docs/anisotropy.md).
HybridMesh build_hybrid_mesh(const CaseSpec& cs, const PipelineOptions& opts = {});
/// The job for a true corner-point reservoir (`ReservoirSpec::corner_point`): the model's active cells
/// as the mesh, and with wells a cavity of model cells per well group (docs/corner-point.md; a cavity
/// reaching the model's outer surface is an InputError). build_hybrid_mesh calls it.
HybridMesh build_corner_point_mesh(const CaseSpec& cs, const PipelineOptions& opts = {});
/// The job in the case's own coordinates, orthogonal in the Euclidean sense.
HybridMesh build_hybrid_mesh_euclidean(const CaseSpec& cs, const PipelineOptions& opts = {});

}  // namespace hm
