// Two-point flux (TPFA) transmissibilities of a PolyMesh, with the exact logarithmic form on the
// ring faces of radial well cells. Formulas, units and measured figures: docs/transmissibility.md.
// Depends on meshgen/core only (no CGAL, no Eigen).
#pragma once
#include <cstdint>
#include <utility>
#include <vector>

#include "meshgen/core/geometry.hpp"
#include "meshgen/core/polymesh.hpp"
#include "meshgen/core/two_point.hpp"  // kDarcyMetric

namespace hm {

struct TransmissibilityOptions {
  /// true: T in cP.rm3/day/bar (METRIC, = CDARCY * mD.m); false: T in mD.m (no Darcy constant).
  bool metric_units = true;
  /// true: the exact logarithmic form on ring faces of radial well cells; false: the generic
  /// two-point form everywhere (only useful to measure what the log form buys).
  bool exact_radial = true;
  /// true: the halves on the side of a reservoir cell (a corner-point model's cell: the user's cell,
  /// exempt from the shape checks) are OPM's corner-point ones (EclTransmissibility on a CpGrid): per
  /// pair of model cells, the pair's summed area vector A and on each side K_dd |A . c| / |c|^2, d the
  /// pair's axis, c from the FV centre (the mean of the 8 corners) to the mean of the 4 corners of that
  /// cell's whole face; the pair's value shared among its mesh faces by area. A cavity triangle's model
  /// side: K_dd |A . c| / |c|^2 with its centroid and its normal's largest axis. Never negative. Radial
  /// and transition cells keep the library's forms. Used for the Eclipse deck and by solver_demo
  /// (deck_transmissibility_options), never by the checker (docs/transmissibility.md).
  bool reservoir_halves_opm = false;
};

/// The options of the transmissibilities an Eclipse deck carries and solver_demo solves with
/// (docs/export-eclipse.md, "A corner-point model"): METRIC, exact radial form, reservoir cells' halves
/// in OPM's corner-point form. On an axis-aligned box (a rectilinear reservoir's cell, FV centre at its
/// centre) OPM's form is the library's: the same numbers up to rounding.
TransmissibilityOptions deck_transmissibility_options();

struct Transmissibilities {
  /// n_faces: half-transmissibility from the owner's FV centre to the face.
  std::vector<double> half_owner;
  /// n_faces: the same from the neighbour's side; 0 on boundary faces.
  std::vector<double> half_neighbour;
  /// n_faces: interior faces: harmonic combination of the two halves; wellbore faces: the
  /// connection factor (= half_owner, q = CF/mu (p_cell - p_w)); other boundary faces: 0. Times
  /// PolyMesh::face_trans_mult (a corner-point model's multipliers) where the mesh has them.
  std::vector<double> face;
  /// n_nncs: the transmissibilities of the mesh's connections without a face (PolyMesh::nnc_trans,
  /// in the units of `face`).
  std::vector<double> nnc;
  /// Number of half-transmissibilities that are negative or not finite (FV centre beyond or on
  /// the face plane). They are kept as computed, never replaced by their absolute value
  /// (TransmissibilityOptions::reservoir_halves_opm computes another form, which is never negative).
  int negative = 0;
  /// The first faces (at most kMaxListedNegative, each once) carrying such a half-transmissibility.
  std::vector<int32_t> negative_faces;
};

constexpr int kMaxListedNegative = 20;

/// The mesh in its permeability frame x' = S^-1 x (S = diag(mesh.metric_scale)), with
/// K' = det(S) S^-1 K S^-1 per cell and metric_scale (1, 1, 1): the fluxes of both are the same
/// (docs/anisotropy.md). A copy of the mesh when it is Euclidean.
PolyMesh in_metric_frame(const PolyMesh& mesh);

/// Half-transmissibilities, face transmissibilities and wellbore connection factors of every face,
/// computed in the mesh's permeability frame (in_metric_frame; `geo` is then not used).
Transmissibilities compute_transmissibilities(const PolyMesh& mesh, const MeshGeometry& geo,
                                              const TransmissibilityOptions& options = {});

/// Connection factors per well: well w's list of (cell, CF), CF summed over the cell's faces on
/// wellbore_patch(w), sorted by cell. Faces of wells >= n_wells are ignored.
std::vector<std::vector<std::pair<int32_t, double>>> well_connection_factors(const PolyMesh& mesh,
                                                                             const Transmissibilities& trans,
                                                                             int n_wells);

/// Permeability seen by radial flow around an axis (unit vector) in a medium with diagonal
/// K = (kx, ky, kz): sqrt(det of K restricted to the plane normal to the axis)
/// = sqrt(ky kz ax^2 + kx kz ay^2 + kx ky az^2); sqrt(kx ky) for a vertical axis.
double transverse_permeability(Vec3 perm, Vec3 unit_axis);

}  // namespace hm
