// The near-well accuracy study (issue #7, docs/accuracy.md): a manufactured exact solution (the
// potential of a uniform line source on the well trajectory) is imposed on the outer boundary
// and on the wellbore; the TPFA solution on (a) the hybrid mesh and (b) the same reservoir grid
// with a Peaceman well is compared with it.
#pragma once
#include <string>
#include <vector>

#include "exporters/vtu/vtu_writer.hpp"
#include "line_source.hpp"
#include "meshgen/case/case.hpp"
#include "meshgen/core/geometry.hpp"
#include "tpfa.hpp"

namespace hm {

struct AccuracyOptions {
  /// false (default): the source is the trajectory shortened by r_w at both ends, strictly inside
  /// the wellbore, so the exact p is smooth on the whole flow domain. true: the source runs to the
  /// trajectory's end points, which lie on the end caps: p is singular (log) at the cap centres.
  bool source_to_tips = false;
  /// Also build the hybrid mesh with the other metric: `hybrid` is then the K-orthogonal mesh
  /// (metric: permeability) and `hybrid_euclidean` today's Euclidean-orthogonal one, whatever
  /// the case's `metric` key (solver_demo --accuracy --compare-metrics).
  bool compare_metrics = false;
};

/// Everything the error measures need, derived from a one-well case with a uniform diagonal k.
struct AccuracySetup {
  LineSourceField field;
  FieldReference reference;   ///< longest leg's midpoint and perpendicular (where p_w and the drawdown are taken)
  double p_w = 0;             ///< exact p on the (equivalent) wellbore at the reference point (= case bhp)
  double drawdown = 0;        ///< |p_exact(reference point at near_radius) - p_w| (= |initial_pressure - bhp|)
  double near_radius = 0;     ///< 3 x drainage radius: the near-well region
  double viscosity = 1;       ///< cP
  double permeability = 0;    ///< mD: k0 = cbrt(kx ky kz), the isotropic k of the scaled frame
  Vec3 permeability_tensor;   ///< mD: the case's (kx, ky, kz)
  double equivalent_radius = 0;  ///< m, scaled frame: the wellbore's equivalent radius at the reference point (r_w if isotropic)
  double exact_rate = 0;      ///< rm3/day, q' x scaled source length (> 0 produced)
  double slab_half_width = 0; ///< plot: cells projecting within this of the reference midpoint
  /// removed from each end of the trajectory to get the source, in the mesh's wellbore frame
  /// (the permeability frame's scaled metres for a K-orthogonal mesh; physical metres otherwise)
  double source_inset = 0;
};

/// Throws InputError when the study does not apply: not exactly one well, per-cell permeability.
AccuracySetup make_accuracy_setup(const CaseSpec& cs, const AccuracyOptions& options = {});

/// The case with its permeability made anisotropic, keeping kh = sqrt(kx ky): kx = kh sqrt(kx_ky),
/// ky = kh / sqrt(kx_ky), kz = kv_kh kh (solver_demo --accuracy --kv-kh R --kx-ky Q). The name
/// gets a suffix `_kvkh<R>_kxky<Q>` when either ratio is not 1. InputError unless both are > 0.
CaseSpec anisotropic_case(const CaseSpec& cs, double kv_kh, double kx_ky);

struct AccuracyErrors {
  double rate_rel_error = 0;                ///< (q - q_exact) / q_exact, signed
  double near_well_pressure_rel_error = 0;  ///< max |p - p_exact| over near-well cells / drawdown
  double l2_pressure_rel_error = 0;         ///< volume-weighted RMS of p - p_exact over near-well cells / drawdown
  double rate = 0, exact_rate = 0;          ///< rm3/day
  int cells = 0, near_well_cells = 0;
  // Diagnostics (the same maximum split by where the cell is; they do not replace the measure):
  double near_well_max_by_region[3] = {0, 0, 0};  ///< over reservoir, transition, well cells
  double near_well_max_lateral = 0;     ///< cells whose closest trajectory point is not an end point
  double near_well_max_beyond_ends = 0; ///< cells whose closest trajectory point is an end point
  int worst_cell = -1;                      ///< where the near-well maximum is reached
  int worst_region = -1;                    ///< its region code
  Vec3 worst_point;                         ///< its FV centre
  double worst_distance = 0;                ///< its distance to the trajectory
  int iterations = 0;
  double relative_residual = 0;
};

/// One cell's pressure against the exact one (plots).
struct PressureSample {
  double distance = 0;  ///< FV centre to the trajectory (m)
  double scaled_distance = 0;  ///< the same in the scaled frame x / s (= distance when isotropic)
  double pressure = 0, exact = 0;
  int region = 0;
  bool in_slab = false;  ///< projects onto the reference leg within slab_half_width of its midpoint
  int32_t cell = -1;
  Vec3 x;                ///< FV centre
  /// Along the source polyline from its nearer end to the closest point (m); 0 beyond the ends.
  double to_end = 0;
  /// Net outflow of the cell with the exact p in every cell (mass_balance_residual), relative to
  /// the exact rate: the local consistency error the cell feeds into the solution.
  double residual = 0;
};

/// Solves the exact-solution problem on a mesh (Dirichlet outer faces, exact p on wellbore faces
/// and on `connections`) and measures the errors. Cells holding a connection are excluded from
/// the pressure errors (Peaceman's cell pressure is not a point value of p). `pressure` (optional)
/// receives the solution, `samples` (optional) one entry per near-well cell.
AccuracyErrors measure_accuracy(const PolyMesh& mesh, const MeshGeometry& geo,
                                const std::vector<WellConnection>& connections, const AccuracySetup& setup,
                                std::vector<double>* pressure = nullptr,
                                std::vector<PressureSample>* samples = nullptr);

/// The case refined by an integer factor: every reservoir interval split into `factor` equal
/// parts, rings and sectors multiplied by it, segment_length divided by it.
CaseSpec refine_case(const CaseSpec& cs, int factor);

struct RefinementLevel {
  int factor = 1;
  int hybrid_cells = 0, cartesian_cells = 0;
  AccuracyErrors hybrid, peaceman;
  bool has_euclidean = false;  ///< compare_metrics: the Euclidean-orthogonal hybrid mesh too
  int hybrid_euclidean_cells = 0;
  AccuracyErrors hybrid_euclidean;
};

struct AccuracyStudy {
  std::string case_name;
  MeshMetric metric = MeshMetric::Euclidean;  ///< the metric of `hybrid`'s mesh
  AccuracySetup setup;                        ///< of `hybrid` and the Peaceman model
  AccuracySetup setup_euclidean;              ///< of `hybrid_euclidean` (compare_metrics)
  AccuracyErrors hybrid, peaceman;
  std::vector<PressureSample> hybrid_samples, peaceman_samples;
  std::vector<RefinementLevel> refinement;  ///< factors 1..levels (factor 1 = the case itself)
  std::vector<std::string> notes;           ///< the mesher's automatic changes
};

/// Builds the hybrid mesh of the case (and of its refinements) and the Cartesian + Peaceman
/// model, solves both, measures. levels >= 1. Throws InputError / std::runtime_error.
AccuracyStudy run_accuracy_study(const CaseSpec& cs, int levels, const AccuracyOptions& options = {});

/// accuracy.json (docs/accuracy.md has the schema).
WriteStatus write_accuracy_json(const std::string& path, const AccuracyStudy& study);
/// The plot: pressure vs distance (exact curve, hybrid and Peaceman points in the reference
/// slab) and the error / drawdown of every near-well cell vs distance.
WriteStatus write_accuracy_svg(const std::string& path, const AccuracyStudy& study);
/// cells.csv: one row per near-well cell of the level-1 hybrid mesh (cell, region, FV centre,
/// distances to the trajectory and along it to its nearer end, pressure, exact, error / drawdown,
/// exact-pressure residual / exact rate).
WriteStatus write_accuracy_cells_csv(const std::string& path, const AccuracyStudy& study);

}  // namespace hm
