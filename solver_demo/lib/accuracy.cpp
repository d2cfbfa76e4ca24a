#include "accuracy.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <cstdio>
#include <set>
#include <string>

#include "fvcheck/lib/transmissibility.hpp"
#include "meshgen/grids/well_block.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"
#include "meshgen/case/near_well_layers.hpp"
#include "meshgen/pipeline/permeability_frame.hpp"
#include "peaceman.hpp"

namespace hm {

namespace {
constexpr double kPi = 3.14159265358979323846;
}

AccuracySetup make_accuracy_setup(const CaseSpec& cs, const AccuracyOptions& opt) {
  if (cs.wells.size() != 1)
    throw InputError("wells: the accuracy study needs exactly one well (got " + std::to_string(cs.wells.size()) + ")");
  if (!cs.reservoir.cell_permx.empty())
    throw InputError("reservoir.grdecl: the accuracy study needs a uniform permeability (reservoir.permeability), "
                     "not per-cell values");
  const Vec3 k = cs.reservoir.permeability;
  const WellSpec& ws = cs.wells[0];
  if (ws.bhp == cs.reservoir.initial_pressure)
    throw InputError("wells[0].bhp: must differ from reservoir.initial_pressure (the study's drawdown)");
  AccuracySetup s;
  s.near_radius = 3 * ws.drainage_radius;
  s.viscosity = cs.fluid.viscosity;
  s.permeability_tensor = k;
  // The exact field is a line source in x' = S^-1 x whatever the mesh's metric; the metric
  // decides where the mesh's wellbore is (the frame it is a circle in, and its radius there).
  const Vec3 scale = frame_scale(k);
  s.permeability = k.x == k.y && k.y == k.z ? k.x : std::cbrt(k.x * k.y * k.z);
  const PermeabilityFrame frame = permeability_frame(cs);  // identity unless metric: permeability
  s.p_w = ws.bhp;
  s.drawdown = std::fabs(cs.reservoir.initial_pressure - ws.bhp);
  // The well as meshed: the block cuts each bend's corner along its fillet wedges, so the
  // exact solution's source follows that axis (the trajectory itself for straight wells).
  // A K-orthogonal block is planned in the scaled frame (its fillet too): its axis mapped back.
  const CaseSpec meshed = scaled_case(cs, frame);
  std::vector<Vec3> axis = meshed_axis(make_well_block(meshed, 0, ws.sectors));  // independent of sectors
  for (Vec3& p : axis) p = to_physical(frame, p);
  // The source stops the wellbore's radius short of the ends in the frame the wellbore is a
  // circle in (r_w for a Euclidean mesh; the scaled equivalent radius for a K-orthogonal one).
  s.source_inset = opt.source_to_tips ? 0.0 : meshed.wells[0].radius;
  s.field = make_line_source_field(axis, ws.radius, ws.bhp, cs.reservoir.initial_pressure, s.near_radius,
                                   s.source_inset, scale, frame.scale);
  s.field.wellbore_scale = frame.scale;
  s.field.wellbore_radius = meshed.wells[0].radius;  // r_w, or the mean equivalent radius of the scaled block
  s.reference = field_reference(axis);
  s.equivalent_radius = equivalent_wellbore_radius(scale, s.reference.direction, ws.radius);
  // q' per unit of scaled source length; the rate is the same in both frames (det S = 1).
  const double q_per_length = 4 * kPi * kDarcyMetric * s.permeability * s.field.coefficient / s.viscosity;
  s.exact_rate = q_per_length * s.field.scaled_source_length();
  const double leg = norm(axis[s.reference.leg + 1] - axis[s.reference.leg]);
  s.slab_half_width = std::max(0.1 * leg, ws.segment_length);
  return s;
}

AccuracyErrors measure_accuracy(const PolyMesh& mesh, const MeshGeometry& geo,
                                const std::vector<WellConnection>& connections, const AccuracySetup& setup,
                                std::vector<double>* pressure_out, std::vector<PressureSample>* samples) {
  const LineSourceField& field = setup.field;
  FlowProblem pb;
  pb.mesh = &mesh;
  pb.geo = &geo;
  pb.viscosity_cp = setup.viscosity;
  pb.gravity = false;  // the manufactured solution has no gravity term
  pb.connections = connections;
  pb.outer_dirichlet = [&](Vec3 x) { return field.pressure(x); };
  // Wellbore faces (hybrid): the exact p on the mesh's own wellbore surface, the Dirichlet data
  // of the manufactured problem. Connections (Peaceman): the pressure of a real well of radius
  // r_w as the line source sees it, p at the equivalent radius (docs/accuracy.md).
  if (connections.empty())
    pb.wellbore_pressure = [&](Vec3 x) { return field.wellbore_pressure(x); };
  else
    pb.wellbore_pressure = [&](Vec3 x) { return field.equivalent_wellbore_pressure(x); };
  const Transmissibilities tr = compute_transmissibilities(mesh, geo);
  const FlowSolution sol = solve_tpfa(pb, tr);
  std::vector<double> residual;
  if (samples) {
    std::vector<double> exact_p(mesh.n_cells());
    for (int c = 0; c < mesh.n_cells(); ++c) exact_p[c] = field.pressure(mesh.cell_fv_center[c]);
    residual = mass_balance_residual(pb, tr, exact_p);
  }

  AccuracyErrors e;
  e.cells = mesh.n_cells();
  e.iterations = sol.iterations;
  e.relative_residual = sol.relative_residual;
  e.exact_rate = setup.exact_rate;
  e.rate = sol.well_rate_m3_per_day.empty() ? 0.0 : sol.well_rate_m3_per_day[0];
  e.rate_rel_error = (e.rate - e.exact_rate) / e.exact_rate;

  std::set<int32_t> connected;
  for (const WellConnection& wc : connections) connected.insert(wc.cell);
  const std::vector<Vec3>& traj = field.polyline;
  const int ref_leg = setup.reference.leg;
  const double ref_len = norm(traj[ref_leg + 1] - traj[ref_leg]);
  std::vector<double> leg_start(traj.size(), 0.0);  // arc length at each polyline point
  for (size_t k = 1; k < traj.size(); ++k) leg_start[k] = leg_start[k - 1] + norm(traj[k] - traj[k - 1]);
  double sum_v = 0, sum_ve2 = 0;
  for (int c = 0; c < mesh.n_cells(); ++c) {
    if (connected.count(c)) continue;
    const Vec3 x = mesh.cell_fv_center[c];
    const PolylinePoint cp = closest_on_polyline(x, traj);
    if (cp.distance > setup.near_radius) continue;
    const double exact = field.pressure(x);
    const double err = std::fabs(sol.pressure[c] - exact) / setup.drawdown;
    ++e.near_well_cells;
    const bool beyond_end = (cp.leg == 0 && cp.t == 0.0) || (cp.leg == static_cast<int>(traj.size()) - 2 && cp.t == 1.0);
    double& side = beyond_end ? e.near_well_max_beyond_ends : e.near_well_max_lateral;
    side = std::max(side, err);
    const int region = mesh.cell_region[c];
    if (region >= 0 && region < 3) e.near_well_max_by_region[region] = std::max(e.near_well_max_by_region[region], err);
    if (err > e.near_well_pressure_rel_error) {
      e.near_well_pressure_rel_error = err;
      e.worst_cell = c;
      e.worst_region = mesh.cell_region[c];
      e.worst_point = x;
      e.worst_distance = cp.distance;
    }
    const double v = std::fabs(geo.cell_volume[c]);
    sum_v += v;
    sum_ve2 += v * err * err;
    if (samples) {
      PressureSample s;
      s.distance = cp.distance;
      s.scaled_distance = field.scaled_distance(x);
      s.pressure = sol.pressure[c];
      s.exact = exact;
      s.region = mesh.cell_region[c];
      s.in_slab = cp.leg == ref_leg && std::fabs(cp.t - 0.5) * ref_len <= setup.slab_half_width;
      s.cell = c;
      s.x = x;
      const double along = leg_start[cp.leg] + cp.t * (leg_start[cp.leg + 1] - leg_start[cp.leg]);
      s.to_end = std::min(along, leg_start.back() - along);
      s.residual = residual[c] / setup.exact_rate;
      samples->push_back(s);
    }
  }
  e.l2_pressure_rel_error = sum_v > 0 ? std::sqrt(sum_ve2 / sum_v) : 0.0;
  if (pressure_out) *pressure_out = sol.pressure;
  return e;
}

CaseSpec anisotropic_case(const CaseSpec& cs, double kv_kh, double kx_ky) {
  if (!(kv_kh > 0) || !std::isfinite(kv_kh)) throw InputError("--kv-kh: must be a positive number");
  if (!(kx_ky > 0) || !std::isfinite(kx_ky)) throw InputError("--kx-ky: must be a positive number");
  CaseSpec out = cs;
  if (kv_kh == 1 && kx_ky == 1) return out;
  const Vec3 k = cs.reservoir.permeability;
  const double kh = std::sqrt(k.x * k.y);
  out.reservoir.permeability = {kh * std::sqrt(kx_ky), kh / std::sqrt(kx_ky), kv_kh * kh};
  auto tag = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    std::string t = buf;
    for (char& ch : t)
      if (ch == '.') ch = 'p';
    return t;
  };
  out.name = cs.name + "_kvkh" + tag(kv_kh) + "_kxky" + tag(kx_ky);
  return out;
}

CaseSpec refine_case(const CaseSpec& cs, int factor) {
  CaseSpec out = cs;
  if (factor <= 1) return out;
  auto split = [factor](const std::vector<double>& v) {
    std::vector<double> r;
    for (size_t i = 0; i + 1 < v.size(); ++i)
      for (int j = 0; j < factor; ++j) r.push_back(v[i] + (v[i + 1] - v[i]) * j / factor);
    r.push_back(v.back());
    return r;
  };
  out.reservoir.x = split(cs.reservoir.x);
  out.reservoir.y = split(cs.reservoir.y);
  out.reservoir.z = split(cs.reservoir.z);
  for (WellSpec& w : out.wells) {
    w.rings *= factor;
    w.sectors *= factor;
    w.segment_length /= factor;
  }
  return out;
}

AccuracyStudy run_accuracy_study(const CaseSpec& cs, int levels, const AccuracyOptions& opt) {
  AccuracyStudy st;
  st.case_name = cs.name;
  CaseSpec main_case = cs, euclidean_case = cs;
  if (opt.compare_metrics) main_case.metric = MeshMetric::Permeability;
  euclidean_case.metric = MeshMetric::Euclidean;
  st.metric = main_case.metric;
  st.setup = make_accuracy_setup(main_case, opt);
  if (opt.compare_metrics) st.setup_euclidean = make_accuracy_setup(euclidean_case, opt);
  for (int f = 1; f <= std::max(1, levels); ++f) {
    const CaseSpec level_case = refine_case(main_case, f);
    RefinementLevel lv;
    lv.factor = f;
    // Each level's exact solution follows that level's meshed axis (the bend wedges are
    // re-planned with the finer segments).
    // The level's case as load_case would give it: in a permeability frame its layers near the
    // well split (near_well_layers.hpp). The hybrid mesh and Cartesian + Peaceman share that grid.
    CaseSpec split_case = level_case;
    split_layers_near_wells(split_case);
    const bool split = split_case.reservoir.z != level_case.reservoir.z;
    const AccuracySetup setup =
        f == 1 && !split ? st.setup : make_accuracy_setup(split ? split_case : level_case, opt);
    if (f == 1) st.setup = setup;
    {
      const HybridMesh hm = build_hybrid_mesh(split_case);
      if (f == 1) st.notes = hm.notes;
      lv.hybrid_cells = hm.mesh.n_cells();
      lv.hybrid = measure_accuracy(hm.mesh, hm.geometry, {}, setup, nullptr, f == 1 ? &st.hybrid_samples : nullptr);
    }
    if (opt.compare_metrics) {
      const CaseSpec e_case = refine_case(euclidean_case, f);
      const AccuracySetup e_setup = f == 1 ? st.setup_euclidean : make_accuracy_setup(e_case, opt);
      const HybridMesh hm = build_hybrid_mesh(e_case);
      lv.has_euclidean = true;
      lv.hybrid_euclidean_cells = hm.mesh.n_cells();
      lv.hybrid_euclidean = measure_accuracy(hm.mesh, hm.geometry, {}, e_setup);
    }
    {
      // Peaceman's well index needs cells several r_w wide across the well (r_o > r_w): where the
      // split layers are thinner, the reference runs on the level's own grid (and says so).
      CartesianMesh cm = make_cartesian_mesh(split_case.reservoir);
      std::vector<WellConnection> wells;
      try {
        wells = peaceman_connections(cm, setup.field.polyline, split_case.wells[0].radius, 0);
      } catch (const std::invalid_argument& e) {
        if (!split) throw;
        st.notes.push_back("level " + std::to_string(f) + ": Cartesian + Peaceman on the grid without the layer split (" +
                           e.what() + " on the split grid)");
        cm = make_cartesian_mesh(level_case.reservoir);
        wells = peaceman_connections(cm, setup.field.polyline, level_case.wells[0].radius, 0);
      }
      lv.cartesian_cells = cm.mesh.n_cells();
      lv.peaceman = measure_accuracy(cm.mesh, cm.geo, wells, setup, nullptr, f == 1 ? &st.peaceman_samples : nullptr);
    }
    if (f == 1) st.hybrid = lv.hybrid, st.peaceman = lv.peaceman;
    st.refinement.push_back(lv);
  }
  return st;
}

}  // namespace hm
