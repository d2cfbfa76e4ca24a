// The whole meshing job: case -> reservoir grid + well blocks -> cavities ->
// transition meshes -> one conforming PolyMesh, with a report of every stage.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "meshgen/case/case.hpp"
#include "meshgen/cavity/cavity.hpp"
#include "meshgen/core/geometry.hpp"
#include "meshgen/core/mesh_builder.hpp"
#include "meshgen/grids/reservoir_grid.hpp"
#include "meshgen/grids/well_block.hpp"
#include "meshgen/transition/transition.hpp"

namespace hm {

struct PipelineOptions {
  bool build_transition = true;  ///< false: stop after the cavities (the mesh then has open cavity faces)
  bool optimize = true;          ///< run the small-edge optimisation when the case asks for it
};

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
  std::vector<std::string> notes;    ///< every automatic change made to the input (sectors, dilation, ...)
  std::vector<std::pair<std::string, double>> timings_s;  ///< stage name -> seconds, in stage order
};

/// Runs the job. Throws InputError for bad input, std::runtime_error for a meshing failure
/// (with a message saying which stage and why).
HybridMesh build_hybrid_mesh(const CaseSpec& cs, const PipelineOptions& opts = {});

}  // namespace hm
