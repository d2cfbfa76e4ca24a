// Runs every finite-volume check on a mesh and collects the results, the quality
// statistics (paper Table 2) and the histograms (paper Figure 19) into one FvReport, which
// the JSON and HTML writers and the fvcheck CLI turn into files. Format: docs/fvcheck.md.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "checks.hpp"
#include "meshgen/core/text_file.hpp"
#include "quality.hpp"

namespace hm {

/// Summary of per-face transmissibilities (filled by the caller, e.g. the fvcheck CLI).
struct TransmissibilitySummary {
  bool present = false;  ///< false: not computed, left out of the reports
  int64_t count = 0;     ///< faces with a non-zero value
  double min = 0, max = 0;  ///< over the faces with a non-zero value
  int64_t negative = 0;  ///< faces with T < 0 or not finite (reported, never silently abs()-ed)
  int64_t negative_halves = 0;          ///< negative or non-finite half-transmissibilities
  std::vector<int32_t> negative_faces;  ///< first faces concerned
  /// A negative or non-finite transmissibility (face or half) is a failed check.
  bool ok() const { return !present || (negative == 0 && negative_halves == 0); }
};
/// Summary of one value per face (0 = no connection).
TransmissibilitySummary summarize_transmissibilities(const std::vector<double>& face_values);

/// A picture of the mesh shown in the HTML report (rendered by exporters/png, not by this module).
struct ReportPicture {
  std::string caption;
  std::string src;  ///< the <img> source: a data: URI (the report stays self-contained) or a path
};

struct FvReport {
  std::string source;  ///< file name or label
  int64_t cells = 0, faces = 0, nodes = 0, boundary_faces = 0;
  CheckOptions options;
  CsrReport structure;                       ///< CSR invariants; when not ok the checks are skipped
  /// Cells the shape checks do not judge: a corner-point model's cells (PolyMesh::reservoir_cells_are_model).
  int64_t model_cells_not_judged = 0;
  /// Connections without a face (PolyMesh::nnc_cells: a model's NNC and MINPV connections); their pairs and values are
  /// checked with the structure, they have no geometry to judge.
  int64_t connections_without_face = 0;
  std::vector<CheckResult> checks;           ///< fixed order: convexity, conformity, closure, volume,
                                             ///< orthogonality, auto_centering, planarity
  std::vector<double> q_s, q_o_cell, q_p_cell;  ///< per cell (empty if skipped); Q_O Euclidean
  /// Per cell: max over its faces of the K-non-orthogonality (deg, face_k_nonorthogonality);
  /// empty when a cell has no positive finite permeability.
  std::vector<double> k_angle_cell;
  std::vector<double> k_angle_interior_cell;  ///< the same over interior faces only
  Stats k_angle_all, k_angle_interior_all;
  /// The mesh was built in a permeability frame (metric_scale != 1): the orthogonality check
  /// measures Q_O in the metric of the frame's K (90 - face_frame_nonorthogonality); q_o_* stay
  /// Euclidean, k_angle_* use each cell's own K.
  bool k_metric = false;
  std::vector<int32_t> cell_region;          ///< copy of the mesh's regions (histograms per region)
  Stats q_s_all, q_o_all, q_p_all;           ///< over all cells
  /// OpenFOAM's face skewness over every face, as checkMesh measures it (not an FV property: a
  /// quality figure of the OpenFOAM export, which checkMesh fails above its limit of 4).
  SkewnessSummary openfoam_skewness;
  /// checkMesh's non-orthogonality (between the face normal and the line between the cells'
  /// centroids, not their FV centres), likewise a figure of the OpenFOAM export.
  NonOrthogonalitySummary openfoam_nonorthogonality;
  std::vector<RegionQuality> by_region;
  TransmissibilitySummary transmissibility;
  std::vector<std::string> notes;            ///< reader warnings etc., shown in the reports
  std::vector<ReportPicture> pictures;       ///< HTML only: shown after the counts, in this order

  /// True when the structure is valid, every check holds and no transmissibility is negative.
  bool ok() const;
  const CheckResult* find(const std::string& name) const;
};

/// Runs the checks. h_ref: reference length per cell for Q_S (empty: mean edge length).
/// build: the builder's report if the mesh was just assembled (folded into conformity).
/// geometry_out: receives compute_geometry(mesh) when the structure is valid (left empty
/// otherwise), so that a caller needing it too does not compute it a second time.
FvReport run_fvcheck(const PolyMesh& mesh, const CheckOptions& opt, const std::vector<double>& h_ref = {},
                     const BuildReport* build = nullptr, MeshGeometry* geometry_out = nullptr);

/// A few lines for a terminal.
std::string report_summary_text(const FvReport& r);

/// One line on checkMesh's skewness (its maximum, the faces above checkMesh's limit): fvcheck's
/// summary and meshgen's OpenFOAM export say it in the same words.
std::string openfoam_skewness_text(const SkewnessSummary& s);
/// The same for checkMesh's non-orthogonality (its maximum and average, its severe faces and errors).
std::string openfoam_nonorthogonality_text(const NonOrthogonalitySummary& s);

/// Self-contained HTML page (inline CSS and SVG).
std::string report_html(const FvReport& r);


}  // namespace hm
