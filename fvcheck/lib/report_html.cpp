// Self-contained HTML report: inline CSS and SVG, no script, no network.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "report.hpp"

namespace hm {

namespace {

std::string fmt(double x, const char* f = "%.4g") {
  if (std::isnan(x)) return "NaN";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  char b[64];
  std::snprintf(b, sizeof b, f, x);
  return b;
}

std::string ids_text(const std::vector<int32_t>& ids) {
  std::string s;
  for (size_t i = 0; i < ids.size(); ++i) s += (i ? ", " : "") + std::to_string(ids[i]);
  return s.empty() ? "&ndash;" : s;
}

// A bar chart of nbins equal bins over [lo, hi].
std::string svg_histogram(const std::string& title, const std::vector<int64_t>& counts, double lo, double hi,
                          const char* tick_fmt, int tick_every, const char* color) {
  const int W = 360, H = 220, L = 44, R = 10, T = 36, B = 34;
  const int pw = W - L - R, ph = H - T - B;
  const int nb = static_cast<int>(counts.size());
  const int64_t cmax = std::max<int64_t>(1, *std::max_element(counts.begin(), counts.end()));
  std::ostringstream s;
  s << "<svg xmlns='http://www.w3.org/2000/svg' width='" << W << "' height='" << H << "' viewBox='0 0 " << W << ' '
    << H << "' role='img'>";
  s << "<text x='" << W / 2 << "' y='16' class='t'>" << xml_escape(title) << "</text>";
  s << "<line x1='" << L << "' y1='" << T + ph << "' x2='" << L + pw << "' y2='" << T + ph << "' class='ax'/>";
  s << "<line x1='" << L << "' y1='" << T << "' x2='" << L << "' y2='" << T + ph << "' class='ax'/>";
  s << "<text x='" << L - 4 << "' y='" << T + 4 << "' class='yl'>" << cmax << "</text>";
  s << "<text x='" << L - 4 << "' y='" << T + ph << "' class='yl'>0</text>";
  const double bw = static_cast<double>(pw) / nb;
  for (int i = 0; i < nb; ++i) {
    // At least one pixel for a non-empty bin, so that a few cells among thousands still show.
    const double h = counts[i] > 0 ? std::max(1.0, ph * static_cast<double>(counts[i]) / static_cast<double>(cmax)) : 0.0;
    const double x = L + i * bw;
    if (counts[i] > 0) {
      s << "<rect x='" << fmt(x + 1, "%.1f") << "' y='" << fmt(T + ph - h, "%.1f") << "' width='"
        << fmt(std::max(bw - 2, 1.0), "%.1f") << "' height='" << fmt(h, "%.1f") << "' fill='" << color
        << "'><title>" << counts[i] << "</title></rect>";
        s << "<text x='" << fmt(x + bw / 2, "%.1f") << "' y='" << fmt(T + ph - h - 3, "%.1f") << "' class='c'>"
          << counts[i] << "</text>";
    }
  }
  for (int i = 0; i <= nb; i += tick_every) {
    const double x = L + i * bw;
    s << "<line x1='" << fmt(x, "%.1f") << "' y1='" << T + ph << "' x2='" << fmt(x, "%.1f") << "' y2='"
      << T + ph + 4 << "' class='ax'/>";
    s << "<text x='" << fmt(x, "%.1f") << "' y='" << T + ph + 16 << "' class='xl'>"
      << fmt(lo + (hi - lo) * i / nb, tick_fmt) << "</text>";
  }
  s << "</svg>";
  return s.str();
}

const char* kCss = R"(
body{font-family:Helvetica,Arial,sans-serif;margin:24px;color:#222;max-width:1150px}
h1{font-size:22px;margin:0 0 4px 0} h2{font-size:17px;border-bottom:1px solid #999;padding-bottom:3px;margin-top:26px}
.badge{display:inline-block;padding:3px 12px;border-radius:4px;color:#fff;font-weight:bold;font-size:15px}
.ok{background:#2e7d32} .fail{background:#c62828}
table{border-collapse:collapse;margin:8px 0;font-size:13px}
th,td{border-top:1px solid #444;border-bottom:1px solid #444;padding:4px 10px;text-align:right}
th{background:#f0f0f0} td.l,th.l{text-align:left}
tr.bad td,p.bad{color:#c62828;font-weight:bold}
.grid{display:flex;flex-wrap:wrap;gap:8px}
svg{border:1px solid #ddd;background:#fff}
svg .t{font-size:13px;text-anchor:middle;font-weight:bold}
svg .ax{stroke:#333;stroke-width:1}
svg .yl{font-size:10px;text-anchor:end}
svg .xl{font-size:10px;text-anchor:middle}
svg .c{font-size:8px;text-anchor:middle;fill:#333}
.small{font-size:12px;color:#555}
)";

}  // namespace

std::string report_html(const FvReport& r) {
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'><title>fvcheck: " << xml_escape(r.source)
    << "</title><style>" << kCss << "</style></head><body>\n";
  h << "<h1>fvcheck report &mdash; " << xml_escape(r.source) << "</h1>\n";
  h << "<p><span class='badge " << (r.ok() ? "ok'>ALL CHECKS HOLD" : "fail'>CHECKS FAILED") << "</span></p>\n";

  // Counts.
  h << "<h2>Mesh</h2><table><tr><th class='l'>item</th><th>count</th></tr>";
  h << "<tr><td class='l'>cells</td><td>" << r.cells << "</td></tr>";
  h << "<tr><td class='l'>faces</td><td>" << r.faces << "</td></tr>";
  h << "<tr><td class='l'>boundary faces</td><td>" << r.boundary_faces << "</td></tr>";
  h << "<tr><td class='l'>nodes</td><td>" << r.nodes << "</td></tr>";
  if (r.connections_without_face > 0)
    h << "<tr><td class='l'>connections without a face (NNC, MINPV)</td><td>" << r.connections_without_face << "</td></tr>";
  for (const RegionQuality& rq : r.by_region)
    h << "<tr><td class='l'>" << xml_escape(rq.name) << " cells</td><td>" << rq.cells << "</td></tr>";
  h << "</table>\n";
  for (const std::string& n : r.notes) h << "<p class='small'>Note: " << xml_escape(n) << "</p>\n";
  if (r.model_cells_not_judged > 0)
    h << "<p class='small'>Convexity, orthogonality, auto-centering and planarity judge the "
      << r.cells - r.model_cells_not_judged << " near-well cells; the " << r.model_cells_not_judged
      << " cells of the corner-point model are the user's.</p>\n";

  // Checks.
  if (!r.pictures.empty()) {
    h << "<h2>Pictures</h2>";
    for (const ReportPicture& p : r.pictures)
      h << "<figure><img src='" << xml_escape(p.src) << "' alt='" << xml_escape(p.caption)
        << "' style='max-width:100%'><figcaption class='small'>" << xml_escape(p.caption) << "</figcaption></figure>\n";
  }

  h << "<h2>Finite-volume checks</h2>";
  if (!r.structure.ok) {
    h << "<p><b>The mesh structure is invalid; the checks were skipped.</b></p><ul>";
    for (const std::string& p : r.structure.problems) h << "<li>" << xml_escape(p) << "</li>";
    h << "</ul>";
  }
  h << "<table><tr><th class='l'>check</th><th class='l'>status</th><th>violations</th><th>worst</th>"
       "<th class='l'>limit</th><th class='l'>worst ids</th></tr>";
  for (const CheckResult& c : r.checks) {
    std::string limit;
    for (const auto& [name, x] : c.measures)
      if (name == "threshold_deg" || name == "tolerance" || name == "rel_tol") limit = name + " " + fmt(x);
    h << "<tr" << (c.ok() ? "" : " class='bad'") << "><td class='l'>" << xml_escape(c.name) << "</td><td class='l'>"
      << (c.skipped ? "skipped" : (c.ok() ? "ok" : "FAILED")) << "</td><td>" << c.violations << "</td><td>"
      << (c.skipped ? "&ndash;" : fmt(c.worst)) << "</td><td class='l'>" << xml_escape(limit) << "</td><td class='l'>"
      << (c.id_kind == IdKind::Face ? "faces " : "cells ") << ids_text(c.worst_ids) << "</td></tr>";
  }
  h << "</table>\n";

  // Failed checks in detail.
  bool any_failed = false;
  for (const CheckResult& c : r.checks)
    if (!c.ok() && !c.skipped) any_failed = true;
  if (any_failed) {
    h << "<h2>Failed checks</h2><ul>";
    for (const CheckResult& c : r.checks) {
      if (c.ok() || c.skipped) continue;
      h << "<li><b>" << xml_escape(c.name) << "</b>: " << c.violations << " violation(s), worst " << fmt(c.worst)
        << "; worst " << (c.id_kind == IdKind::Face ? "faces" : "cells") << ": " << ids_text(c.worst_ids);
      std::string sub;
      for (const auto& [name, n] : c.counts)
        if (n > 0) sub += (sub.empty() ? "" : "; ") + xml_escape(name) + " " + std::to_string(n);
      if (!sub.empty()) h << "<br><span class='small'>" << sub << "</span>";
      for (const auto& [name, ids] : c.id_lists)
        if (!ids.empty()) h << "<br><span class='small'>" << xml_escape(name) << ": " << ids_text(ids) << "</span>";
      h << "</li>";
    }
    h << "</ul>\n";
  }

  if (r.structure.ok) {
    // Quality table in the layout of the paper's Table 2, one column per region.
    h << "<h2>Quality (paper section 6.1)</h2><table><tr><th class='l'>criterion</th><th class='l'></th>"
         "<th>all cells</th>";
    for (const RegionQuality& rq : r.by_region) h << "<th>" << xml_escape(rq.name) << "</th>";
    h << "</tr>";
    struct Row {
      const char* name;
      const char* f;
      Stats all;
      Stats RegionQuality::*member;
      const char* unit;
    };
    const Row rows[5] = {{"Q_S", "%.2f", r.q_s_all, &RegionQuality::q_s, ""},
                         {"Q_O", "%.2f", r.q_o_all, &RegionQuality::q_o, "&deg;"},
                         {"Q_P", "%.2f", r.q_p_all, &RegionQuality::q_p, "&deg;"},
                         {"K-non-orth.", "%.3g", r.k_angle_all, &RegionQuality::k_angle, "&deg;"},
                         {"K-non-orth. (interior faces)", "%.3g", r.k_angle_interior_all, &RegionQuality::k_angle_interior, "&deg;"}};
    for (const Row& row : rows) {
      if ((row.member == &RegionQuality::k_angle || row.member == &RegionQuality::k_angle_interior) &&
          r.k_angle_cell.empty())
        continue;
      const char* what[3] = {"min.", "max.", "average"};
      for (int k = 0; k < 3; ++k) {
        auto pick = [&](const Stats& s) { return k == 0 ? s.min : (k == 1 ? s.max : s.mean); };
        h << "<tr><td class='l'>" << (k == 0 ? row.name : "") << "</td><td class='l'>" << what[k] << "</td><td>"
          << fmt(pick(row.all), row.f) << row.unit << "</td>";
        for (const RegionQuality& rq : r.by_region) h << "<td>" << fmt(pick(rq.*(row.member)), row.f) << row.unit << "</td>";
        h << "</tr>";
      }
    }
    h << "</table><p class='small'>Cell values: Q_S(V) eq. 7, Q_O(V) = min over faces (eq. 9), "
         "Q_P(V) = max over faces (eq. 11); Q_O is Euclidean; K-non-orth.: max over faces of the angle between "
         "K n and the centre-to-centre line (docs/fvcheck.md)"
      << (r.k_metric ? "; this mesh was built in a permeability frame, its orthogonality check is in the K metric" : "")
      << ".</p>\n";
    const SkewnessSummary& sk = r.openfoam_skewness;
    h << "<p" << (sk.above_limit > 0 ? " class='bad'" : "") << ">checkMesh skewness (OpenFOAM's measure, every face): max "
      << fmt(sk.max, "%.4g") << (sk.worst_face >= 0 ? " (face " + std::to_string(sk.worst_face) + ")" : std::string()) << "; "
      << sk.above_limit << (sk.above_limit == 1 ? " face" : " faces") << " above checkMesh's limit of " << fmt(kCheckMeshSkewnessLimit, "%.0f")
      << (sk.above_limit > 0 ? ": checkMesh reports them on the OpenFOAM export (not an FV check)" : "") << ".</p>\n";
    const NonOrthogonalitySummary& no = r.openfoam_nonorthogonality;
    h << "<p" << (no.errors > 0 ? " class='bad'" : "") << ">checkMesh non-orthogonality (OpenFOAM's measure, between "
      << "cell centroids): max " << fmt(no.max, "%.4g") << " deg"
      << (no.worst_face >= 0 ? " (face " + std::to_string(no.worst_face) + ")" : std::string()) << ", average "
      << fmt(no.average, "%.4g") << " deg; " << no.severe << " severe (above " << fmt(kCheckMeshSevereNonOrthogonality, "%.0f")
      << " deg, a warning); " << no.errors << " at 90 deg or more"
      << (no.errors > 0 ? ": checkMesh fails them on the OpenFOAM export (not an FV check)" : "") << ".</p>\n";

    // Histograms per region (paper Figure 19 style), at most 6 regions.
    h << "<h2>Histograms</h2>";
    size_t shown = 0;
    for (const RegionQuality& rq : r.by_region) {
      if (++shown > 6) {
        h << "<p class='small'>More regions not shown.</p>";
        break;
      }
      std::vector<bool> mask(r.cell_region.size());
      for (size_t c = 0; c < mask.size(); ++c) mask[c] = r.cell_region[c] == rq.region;
      h << "<h3>" << xml_escape(rq.name) << " (" << rq.cells << " cells)</h3><div class='grid'>";
      h << svg_histogram("Q_S (bins of 0.1)", histogram(r.q_s, mask, 0.0, 1.0, 10), 0.0, 1.0, "%.1f", 1, "#1565c0");
      h << svg_histogram("Q_O (deg, bins of 5)", histogram(r.q_o_cell, mask, 0.0, 90.0, 18), 0.0, 90.0, "%.0f", 3, "#2e7d32");
      h << svg_histogram("Q_P (deg, bins of 5)", histogram(r.q_p_cell, mask, 0.0, 90.0, 18), 0.0, 90.0, "%.0f", 3, "#ef6c00");
      h << "</div>\n";
    }
  }

  if (r.transmissibility.present) {
    h << "<h2>Transmissibilities</h2><table><tr><th class='l'>faces with T &ne; 0</th><th>min</th><th>max</th>"
         "<th>negative faces</th><th>negative halves</th></tr><tr"
      << (!r.transmissibility.ok() ? " class='bad'" : "") << "><td class='l'>" << r.transmissibility.count
      << "</td><td>" << fmt(r.transmissibility.min) << "</td><td>" << fmt(r.transmissibility.max) << "</td><td>"
      << r.transmissibility.negative << "</td><td>" << r.transmissibility.negative_halves << "</td></tr></table>\n";
    if (!r.transmissibility.negative_faces.empty())
      h << "<p class='small'>Faces with a negative transmissibility (a failed check): " << ids_text(r.transmissibility.negative_faces)
        << "</p>\n";
  }

  h << "<h2>Thresholds</h2><p class='small'>relative geometric tolerance " << fmt(r.options.rel_tol)
    << "; closure " << fmt(r.options.closure_tol) << "; volume &gt; " << fmt(r.options.volume_rel_tol)
    << "&middot;L<sup>3</sup>; Q_O &ge; " << fmt(r.options.min_orthogonality_deg) << "&deg;; Q_P &le; "
    << fmt(r.options.max_planarity_deg) << "&deg;. Definitions: docs/fvcheck.md.</p>\n";
  h << "</body></html>\n";
  return h.str();
}

}  // namespace hm
