// The case file's data model (docs/case-format.md). Units: m, mD, bar, cP, kg/m3;
// z is depth, positive down. Everything here is validated by load_case().
#pragma once
#include <array>
#include <stdexcept>
#include <memory>
#include <string>
#include <vector>

#include "meshgen/core/vec3.hpp"

namespace hm {

/// Bad user input: the message names the key path and the reason, e.g.
/// "wells[1].radius: must be > 0". Executables print it and exit with code 2.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct CornerPointModel;
struct CellAttributes;

struct ReservoirSpec {
  std::vector<double> x, y, z;        ///< node coordinates, strictly increasing, >= 2 each
  Vec3 permeability{100, 100, 10};    ///< kx, ky, kz (mD), > 0
  double porosity = 0.2;              ///< in (0, 1]
  double initial_pressure = 200;      ///< bar
  /// Per-cell rock in natural order (size nx*ny*nz), or empty for the uniform values above:
  /// a model read from `reservoir.grdecl` (PERMX/PERMY x NTG, PERMZ in mD; PORO x NTG).
  std::vector<double> cell_permx, cell_permy, cell_permz, cell_poro;
  /// Per cell as above, or empty (every cell 1): the model's pore-volume multiplier (OPM's pore volume
  /// over volume x PORO x NTG: MULTPV, PORV edits), finite and > 0 on active cells.
  std::vector<double> cell_pore_volume_mult;
  std::string grdecl;                 ///< the model file the grid came from, or empty
  /// A true corner-point model (grdecl whose cells are not all axis-aligned boxes): its cells are
  /// the mesh's reservoir cells (meshgen/grids/corner_point_grid.hpp); x/y/z are then only its
  /// bounding box divided into nx, ny, nz. Null for a rectilinear reservoir.
  std::shared_ptr<const CornerPointModel> corner_point;
  /// The model's MAPAXES (grdecl): the map position of grid point (0, 0) and of the grid's unit x
  /// and y directions (z: unused). Well paths in the case file are in map coordinates and are
  /// brought into the grid frame with it (OPM's convention: COORD is in the grid frame).
  bool has_map_axes = false;
  Vec3 map_origin{0, 0, 0}, map_unit_x{1, 0, 0}, map_unit_y{0, 1, 0};
  /// `reservoir.near_well_cell_size` (corner-point models with wells): the size the model's columns
  /// near a well are split to (meshgen/case/corner_point_refine.hpp); 0 = auto (each well's
  /// drainage radius), < 0 = off. After load_case, `corner_point` is the refined model.
  double near_well_cell_size = 0;
  /// `reservoir.near_well_grading` (with the refinement): on, a split column's children grow away
  /// from the well's path (the target size within reach, coarser toward the column's sides); off,
  /// equal widths across the column, all of the finest size it needs.
  bool near_well_grading = true;
  /// `reservoir.upright_pillars` (corner-point models with wells): auto turns the model's pillars
  /// near a well upright where they lean obliquely to the grid (kStraightenWallAngleBelow,
  /// meshgen/case/corner_point_straighten.hpp), on wherever they lean, off keeps them.
  enum class Upright { Off, Auto, On } upright_pillars = Upright::Auto;
  /// `reservoir.near_well_layer_aspect` (metric: permeability): layers near the wells are split so
  /// that their cells there are, in the permeability frame, at most this many times taller than
  /// wide (meshgen/case/near_well_layers.hpp); 0 = off. After load_case, `z` is the split grid's.
  double near_well_layer_aspect = 1.5;
};

/// The grid-frame point of map point p (MAPAXES inverse; the identity without MAPAXES); z unchanged.
Vec3 map_to_grid(const ReservoirSpec& r, Vec3 p);

/// Linear (natural-order) index of the reservoir cell that holds p; points outside the box are
/// taken to the nearest cell; on a grid plane, the cell on its upper side.
int reservoir_cell_at(const ReservoirSpec& r, Vec3 p);
/// Rock of reservoir cell c (uniform or per cell).
Vec3 reservoir_permeability(const ReservoirSpec& r, int c);
double reservoir_porosity(const ReservoirSpec& r, int c);
/// The rock a mesh cell takes from reservoir cell c: permeability, porosity, pore-volume multiplier.
void assign_reservoir_rock(const ReservoirSpec& r, int c, CellAttributes& at);

enum class WellType { Producer, Injector };

/// How the radial block closes at the trajectory's two ends (docs/case-format.md).
enum class EndCaps {
  Flat,        ///< flat end faces through the end points; the transition mesh fills beyond them
  Hemisphere,  ///< a radial half-ball block per end (paper 5.1, "segments of a sphere")
};

struct WellSpec {
  std::string name;
  WellType type = WellType::Producer;
  std::vector<Vec3> trajectory;   ///< polyline, >= 2 distinct consecutive points
  double radius = 0.1;            ///< wellbore radius r_w (m)
  double drainage_radius = 8.0;   ///< outer radius of the radial grid (m), > radius
  int rings = 6;                  ///< radial cells (geometric progression), >= 1
  int sectors = 12;               ///< angular cells, >= 3 (raised when Gabriel needs it)
  double segment_length = 4.0;    ///< target cell length along the trajectory (m), > 0
  double bhp = 150;               ///< bottom-hole pressure (bar)
  EndCaps end_caps = EndCaps::Hemisphere;  ///< closing of the block at both ends (docs/case-format.md)
  /// end_caps: auto (the default): hemispherical caps, but flat ends when the caps cannot be
  /// meshed (build_hybrid_mesh retries with flat ends and says so in its notes).
  bool end_caps_fallback = true;
  /// Measured depth (m) of each trajectory point: the survey's station depths (head at 0), or
  /// empty for a `trajectory` (then the length along the polyline from its first point,
  /// well_measured_depths()).
  std::vector<double> trajectory_md;
  /// Perforated intervals [md_from, md_to] (m), sorted and disjoint; empty: the whole path inside
  /// the reservoir is open. Wellbore faces outside them are closed walls (closed_wellbore_patch).
  std::vector<std::array<double, 2>> perforations;
};

/// Measured depth of each trajectory point (trajectory_md when given, else the length along
/// the polyline from its first point).
std::vector<double> well_measured_depths(const WellSpec& ws);

/// Latitude bands of a hemispherical end cap (the polar one, a fan of triangles about the pole,
/// included): (sectors + 2) / 4 + 1, 4 for 12 sectors, so that the polar triangles are narrow
/// (3 bands left transition faces of OpenFOAM skewness 4.3 beyond the pole of the bent accuracy
/// case, docs/accuracy.md); 2 for 3-5 sectors (1 band left the end-plane faces 13-19 degrees
/// from orthogonal).
inline int hemisphere_cap_bands(int sectors) { return (sectors + 2) / 4 + 1; }

/// The radii of a well's rings, r_w = radii[0] < ... < radii[rings] = drainage radius, in geometric
/// progression (the radial block's, meshgen/grids/well_block.hpp).
std::vector<double> ring_radii(const WellSpec& ws);

/// Distances from a trajectory end of the extra stations of a block with hemispherical caps
/// (empty with flat ends): r_k - r_w, k = 1, 2, ... (r_k = r_w q^k, q the ring ratio), while the
/// layer they close (r_k - r_{k-1} thick) is thinner than a segment, within 3 segments of the
/// end, and at most `rings` of them. Near a well's end the field varies along the axis on the
/// scale of the distance to the end, as it does radially: the cap's cells next to the end
/// cross-section are as small as the rings, and so must be the layers of the cylinder behind it
/// (docs/architecture.md, "End caps").
std::vector<double> hemisphere_end_grading(const WellSpec& ws);

struct TransitionSpec {
  double dilation = 1.5;                       ///< >= 1
  bool optimize = true;
  std::array<double, 3> gamma{0.05, 0.30, 0.40};  ///< 0 < G1 <= G2 <= G3 <= 0.5
  double omega_o = 85;                         ///< degrees, in [80, 90]
  double omega_p = 10;                         ///< degrees, in [0, 10]
  double expansion = 1.1;                      ///< in (1, 1.1]
};

struct FluidSpec {
  double viscosity = 1.0;          ///< cP, > 0
  double density = 1000;           ///< kg/m3, > 0
  double compressibility = 1e-8;   ///< 1/bar, >= 0
};

/// The metric the near-well cells are built orthogonal in (docs/case-format.md, docs/anisotropy.md).
enum class MeshMetric {
  Permeability,  ///< K-orthogonal: meshed in coordinates scaled by K^-1/2 (diagonal K)
  Euclidean,     ///< orthogonal in the Euclidean sense (the mesh before issue 15)
};

struct CaseSpec {
  std::string name;                ///< [A-Za-z0-9_-]+
  MeshMetric metric = MeshMetric::Euclidean;  ///< top-level `metric`
  ReservoirSpec reservoir;
  std::vector<WellSpec> wells;     ///< may be empty (then there is no cavity)
  TransitionSpec transition;
  FluidSpec fluid;
  /// What reading the case changed in it (a well's path clipped to a corner-point model): the
  /// job's notes start with these.
  std::vector<std::string> notes;
};

/// Parses and validates a YAML case file. Throws InputError (never anything else for
/// bad content) with "key.path: reason". A missing or unreadable file is an InputError too.
CaseSpec load_case(const std::string& path);
/// Same, from YAML text; relative file names in it (reservoir.grdecl) are taken from `base_dir`
/// (load_case: the case file's folder; empty: the working directory).
CaseSpec parse_case(const std::string& yaml_text, const std::string& base_dir = "");

}  // namespace hm
