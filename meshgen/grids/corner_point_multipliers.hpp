// The model's transmissibility multipliers (MULTX..MULTZ-, FAULTS/MULTFLT folded in by OPM's
// TransMult) on the mesh's faces, applied as OPM Flow applies them to a connection
// (docs/corner-point.md, "Transmissibility multipliers").
#pragma once
#include <cstdint>
#include <vector>

#include "corner_point_grid.hpp"
#include "meshgen/case/grdecl.hpp"
#include "meshgen/core/polymesh.hpp"

namespace hm {

/// Whether model cells a and b (natural indices) are of one column and not logical neighbours: a mesh
/// face between them crosses layers of zero thickness (pinched out).
bool across_pinched_layers(const CornerPointModel& model, int64_t a, int64_t b);

/// Whether OPM Flow connects model cells a and b (natural indices, refined or not) across cells its MINPV
/// processing removes (CornerPointModel::minpv_connections, asked with the cells as read).
bool minpv_connects(const CornerPointModel& model, int64_t a, int64_t b);

/// OPM Flow's multiplier of a connection between model cells a and b of one column that are not logical
/// neighbours (across pinched-out layers or cells MINPV removed): MULTZ of the upper cell (MULTZ option
/// TOP; ALL: the smallest MULTZ from it down to the last cell between) x MULTZ- of the lower, x MULTREGT's
/// and EDITNNC's.
double column_connection_multiplier(const CornerPointModel& model, int64_t a, int64_t b);

/// OPM Flow's multiplier of the connection between model cells a and b (natural indices, logical
/// neighbours or across a fault): m_d(a) m_-d(b), d the direction from a to b by their indices
/// (I where their i differ, else J where their j differ, else K). Across pinched-out layers of a
/// column: 0 without PINCH (OPM Flow does not connect them) and for a pair MINPV connects (minpv_connects:
/// the mesh's connection without a face carries it), else MULTZ of the upper cell (MULTZ option TOP; ALL:
/// the smallest MULTZ from it down to the last pinched cell) x MULTZ- of the lower.
/// Times MULTREGT's region multiplier (region_multiplier) and EDITNNC's (edit_nnc_multiplier).
double connection_multiplier(const CornerPointModel& model, int64_t a, int64_t b);

struct FaceMultipliers {
  std::vector<double> face;     ///< per mesh face (PolyMesh::face_trans_mult), empty when the model has none
  int64_t model_faces = 0;      ///< faces between two model cells with a multiplier not 1, pinch faces apart
  int64_t wall_faces = 0;       ///< faces between a model cell and a near-well cell with a multiplier not 1
  int64_t pinch_faces = 0;      ///< faces between two cells of a column across pinched-out layers, with PINCH
  int64_t unpinched_faces = 0;  ///< the same without PINCH: multiplier 0, as OPM Flow does not connect them
  int64_t unmatched_walls = 0;  ///< faces of a model cell toward a near-well cell that are none of its cavity triangles (a bug)
  int64_t edit_nnc_faces = 0;   ///< faces between model cells that an EDITNNC record multiplies
  int64_t edit_nnc_pairs_on_faces = 0;  ///< EDITNNC pairs (of the model as read) found on those faces
  /// Model faces between two cells of a cavity (deactivated) whose multiplier is not 1: the near-well
  /// cells replace both cells and do not carry it. Count and range.
  int64_t inside_cavities = 0;
  double inside_min = 1, inside_max = 1;
};

/// The multiplier of every face of `mesh`, whose reservoir cells are the model's (cell_ijk): between
/// model cells a and b, connection_multiplier(a, b); between model cell a and a near-well cell, on a's
/// face toward cavity cell c (its cavity triangle), connection_multiplier(a, c); 1 elsewhere. Empty
/// when every one would be 1 (no multiplier in the model, no face across pinched-out layers). `cells`
/// and `active` as the mesh was built from (add_corner_point_cells); `cells` may be null for a mesh
/// without near-well cells.
FaceMultipliers face_multipliers(const PolyMesh& mesh, const CornerPointModel& model, const CornerPointCellFaces* cells,
                                 const std::vector<char>& active, const std::vector<Vec3>& coords);

}  // namespace hm
