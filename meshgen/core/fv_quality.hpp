// The finite-volume quality kernel of HybridMesh (paper section 6.1): orthogonality Q_O
// (eq. 8-9), planarity Q_P (eq. 10-11), shape Q_S (eq. 7) and their statistics. One
// implementation used by the mesher (transition optimiser, summary), fvcheck and the writers;
// face areas and centroids come from MeshGeometry (geometry.hpp).
#pragma once
#include <cstdint>
#include <vector>

#include "geometry.hpp"
#include "polymesh.hpp"

namespace hm {

/// The boundary point of the two-point flux of every boundary face (docs/fvcheck.md, "Boundary
/// faces"): the point of the face (its fan of triangles around the node mean, as in
/// compute_geometry) nearest to the owner's FV centre, distances measured in the mesh's
/// permeability frame (coordinates divided by metric_scale; Euclidean when it is (1, 1, 1)).
/// It is the foot of the perpendicular from the FV centre when that foot lies in the face, so
/// the pair (FV centre, point) is then exactly normal to a planar face; otherwise a point of the
/// face's edge. Interior faces: their centroid. The solver's Dirichlet value, the boundary
/// half-transmissibility and Q_O of boundary faces all use this point.
std::vector<Vec3> boundary_flux_points(const PolyMesh& mesh, const MeshGeometry& geo);
/// The same point for one face f (its centroid for an interior face), without an array of them all.
Vec3 boundary_flux_point(const PolyMesh& mesh, const MeshGeometry& geo, int f);

/// Which point the boundary faces' two-point segment ends on in face_orthogonality.
enum class BoundaryPoint {
  Flux,      ///< boundary_flux_points: the checked measure (fvcheck, the self-check)
  Centroid,  ///< the face centroid: the paper's literal eq. 8, reported for information only
};

/// Q_O(F) in degrees for every face (eq. 8): arcsin |u . n| with u the unit vector between
/// the FV centres of owner and neighbour (boundary face: owner's FV centre -> its boundary
/// flux point, or the face centroid with BoundaryPoint::Centroid) and n the unit face normal.
/// 0 for a degenerate face or coincident points.
std::vector<double> face_orthogonality(const PolyMesh& mesh, const MeshGeometry& geo,
                                       BoundaryPoint boundary = BoundaryPoint::Flux);
/// Q_O(F) of face f alone, its boundary segment (if a boundary face) ending at boundary_end.
double face_orthogonality_of(const PolyMesh& mesh, const MeshGeometry& geo, int f, Vec3 boundary_end);

/// K-non-orthogonality in degrees for every face (docs/anisotropy.md): the angle between K n and
/// the line d between the FV centres of owner and neighbour (boundary face: owner's FV centre ->
/// its boundary flux point), measured in the metric of K^-1, i.e. the angle between n and d in coordinates
/// scaled by K^-1/2 where the cell's K is isotropic (invariant under that scaling, so it equals
/// the Euclidean non-orthogonality of the mesh in a permeability frame); K the cell's diagonal
/// permeability, the larger of the owner's and the neighbour's angle. 0 iff K n || d; 90 for a
/// degenerate face. With isotropic K it is 90 - Q_O(F).
std::vector<double> face_k_nonorthogonality(const PolyMesh& mesh, const MeshGeometry& geo);

/// The same angle with one K for every cell, the one the mesh was built orthogonal for: K ~ S^2,
/// S = mesh.metric_scale (the permeability frame, docs/anisotropy.md). Equal to
/// face_k_nonorthogonality where the cells' K are that K up to a factor; where the rock's anisotropy
/// varies from cell to cell (a corner-point model's), it is what the construction guarantees and
/// face_k_nonorthogonality is what the fluxes see.
std::vector<double> face_frame_nonorthogonality(const PolyMesh& mesh, const MeshGeometry& geo);

/// A fan triangle of Q_P with at most this fraction of its face's area is not judged: it carries
/// nothing of the face's area vector, and its normal is set by rounding (a micro-edge between
/// near-coincident power vertices; docs/robustness.md, "Micro-edges judged for planarity"). A vertex
/// off the face's plane still tilts its other, larger fan triangles, which are judged.
constexpr double kPlanarityNegligibleArea = 1e-6;

/// Q_P(F) in degrees for every face (eq. 10): the largest angle between the face normal and
/// the normals of the fan triangles (G, A_i, A_{i+1}), G the mean of the face's nodes.
/// Fan triangles of area <= kPlanarityNegligibleArea * face area are skipped; a face of zero
/// area gets 90.
std::vector<double> face_planarity(const PolyMesh& mesh, const MeshGeometry& geo);

/// Q_O(V) = min of Q_O(F) over the cell's faces (eq. 9).
std::vector<double> cell_min_of_faces(const PolyMesh& mesh, const std::vector<double>& face_values);
/// Q_P(V) = max of Q_P(F) over the cell's faces (eq. 11).
std::vector<double> cell_max_of_faces(const PolyMesh& mesh, const std::vector<double>& face_values);

/// Mean length of the distinct edges of each cell.
std::vector<double> cell_mean_edge_length(const PolyMesh& mesh);

/// Q_S(V) = min over the cell's distinct edges of min(l/h, h/l) (eq. 7). h_ref[c] is the
/// reference length of cell c; when h_ref is empty, or h_ref[c] is not a positive finite
/// number, the cell's mean edge length is used. A zero-length edge gives 0.
std::vector<double> cell_shape_quality(const PolyMesh& mesh, const std::vector<double>& h_ref);

struct Stats {
  int64_t count = 0;
  double min = 0, max = 0, mean = 0;  ///< 0 when count == 0
};
/// Statistics of the values whose mask entry is true (all values when mask is empty).
Stats stats_of(const std::vector<double>& values, const std::vector<bool>& mask = {});

/// OpenFOAM's cell centres as checkMesh computes them (primitiveMesh cell centres: the
/// volume-weighted centroids of the pyramids from the mean of the face centres), per cell. Not the
/// FV centres (cell_fv_center): OpenFOAM's fluxes and checks use these.
std::vector<Vec3> openfoam_cell_centres(const PolyMesh& mesh);

/// OpenFOAM's face skewness (checkMesh flags faces above 4), per face: cell centres are
/// geometric centroids and face centres area-weighted, computed as OpenFOAM does
/// (primitiveMeshTools::faceSkewness), so that it reproduces checkMesh's figures.
std::vector<double> openfoam_face_skewness(const PolyMesh& mesh);
/// The same with the cell centres given (openfoam_cell_centres of the mesh).
std::vector<double> openfoam_face_skewness(const PolyMesh& mesh, const std::vector<Vec3>& centres);

/// checkMesh's face orthogonality (polyMeshTools::faceOrthogonality) per face: the cosine of the
/// angle between the face's area vector and the line from the owner's to the neighbour's OpenFOAM
/// centre (openfoam_cell_centres); 1 on a boundary face (checkMesh's summary leaves them out). Its
/// non-orthogonality is the arccosine. Unlike Q_O it measures from centroids, not from FV centres.
std::vector<double> openfoam_face_nonorthogonality_cosine(const PolyMesh& mesh, const std::vector<Vec3>& centres);

/// checkMesh's limit: a face above it is "highly skew" and checkMesh ends with "Failed 1 mesh checks".
inline constexpr double kCheckMeshSkewnessLimit = 4.0;
/// Skewness above which the optimiser counts a face as skewed: checkMesh's limit, less a margin for
/// the precision of the written points.
inline constexpr double kOpenFoamSkewnessLimit = kCheckMeshSkewnessLimit - 0.05;

/// What checkMesh would say of a mesh's face skewness (openfoam_face_skewness, every face).
struct SkewnessSummary {
  double max = 0;           ///< the largest value (0 for a mesh without faces)
  int32_t worst_face = -1;  ///< the face that has it
  int64_t above_limit = 0;  ///< faces above kCheckMeshSkewnessLimit: checkMesh's "highly skew faces"
};
SkewnessSummary summarize_skewness(const std::vector<double>& face_skewness);

/// checkMesh's threshold for "severely non-orthogonal" faces (degrees; a warning, not a failure).
inline constexpr double kCheckMeshSevereNonOrthogonality = 70.0;
/// OpenFOAM's SMALL: checkMesh counts a face whose cosine is at most this as a non-orthogonality
/// error (the line between the centres at 90 degrees or more from the face normal) and fails.
inline constexpr double kCheckMeshSmall = 1e-15;

/// What checkMesh would say of a mesh's non-orthogonality (openfoam_face_nonorthogonality_cosine
/// of its interior faces): "Mesh non-orthogonality Max: <max> average: <average>", its severe
/// faces and errors.
struct NonOrthogonalitySummary {
  double max = 0;           ///< degrees: the arccosine of the smallest cosine
  double average = 0;       ///< degrees: the arccosine of the mean cosine, as checkMesh has it
  int32_t worst_face = -1;  ///< the face with the largest angle
  int64_t severe = 0;       ///< faces above kCheckMeshSevereNonOrthogonality with a cosine above kCheckMeshSmall
  int64_t errors = 0;       ///< faces with a cosine at most kCheckMeshSmall: checkMesh fails
};
NonOrthogonalitySummary summarize_nonorthogonality(const PolyMesh& mesh, const std::vector<double>& cosine);

/// checkMesh's skewness and non-orthogonality of a mesh, its OpenFOAM centres computed once.
struct CheckMeshFigures {
  SkewnessSummary skewness;
  NonOrthogonalitySummary nonorthogonality;
};
CheckMeshFigures checkmesh_figures(const PolyMesh& mesh);

}  // namespace hm
