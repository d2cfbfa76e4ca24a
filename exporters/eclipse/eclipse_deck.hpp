// Eclipse/OPM Flow export of a hybrid mesh (docs/export-eclipse.md).
//
// Deck layout ("layout 2" of shared/reference/opm-flow-deck.md): the structured reservoir keeps
// its (i,j,k) in columns 1..NX of a corner-point grid; reservoir cells replaced by the cavity are
// inactive; column NX+1 is an inactive separator; every other cell (well and transition cells)
// is a thin box at its true FV-centre depth in the extra columns NX+2..NX+1+MX (every other I and
// every other J, so that boxes of different columns never touch). Flow then uses
// OUR numbers: TRANX/Y/Z (EDIT) for logical reservoir neighbours, NNC for every other connection,
// PORV (EDIT) = volume * porosity, COMPDAT CF = wellbore connection factors, depths = FV centres.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "exporters/vtu/vtu_writer.hpp"  // WriteStatus (shared by the exporters)
#include "fvcheck/lib/transmissibility.hpp"
#include "meshgen/case/case.hpp"
#include "meshgen/core/geometry.hpp"
#include "meshgen/core/polymesh.hpp"

namespace hm {

/// How the deck's SCHEDULE reaches the steady state (docs/export-eclipse.md, "Running as typed").
enum class EclipseSchedule {
  /// For `flow NAME.DATA` with no options (the default): `WTEST` re-opens every well flow shut
  /// because it could not flow at its BHP, then `TSTEP first (end - first)`:
  /// flow's own time stepping (x3 per step, at most 365 days) carries the transient to its
  /// steady state. end = end_days, or automatically max(1, kAsTypedRelaxationTimes x eclipse_relaxation_time_days).
  AsTyped,
  /// kSteadyReportSteps long report steps (tstep_days in all), for `flow` with
  /// flow_steady_state_options() (optional): a steady-state solve.
  Steady,
};

constexpr double kOneSecondInDays = 1.0 / 86400;
/// Steady: the number of equal report steps. One backward-Euler step leaves the accumulation
/// PV (b(p) - b(p_init)) / dt in the balance (on Reek a net production of 1e-6 of the rates); the
/// second starts at that state and leaves a term smaller by the step's damping, below flow's
/// float32 output (docs/export-eclipse.md, "Compressible water").
constexpr int kSteadyReportSteps = 2;
/// AsTyped runs this many estimated relaxation times. The estimate is a lower bound of the
/// slowest mode: on three_wells 40 of them ended 1.7e-6 (relative) short of the steady state
/// that 500 days give, 100 of them 1.2e-7 (docs/export-eclipse.md).
constexpr double kAsTypedRelaxationTimes = 100;

struct EclipseDeckOptions {
  EclipseSchedule schedule = EclipseSchedule::AsTyped;
  /// AsTyped: the first report step (days); 0 = automatic, clamp(tau / 2, 1 s, 1 day) with tau =
  /// eclipse_relaxation_time_days (flow rounds report steps to whole seconds). Flow 2022.10
  /// starts its time stepping at min(1 day, report step); a first step shorter than the
  /// relaxation time keeps its Newton error below the distance still to go, so that a lone
  /// producer in a closed box is not shut by flow before its steady state (not a guarantee:
  /// docs/export-eclipse.md, accuracy_bent).
  double first_step_days = 0;
  /// AsTyped: the end of the run (days); 0 = automatic (see EclipseSchedule::AsTyped).
  double end_days = 0;
  /// Steady: the length of the run (days), in kSteadyReportSteps equal report steps. Long enough
  /// that the compressible accumulation left after the steps is negligible: the run is a
  /// steady-state solve. The run starts on 1 Jan 1900 and flow's dates end in 2262: at most ~131,000 days.
  double tstep_days = 1.0e5;
  /// Thickness (m) of the thin boxes that carry the non-reservoir cells. Their depth (centre)
  /// is exact; the thickness only decides how many fit in one column.
  double thin_cell_thickness = 1.0e-3;
  /// Width (m) of each extra column (and of the separator column); geometry only, no physics.
  double extra_column_width = 1.0;
};

/// Where every mesh cell sits in the deck's corner-point grid.
struct EclipseLayout {
  int nx = 0, ny = 0, nz = 0;   ///< the reservoir lattice of the case
  int extra_columns = 0;        ///< MX: i-columns after the separator (0: none); boxes on every other i and j
  int deck_nx = 0;              ///< NX of DIMENS: nx, or nx + 1 + extra_columns
  /// n_cells: 0-based natural deck index I + deck_nx (J + ny K) of each mesh cell.
  std::vector<int32_t> cell_deck_index;
  /// deck_nx * ny * nz: the mesh cell at each deck cell, -1 where inactive (ACTNUM 0).
  std::vector<int32_t> deck_cell;
  /// deck_nx * ny * nz: top and bottom depth of each deck cell (flat top and bottom).
  std::vector<double> top, bottom;
  /// deck_nx + 1 pillar x positions; pillar y positions are the lattice's y.
  std::vector<double> pillar_x, pillar_y;
  double pillar_top = 0, pillar_bottom = 0;  ///< depth range of the vertical pillars
  /// The reservoir is a corner-point model: columns 1..nx of the deck's grid are the model's
  /// COORD/ZCORN (pillar_x/pillar_y above then only place the extra columns' vertical pillars, and
  /// top/bottom of a model cell are its corners' depth range, information only).
  bool corner_point = false;

  int n_deck_cells() const { return deck_nx * ny * nz; }
  std::array<int, 3> deck_ijk(int32_t g) const { return {g % deck_nx, (g / deck_nx) % ny, g / (deck_nx * ny)}; }
};

/// Places the cells. Reservoir cells (cell_ijk valid) keep their (i,j,k) and must have their FV
/// centre at the lattice cell's centre depth; the others are packed, deepest last, into extra
/// columns so that no two boxes of one column overlap. Returns false with `error` set if the
/// mesh does not fit the case's lattice (bad or duplicate ijk, wrong depth, sizes).
bool make_eclipse_layout(const ReservoirSpec& reservoir, const PolyMesh& mesh, const EclipseDeckOptions& options,
                         EclipseLayout* layout, std::string* error);

/// OPM Flow sets every connection between cells that are not logical (I,J,K) neighbours to zero
/// when its transmissibility is below this value in the deck's units (cP.rm3/day/bar in METRIC);
/// its INIT file then lists the NNC with a negative TRANNNC.
constexpr double kFlowNncThreshold = 1e-6;

/// The transmissibilities as the deck carries them (METRIC, cP.rm3/day/bar).
struct EclipseConnections {
  /// deck cells: transmissibility to the +I / +J / +K neighbour, for logical neighbours that are
  /// both reservoir cells; 0 everywhere else (this also zeroes flow's geometric values).
  std::vector<double> tranx, trany, tranz;
  struct Nnc {
    int32_t a = 0, b = 0;  ///< deck natural indices, a < b
    double t = 0;          ///< summed over the faces joining the two cells
  };
  std::vector<Nnc> nnc;      ///< every other connection, sorted by (a, b), t != 0
  int zero_faces = 0;        ///< interior faces with T == 0 (nothing to write)
  int negative_faces = 0;    ///< interior faces with T < 0 or not finite (written as computed)
  int below_flow_threshold = 0;        ///< NNC records flow ignores: |t| < kFlowNncThreshold, not logical neighbours
  /// NNC records flow would also set to zero: t <= -kFlowNncThreshold, not logical neighbours (flow's test
  /// is t < threshold, sign included). write_eclipse_deck refuses them; `first_negative_nnc` names one.
  int negative_nnc = 0;
  Nnc first_negative_nnc;
  double below_flow_threshold_sum = 0; ///< their summed |t|
  double total = 0;          ///< sum of all interior face transmissibilities (for checks)
};

EclipseConnections make_eclipse_connections(const PolyMesh& mesh, const EclipseLayout& layout,
                                            const Transmissibilities& trans);

/// Flow's test of a logical neighbour in the deck: natural indices a < b differing by 1, NX or
/// NX*NY (a pair across a row's end included, as in flow).
bool flow_logical_neighbours(const EclipseLayout& layout, int32_t a, int32_t b);

/// The connections OPM Flow leaves out of the deck's equation.
struct FlowDroppedConnections {
  int pairs = 0;          ///< deck cell pairs set to 0
  int model_pairs = 0;    ///< of them, pairs of two model cells (the user's own, e.g. across a sealing fault)
  double sum = 0;         ///< their summed |T| before (cP.rm3/day/bar)
};

/// Sets to 0 in `trans` (faces and NNCs) every pair of deck cells that flow does not connect:
/// not logical neighbours, summed transmissibility below kFlowNncThreshold
/// (`removeSmallNonCartesianTransmissibilities_`; flow applies it to the user's own deck too).
/// A solve with the result is the deck's equation; the deck written with it lists none of them.
FlowDroppedConnections drop_connections_flow_ignores(const PolyMesh& mesh, const EclipseLayout& layout,
                                                     Transmissibilities* trans);

/// "N connections below flow's threshold (M between model cells, sum S) are not connected, as in flow".
std::string describe(const FlowDroppedConnections& dropped);

/// The same on the layout write_eclipse_deck makes of (reservoir, mesh, options). False, `trans`
/// untouched and `error` set, when the mesh has no deck layout (no deck can be written).
bool drop_connections_flow_ignores(const ReservoirSpec& reservoir, const PolyMesh& mesh,
                                   const EclipseDeckOptions& options, Transmissibilities* trans,
                                   FlowDroppedConnections* dropped, std::string* error);

/// What write_eclipse_deck wrote.
struct EclipseDeckInfo {
  std::string data_file;              ///< dir/NAME.DATA
  std::vector<std::string> files;     ///< every file written, NAME.DATA last
  EclipseLayout layout;
  int nnc = 0;                        ///< NNC records written
  int tran_connections = 0;           ///< non-zero TRANX/Y/Z entries written
  std::vector<std::vector<std::pair<int32_t, double>>> well_connections;  ///< per well: (cell, CF)
  std::vector<std::string> warnings;  ///< e.g. negative transmissibilities written as computed
  double relaxation_time_days = 0;    ///< eclipse_relaxation_time_days of the case
  double first_step_days = 0;         ///< AsTyped: the first report step (days)
  double end_days = 0;                ///< simulated time of the deck's SCHEDULE (days)
};

/// An estimate of the slowest pressure relaxation time (days) of the deck's transient:
/// max(diffusion phi mu c L_d^2 / (CDARCY k_d) over the axes d, with L_d the reservoir's extent,
/// k_d the harmonic mean and phi the mean over reservoir cells; depletion PV c mu / sum CF over
/// all wells), c = the deck's Cw (rock incompressible). The AsTyped schedule runs kAsTypedRelaxationTimes of them.
double eclipse_relaxation_time_days(const CaseSpec& cs, const PolyMesh& mesh, const MeshGeometry& geo,
                                    const std::vector<std::vector<std::pair<int32_t, double>>>& well_connections);

/// NAME of the deck: the case name upper-cased.
std::string eclipse_deck_name(const CaseSpec& cs);

/// Writes dir/NAME.DATA with its includes NAME_GRID.INC, NAME_NNC.INC, NAME_EDIT.INC,
/// NAME_SCHEDULE.INC, plus NAME_GRID.GRDECL (the structured reservoir alone, for viewers).
/// `trans` must come from compute_transmissibilities(mesh, geo) with metric_units = true.
/// Creates `dir` if needed. All files are written under temporary names and renamed at the end
/// (NAME.DATA last): on failure nothing complete-looking is left. Never throws for I/O.
WriteStatus write_eclipse_deck(const std::string& dir, const CaseSpec& cs, const PolyMesh& mesh,
                               const MeshGeometry& geo, const Transmissibilities& trans,
                               const EclipseDeckOptions& options = {}, EclipseDeckInfo* info = nullptr);

/// The structured reservoir alone as GRDECL (SPECGRID, COORD, ZCORN, ACTNUM, PORO, PERMX/Y/Z):
/// ACTNUM 1 where the mesh has the reservoir cell, 0 where the cavity replaced it.
WriteStatus write_reservoir_grdecl(const std::string& path, const ReservoirSpec& reservoir, const PolyMesh& mesh);

/// Command-line options for `flow` that make the steady deck (EclipseSchedule::Steady) a
/// steady-state solve and make it converge to the accuracy of its float32 output
/// (docs/export-eclipse.md explains each). Optional: the default deck runs as typed.
std::vector<std::string> flow_steady_state_options();

}  // namespace hm
