// Two-point flux (TPFA) transmissibilities of a PolyMesh, with the exact logarithmic form on the
// ring faces of radial well cells. Formulas, units and measured figures: docs/transmissibility.md.
// Depends on meshgen/core only (no CGAL, no Eigen).
#pragma once
#include <cstdint>
#include <utility>
#include <vector>

#include "meshgen/core/geometry.hpp"
#include "meshgen/core/polymesh.hpp"

namespace hm {

/// Eclipse METRIC Darcy constant CDARCY: k [mD] * length [m] -> transmissibility [cP.rm3/day/bar]
/// (1 mD = 9.869233e-16 m2, 1 cP = 1e-3 Pa.s, 1 day = 86400 s, 1 bar = 1e5 Pa; E300 value).
constexpr double kDarcyMetric = 0.00852702;

struct TransmissibilityOptions {
  /// true: T in cP.rm3/day/bar (METRIC, = CDARCY * mD.m); false: T in mD.m (no Darcy constant).
  bool metric_units = true;
  /// true: the exact logarithmic form on ring faces of radial well cells; false: the generic
  /// two-point form everywhere (only useful to measure what the log form buys).
  bool exact_radial = true;
  /// true: a half-transmissibility on the side of a reservoir cell (a corner-point model's cell: the
  /// user's cell, exempt from the shape checks) that comes out negative is taken as its absolute
  /// value, OPM's convention (K |A . d| / |d|^2) for the model's cells. Radial and transition cells
  /// keep their sign. The halves are counted in `negative` either way. Used for the Eclipse deck and
  /// by solver_demo (deck_transmissibility_options), never by the checker.
  bool reservoir_halves_absolute = false;
};

/// The options of the transmissibilities an Eclipse deck carries and solver_demo solves with
/// (docs/export-eclipse.md, "A corner-point model"): METRIC, exact radial form, reservoir cells'
/// negative halves taken as their absolute value. On a mesh whose reservoir cells are boxes (a
/// rectilinear reservoir) they equal the defaults: a box's halves are never negative.
TransmissibilityOptions deck_transmissibility_options();

struct Transmissibilities {
  /// n_faces: half-transmissibility from the owner's FV centre to the face.
  std::vector<double> half_owner;
  /// n_faces: the same from the neighbour's side; 0 on boundary faces.
  std::vector<double> half_neighbour;
  /// n_faces: interior faces: harmonic combination of the two halves; wellbore faces: the
  /// connection factor (= half_owner, q = CF/mu (p_cell - p_w)); other boundary faces: 0.
  std::vector<double> face;
  /// Number of half-transmissibilities that are negative or not finite (FV centre beyond or on
  /// the face plane). They are kept as computed, never replaced by their absolute value, except
  /// on reservoir cells with TransmissibilityOptions::reservoir_halves_absolute (still counted).
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
