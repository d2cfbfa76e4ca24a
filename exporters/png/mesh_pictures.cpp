// VTK rendering of the mesh pictures (docs/output-formats.md, "Pictures"). The mesh comes from the
// mesh file through VTK's own reader, so a picture shows exactly what ParaView would open.
#include "exporters/png/mesh_pictures.hpp"

#include <vtkActor.h>
#include <vtkActor2D.h>
#include <vtkAutoInit.h>
#include <vtkBase64Utilities.h>
#include <vtkCamera.h>
#include <vtkCellData.h>
#include <vtkCellArray.h>
#include <vtkColorTransferFunction.h>
#include <vtkCoordinate.h>
#include <vtkDataArray.h>
#include <vtkDataSetMapper.h>
#include <vtkDataSetSurfaceFilter.h>
#include <vtkIdList.h>
#include <vtkIntArray.h>
#include <vtkLookupTable.h>
#include <vtkMath.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolyDataMapper2D.h>
#include <vtkProperty.h>
#include <vtkProperty2D.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkSmartPointer.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkThreshold.h>
#include <vtkUnstructuredGrid.h>
#include <vtkVariant.h>
#include <vtkWindowToImageFilter.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "exporters/png/offscreen_display.hpp"
#include "meshgen/core/polymesh.hpp"

// The rendering back end and the fonts of the captions (static factories, registered explicitly).
VTK_MODULE_INIT(vtkRenderingOpenGL2);
VTK_MODULE_INIT(vtkRenderingFreeType);

namespace hm {

namespace {

using Vec = std::array<double, 3>;

Vec sub(const Vec& a, const Vec& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec add(const Vec& a, const Vec& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
Vec scale(const Vec& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
double dot(const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec cross(const Vec& a, const Vec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
Vec unit(const Vec& a) {
  const double n = std::sqrt(dot(a, a));
  return n > 0 ? scale(a, 1 / n) : a;
}

/// A trajectory bends "visibly" when the second principal spread of its axis points is at least
/// this fraction of the first (eigenvalues of their covariance): the cut is then the trajectory's
/// best-fit plane; below it the well counts as straight and the cut is the vertical plane through
/// it (the view shows depth downwards). A choice of view, not of geometry.
constexpr double kBentTrajectoryRatio = 1e-4;
/// A cell's bounding box within this fraction of the frame's diagonal from a plane touches it
/// (choice of view only).
constexpr double kTouchingPlane = 1e-9;
/// Empty space around a well's cavity in its pictures, as a fraction of the framed size.
constexpr double kFrameMargin = 0.3;

/// The drawing frame: the file's (x, y, depth) is a left-handed frame in the eyes of a geologist
/// (east, north, down), and VTK would draw it mirrored; pictures are drawn in (x, y, elevation)
/// about the model's centre: x - cx, y - cy, -(z - cz). Elevation points up.
const Vec kUp = {0, 0, 1};
Vec to_drawing(const Vec& p, const Vec& centre) { return {p[0] - centre[0], p[1] - centre[1], centre[2] - p[2]}; }

/// Layout of a picture: the mesh on the left, the legend in a white strip on the right, the
/// caption in a white strip at the bottom (fractions of the picture).
constexpr double kMeshWidth = 0.84;
constexpr double kCaptionHeight = 0.06;

/// The cell arrays the pictures read, one value per cell (components interleaved).
struct CellArrays {
  vtkDataArray* region = nullptr;
  vtkDataArray* fv_center = nullptr;
  vtkDataArray* qs = nullptr;
  vtkDataArray* radial_well = nullptr;
  vtkDataArray* radial_ring = nullptr;
  vtkDataArray* radial_segment = nullptr;
  vtkDataArray* radial_band = nullptr;
  vtkDataArray* radial_cap_center = nullptr;
  vtkDataArray* cavity = nullptr;
};

struct Box {
  Vec lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
         std::numeric_limits<double>::infinity()};
  Vec hi{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
         -std::numeric_limits<double>::infinity()};
  bool empty() const { return lo[0] > hi[0]; }
  void add(const Vec& p) {
    for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], p[d]), hi[d] = std::max(hi[d], p[d]);
  }
  bool intersects(const Box& b) const {
    for (int d = 0; d < 3; ++d)
      if (hi[d] < b.lo[d] || b.hi[d] < lo[d]) return false;
    return true;
  }
};

/// The points of cell c (shifted frame).
void add_cell_points(vtkUnstructuredGrid* grid, vtkIdType c, Box* box) {
  vtkNew<vtkIdList> ids;
  grid->GetCellPoints(c, ids);
  for (vtkIdType i = 0; i < ids->GetNumberOfIds(); ++i) {
    double p[3];
    grid->GetPoint(ids->GetId(i), p);
    box->add({p[0], p[1], p[2]});
  }
}

/// A cut plane through a well: centre, normal (towards the camera), and the picture's up vector.
struct CutPlane {
  Vec centre, normal, up;
};

/// The trajectory as meshed: per cylindrical segment the mean FV centre of its ring-0 cells (on the
/// axis for a regular ring), plus the end caps' centres.
std::vector<Vec> well_axis_points(const CellArrays& a, vtkIdType n_cells, int well, const Vec& shift) {
  std::map<int, std::pair<Vec, int>> by_segment;
  std::vector<Vec> caps;
  for (vtkIdType c = 0; c < n_cells; ++c) {
    if (static_cast<int>(a.radial_well->GetComponent(c, 0)) != well) continue;
    const bool in_cap = a.radial_band && a.radial_band->GetComponent(c, 0) >= 0;
    if (in_cap) {
      if (a.radial_cap_center) {
        const Vec p = to_drawing({a.radial_cap_center->GetComponent(c, 0), a.radial_cap_center->GetComponent(c, 1),
                                  a.radial_cap_center->GetComponent(c, 2)},
                                 shift);
        if (std::none_of(caps.begin(), caps.end(), [&](const Vec& q) { return q == p; })) caps.push_back(p);
      }
      continue;
    }
    if (a.radial_ring && a.radial_ring->GetComponent(c, 0) != 0) continue;
    const int seg = a.radial_segment ? static_cast<int>(a.radial_segment->GetComponent(c, 0)) : 0;
    auto& [sum, count] = by_segment[seg];
    if (count == 0) sum = {0, 0, 0};
    sum = add(sum, {a.fv_center->GetComponent(c, 0), a.fv_center->GetComponent(c, 1), a.fv_center->GetComponent(c, 2)});
    ++count;
  }
  std::vector<Vec> out;
  for (const auto& [seg, sc] : by_segment) out.push_back(to_drawing(scale(sc.first, 1.0 / sc.second), shift));
  out.insert(out.end(), caps.begin(), caps.end());
  return out;
}

/// A plane through centre with normal n, seen from the side n points to; up: the picture's up
/// (elevation where the plane is not horizontal, else north, else the trajectory).
CutPlane plane_facing(const Vec& centre, Vec n, const Vec& d1) {
  if (dot(n, {0.3, -1, 0.1}) < 0) n = scale(n, -1);  // a stable side to look from: south, above
  Vec up{0, 0, 0};
  for (const Vec& want : {kUp, Vec{0, 1, 0}, d1}) {
    up = sub(want, scale(n, dot(n, want)));
    if (dot(up, up) > 1e-2) break;
  }
  return {centre, n, unit(up)};
}

/// The candidate planes of the cut, preferred first: the trajectory's best-fit plane when it
/// bends; for a straight well the vertical plane through it, then the plane through it
/// perpendicular to that one (for a horizontal well: the horizontal plane).
std::vector<CutPlane> cut_planes_of(const std::vector<Vec>& pts) {
  if (pts.size() < 2) return {};
  Vec c{0, 0, 0};
  for (const Vec& p : pts) c = add(c, p);
  c = scale(c, 1.0 / pts.size());
  double cov[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  for (const Vec& p : pts) {
    const Vec d = sub(p, c);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) cov[i][j] += d[i] * d[j];
  }
  double eval[3], evec[3][3];
  double* rows[3] = {cov[0], cov[1], cov[2]};
  double* vrows[3] = {evec[0], evec[1], evec[2]};
  vtkMath::Jacobi(rows, eval, vrows);  // eigenvalues descending, eigenvectors in columns
  if (!(eval[0] > 0)) return {};
  const Vec d1 = unit({evec[0][0], evec[1][0], evec[2][0]});
  if (eval[1] >= kBentTrajectoryRatio * eval[0]) return {plane_facing(c, unit({evec[0][2], evec[1][2], evec[2][2]}), d1)};
  const Vec side = cross(d1, kUp);
  const Vec vertical_normal = dot(side, side) > 1e-12 ? unit(side) : Vec{0, 1, 0};  // a vertical well: the x-z plane
  return {plane_facing(c, vertical_normal, d1), plane_facing(c, unit(cross(d1, vertical_normal)), d1)};
}

/// Reservoir cells inside `box` that the plane cuts or touches (their bounding box has corners on
/// both sides, or within a hair of it: a plane through a layer boundary touches the layers' faces).
int64_t reservoir_cells_cut(vtkUnstructuredGrid* grid, vtkDataArray* region, const Box& box, const CutPlane& pl) {
  const double hair = kTouchingPlane * std::sqrt(dot(sub(box.hi, box.lo), sub(box.hi, box.lo)));
  int64_t count = 0;
  for (vtkIdType c = 0; c < grid->GetNumberOfCells(); ++c) {
    if (static_cast<int>(region->GetComponent(c, 0)) != kReservoir) continue;
    double b[6];
    grid->GetCellBounds(c, b);
    Box cell;
    cell.add({b[0], b[2], b[4]});
    cell.add({b[1], b[3], b[5]});
    if (!cell.intersects(box)) continue;
    bool below = false, above = false;
    for (int corner = 0; corner < 8; ++corner) {
      const double d = dot(sub({b[corner & 1 ? 1 : 0], b[corner & 2 ? 3 : 2], b[corner & 4 ? 5 : 4]}, pl.centre), pl.normal);
      below |= d <= hair;
      above |= d >= -hair;
    }
    count += below && above;
  }
  return count;
}

vtkSmartPointer<vtkLookupTable> region_lookup_table() {
  auto lut = vtkSmartPointer<vtkLookupTable>::New();
  lut->SetNumberOfTableValues(3);
  const char* names[3] = {"reservoir", "transition", "radial (well)"};
  for (int r = 0; r < 3; ++r) {
    const unsigned char* c = region_colours().rgb[r];
    lut->SetTableValue(r, c[0] / 255.0, c[1] / 255.0, c[2] / 255.0, 1.0);
    lut->SetAnnotation(vtkVariant(r), names[r]);
  }
  lut->SetTableRange(0, 2);
  lut->IndexedLookupOn();
  return lut;
}

/// Q_S in [0, 1] (eq. 7): a perceptually ordered map (viridis' end points and middle), 0 dark.
vtkSmartPointer<vtkLookupTable> qs_lookup_table() {
  vtkNew<vtkColorTransferFunction> ctf;
  ctf->AddRGBPoint(0.0, 0.267, 0.005, 0.329);
  ctf->AddRGBPoint(0.25, 0.230, 0.322, 0.546);
  ctf->AddRGBPoint(0.5, 0.128, 0.567, 0.551);
  ctf->AddRGBPoint(0.75, 0.369, 0.789, 0.383);
  ctf->AddRGBPoint(1.0, 0.993, 0.906, 0.144);
  auto lut = vtkSmartPointer<vtkLookupTable>::New();
  lut->SetNumberOfTableValues(256);
  for (int i = 0; i < 256; ++i) {
    double rgb[3];
    ctf->GetColor(i / 255.0, rgb);
    lut->SetTableValue(i, rgb[0], rgb[1], rgb[2], 1.0);
  }
  lut->SetTableRange(0, 1);
  return lut;
}

/// The whole cells `cells` of grid (vtkThreshold on a 0/1 cell mask; VTK's vtkExtractCells would
/// pull in Debian VTK's MPI-dependent module).
vtkSmartPointer<vtkUnstructuredGrid> extract(vtkUnstructuredGrid* grid, const std::vector<vtkIdType>& cells) {
  vtkNew<vtkIntArray> mask;
  mask->SetName("hm_picture_mask");
  mask->SetNumberOfValues(grid->GetNumberOfCells());
  mask->Fill(0);
  for (vtkIdType c : cells) mask->SetValue(c, 1);
  vtkNew<vtkUnstructuredGrid> masked;
  masked->ShallowCopy(grid);
  masked->GetCellData()->AddArray(mask);
  vtkNew<vtkThreshold> th;
  th->SetInputData(masked);
  th->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_CELLS, "hm_picture_mask");
  th->SetLowerThreshold(0.5);
  th->SetUpperThreshold(1.5);
  th->SetThresholdFunction(vtkThreshold::THRESHOLD_BETWEEN);
  th->Update();
  auto out = vtkSmartPointer<vtkUnstructuredGrid>::New();
  out->ShallowCopy(th->GetOutput());
  return out;
}

/// An actor showing `cells` coloured by the cell array `array` through `lut`, cell edges drawn.
vtkSmartPointer<vtkActor> cells_actor(vtkUnstructuredGrid* cells, const char* array, vtkLookupTable* lut, bool lit) {
  vtkNew<vtkDataSetMapper> mapper;
  mapper->SetInputData(cells);
  mapper->SetScalarModeToUseCellFieldData();
  mapper->SelectColorArray(array);
  mapper->SetLookupTable(lut);
  mapper->UseLookupTableScalarRangeOn();
  mapper->ScalarVisibilityOn();
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  vtkProperty* p = actor->GetProperty();
  p->SetLighting(lit);
  p->EdgeVisibilityOn();
  p->SetEdgeColor(0.12, 0.12, 0.12);
  p->SetLineWidth(1.0);
  return actor;
}

using Props = std::vector<vtkSmartPointer<vtkProp>>;

void set_text_style(vtkTextProperty* t, int size) {
  t->SetColor(0.05, 0.05, 0.05);
  t->SetFontSize(size);
  t->ShadowOff();
  t->BoldOff();
  t->ItalicOff();
}

/// The region legend: a swatch of each region's colour with its name, in the side strip
/// (normalized viewport coordinates of the strip's renderer).
Props region_legend(int font_size) {
  Props out;
  const char* names[3] = {"reservoir", "transition", "radial (well)"};
  auto title = vtkSmartPointer<vtkTextActor>::New();
  title->SetInput("region");
  set_text_style(title->GetTextProperty(), font_size);
  title->GetTextProperty()->BoldOn();
  title->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  title->SetPosition(0.08, 0.8);
  out.push_back(title);
  for (int r = 0; r < 3; ++r) {
    const double y0 = 0.7 - 0.1 * r, y1 = y0 + 0.06;
    vtkNew<vtkPoints> p;
    p->InsertNextPoint(0.08, y0, 0);
    p->InsertNextPoint(0.28, y0, 0);
    p->InsertNextPoint(0.28, y1, 0);
    p->InsertNextPoint(0.08, y1, 0);
    vtkNew<vtkCellArray> quad;
    const vtkIdType ids[4] = {0, 1, 2, 3};
    quad->InsertNextCell(4, ids);
    vtkNew<vtkPolyData> swatch;
    swatch->SetPoints(p);
    swatch->SetPolys(quad);
    vtkNew<vtkCoordinate> normalized;
    normalized->SetCoordinateSystemToNormalizedViewport();
    vtkNew<vtkPolyDataMapper2D> mapper;
    mapper->SetInputData(swatch);
    mapper->SetTransformCoordinate(normalized);
    auto actor = vtkSmartPointer<vtkActor2D>::New();
    actor->SetMapper(mapper);
    const unsigned char* c = region_colours().rgb[r];
    actor->GetProperty()->SetColor(c[0] / 255.0, c[1] / 255.0, c[2] / 255.0);
    out.push_back(actor);
    auto label = vtkSmartPointer<vtkTextActor>::New();
    label->SetInput(names[r]);
    set_text_style(label->GetTextProperty(), font_size);
    label->GetTextProperty()->SetVerticalJustificationToCentered();
    label->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
    label->SetPosition(0.34, 0.5 * (y0 + y1));
    out.push_back(label);
  }
  return out;
}

/// The Q_S colour bar.
Props qs_legend(vtkLookupTable* lut, int font_size) {
  auto bar = vtkSmartPointer<vtkScalarBarActor>::New();
  bar->SetLookupTable(lut);
  bar->SetTitle("Q_S");
  bar->SetOrientationToVertical();
  bar->SetPosition(0.06, 0.08);
  bar->SetWidth(0.84);
  bar->SetHeight(0.8);
  bar->SetMaximumWidthInPixels(1000);
  bar->SetVerticalTitleSeparation(12);
  bar->SetNumberOfLabels(6);
  bar->SetLabelFormat("%.2f");
  bar->SetTextPositionToSucceedScalarBar();
  bar->SetUnconstrainedFontSize(true);
  for (vtkTextProperty* t : {bar->GetTitleTextProperty(), bar->GetLabelTextProperty()}) set_text_style(t, font_size);
  bar->GetTitleTextProperty()->BoldOn();
  return {bar};
}

vtkSmartPointer<vtkRenderer> white_renderer(double x0, double y0, double x1, double y1) {
  auto r = vtkSmartPointer<vtkRenderer>::New();
  r->SetBackground(1, 1, 1);
  r->SetViewport(x0, y0, x1, y1);
  return r;
}

/// Renders `mesh` (its viewport set here), the legend and the caption into a PNG.
WriteStatus render_png(vtkRenderer* mesh, const Props& legend, const std::string& caption, int width,
                       int height, const std::string& path) {
  // Each window opens its own X connection, and VTK aborts the process when that fails: the
  // server may have gone since the last picture (a virtual one killed by someone else).
  if (const std::string why = display_problem(); !why.empty())
    return {false, "pictures: " + why + " (before '" + path + "'); VTK needs an X server to render"};
  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetMultiSamples(0);  // exact colours on the unlit cut pictures (tests count them)
  window->SetSize(width, height);
  mesh->SetViewport(0, kCaptionHeight, kMeshWidth, 1);
  window->AddRenderer(mesh);
  const vtkSmartPointer<vtkRenderer> side = white_renderer(kMeshWidth, kCaptionHeight, 1, 1);
  for (const vtkSmartPointer<vtkProp>& p : legend) side->AddViewProp(p);
  window->AddRenderer(side);
  const vtkSmartPointer<vtkRenderer> bottom = white_renderer(0, 0, 1, kCaptionHeight);
  vtkNew<vtkTextActor> text;
  text->SetInput(caption.c_str());
  // As large as the strip's height allows and narrow enough for the whole line (a glyph is
  // about half as wide as the font size).
  const double fit_width = (width - 20) / (0.52 * std::max<size_t>(caption.size(), 1));
  text->GetTextProperty()->SetFontSize(std::max(9, static_cast<int>(std::min(height * kCaptionHeight * 0.45, fit_width))));
  text->GetTextProperty()->SetColor(0.05, 0.05, 0.05);
  text->GetTextProperty()->SetVerticalJustificationToCentered();
  text->SetPosition(10, 0.5 * height * kCaptionHeight);
  bottom->AddActor2D(text);
  window->AddRenderer(bottom);
  window->Render();
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();
  // PATH.tmp first, renamed at the end (like every writer: a failed write leaves no complete-looking file).
  const std::string tmp = path + ".tmp";
  vtkNew<vtkPNGWriter> writer;
  writer->SetFileName(tmp.c_str());
  writer->SetInputConnection(grab->GetOutputPort());
  writer->Write();
  std::error_code ec;
  if (writer->GetErrorCode() != 0 || !std::filesystem::is_regular_file(tmp, ec)) {
    std::filesystem::remove(tmp, ec);
    return {false, "pictures: cannot write '" + path + "'"};
  }
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    return {false, "pictures: cannot rename '" + tmp + "' to '" + path + "'"};
  }
  return {};
}

std::string well_label(const PictureOptions& o, int w) {
  return w < static_cast<int>(o.well_names.size()) && !o.well_names[w].empty() ? o.well_names[w]
                                                                               : "well " + std::to_string(w);
}

}  // namespace

const RegionColours& region_colours() {
  static const RegionColours c{{{206, 198, 178}, {240, 140, 40}, {40, 110, 210}}};
  return c;
}

std::string well_region_picture_name(int well) { return "well_" + std::to_string(well) + "_region.png"; }
std::string well_qs_picture_name(int well) { return "well_" + std::to_string(well) + "_qs.png"; }

PicturesWritten write_mesh_pictures(const std::string& vtu_path, const std::string& out_dir,
                                    const PictureOptions& opt) {
  PicturesWritten result;
  auto fail = [&](const std::string& why) {
    result.status = {false, "pictures: " + why};
    return result;
  };
  auto input_fail = [&](const std::string& why) {
    result.input_error = true;
    return fail(why);
  };
  std::error_code ec;
  if (!std::filesystem::is_regular_file(vtu_path, ec)) return input_fail("no mesh file '" + vtu_path + "'");
  if (opt.width < 64 || opt.height < 64 || opt.width > 8192 || opt.height > 8192)
    return fail("picture size must be within 64..8192 pixels");

  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName(vtu_path.c_str());
  reader->Update();
  vtkUnstructuredGrid* in = reader->GetOutput();
  if (reader->GetErrorCode() != 0 || in == nullptr || in->GetNumberOfCells() == 0)
    return input_fail("VTK cannot read '" + vtu_path + "' (or it has no cells)");
  const vtkIdType n = in->GetNumberOfCells();

  vtkCellData* cd = in->GetCellData();
  CellArrays a;
  struct Need {
    const char* name;
    vtkDataArray** slot;
    int components;
    bool required;
  };
  for (const Need& need : {Need{"region", &a.region, 1, true}, Need{"fv_center", &a.fv_center, 3, true},
                           Need{"Q_S", &a.qs, 1, true}, Need{"radial_well", &a.radial_well, 1, true},
                           Need{"radial_ring", &a.radial_ring, 1, false},
                           Need{"radial_segment", &a.radial_segment, 1, false},
                           Need{"radial_band", &a.radial_band, 1, false},
                           Need{"radial_cap_center", &a.radial_cap_center, 3, false},
                           Need{"cavity", &a.cavity, 1, false}}) {
    vtkDataArray* arr = cd->GetArray(need.name);
    if (arr != nullptr && (arr->GetNumberOfComponents() != need.components || arr->GetNumberOfTuples() != n))
      return input_fail(std::string("cell array '") + need.name + "' has the wrong size");
    if (arr == nullptr && need.required)
      return input_fail(std::string("'") + vtu_path + "' has no cell array '" + need.name +
                  "' (the pictures need a mesh file written by meshgen)");
    *need.slot = arr;
  }

  // Draw in a frame centred on the model: OpenGL's single precision would shake field (UTM)
  // coordinates. FV centres are shifted the same way when read.
  double bounds[6];
  in->GetBounds(bounds);
  const Vec shift = {0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3]), 0.5 * (bounds[4] + bounds[5])};
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  pts->SetNumberOfPoints(in->GetNumberOfPoints());
  for (vtkIdType i = 0; i < in->GetNumberOfPoints(); ++i) {
    double p[3];
    in->GetPoint(i, p);
    const Vec q = to_drawing({p[0], p[1], p[2]}, shift);
    pts->SetPoint(i, q[0], q[1], q[2]);
  }
  auto grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
  grid->ShallowCopy(in);
  grid->SetPoints(pts);
  auto centre_of = [&](vtkIdType c) {
    return to_drawing({a.fv_center->GetComponent(c, 0), a.fv_center->GetComponent(c, 1), a.fv_center->GetComponent(c, 2)}, shift);
  };
  auto region_of = [&](vtkIdType c) { return static_cast<int>(a.region->GetComponent(c, 0)); };
  auto cavity_of = [&](vtkIdType c) { return a.cavity ? static_cast<int>(a.cavity->GetComponent(c, 0)) : -1; };

  int n_wells = 0;
  for (vtkIdType c = 0; c < n; ++c) n_wells = std::max(n_wells, static_cast<int>(a.radial_well->GetComponent(c, 0)) + 1);

  // Boxes of every cavity's transition cells and of every well's radial cells; a well's cavity is
  // one whose box meets the well's (the radial block lies inside its cavity).
  std::map<int, Box> cavity_box;
  std::map<int, std::pair<Vec, int>> cavity_centre_sum;
  std::vector<Box> well_box(n_wells);
  for (vtkIdType c = 0; c < n; ++c) {
    const int w = static_cast<int>(a.radial_well->GetComponent(c, 0));
    if (w >= 0) add_cell_points(grid, c, &well_box[w]);
    if (region_of(c) == kTransition && cavity_of(c) >= 0) {
      add_cell_points(grid, c, &cavity_box[cavity_of(c)]);
      auto& [sum, count] = cavity_centre_sum[cavity_of(c)];
      if (count == 0) sum = {0, 0, 0};
      sum = add(sum, centre_of(c));
      ++count;
    }
  }
  std::vector<std::vector<int>> well_cavities(n_wells);
  for (int w = 0; w < n_wells; ++w)
    for (const auto& [k, box] : cavity_box)
      if (box.intersects(well_box[w])) well_cavities[w].push_back(k);

  const DisplayConnection held;  // keeps the X server from resetting between two pictures
  if (!held.ok()) return fail(display_problem() + "; VTK needs an X server to render");
  const vtkSmartPointer<vtkLookupTable> region_lut = region_lookup_table();
  const vtkSmartPointer<vtkLookupTable> qs_lut = qs_lookup_table();
  const std::filesystem::path dir(out_dir);
  const double aspect = (kMeshWidth * opt.width) / ((1 - kCaptionHeight) * opt.height);  // of the mesh's viewport
  std::vector<CutPlane> planes(n_wells);
  const int legend_font = std::max(9, std::min(opt.height / 45, static_cast<int>((1 - kMeshWidth) * opt.width / 11)));

  for (int w = 0; w < n_wells; ++w) {
    if (well_box[w].empty()) continue;  // a well with no cell in the mesh (none of it inside the reservoir)
    const std::vector<CutPlane> candidates = cut_planes_of(well_axis_points(a, n, w, shift));
    if (candidates.empty())
      return fail("well " + well_label(opt, w) + ": fewer than two distinct points on its meshed trajectory");
    // Frame: the well's radial block and its cavities (then in the picture's (right, up) axes).
    Box frame = well_box[w];
    for (int k : well_cavities[w]) frame.add(cavity_box[k].lo), frame.add(cavity_box[k].hi);
    // A straight well's second plane is taken when the first cuts too few reservoir cells near
    // the well to show any (a horizontal well in a layer its cavity fills top to bottom).
    size_t choice = 0;
    if (candidates.size() == 2) {
      const Vec pad = scale(sub(frame.hi, frame.lo), kFrameMargin);
      Box near;
      near.add(sub(frame.lo, pad));
      near.add(add(frame.hi, pad));
      const std::array<int64_t, 2> cut_cells = {reservoir_cells_cut(grid, a.region, near, candidates[0]),
                                                reservoir_cells_cut(grid, a.region, near, candidates[1])};
      if (4 * cut_cells[0] < cut_cells[1]) choice = 1;
    }
    planes[w] = candidates[choice];
    const CutPlane& pl = planes[w];
    std::vector<vtkIdType> behind;
    for (vtkIdType c = 0; c < n; ++c)
      if (dot(sub(centre_of(c), pl.centre), pl.normal) <= 0) behind.push_back(c);
    const vtkSmartPointer<vtkUnstructuredGrid> cut = extract(grid, behind);
    const Vec right = cross(pl.up, pl.normal);
    double u_lo = 1e300, u_hi = -1e300, v_lo = 1e300, v_hi = -1e300;
    for (int corner = 0; corner < 8; ++corner) {
      const Vec p = {(corner & 1) ? frame.hi[0] : frame.lo[0], (corner & 2) ? frame.hi[1] : frame.lo[1],
                     (corner & 4) ? frame.hi[2] : frame.lo[2]};
      const double u = dot(sub(p, pl.centre), right), v = dot(sub(p, pl.centre), pl.up);
      u_lo = std::min(u_lo, u), u_hi = std::max(u_hi, u), v_lo = std::min(v_lo, v), v_hi = std::max(v_hi, v);
    }
    const double half_h = 0.5 * (1 + kFrameMargin) * std::max(v_hi - v_lo, (u_hi - u_lo) / aspect);
    const Vec focus = add(pl.centre, add(scale(right, 0.5 * (u_lo + u_hi)), scale(pl.up, 0.5 * (v_lo + v_hi))));
    const double diag = std::sqrt(dot(sub(frame.hi, frame.lo), sub(frame.hi, frame.lo)));

    for (const bool by_region : {true, false}) {
      const vtkSmartPointer<vtkRenderer> ren = white_renderer(0, 0, 1, 1);
      ren->AddActor(by_region ? cells_actor(cut, "region", region_lut, false) : cells_actor(cut, "Q_S", qs_lut, false));
      const std::string text = opt.title + ": well " + well_label(opt, w) +
                               ", whole cells behind the plane of its trajectory, coloured by " +
                               (by_region ? "region" : "Q_S (shape quality, eq. 7)");
      vtkCamera* cam = ren->GetActiveCamera();
      cam->ParallelProjectionOn();
      cam->SetFocalPoint(focus.data());
      const Vec eye = add(focus, scale(pl.normal, 4 * diag + 1));
      cam->SetPosition(eye.data());
      cam->SetViewUp(pl.up.data());
      cam->SetParallelScale(half_h);
      ren->ResetCameraClippingRange();
      const std::string path = (dir / (by_region ? well_region_picture_name(w) : well_qs_picture_name(w))).string();
      const Props bar = by_region ? region_legend(legend_font) : qs_legend(qs_lut, legend_font);
      if (WriteStatus st = render_png(ren, bar, text, opt.width, opt.height, path); !st.ok) {
        result.status = st;
        return result;
      }
      result.files.push_back(path);
    }
  }

  // Overview: the reservoir as a light wire frame; every cavity (transition and radial cells)
  // halved by a plane through its centre facing the camera, so that the radial blocks show.
  const Vec view = unit({1.0, -1.5, 1.1});  // from the south-east and above
  std::vector<vtkIdType> reservoir, near_well;
  for (vtkIdType c = 0; c < n; ++c) {
    if (region_of(c) == kReservoir) {
      reservoir.push_back(c);
      continue;
    }
    Vec centre;
    const int w = static_cast<int>(a.radial_well->GetComponent(c, 0));
    const int k = w >= 0 ? (well_cavities[w].empty() ? -1 : well_cavities[w][0]) : cavity_of(c);
    if (k >= 0 && cavity_centre_sum.count(k)) {
      centre = scale(cavity_centre_sum[k].first, 1.0 / cavity_centre_sum[k].second);
    } else if (w >= 0 && !well_box[w].empty()) {
      centre = planes[w].centre;
    } else {
      near_well.push_back(c);
      continue;
    }
    if (dot(sub(centre_of(c), centre), view) <= 0) near_well.push_back(c);
  }
  {
    const vtkSmartPointer<vtkRenderer> ren = white_renderer(0, 0, 1, 1);
    vtkNew<vtkDataSetSurfaceFilter> skin;
    skin->SetInputData(extract(grid, reservoir));
    vtkNew<vtkPolyDataMapper> skin_mapper;
    skin_mapper->SetInputConnection(skin->GetOutputPort());
    skin_mapper->ScalarVisibilityOff();
    vtkNew<vtkActor> skin_actor;
    skin_actor->SetMapper(skin_mapper);
    skin_actor->GetProperty()->SetRepresentationToWireframe();
    skin_actor->GetProperty()->SetColor(0.55, 0.52, 0.45);
    skin_actor->GetProperty()->SetOpacity(0.35);
    skin_actor->GetProperty()->LightingOff();
    ren->AddActor(skin_actor);
    if (!near_well.empty()) ren->AddActor(cells_actor(extract(grid, near_well), "region", region_lut, true));
    vtkCamera* cam = ren->GetActiveCamera();
    cam->SetFocalPoint(0, 0, 0);
    cam->SetPosition(view.data());
    cam->SetViewUp(kUp.data());
    ren->ResetCamera();
    // ResetCamera fits the bounding sphere, so the box fills less of the frame: zoom until the
    // model's projected corners span 92 % of the mesh's viewport (twice: the perspective projection
    // makes one step inexact).
    for (int step = 0; step < 2; ++step) {
      vtkMatrix4x4* m = cam->GetCompositeProjectionTransformMatrix(aspect, -1, 1);
      double extent = 0;
      for (int corner = 0; corner < 8; ++corner) {
        const Vec v = to_drawing({bounds[corner & 1 ? 1 : 0], bounds[corner & 2 ? 3 : 2], bounds[corner & 4 ? 5 : 4]}, shift);
        const double p[4] = {v[0], v[1], v[2], 1.0};
        double q[4];
        m->MultiplyPoint(p, q);
        if (q[3] > 0) extent = std::max({extent, std::abs(q[0] / q[3]), std::abs(q[1] / q[3])});
      }
      if (extent > 0) cam->Zoom(0.92 / extent);
    }
    ren->ResetCameraClippingRange();
    const std::string path = (dir / kOverviewPictureName).string();
    const std::string text = opt.title + ": overview, the reservoir grid as a wire frame, each cavity cut in half";
    if (WriteStatus st = render_png(ren, region_legend(legend_font), text, opt.width, opt.height, path);
        !st.ok) {
      result.status = st;
      return result;
    }
    result.files.push_back(path);
  }
  return result;
}

std::vector<PictureFile> find_mesh_pictures(const std::string& dir) {
  namespace fs = std::filesystem;
  std::vector<PictureFile> out;
  std::error_code ec;
  for (int w = 0;; ++w) {
    const fs::path region = fs::path(dir) / well_region_picture_name(w), qs = fs::path(dir) / well_qs_picture_name(w);
    const bool has_region = fs::is_regular_file(region, ec), has_qs = fs::is_regular_file(qs, ec);
    if (!has_region && !has_qs) break;
    const std::string well = "well " + std::to_string(w);
    if (has_region) out.push_back({well + ": cut along its trajectory, coloured by region", region.string()});
    if (has_qs) out.push_back({well + ": cut along its trajectory, coloured by Q_S", qs.string()});
  }
  const fs::path overview = fs::path(dir) / kOverviewPictureName;
  if (fs::is_regular_file(overview, ec)) out.push_back({"overview", overview.string()});
  return out;
}

std::string png_data_uri(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return "";
  const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  if (bytes.empty()) return "";
  std::vector<unsigned char> text(4 * ((bytes.size() + 2) / 3) + 1);
  const unsigned long n = vtkBase64Utilities::Encode(bytes.data(), bytes.size(), text.data());
  return "data:image/png;base64," + std::string(text.begin(), text.begin() + static_cast<long>(n));
}

}  // namespace hm
