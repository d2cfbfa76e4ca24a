// Reservoir models from Eclipse/OPM decks (GRDECL: SPECGRID/COORD/ZCORN/ACTNUM, PERMX/PERMY/PERMZ,
// PORO, NTG, MAPAXES), read with OPM's own parser and grid (libopm-common), so that every keyword
// (INCLUDE, MULTIPLY, BOX, EQUALS, PINCH, MULTREGT, ...) means what it means in OPM Flow; MINPV is
// counted, not applied (docs/corner-point.md, "MINPV").
#pragma once
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "meshgen/core/vec3.hpp"

namespace hm {

struct ReservoirSpec;

/// OPM's region multipliers (MULTREGT) of a model, opaque here (grdecl.cpp holds OPM's TransMult).
struct RegionMultipliers;

/// A corner-point model as OPM reads it. Arrays are per cell in natural order
/// (i fastest, then j, then k; size nx*ny*nz), rock in mD and fractions.
struct CornerPointModel {
  int nx = 0, ny = 0, nz = 0;
  std::vector<int> actnum;                     ///< 1 active, 0 inactive (EclipseGrid: ACTNUM, cells of no volume; not MINPV)
  std::vector<double> permx, permy, permz;     ///< mD
  std::vector<double> poro, ntg;               ///< NTG is 1 where the deck has none
  /// The deck's geometry as OPM holds it (EclipseGrid::getCOORD/getZCORN): 6 numbers per pillar
  /// (top x y z, bottom x y z; pillar (i, j) at i + (nx+1) j) and 8 depths per cell (Eclipse order,
  /// `zcorn_index`). The mesh's model cells and the exported deck's COORD/ZCORN come from these, and
  /// so do the cells' corners (`corner`, `cell_corners`: computed, not stored; getCornerPos's bit for bit).
  std::vector<double> coord, zcorn;
  std::vector<double> opm_volume;              ///< EclipseGrid::getCellVolume per cell (m3), for comparisons; empty for a refined model
  /// OPM's transmissibility multipliers per cell and face direction (TransMult::getMultiplier: MULTX,
  /// MULTX-, ..., MULTZ with FAULTS/MULTFLT folded in), in the order +x, -x, +y, -y, +z, -z.
  std::array<std::vector<double>, 6> trans_mult;
  /// A model refined near wells (corner_point_refine.hpp): the cell of the model as read that each
  /// cell lies in (natural order of that model). Empty for a model as read.
  std::vector<int32_t> parent_cell;
  int parent_nx = 0, parent_ny = 0;  ///< refined model: nx, ny of the model as read
  /// A model whose layers are split at fault steps (corner_point_fault_steps.hpp): the layer of the
  /// model as read that each layer lies in, and that model's nz. Empty and 0 when no layer is split.
  std::vector<int> parent_layer;
  int parent_nz = 0;
  /// PINCH as OPM read it (EclipseGrid::isPinchActive and the keyword's items). OPM Flow connects two
  /// cells of a column that touch across layers of zero thickness only with PINCH (opm-grid's
  /// process_grdecl); the other items are kept to write the keyword back (docs/corner-point.md,
  /// "Pinched-out layers").
  struct Pinch {
    bool active = false;
    double threshold = 0.001;     ///< THRESHOLD_THICKNESS (m)
    bool nogap = false;           ///< CONTROL_OPTION NOGAP (else GAP)
    double max_empty_gap = 1e20;  ///< MAX_EMPTY_GAP (m)
    bool pinchout_all = false;    ///< PINCHOUT_OPTION ALL (else TOPBOT)
    bool multz_all = false;       ///< MULTZ_OPTION ALL: the smallest MULTZ down the pinched column (else TOP)
  } pinch;
  /// MINPV (MINPV, MINPORV, MINPVV): active cells whose pore volume (OPM's, PORV with NTG and MULTPV) is
  /// below it, which OPM Flow removes (opm-grid's MinpvProcessor) and connects across: they are inactive
  /// here too (actnum 0; docs/corner-point.md, "MINPV"). Their count and pore volume, and the active total
  /// before their removal.
  int64_t below_minpv = 0;
  double below_minpv_pore_volume = 0, active_pore_volume = 0;
  /// The cells of a column OPM Flow connects across removed cells (upper, lower; natural indices of the
  /// model as read): the mesh connects them through the cells' own faces as flow does (a connection
  /// without a face where a gap is left between them).
  std::vector<std::pair<int64_t, int64_t>> minpv_connections;
  /// The cells MINPV removed (natural indices of the model as read), in order; a case keeps those near
  /// its wells (keep_minpv_cells_near_wells in case.cpp: the near-well cells replace them).
  std::vector<int64_t> minpv_removed;
  /// Active cells whose OPM pore volume is not volume x PORO x NTG (MULTPV, PORV edits), which the mesh's
  /// porosity is: their count and OPM's pore volume of them against that product (docs/corner-point.md).
  int64_t other_pore_volume = 0;
  double other_pore_volume_opm = 0, other_pore_volume_ours = 0;
  /// Per cell: OPM's pore volume over volume x PORO x NTG on those cells, exactly 1 elsewhere (inactive
  /// cells included); empty when every cell's is 1. The mesh carries it (PolyMesh::cell_pore_volume_mult).
  std::vector<double> pore_volume_mult;
  /// NNC of the deck as OPM reads it (EclipseState::getInputNNC().input(): an EDITNNC of the same pair
  /// folded in): connections between two cells that need not share a face, by natural indices of the
  /// model as read (a < b), transmissibility in cP.rm3/day/bar (METRIC). The mesh carries them
  /// (PolyMesh::nnc_cells; docs/corner-point.md, "NNC and EDITNNC").
  struct Nnc {
    int64_t a = 0, b = 0;
    double trans = 0;
  };
  std::vector<Nnc> nnc;
  /// EDITNNC records OPM keeps for flow's own connections (NNC::edit()).
  int64_t deck_editnnc = 0;
  /// EDITNNC as OPM keeps it for flow's own connections (NNC::edit(): pairs that are not logical
  /// neighbours and not a deck NNC, e.g. across a fault), by pair of natural indices of the model as
  /// read (smaller first): the product of its records' multipliers. The mesh carries it on the faces
  /// between the pair's cells (edit_nnc_multiplier, connection_multiplier).
  std::map<std::pair<int64_t, int64_t>, double> edit_nnc;
  /// MULTREGT: OPM's own region multipliers (TransMult::getRegionMultiplier, in the model as read: a
  /// refined model asks with its cells' parents), null without the keyword; its records and the region
  /// arrays they name (MULTNUM, FLUXNUM, OPERNUM; per cell of the model as read) as the deck gives them,
  /// to write them back (docs/corner-point.md, "Region multipliers").
  std::shared_ptr<const RegionMultipliers> region_mult;
  std::vector<std::string> multregt_records;              ///< each record's items, defaults as `1*`
  std::map<std::string, std::vector<int>> region_arrays;  ///< by keyword
  bool has_mapaxes = false;
  /// MAPAXES as OPM applies it: the map (world) position of grid point (0, 0) and of the
  /// unit grid x and y directions (origin, unit_x, unit_y), for has_mapaxes.
  std::array<double, 2> map_origin{0, 0}, map_unit_x{1, 0}, map_unit_y{0, 1};
  int n_active() const;
  size_t n_cells() const { return size_t(nx) * size_t(ny) * size_t(nz); }
};

/// Reads a deck or a GRDECL file (INCLUDEs followed, relative to its folder). Throws InputError
/// naming `key` when the file is missing, OPM refuses it, or it has no grid or no PERMX/PORO.
CornerPointModel read_corner_point_model(const std::string& path, const std::string& key);

/// The reservoir of a corner-point model whose geometry is a rectilinear grid (vertical pillars
/// on lines x = x_i, y = y_j, horizontal layers z = z_k, every cell active): axes and per-cell
/// rock (porosity x NTG). Decided by exact equality of the corner coordinates, no tolerance. Throws
/// InputError naming `key` and the first cell that is not (corner-point geometry is not meshed yet).
ReservoirSpec rectilinear_reservoir(const CornerPointModel& model, const std::string& key);

/// OPM Flow's MULTREGT multiplier of the connection between model cells a and b (natural indices of
/// `model`, refined or not): TransMult::getRegionMultiplier of their cells in the model as read, in the
/// direction of the axis along which those differ (I, else J, else K); 1 without MULTREGT or within
/// one cell of the model as read.
double region_multiplier(const CornerPointModel& model, int64_t a, int64_t b);

/// Sizes the per-cell arrays of `r` (r.nx x r.ny x r.nz cells), a model derived from `m` (refined,
/// split): ZCORN, ACTNUM, parent_cell, rock, and the pore-volume and transmissibility
/// multipliers that `m` has.
void resize_cell_arrays(CornerPointModel& r, const CornerPointModel& m);

/// Cell c of derived model r lies in cell s of m: it takes its ACTNUM, rock and pore-volume multiplier,
/// and its cell as read (parent_cell). Not its geometry or transmissibility multipliers.
void inherit_cell(CornerPointModel& r, size_t c, const CornerPointModel& m, size_t s);

/// The cell of the model as read that cell c of `model` (refined or not) lies in.
inline int64_t cell_as_read(const CornerPointModel& model, int64_t c) {
  return model.parent_cell.empty() ? c : model.parent_cell[static_cast<size_t>(c)];
}

/// EDITNNC's multiplier of the connection between model cells a and b (natural indices of `model`,
/// refined or not: a refined model asks with its cells' parents); 1 for a pair it does not name.
double edit_nnc_multiplier(const CornerPointModel& model, int64_t a, int64_t b);

/// Whether any of the model's transmissibility multipliers (trans_mult) is not 1, or it has MULTREGT or
/// EDITNNC (edit_nnc).
bool has_transmissibility_multipliers(const CornerPointModel& model);

/// Whether every cell is an axis-aligned box on common axes and active (exact equality, no tolerance):
/// such a model is meshed as the rectilinear grid of `rectilinear_reservoir`.
bool is_rectilinear(const CornerPointModel& model);

/// Index in ZCORN of corner q (bit 0 = +i, bit 1 = +j, bit 2 = +k) of cell (i, j, k).
size_t zcorn_index(const CornerPointModel& m, int i, int j, int k, int q);
/// Depth of corner q of cell c (natural index).
double corner_depth(const CornerPointModel& m, int c, int q);
/// The point of pillar p (i + (nx+1) j) at depth z (linear along the pillar; a pillar whose two
/// COORD points have the same depth is vertical through its top point), as OPM places corners:
/// OPM's getCellCorners arithmetic, so that a corner computed here equals getCornerPos bit for bit.
Vec3 pillar_point(const CornerPointModel& m, int p, double z);
/// Corner q (bit 0 = +i, bit 1 = +j, bit 2 = +k; OPM's and Eclipse's order) of cell `cell` (natural
/// index): the point of its pillar at its ZCORN depth (pillar_point), in the grid's input frame (z
/// depth, positive down). For a model as read, EclipseGrid::getCornerPos bit for bit.
Vec3 corner(const CornerPointModel& m, size_t cell, int q);
/// The 8 corners of a cell, indexed as `corner`'s q.
std::array<Vec3, 8> cell_corners(const CornerPointModel& m, size_t cell);

/// Depths on one pillar within this many units in the last place of each other are one depth written
/// with a rounding: a fault whose throw is a whole number of layers, or passes through zero.
constexpr double kSameDepthUlps = 8;

/// Makes the depths of the corners on each pillar that lie within kSameDepthUlps of the smallest of
/// their run one depth (that smallest; the corners moved along the pillar with it), so that the mesh
/// has one node there and not a fault of 1e-13 m whose faces overlap by slivers. Returns the number
/// of corner depths changed.
int64_t merge_rounded_depths(CornerPointModel& model);

/// Geometry a model must have to be meshed as a corner-point reservoir: in every active cell the
/// top corner is not below the bottom corner on any of its 4 pillars, and an active cell does not
/// reach into the next active cell below it in its column (bottom depth <= that cell's top depth on
/// each pillar). Exact comparisons of the ZCORN values. Throws InputError naming `key` and the cell.
void check_corner_point_geometry(const CornerPointModel& model, const std::string& key);

/// The reservoir of a true corner-point model (meshgen/grids/corner_point_grid.hpp meshes its cells):
/// per-cell rock as `rectilinear_reservoir`, `corner_point` = the model, and x/y/z = the model's
/// bounding box divided uniformly into nx, ny, nz (index arithmetic and the box limits only; the
/// geometry is the model's).
ReservoirSpec corner_point_reservoir(std::shared_ptr<const CornerPointModel> model, const std::string& key);

/// The model moved by `shift` (COORD x, y, z; ZCORN z): the local frame of meshgen.
CornerPointModel translated_model(const CornerPointModel& m, Vec3 shift);

}  // namespace hm
