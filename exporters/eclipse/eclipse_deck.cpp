// Eclipse deck writer (docs/export-eclipse.md explains every keyword choice).
#include "eclipse_deck.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "meshgen/case/grdecl.hpp"
#include "meshgen/core/mesh_builder.hpp"
#include "staged_files.hpp"
#include "text_out.hpp"

namespace hm {

namespace {

namespace fs = std::filesystem;

std::string quoted(const std::string& s) { return "'" + s + "'"; }

// COORD of vertical pillars at (px[i], py[j]), i fastest.
void write_coord(TextOut& o, const std::vector<double>& px, const std::vector<double>& py, double ztop, double zbot) {
  o << "COORD\n";
  for (double y : py)
    for (double x : px) o << x << ' ' << y << ' ' << ztop << ' ' << x << ' ' << y << ' ' << zbot << '\n';
  o << "/\n\n";
}

// ZCORN of flat-topped cells: per layer k, the top face then the bottom face; each face row j
// written twice (near and far corners), each cell's value twice along i.
void write_zcorn(TextOut& o, int nx, int ny, int nz, const std::vector<double>& top, const std::vector<double>& bottom) {
  std::vector<double> z;
  z.reserve(static_cast<size_t>(8) * nx * ny * nz);
  for (int k = 0; k < nz; ++k)
    for (int side = 0; side < 2; ++side)
      for (int j = 0; j < ny; ++j)
        for (int rep = 0; rep < 2; ++rep)
          for (int i = 0; i < nx; ++i) {
            const size_t g = i + static_cast<size_t>(nx) * (j + static_cast<size_t>(ny) * k);
            const double v = side == 0 ? top[g] : bottom[g];
            z.push_back(v);
            z.push_back(v);
          }
  o.eclipse_array("ZCORN", z);
}

// A corner-point model's own COORD and ZCORN, as OPM read them (the user's geometry, in the frame of
// the deck: MAPAXES is not repeated, the wells of the deck are on cells), widened by the layout's
// separator and extra columns: the pillars of row J are the model's (I = 0..nx, 6 numbers each) then
// the layout's vertical ones; ZCORN in Eclipse order with the deck's NX, the model's values for
// I < nx and the layout's flat tops and bottoms beyond. Without extra columns: the model's arrays.
void write_model_geometry(TextOut& o, const CornerPointModel& m, const EclipseLayout* layout) {
  if (layout == nullptr || layout->deck_nx == m.nx) {
    o.eclipse_array("COORD", m.coord);
    o.eclipse_array("ZCORN", m.zcorn);
    return;
  }
  const EclipseLayout& L = *layout;
  std::vector<double> coord;
  coord.reserve(static_cast<size_t>(6) * (L.deck_nx + 1) * (m.ny + 1));
  for (int J = 0; J <= m.ny; ++J) {
    for (int I = 0; I <= m.nx; ++I) {
      const size_t p = 6 * (I + static_cast<size_t>(m.nx + 1) * J);
      coord.insert(coord.end(), m.coord.begin() + p, m.coord.begin() + p + 6);
    }
    for (int I = m.nx + 1; I <= L.deck_nx; ++I)
      coord.insert(coord.end(), {L.pillar_x[I], L.pillar_y[J], L.pillar_top, L.pillar_x[I], L.pillar_y[J], L.pillar_bottom});
  }
  std::vector<double> z;
  z.reserve(static_cast<size_t>(8) * L.n_deck_cells());
  for (int k = 0; k < m.nz; ++k)
    for (int c = 0; c < 2; ++c)
      for (int j = 0; j < m.ny; ++j)
        for (int b = 0; b < 2; ++b)
          for (int i = 0; i < L.deck_nx; ++i)
            for (int a = 0; a < 2; ++a) {
              if (i < m.nx) {
                z.push_back(m.zcorn[zcorn_index(m, i, j, k, a + 2 * b + 4 * c)]);
              } else {
                const size_t g = i + static_cast<size_t>(L.deck_nx) * (j + static_cast<size_t>(m.ny) * k);
                z.push_back(c == 0 ? L.top[g] : L.bottom[g]);
              }
            }
  o.eclipse_array("COORD", coord);
  o.eclipse_array("ZCORN", z);
}

// The model's PINCH, item by item, so that flow connects its cells across layers of zero thickness as it
// would in the model's own deck (a deck with near-well cells carries those connections as NNC instead).
void write_pinch(TextOut& o, const CornerPointModel::Pinch& p) {
  if (!p.active) return;
  o << "-- The model's PINCH: flow connects cells across layers of zero thickness with it only.\n"
    << "PINCH\n " << p.threshold << (p.nogap ? " NOGAP " : " GAP ") << p.max_empty_gap
    << (p.pinchout_all ? " ALL" : " TOPBOT") << (p.multz_all ? " ALL" : " TOP") << " /\n\n";
}

// The model's MULTREGT and the region arrays it names, as the deck gave them (a deck with near-well
// cells carries their effect in its transmissibilities instead).
void write_region_multipliers(TextOut& o, const CornerPointModel& m) {
  if (m.multregt_records.empty()) return;
  o << "-- The model's region multipliers (MULTREGT) and the region arrays they name.\n";
  for (const auto& [name, values] : m.region_arrays) o.eclipse_array(name.c_str(), values);
  o << "MULTREGT\n";
  for (const std::string& r : m.multregt_records) o << " " << r << " /\n";
  o << "/\n\n";
}

std::string grdecl_text(const ReservoirSpec& res, const PolyMesh& mesh, std::string* error) {
  const int nx = static_cast<int>(res.x.size()) - 1, ny = static_cast<int>(res.y.size()) - 1,
            nz = static_cast<int>(res.z.size()) - 1;
  if (nx < 1 || ny < 1 || nz < 1) {
    *error = "reservoir lattice needs at least 2 nodes per axis";
    return {};
  }
  const size_t n = static_cast<size_t>(nx) * ny * nz;
  std::vector<int> actnum(n, 0);
  std::vector<double> poro(n, res.porosity), kx(n, res.permeability.x), ky(n, res.permeability.y),
      kz(n, res.permeability.z), top(n), bottom(n), multpv(n, 1.0);
  for (int c = 0; c < mesh.n_cells(); ++c) {
    const auto& ijk = mesh.cell_ijk[c];
    if (mesh.cell_region[c] != kReservoir || ijk[0] < 0) continue;
    if (ijk[0] >= nx || ijk[1] < 0 || ijk[1] >= ny || ijk[2] < 0 || ijk[2] >= nz) {
      *error = "cell " + std::to_string(c) + ": (i,j,k) outside the reservoir lattice";
      return {};
    }
    const size_t g = ijk[0] + static_cast<size_t>(nx) * (ijk[1] + static_cast<size_t>(ny) * ijk[2]);
    actnum[g] = 1;
    poro[g] = mesh.cell_porosity[c];
    multpv[g] = mesh.pore_volume_mult(c);
    kx[g] = mesh.cell_perm[c].x;
    ky[g] = mesh.cell_perm[c].y;
    kz[g] = mesh.cell_perm[c].z;
  }
  for (size_t g = 0; g < n; ++g) {
    const int k = static_cast<int>(g / (static_cast<size_t>(nx) * ny));
    top[g] = res.z[k];
    bottom[g] = res.z[k + 1];
  }
  TextOut o;
  o << "-- Structured reservoir of the hybrid mesh (HybridMesh). Cells replaced by the\n"
    << "-- near-well (cavity) mesh have ACTNUM 0. Units: METRIC (m, mD); depth positive down.\n"
    << "SPECGRID\n" << nx << ' ' << ny << ' ' << nz << " 1 F /\n\n";
  if (res.corner_point) {
    write_model_geometry(o, *res.corner_point, nullptr);
  } else {
    write_coord(o, res.x, res.y, res.z.front(), res.z.back());
    write_zcorn(o, nx, ny, nz, top, bottom);
  }
  o.eclipse_array("ACTNUM", actnum);
  o.eclipse_array("PORO", poro);
  if (!mesh.cell_pore_volume_mult.empty()) o.eclipse_array("MULTPV", multpv);
  o.eclipse_array("PERMX", kx);
  o.eclipse_array("PERMY", ky);
  o.eclipse_array("PERMZ", kz);
  if (mesh.n_nncs() > 0) {
    o << "-- Connections without a face between the cells above (the model's NNC, an EDITNNC of the pair folded in;\n"
      << "-- connections across the cells its MINPV removes), T in cP.rm3/day/bar.\n"
      << "NNC\n";
    for (int k = 0; k < mesh.n_nncs(); ++k) {
      const auto a = mesh.cell_ijk[mesh.nnc_cells[k][0]], b = mesh.cell_ijk[mesh.nnc_cells[k][1]];
      if (a[0] < 0 || b[0] < 0) continue;  // not between two reservoir cells: no (i, j, k) to name
      o << a[0] + 1 << ' ' << a[1] + 1 << ' ' << a[2] + 1 << ' ' << b[0] + 1 << ' ' << b[1] + 1 << ' ' << b[2] + 1 << ' '
        << mesh.nnc_trans[k] << " /\n";
    }
    o << "/\n";
  }
  return std::move(o.text);
}

std::string upper(std::string s) {
  for (char& ch : s) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  return s;
}

}  // namespace

std::string eclipse_deck_name(const CaseSpec& cs) { return upper(cs.name); }

double eclipse_relaxation_time_days(const CaseSpec& cs, const PolyMesh& mesh, const MeshGeometry& geo,
                                    const std::vector<std::vector<std::pair<int32_t, double>>>& well_connections) {
  const double c = std::max(cs.fluid.compressibility, 1e-8), mu = cs.fluid.viscosity;
  double inv_k[3] = {0, 0, 0}, phi = 0, pv = 0;
  int n = 0;
  for (int cell = 0; cell < mesh.n_cells(); ++cell) {
    pv += geo.cell_volume[cell] * mesh.cell_porosity[cell] * mesh.pore_volume_mult(cell);
    if (mesh.cell_region[cell] != kReservoir) continue;
    const Vec3& k = mesh.cell_perm[cell];
    inv_k[0] += 1 / k.x;
    inv_k[1] += 1 / k.y;
    inv_k[2] += 1 / k.z;
    phi += mesh.cell_porosity[cell] * mesh.pore_volume_mult(cell);
    ++n;
  }
  double tau = 0;
  if (n > 0) {
    const ReservoirSpec& r = cs.reservoir;
    const double extent[3] = {r.x.back() - r.x.front(), r.y.back() - r.y.front(), r.z.back() - r.z.front()};
    for (int d = 0; d < 3; ++d) {
      const double k_harmonic = n / inv_k[d];
      tau = std::max(tau, phi / n * mu * c * extent[d] * extent[d] / (kDarcyMetric * k_harmonic));
    }
  }
  double cf = 0;
  for (const auto& w : well_connections)
    for (const auto& wc : w) cf += wc.second;
  if (cf > 0) tau = std::max(tau, pv * c * mu / cf);
  return tau;
}

std::vector<std::string> flow_steady_state_options() {
  return {"--enable-adaptive-time-stepping=false", "--time-step-control=newtoniterationcount",
          "--max-residual-allowed=1e30", "--linear-solver-reduction=1e-6", "--tolerance-mb=1e-9"};
}

WriteStatus write_reservoir_grdecl(const std::string& path, const ReservoirSpec& reservoir, const PolyMesh& mesh) {
  auto fail = [&](const std::string& why) { return WriteStatus{false, "write_reservoir_grdecl " + path + ": " + why}; };
  if (path.empty()) return WriteStatus{false, "write_reservoir_grdecl: empty path"};
  std::string error;
  const std::string text = grdecl_text(reservoir, mesh, &error);
  if (!error.empty()) return fail(error);
  const fs::path p(path);
  if (p.has_parent_path() && !StagedFiles::make_directory(p.parent_path().string(), &error)) return fail(error);
  StagedFiles files;
  if (!files.stage(path, text) || !files.commit()) return fail(files.error());
  return {};
}

WriteStatus write_eclipse_deck(const std::string& dir, const CaseSpec& cs, const PolyMesh& mesh,
                               const MeshGeometry& geo, const Transmissibilities& trans,
                               const EclipseDeckOptions& options, EclipseDeckInfo* info) {
  const std::string name = eclipse_deck_name(cs);
  auto fail = [&](const std::string& why) { return WriteStatus{false, "write_eclipse_deck " + dir + ": " + why}; };
  if (name.empty()) return fail("the case has no name");
  const int nc = mesh.n_cells();
  const CsrReport csr = check_csr_invariants(mesh);
  if (!csr.ok) return fail("invalid mesh: " + (csr.problems.empty() ? std::string("?") : csr.problems[0]));
  if (static_cast<int>(geo.cell_volume.size()) != nc || static_cast<int>(trans.face.size()) != mesh.n_faces() ||
      trans.nnc.size() != mesh.nnc_cells.size())
    return fail("geometry or transmissibilities do not belong to this mesh (sizes differ)");
  for (int c = 0; c < nc; ++c)
    if (!(geo.cell_volume[c] > 0))
      return fail("cell " + std::to_string(c) + " has a non-positive volume " + std::to_string(geo.cell_volume[c]));
  // Flow's calendar ends in 2262 (64-bit nanoseconds); the deck starts in 1900.
  if (!(options.tstep_days > 0 && options.tstep_days <= 130000)) return fail("tstep_days must be in (0, 130000]");
  if (!(options.first_step_days >= 0 && options.first_step_days <= 1))
    return fail("first_step_days must be 0 (automatic) or in (0, 1]");
  if (!(options.end_days == 0 || (options.end_days > options.first_step_days && options.end_days <= 130000)))
    return fail("end_days must be 0 (automatic) or in (first_step_days, 130000]");

  EclipseLayout L;
  std::string error;
  if (!make_eclipse_layout(cs.reservoir, mesh, options, &L, &error)) return fail(error);
  const EclipseConnections conn = make_eclipse_connections(mesh, L, trans);
  const int n_wells = static_cast<int>(cs.wells.size());
  const auto wells = well_connection_factors(mesh, trans, n_wells);
  for (int w = 0; w < n_wells; ++w) {
    if (wells[w].empty()) return fail("well " + cs.wells[w].name + " has no cell on its wellbore");
    if (cs.wells[w].trajectory.empty()) return fail("well " + cs.wells[w].name + " has no trajectory");
  }
  std::vector<std::string> warnings;
  // A well that cannot flow at its BHP from the initial pressure: flow shuts it at the start and
  // (AsTyped) WTEST re-opens it when the reservoir pressure allows: correct, but a slower start.
  auto text_number = [](double v) { return (TextOut() << v).text; };
  for (const WellSpec& w : cs.wells)
    if ((w.type == WellType::Producer) ? w.bhp > cs.reservoir.initial_pressure : w.bhp < cs.reservoir.initial_pressure)
      warnings.push_back("well " + w.name + ": BHP " + text_number(w.bhp) + " bar cannot " +
                         (w.type == WellType::Producer ? "produce" : "inject") + " from the initial pressure " +
                         text_number(cs.reservoir.initial_pressure) +
                         " bar: flow shuts it at the start of a transient run (the deck's WTEST re-opens it)");
  // AsTyped: the transient runs kAsTypedRelaxationTimes relaxation times (at least 1 day), within flow's calendar.
  const double relaxation = eclipse_relaxation_time_days(cs, mesh, geo, wells);
  const double first_step =
      options.first_step_days > 0 ? options.first_step_days : std::clamp(0.5 * relaxation, kOneSecondInDays, 1.0);
  double end_days = options.end_days > 0 ? options.end_days : std::max(1.0, kAsTypedRelaxationTimes * relaxation);
  if (end_days <= first_step) return fail("end_days must be longer than the first step");
  if (end_days > 130000) {
    warnings.push_back("the estimated relaxation time (" + std::to_string(relaxation) +
                       " days) needs a run beyond flow's calendar: the deck ends at 130000 days");
    end_days = 130000;
  }
  // A corner-point model alone (no near-well cells): flow computes the model's connections and pore
  // volumes itself. With near-well cells every connection and pore volume is ours, the model's too
  // (docs/export-eclipse.md, "A corner-point model": flow's corner-point transmissibilities are not
  // the ones solver_demo solves with).
  const bool model_only = L.corner_point && L.extra_columns == 0;
  // With near-well cells the model's multipliers are in `trans` (PolyMesh::face_trans_mult): a mesh
  // without them would not be the model.
  if (L.corner_point && !model_only && has_transmissibility_multipliers(*cs.reservoir.corner_point) &&
      mesh.face_trans_mult.empty())
    return fail("the corner-point model has transmissibility multipliers (MULTX..MULTZ-, FAULTS/MULTFLT) that the "
                "mesh does not carry (PolyMesh::face_trans_mult): a deck of it with near-well cells would not be "
                "the model");
  if (conn.negative_nnc > 0 && !model_only) {
    const auto a = L.deck_ijk(conn.first_negative_nnc.a), b = L.deck_ijk(conn.first_negative_nnc.b);
    std::ostringstream w;
    w << conn.negative_nnc << " NNC records have a negative transmissibility, which OPM Flow sets to zero (first: ("
      << a[0] + 1 << "," << a[1] + 1 << "," << a[2] + 1 << ") - (" << b[0] + 1 << "," << b[1] + 1 << "," << b[2] + 1
      << "), T = " << conn.first_negative_nnc.t
      << "): the deck would not be the mesh; compute the transmissibilities with deck_transmissibility_options()";
    return fail(w.str());
  }
  if (conn.negative_faces > 0 && !model_only)
    warnings.push_back(std::to_string(conn.negative_faces) +
                       " interior faces have a negative or non-finite transmissibility (written as computed)");
  if (conn.below_flow_threshold > 0 && !model_only) {
    std::ostringstream w;
    w << conn.below_flow_threshold << " NNC records have T < " << kFlowNncThreshold
      << " cP.rm3/day/bar, which OPM Flow ignores (sum " << conn.below_flow_threshold_sum << " of a total "
      << conn.total << ")";
    warnings.push_back(w.str());
  }
  if (conn.zero_faces > 0 && !model_only)
    warnings.push_back(std::to_string(conn.zero_faces) + " interior faces have a zero transmissibility (no connection)");

  const size_t nd = static_cast<size_t>(L.n_deck_cells());
  const fs::path out(dir);
  const std::string grid_inc = name + "_GRID.INC", nnc_inc = name + "_NNC.INC", edit_inc = name + "_EDIT.INC",
                    sched_inc = name + "_SCHEDULE.INC";

  // ---- GRID include: the corner-point grid and rock properties of every deck cell.
  std::string grid_text;
  {
    TextOut o;
    o << "-- Deck grid: reservoir columns 1.." << L.nx;
    if (L.extra_columns > 0)
      o << ", separator column " << L.nx + 1 << " (inactive), well/transition cells in columns " << L.nx + 2 << ".."
        << L.deck_nx << " (thin boxes at their FV-centre depth, on every other I and J)";
    o << ".\n\n";
    if (model_only) {
      o << "-- The model's own corner-point geometry (COORD/ZCORN as OPM read them). flow computes the\n"
        << "-- connections between the model's cells itself, fault NNCs included, with OPM's multipliers\n"
        << "-- of the model (MULTX..MULTZ-, FAULTS/MULTFLT folded in, as TransMult gives them).\n";
      write_model_geometry(o, *cs.reservoir.corner_point, &L);
      static const char* kMult[6] = {"MULTX", "MULTX-", "MULTY", "MULTY-", "MULTZ", "MULTZ-"};
      for (int d = 0; d < 6; ++d) {
        const std::vector<double>& v = cs.reservoir.corner_point->trans_mult[d];
        if (std::any_of(v.begin(), v.end(), [](double x) { return x != 1.0; })) o.eclipse_array(kMult[d], v);
      }
      write_pinch(o, cs.reservoir.corner_point->pinch);
      write_region_multipliers(o, *cs.reservoir.corner_point);
    } else if (L.corner_point) {
      o << "-- Columns 1.." << L.nx << ": the model's own corner-point geometry (COORD/ZCORN as OPM read them),\n"
        << "-- widened by the separator and extra columns (vertical pillars beyond the model's +x side).\n"
        << "-- Every connection is HybridMesh's (TRANX/Y/Z in EDIT, NNC): none of flow's geometric ones.\n";
      write_model_geometry(o, *cs.reservoir.corner_point, &L);
      // TRANX/Y/Z replace flow's values between logical neighbours only; its geometric connections
      // across faults would stay beside our NNC records (docs/export-eclipse.md, "Faults").
      o << "-- flow's own geometric connections x 0 (those across faults among them): TRANX/Y/Z and NNC are the deck's.\n";
      const std::vector<double> zero(nd, 0.0);
      for (const char* k : {"MULTX", "MULTY", "MULTZ"}) o.eclipse_array(k, zero);
    } else {
      write_coord(o, L.pillar_x, L.pillar_y, L.pillar_top, L.pillar_bottom);
      write_zcorn(o, L.deck_nx, L.ny, L.nz, L.top, L.bottom);
    }
    std::vector<int> actnum(nd, 0);
    std::vector<double> poro(nd, 0.0), kx(nd, 0.0), ky(nd, 0.0), kz(nd, 0.0);
    for (size_t g = 0; g < nd; ++g) {
      const int32_t c = L.deck_cell[g];
      if (c < 0) continue;
      actnum[g] = 1;
      poro[g] = mesh.cell_porosity[c];
      kx[g] = mesh.cell_perm[c].x;
      ky[g] = mesh.cell_perm[c].y;
      kz[g] = mesh.cell_perm[c].z;
    }
    o.eclipse_array("ACTNUM", actnum);
    o.eclipse_array("PORO", poro);
    if (model_only && !mesh.cell_pore_volume_mult.empty()) {
      // flow's own pore volumes, as the model's: with near-well cells PORV (EDIT) carries them instead.
      std::vector<double> multpv(nd, 1.0);
      for (size_t g = 0; g < nd; ++g)
        if (L.deck_cell[g] >= 0) multpv[g] = mesh.pore_volume_mult(L.deck_cell[g]);
      o << "-- The model's pore-volume multipliers (its MULTPV and PORV edits as OPM read them).\n";
      o.eclipse_array("MULTPV", multpv);
    }
    o << "-- PERMX/Y/Z are required by flow; the transmissibilities used are TRANX/Y/Z and NNC.\n";
    o.eclipse_array("PERMX", kx);
    o.eclipse_array("PERMY", ky);
    o.eclipse_array("PERMZ", kz);
    grid_text = std::move(o.text);
  }

  // ---- NNC include: every connection that is not between logical reservoir neighbours.
  std::string nnc_text;
  {
    TextOut o;
    o << "-- Non-neighbour connections (I1 J1 K1 I2 J2 K2 T), T in cP.rm3/day/bar, from HybridMesh's\n"
      << "-- two-point transmissibilities (faces joining the same two cells summed).\n";
    if (!conn.nnc.empty() && !model_only) {
      o << "NNC\n";
      for (const auto& r : conn.nnc) {
        const auto a = L.deck_ijk(r.a), b = L.deck_ijk(r.b);
        o << a[0] + 1 << ' ' << a[1] + 1 << ' ' << a[2] + 1 << ' ' << b[0] + 1 << ' ' << b[1] + 1 << ' ' << b[2] + 1
          << ' ' << r.t << " /\n";
      }
      o << "/\n";
    }
    if (model_only && mesh.n_nncs() > 0) {
      // flow computes the model's own connections; the deck's NNC adds the rest, as in the model's deck.
      o << "-- The model's NNC (an EDITNNC of the pair folded in, as OPM reads it) and its connections across\n"
        << "-- the cells MINPV removes (those ACTNUM 0 above; no MINPV here, so flow removes nothing else).\nNNC\n";
      for (int k = 0; k < mesh.n_nncs(); ++k) {
        const auto a = L.deck_ijk(L.cell_deck_index[mesh.nnc_cells[k][0]]),
                   b = L.deck_ijk(L.cell_deck_index[mesh.nnc_cells[k][1]]);
        o << a[0] + 1 << ' ' << a[1] + 1 << ' ' << a[2] + 1 << ' ' << b[0] + 1 << ' ' << b[1] + 1 << ' ' << b[2] + 1
          << ' ' << trans.nnc[k] << " /\n";
      }
      o << "/\n";
    }
    nnc_text = std::move(o.text);
  }

  // ---- EDIT include: pore volumes and transmissibilities replace flow's geometric ones.
  std::string edit_text;
  int tran_connections = 0;
  if (model_only) {
    TextOut o;
    o << "-- A corner-point model's cells: flow's own pore volumes and transmissibilities (GRID include).\n";
    const CornerPointModel& m = *cs.reservoir.corner_point;
    if (!m.edit_nnc.empty()) {  // the model as read (a model-only deck is never refined)
      o << "-- The model's EDITNNC (as OPM keeps it for flow's own connections, records of a pair multiplied).\n"
        << "EDITNNC\n";
      const int64_t nx = m.nx, nxy = nx * m.ny;
      for (const auto& [pair, mult] : m.edit_nnc)
        o << pair.first % nx + 1 << ' ' << (pair.first / nx) % m.ny + 1 << ' ' << pair.first / nxy + 1 << ' '
          << pair.second % nx + 1 << ' ' << (pair.second / nx) % m.ny + 1 << ' ' << pair.second / nxy + 1 << ' ' << mult
          << " /\n";
      o << "/\n";
    }
    edit_text = std::move(o.text);
  } else {
    TextOut o;
    std::vector<double> porv(nd, 0.0);
    for (int c = 0; c < nc; ++c)
      porv[L.cell_deck_index[c]] = geo.cell_volume[c] * mesh.cell_porosity[c] * mesh.pore_volume_mult(c);
    o << (mesh.cell_pore_volume_mult.empty() ? "-- Pore volume = cell volume * porosity (rm3).\n"
                                             : "-- Pore volume = cell volume * porosity * the model's pore-volume multiplier (MULTPV, PORV) (rm3).\n");
    o.eclipse_array("PORV", porv);
    o << "-- Transmissibilities (cP.rm3/day/bar) between logical reservoir neighbours; 0 elsewhere,\n"
      << "-- which removes flow's own geometric values (all other connections are NNC).\n";
    o.eclipse_array("TRANX", conn.tranx);
    o.eclipse_array("TRANY", conn.trany);
    o.eclipse_array("TRANZ", conn.tranz);
    for (size_t g = 0; g < nd; ++g)
      tran_connections += (conn.tranx[g] != 0) + (conn.trany[g] != 0) + (conn.tranz[g] != 0);
    edit_text = std::move(o.text);
  }

  // ---- SCHEDULE include: wells under BHP control, one COMPDAT record per connected cell.
  int max_connections = 1;
  std::string sched_text;
  {
    TextOut o;
    if (n_wells == 0) o << "-- The case has no wells.\n";
    if (n_wells > 0) o << "WELSPECS\n";
    for (int w = 0; w < n_wells; ++w) {
      const auto head = L.deck_ijk(L.cell_deck_index[wells[w][0].first]);
      // Item 5: BHP reference depth = first trajectory point (the wellhead end of the well).
      o << quoted(cs.wells[w].name) << " 'G1' " << head[0] + 1 << ' ' << head[1] + 1 << ' '
        << cs.wells[w].trajectory.front().z << " 'WATER' /\n";
    }
    if (n_wells > 0)
      o << "/\n\nCOMPDAT\n-- WELL I J K1 K2 STATUS SATNUM CF: CF = HybridMesh's wellbore connection factor.\n";
    for (int w = 0; w < n_wells; ++w) {
      max_connections = std::max(max_connections, static_cast<int>(wells[w].size()));
      for (const auto& [cell, cf] : wells[w]) {
        const auto ijk = L.deck_ijk(L.cell_deck_index[cell]);
        o << quoted(cs.wells[w].name) << ' ' << ijk[0] + 1 << ' ' << ijk[1] + 1 << ' ' << ijk[2] + 1 << ' '
          << ijk[2] + 1 << " 'OPEN' 1* " << cf << " /\n";
      }
    }
    if (n_wells > 0) o << "/\n\n";
    bool any_prod = false, any_inj = false;
    for (const WellSpec& w : cs.wells) (w.type == WellType::Producer ? any_prod : any_inj) = true;
    if (any_prod) {
      o << "WCONPROD\n";
      for (const WellSpec& w : cs.wells)
        if (w.type == WellType::Producer) o << quoted(w.name) << " 'OPEN' 'BHP' 5* " << w.bhp << " /\n";
      o << "/\n\n";
    }
    if (any_inj) {
      o << "WCONINJE\n";
      for (const WellSpec& w : cs.wells)
        if (w.type == WellType::Injector) o << quoted(w.name) << " 'WATER' 'OPEN' 'BHP' 2* " << w.bhp << " /\n";
      o << "/\n\n";
    }
    sched_text = std::move(o.text);
  }

  // ---- main deck
  std::string data_text;
  {
    const FluidSpec& fl = cs.fluid;
    // Flow needs Cw > 0 (Cw = 0 with one large step gave NaN); 1e-8 /bar changes nothing steady.
    const double cw = std::max(fl.compressibility, 1e-8);
    if (fl.compressibility < 1e-8)
      warnings.push_back("fluid compressibility raised to 1e-8 /bar in PVTW (flow needs Cw > 0)");
    TextOut o;
    o << "-- " << name << ": single-phase steady-state deck written by HybridMesh (docs/export-eclipse.md).\n";
    if (options.schedule == EclipseSchedule::Steady) {
      o << "-- Run: flow";
      for (const std::string& a : flow_steady_state_options()) o << ' ' << a;
      o << ' ' << name << ".DATA\n\n";
    } else {
      o << "-- Run: flow " << name << ".DATA   (no options needed)\n\n";
    }
    if (L.corner_point) {
      warnings.push_back("corner-point model: if flow stops with 'Convergence failure for linear solver', run it with "
                         "--linear-solver-max-iter=5000 (the deck's first lines say why)");
      o << "-- On a large corner-point model flow's default linear solver (ILU0, 200 iterations) can stop with\n"
        << "-- 'Convergence failure for linear solver' (refined Reek, 1e5-1.6e6 cells, Cw 1e-8): then add\n"
        << "-- --linear-solver-max-iter=5000 (docs/export-eclipse.md, \"Reek with a well\").\n\n";
    }
    o
      << "RUNSPEC\n\nTITLE\n" << name << "\n\n"
      << "DIMENS\n" << L.deck_nx << ' ' << L.ny << ' ' << L.nz << " /\n\n"
      << "WATER\n\nMETRIC\n\n"
      << "-- table dimensions: the defaults (one PVT and one saturation region)\n"
      << "TABDIMS\n/\n\n"
      << "-- 1900: flow keeps dates as 64-bit nanoseconds (years 1678..2262); a long step from 2000 wraps.\n"
      << "START\n1 'JAN' 1900 /\n\n"
      << "-- max wells, max connections per well, max groups, max wells per group\n"
      << "WELLDIMS\n" << std::max(n_wells, 1) << ' ' << max_connections << " 1 " << std::max(n_wells, 1) << " /\n\n"
      << "UNIFOUT\n\n"
      << "GRID\n\nINIT\n\n"
      << "INCLUDE\n" << quoted(grid_inc) << " /\n\n"
      << "INCLUDE\n" << quoted(nnc_inc) << " /\n\n"
      << "EDIT\n\n"
      << "INCLUDE\n" << quoted(edit_inc) << " /\n\n"
      << "PROPS\n\n"
      << "-- Pref (bar) Bw Cw (1/bar) viscosity (cP) viscosibility\n"
      << "PVTW\n" << cs.reservoir.initial_pressure << " 1.0 " << cw << ' ' << fl.viscosity << " 0.0 /\n\n"
      << "-- surface densities: oil water gas (kg/m3); only water is used\n"
      << "DENSITY\n1* " << fl.density << " 1* /\n\n"
      << "-- incompressible rock: pore volumes stay the exported PORV\n"
      << "ROCK\n" << cs.reservoir.initial_pressure << " 0.0 /\n\n"
      << "SOLUTION\n\n"
      << "PRESSURE\n" << static_cast<long long>(nd) << '*' << cs.reservoir.initial_pressure << " /\n\n"
      << "SUMMARY\n\nWBHP\n/\nWWPR\n/\nWWIR\n/\nFWPR\nFWIR\n\n"
      << "SCHEDULE\n\n"
      << "RPTRST\n'BASIC=2' /\n\n"
      << "INCLUDE\n" << quoted(sched_inc) << " /\n\n";
    if (options.schedule == EclipseSchedule::Steady) {
      o << "-- Long steps (run flow with the options above): backward Euler then gives the steady state;\n"
        << "-- the second removes the accumulation the first leaves (docs/export-eclipse.md).\n"
        << "TSTEP\n";
      for (int s = 0; s < kSteadyReportSteps; ++s) o << options.tstep_days / kSteadyReportSteps << ' ';
      o << "/\n\nEND\n";
    } else {
      o << "-- Run as typed: flow 2022.10 reads no time-step keyword without options (TUNING, NEXTSTEP need\n"
        << "-- --enable-tuning); it starts at min(1 day, report step), grows at most 3x per step, at most 365 days.\n"
        << "-- The run is the case's transient from its initial pressure to the steady state, "
        << end_days << " days = " << kAsTypedRelaxationTimes << " x the\n"
        << "-- estimated relaxation time " << relaxation << " days (docs/export-eclipse.md).\n"
        << (n_wells > 0 ? "-- Re-open any well flow shut because it could not flow at its BHP, as soon as it can:\n"
                          "WTEST\n'*' 0.01 'P' /\n/\n\n"
                        : "-- No wells (flow refuses WTEST '*' matching none).\n")
        << "TSTEP\n" << first_step << ' ' << end_days - first_step << " /\n\nEND\n";
    }
    data_text = std::move(o.text);
  }

  std::string grdecl = grdecl_text(cs.reservoir, mesh, &error);
  if (!error.empty()) return fail(error);

  if (!StagedFiles::make_directory(dir, &error)) return fail(error);
  StagedFiles files;
  const bool staged = files.stage((out / grid_inc).string(), grid_text) &&
                      files.stage((out / nnc_inc).string(), nnc_text) &&
                      files.stage((out / edit_inc).string(), edit_text) &&
                      files.stage((out / sched_inc).string(), sched_text) &&
                      files.stage((out / (name + "_GRID.GRDECL")).string(), grdecl) &&
                      files.stage((out / (name + ".DATA")).string(), data_text);
  if (!staged || !files.commit()) return fail(files.error());

  if (info) {
    info->data_file = (out / (name + ".DATA")).string();
    info->files = files.paths();
    info->layout = std::move(L);
    info->nnc = model_only ? 0 : static_cast<int>(conn.nnc.size());
    info->tran_connections = tran_connections;
    info->well_connections = wells;
    info->warnings = warnings;
    info->relaxation_time_days = relaxation;
    info->first_step_days = first_step;
    info->end_days = options.schedule == EclipseSchedule::Steady ? options.tstep_days : end_days;
  }
  return {};
}

}  // namespace hm
