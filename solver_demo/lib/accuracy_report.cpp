// accuracy.json and the SVG plot of the accuracy study.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>

#include "accuracy.hpp"
#include "meshgen/core/text_file.hpp"

namespace hm {

namespace {

const char* region_name(int r) {
  switch (r) {
    case kReservoir: return "reservoir";
    case kTransition: return "transition";
    case kWell: return "well";
    default: return "?";
  }
}

nlohmann::json errors_json(const AccuracyErrors& e) {
  return {{"rate_rel_error", e.rate_rel_error},
          {"near_well_pressure_rel_error", e.near_well_pressure_rel_error},
          {"l2_pressure_rel_error", e.l2_pressure_rel_error},
          {"rate_m3_per_day", e.rate},
          {"exact_rate_m3_per_day", e.exact_rate},
          {"near_well_diagnostics",
           {{"max_reservoir_cells", e.near_well_max_by_region[kReservoir]},
            {"max_transition_cells", e.near_well_max_by_region[kTransition]},
            {"max_well_cells", e.near_well_max_by_region[kWell]},
            {"max_lateral", e.near_well_max_lateral},
            {"max_beyond_ends", e.near_well_max_beyond_ends}}},
          {"cells", e.cells},
          {"near_well_cells", e.near_well_cells},
          {"worst_cell",
           {{"cell", e.worst_cell},
            {"region", region_name(e.worst_region)},
            {"fv_center", {e.worst_point.x, e.worst_point.y, e.worst_point.z}},
            {"distance_to_trajectory", e.worst_distance}}},
          {"iterations", e.iterations},
          {"relative_residual", e.relative_residual}};
}

WriteStatus write_text(const std::string& path, const std::string& text) {
  std::string error;
  if (!write_text_file(path, text, &error)) return {false, error};
  return {};
}

// ---------------------------------------------------------------- SVG

std::string fmt(double v, int prec = 4) {
  std::ostringstream os;
  os << std::setprecision(prec) << v;
  return os.str();
}

struct Panel {
  double x0, y0, w, h;              // pixel box
  double dmin, dmax, vmin, vmax;    // data box (x is log10 of the distance)
  double px(double d) const { return x0 + w * (std::log10(d) - std::log10(dmin)) / (std::log10(dmax) - std::log10(dmin)); }
  double py(double v) const { return y0 + h * (1 - (v - vmin) / (vmax - vmin)); }
  bool inside(double d, double v) const { return d >= dmin && d <= dmax && v >= vmin && v <= vmax; }
};

// A "nice" tick step covering span with about n ticks.
double nice_step(double span, int n) {
  const double raw = span / n, mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * mag >= raw) return m * mag;
  return 10 * mag;
}

void axes(std::ostringstream& s, const Panel& p, const std::string& xlabel, const std::string& ylabel,
          const std::string& title) {
  s << "<rect x='" << p.x0 << "' y='" << p.y0 << "' width='" << p.w << "' height='" << p.h
    << "' fill='none' stroke='#000'/>\n";
  for (int e = static_cast<int>(std::floor(std::log10(p.dmin))); e <= static_cast<int>(std::ceil(std::log10(p.dmax))); ++e)
    for (int m = 1; m <= 9; ++m) {
      const double d = m * std::pow(10.0, e);
      if (d < p.dmin || d > p.dmax) continue;
      const double x = p.px(d);
      s << "<line x1='" << x << "' y1='" << p.y0 + p.h << "' x2='" << x << "' y2='" << p.y0 + p.h - (m == 1 ? 8 : 4)
        << "' stroke='#000'/>\n";
      if (m == 1)
        s << "<text x='" << x << "' y='" << p.y0 + p.h + 16 << "' font-size='12' text-anchor='middle'>" << fmt(d)
          << "</text>\n";
    }
  const double step = nice_step(p.vmax - p.vmin, 6);
  for (double v = std::ceil(p.vmin / step) * step; v <= p.vmax + 1e-9 * step; v += step) {
    const double y = p.py(v);
    s << "<line x1='" << p.x0 << "' y1='" << y << "' x2='" << p.x0 + p.w << "' y2='" << y
      << "' stroke='#ddd'/>\n<text x='" << p.x0 - 6 << "' y='" << y + 4 << "' font-size='12' text-anchor='end'>"
      << fmt(std::fabs(v) < 1e-12 * step ? 0.0 : v) << "</text>\n";
  }
  s << "<text x='" << p.x0 + p.w / 2 << "' y='" << p.y0 + p.h + 34
    << "' font-size='13' text-anchor='middle'>" << xlabel << "</text>\n";
  s << "<text x='" << p.x0 - 52 << "' y='" << p.y0 + p.h / 2 << "' font-size='13' text-anchor='middle' transform='rotate(-90 "
    << p.x0 - 52 << ' ' << p.y0 + p.h / 2 << ")'>" << ylabel << "</text>\n";
  s << "<text x='" << p.x0 + p.w / 2 << "' y='" << p.y0 - 10 << "' font-size='14' text-anchor='middle'>" << title
    << "</text>\n";
}

void marker(std::ostringstream& s, const Panel& p, double d, double v, bool hybrid) {
  if (!p.inside(d, v)) return;
  const double x = p.px(d), y = p.py(v);
  if (hybrid)
    s << "<circle cx='" << fmt(x, 6) << "' cy='" << fmt(y, 6) << "' r='2.5' fill='none' stroke='#1f77b4'/>\n";
  else
    s << "<path d='M" << fmt(x - 3, 6) << ',' << fmt(y - 3, 6) << "l6,6m0,-6l-6,6' stroke='#d62728'/>\n";
}

void vline(std::ostringstream& s, const Panel& p, double d, const std::string& label) {
  if (d < p.dmin || d > p.dmax) return;
  const double x = p.px(d);
  s << "<line x1='" << x << "' y1='" << p.y0 << "' x2='" << x << "' y2='" << p.y0 + p.h
    << "' stroke='#888' stroke-dasharray='4,3'/>\n<text x='" << x + 3 << "' y='" << p.y0 + 14
    << "' font-size='11' fill='#555'>" << label << "</text>\n";
}

void legend(std::ostringstream& s, double x, double y) {
  s << "<line x1='" << x << "' y1='" << y << "' x2='" << x + 24 << "' y2='" << y << "' stroke='#000' stroke-width='1.5'/>"
    << "<text x='" << x + 30 << "' y='" << y + 4 << "' font-size='12'>exact (line source)</text>\n";
  s << "<circle cx='" << x + 12 << "' cy='" << y + 18 << "' r='2.5' fill='none' stroke='#1f77b4'/>"
    << "<text x='" << x + 30 << "' y='" << y + 22 << "' font-size='12'>hybrid mesh</text>\n";
  s << "<path d='M" << x + 9 << ',' << y + 33 << "l6,6m0,-6l-6,6' stroke='#d62728'/>"
    << "<text x='" << x + 30 << "' y='" << y + 40 << "' font-size='12'>Cartesian + Peaceman</text>\n";
}

}  // namespace

WriteStatus write_accuracy_json(const std::string& path, const AccuracyStudy& st) {
  nlohmann::json j;
  j["case"] = st.case_name;
  j["metric"] = st.metric == MeshMetric::Permeability ? "permeability" : "euclidean";
  const AccuracySetup& s = st.setup;
  j["setup"] = {{"exact_solution", "uniform line source on the trajectory (finite-segment potentials summed)"},
                {"source_inset_m", s.source_inset},
                {"wellbore_pressure_bar", s.p_w},
                {"drawdown_bar", s.drawdown},
                {"near_well_radius_m", s.near_radius},
                {"exact_rate_m3_per_day", s.exact_rate},
                {"rate_per_length_m3_per_day_per_m", s.exact_rate / s.field.source_length()},
                {"permeability_md", {s.permeability_tensor.x, s.permeability_tensor.y, s.permeability_tensor.z}},
                {"scaled_frame_permeability_md", s.permeability},
                {"scale", {s.field.scale.x, s.field.scale.y, s.field.scale.z}},
                {"equivalent_wellbore_radius_m", s.equivalent_radius},
                {"wellbore_frame_scale", {s.field.wellbore_scale.x, s.field.wellbore_scale.y, s.field.wellbore_scale.z}},
                {"wellbore_frame_radius_m", s.field.wellbore_radius},
                {"reference_point", {s.reference.mid.x, s.reference.mid.y, s.reference.mid.z}},
                {"reference_normal", {s.reference.normal.x, s.reference.normal.y, s.reference.normal.z}}};
  j["hybrid"] = errors_json(st.hybrid);
  j["cartesian_peaceman"] = errors_json(st.peaceman);
  j["refinement"] = nlohmann::json::array();
  for (const RefinementLevel& lv : st.refinement) {
    nlohmann::json l = {{"factor", lv.factor},
                        {"hybrid_cells", lv.hybrid_cells},
                        {"cartesian_cells", lv.cartesian_cells},
                        {"hybrid", errors_json(lv.hybrid)},
                        {"cartesian_peaceman", errors_json(lv.peaceman)}};
    if (lv.has_euclidean) {
      l["hybrid_euclidean_cells"] = lv.hybrid_euclidean_cells;
      l["hybrid_euclidean"] = errors_json(lv.hybrid_euclidean);
    }
    j["refinement"].push_back(l);
  }
  if (!st.refinement.empty() && st.refinement[0].has_euclidean) {
    j["hybrid_euclidean"] = errors_json(st.refinement[0].hybrid_euclidean);
    j["setup_euclidean"] = {{"exact_rate_m3_per_day", st.setup_euclidean.exact_rate},
                            {"wellbore_frame_scale", {st.setup_euclidean.field.wellbore_scale.x,
                                                      st.setup_euclidean.field.wellbore_scale.y,
                                                      st.setup_euclidean.field.wellbore_scale.z}},
                            {"wellbore_frame_radius_m", st.setup_euclidean.field.wellbore_radius}};
  }
  j["notes"] = st.notes;
  return write_text(path, j.dump(2) + "\n");
}

WriteStatus write_accuracy_svg(const std::string& path, const AccuracyStudy& st) {
  const AccuracySetup& s = st.setup;
  // Anisotropic k: the abscissa is the distance in the scaled frame x / s, where the exact field
  // is the radial law whatever the direction (docs/accuracy.md).
  const Vec3 sc = s.field.scale;
  const bool scaled = !(sc.x == 1 && sc.y == 1 && sc.z == 1);
  const double dmin = scaled ? s.equivalent_radius : s.field.r_w;
  const double dmax = scaled ? s.field.scaled_distance(s.reference.mid + s.near_radius * s.reference.normal) : s.near_radius;
  const std::string xlabel = scaled ? "distance from the well in the scaled frame x / sqrt(k / k0) (m, log scale)"
                                    : "distance from the well trajectory (m, log scale)";
  auto dist = [&](const PressureSample& p) { return scaled ? p.scaled_distance : p.distance; };
  const double sign = s.field.coefficient >= 0 ? 1.0 : -1.0;  // producer: p rises away from the well
  const double p_far = s.p_w + sign * s.drawdown;
  Panel top{90, 50, 640, 330, dmin, dmax, std::min(s.p_w, p_far), std::max(s.p_w, p_far)};
  const double pad = 0.05 * (top.vmax - top.vmin);
  top.vmin -= pad, top.vmax += pad;
  // Error panel: symmetric range covering every near-well sample (percent of the drawdown).
  double emax = 0;
  for (const auto* v : {&st.hybrid_samples, &st.peaceman_samples})
    for (const PressureSample& p : *v) emax = std::max(emax, std::fabs(p.pressure - p.exact) / s.drawdown * 100);
  emax = std::max(emax, 1e-3) * 1.1;
  Panel bottom{90, 470, 640, 300, dmin, dmax, -emax, emax};

  std::ostringstream o;
  o << "<?xml version='1.0' encoding='UTF-8'?>\n<svg xmlns='http://www.w3.org/2000/svg' width='800' height='860' "
       "font-family='sans-serif'>\n<rect width='100%' height='100%' fill='#fff'/>\n";
  axes(o, top, xlabel, "pressure (bar)",
       st.case_name + ": cells within " + fmt(s.slab_half_width, 3) + " m of the reference cross-section");
  axes(o, bottom, xlabel, "(p - p_exact) / drawdown (%)", "error of every cell within 3 drainage radii");
  for (const Panel* p : {&top, &bottom}) {
    if (!scaled) vline(o, *p, s.near_radius / 3, "drainage radius");
  }
  // Exact curve along the reference perpendicular (of the scaled leg when anisotropic).
  const Vec3 mid_s = to_scaled(s.reference.mid, sc), normal_s = perpendicular_unit(to_scaled(s.reference.direction, sc));
  o << "<polyline fill='none' stroke='#000' stroke-width='1.5' points='";
  for (int i = 0; i <= 200; ++i) {
    const double d = dmin * std::pow(dmax / dmin, i / 200.0);
    o << fmt(top.px(d), 6) << ',' << fmt(top.py(s.field.pressure(from_scaled(mid_s + d * normal_s, sc))), 6) << ' ';
  }
  o << "'/>\n";
  o << "<line x1='" << bottom.x0 << "' y1='" << bottom.py(0) << "' x2='" << bottom.x0 + bottom.w << "' y2='"
    << bottom.py(0) << "' stroke='#000' stroke-width='1.5'/>\n";
  for (const PressureSample& p : st.peaceman_samples) {
    if (p.in_slab) marker(o, top, dist(p), p.pressure, false);
    marker(o, bottom, dist(p), (p.pressure - p.exact) / s.drawdown * 100, false);
  }
  for (const PressureSample& p : st.hybrid_samples) {
    if (p.in_slab) marker(o, top, dist(p), p.pressure, true);
    marker(o, bottom, dist(p), (p.pressure - p.exact) / s.drawdown * 100, true);
  }
  legend(o, top.x0 + 20, top.y0 + 20);
  o << "<text x='90' y='830' font-size='12'>hybrid mesh: rate error " << fmt(st.hybrid.rate_rel_error * 100, 3)
    << " %, near-well pressure error " << fmt(st.hybrid.near_well_pressure_rel_error * 100, 3)
    << " % of the drawdown</text>\n<text x='90' y='848' font-size='12'>Cartesian + Peaceman: rate error "
    << fmt(st.peaceman.rate_rel_error * 100, 3) << " %, near-well pressure error "
    << fmt(st.peaceman.near_well_pressure_rel_error * 100, 3) << " % of the drawdown</text>\n";
  o << "</svg>\n";
  return write_text(path, o.str());
}

WriteStatus write_accuracy_cells_csv(const std::string& path, const AccuracyStudy& st) {
  std::ostringstream o;
  o << std::setprecision(10) << "cell,region,x,y,z,distance,scaled_distance,to_end,pressure,exact,error,residual\n";
  for (const PressureSample& p : st.hybrid_samples)
    o << p.cell << ',' << region_name(p.region) << ',' << p.x.x << ',' << p.x.y << ',' << p.x.z << ',' << p.distance
      << ',' << p.scaled_distance << ',' << p.to_end << ',' << p.pressure << ',' << p.exact << ','
      << (p.pressure - p.exact) / st.setup.drawdown << ',' << p.residual << '\n';
  return write_text(path, o.str());
}

}  // namespace hm
