// OpenFOAM polyMesh writer (docs/export-openfoam.md).
#include "openfoam_case.hpp"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <numeric>

#include "exporters/eclipse/staged_files.hpp"
#include "exporters/eclipse/text_out.hpp"
#include "meshgen/core/mesh_builder.hpp"

namespace hm {

namespace {

namespace fs = std::filesystem;

bool is_foam_word(const std::string& s) {
  if (s.empty()) return false;
  for (char ch : s)
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-' || ch == '.')) return false;
  return true;
}

void foam_header(TextOut& o, bool binary, const char* cls, const char* location, const char* object,
                 const std::string& note = {}) {
  o << "/*--------------------------------*- C++ -*----------------------------------*\\\n"
    << "  Written by HybridMesh (docs/export-openfoam.md)\n"
    << "\\*---------------------------------------------------------------------------*/\n"
    << "FoamFile\n{\n    version     2.0;\n    format      " << (binary ? "binary" : "ascii") << ";\n";
  if (binary) o << "    arch        \"LSB;label=32;scalar=64\";\n";
  o << "    class       " << cls << ";\n";
  if (!note.empty()) o << "    note        \"" << note << "\";\n";
  if (location[0] != '\0') o << "    location    \"" << location << "\";\n";
  o << "    object      " << object << ";\n}\n\n";
}

// A binary list: its length, then the raw bytes between parentheses.
void raw_bytes(TextOut& o, size_t length, const void* data, size_t bytes) {
  o << static_cast<long long>(length) << "\n(";
  o.text.append(static_cast<const char*>(data), bytes);
  o << ")\n";
}

template <class T>
void raw_list(TextOut& o, const T* data, size_t n) {
  raw_bytes(o, n, data, n * sizeof(T));
}

void label_list(TextOut& o, bool binary, const std::vector<int32_t>& v) {
  if (binary) {
    raw_list(o, v.data(), v.size());
  } else {
    o << static_cast<long long>(v.size()) << "\n(\n";
    for (int32_t x : v) o << x << '\n';
    o << ")\n";
  }
  o << "\n";
}

bool little_endian() {
  const uint16_t one = 1;
  unsigned char b = 0;
  std::memcpy(&b, &one, 1);
  return b == 1;
}

}  // namespace

bool make_openfoam_order(const PolyMesh& mesh, const OpenFoamOptions& options, OpenFoamInfo* info,
                         std::string* error) {
  const int nf = mesh.n_faces();
  int n_wells = options.n_wells;
  if (n_wells < 0) {
    n_wells = static_cast<int>(options.well_names.size());
    for (int f = 0; f < nf; ++f)
      if (is_wellbore_patch(mesh.face_patch[f])) n_wells = std::max(n_wells, well_of_patch(mesh.face_patch[f]) + 1);
  }
  std::vector<int32_t> internal, boundary;
  for (int f = 0; f < nf; ++f) {
    const int32_t p = mesh.face_patch[f];
    if (mesh.face_neighbour[f] >= 0) {
      internal.push_back(f);
    } else if (p == kOuterBoundary || (is_wellbore_patch(p) && well_of_patch(p) < n_wells) ||
               (is_closed_wellbore_patch(p) && well_of_closed_patch(p) < n_wells)) {
      boundary.push_back(f);
    } else {
      *error = "face " + std::to_string(f) + " is a boundary face of unknown patch " + std::to_string(p) +
               (p == kUnmatchedFace ? " (unmatched: the mesh is not conforming)" : "");
      return false;
    }
  }
  auto lo = [&](int32_t f) { return std::min(mesh.face_owner[f], mesh.face_neighbour[f]); };
  auto hi = [&](int32_t f) { return std::max(mesh.face_owner[f], mesh.face_neighbour[f]); };
  std::sort(internal.begin(), internal.end(), [&](int32_t a, int32_t b) {
    const int32_t la = lo(a), lb = lo(b);
    if (la != lb) return la < lb;
    const int32_t ha = hi(a), hb = hi(b);
    return ha != hb ? ha < hb : a < b;
  });
  // Patch order: outer (code 0) first, then the wells in order (codes 1..n), then the closed
  // (unperforated) wellbore walls of the wells that have them: a stable sort by that rank.
  auto rank = [&](int32_t code) { return is_closed_wellbore_patch(code) ? n_wells + 1 + well_of_closed_patch(code) : code; };
  std::stable_sort(boundary.begin(), boundary.end(),
                   [&](int32_t a, int32_t b) { return rank(mesh.face_patch[a]) < rank(mesh.face_patch[b]); });
  std::vector<int32_t> codes;
  for (int32_t code = 0; code <= n_wells; ++code) codes.push_back(code);
  for (int32_t f : boundary)
    if (is_closed_wellbore_patch(mesh.face_patch[f]) && codes.back() != mesh.face_patch[f]) codes.push_back(mesh.face_patch[f]);

  OpenFoamInfo out;
  out.n_internal_faces = static_cast<int32_t>(internal.size());
  out.face_order = internal;
  out.face_order.insert(out.face_order.end(), boundary.begin(), boundary.end());
  out.face_flipped.assign(nf, 0);
  for (size_t i = 0; i < internal.size(); ++i) out.face_flipped[i] = mesh.face_owner[internal[i]] > mesh.face_neighbour[internal[i]];
  int32_t start = out.n_internal_faces;
  for (const int32_t code : codes) {
    OpenFoamPatch p;
    p.code = code;
    if (code == kOuterBoundary) {
      p.name = "outer";
    } else {
      const bool closed = is_closed_wellbore_patch(code);
      const int w = closed ? well_of_closed_patch(code) : well_of_patch(code);
      p.name = "wellbore_" + (w < static_cast<int>(options.well_names.size()) ? options.well_names[w] : std::to_string(w)) +
               (closed ? "_closed" : "");
    }
    if (!is_foam_word(p.name)) {
      *error = "patch name '" + p.name + "' is not a valid OpenFOAM word";
      return false;
    }
    for (const OpenFoamPatch& q : out.patches)
      if (q.name == p.name) {
        *error = "two patches are called '" + p.name + "'";
        return false;
      }
    p.start_face = start;
    while (start < nf && mesh.face_patch[out.face_order[start]] == code) ++start;
    p.n_faces = start - p.start_face;
    out.patches.push_back(p);
  }
  *info = std::move(out);
  return true;
}

WriteStatus write_openfoam_case(const std::string& dir, const PolyMesh& mesh, const OpenFoamOptions& options,
                                OpenFoamInfo* info) {
  auto fail = [&](const std::string& why) { return WriteStatus{false, "write_openfoam_case " + dir + ": " + why}; };
  const CsrReport csr = check_csr_invariants(mesh);
  if (!csr.ok) return fail("invalid mesh: " + (csr.problems.empty() ? std::string("?") : csr.problems[0]));
  if (mesh.n_cells() == 0) return fail("the mesh has no cells");
  if (options.binary && !little_endian()) return fail("binary output is only implemented on little-endian hosts");
  OpenFoamInfo order;
  std::string error;
  if (!make_openfoam_order(mesh, options, &order, &error)) return fail(error);
  const bool bin = options.binary;
  const int nf = mesh.n_faces();

  std::string points_text, faces_text, owner_text, neighbour_text, boundary_text;
  {
    TextOut o;
    foam_header(o, bin, "vectorField", "constant/polyMesh", "points");
    if (bin) {
      // A vectorField in binary: the number of vectors, then 3 doubles per vector.
      static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 must be three packed doubles");
      raw_bytes(o, mesh.nodes.size(), mesh.nodes.data(), mesh.nodes.size() * sizeof(Vec3));
    } else {
      o << static_cast<long long>(mesh.nodes.size()) << "\n(\n";
      for (const Vec3& p : mesh.nodes) o << '(' << p.x << ' ' << p.y << ' ' << p.z << ")\n";
      o << ")\n";
    }
    points_text = std::move(o.text);
  }
  {
    TextOut o;
    std::vector<int32_t> offsets{0}, nodes;
    nodes.reserve(mesh.face_nodes.size());
    for (int i = 0; i < nf; ++i) {
      const int32_t f = order.face_order[i];
      const int32_t* b = mesh.face_begin(f);
      const int32_t* e = mesh.face_end(f);
      if (order.face_flipped[i])
        nodes.insert(nodes.end(), std::reverse_iterator<const int32_t*>(e), std::reverse_iterator<const int32_t*>(b));
      else
        nodes.insert(nodes.end(), b, e);
      offsets.push_back(static_cast<int32_t>(nodes.size()));
    }
    if (bin) {
      foam_header(o, bin, "faceCompactList", "constant/polyMesh", "faces");
      raw_list(o, offsets.data(), offsets.size());
      o << "\n";
      raw_list(o, nodes.data(), nodes.size());
    } else {
      foam_header(o, bin, "faceList", "constant/polyMesh", "faces");
      o << nf << "\n(\n";
      for (int i = 0; i < nf; ++i) {
        o << offsets[i + 1] - offsets[i] << '(';
        for (int32_t k = offsets[i]; k < offsets[i + 1]; ++k) {
          if (k > offsets[i]) o << ' ';
          o << nodes[k];
        }
        o << ")\n";
      }
      o << ")\n";
    }
    faces_text = std::move(o.text);
  }
  {
    std::vector<int32_t> owner(nf), neighbour(order.n_internal_faces);
    for (int i = 0; i < nf; ++i) {
      const int32_t f = order.face_order[i];
      owner[i] = i < order.n_internal_faces ? std::min(mesh.face_owner[f], mesh.face_neighbour[f]) : mesh.face_owner[f];
      if (i < order.n_internal_faces) neighbour[i] = std::max(mesh.face_owner[f], mesh.face_neighbour[f]);
    }
    const std::string note = "nPoints:" + std::to_string(mesh.n_nodes()) + "  nCells:" + std::to_string(mesh.n_cells()) +
                             "  nFaces:" + std::to_string(nf) + "  nInternalFaces:" + std::to_string(order.n_internal_faces);
    TextOut o;
    foam_header(o, bin, "labelList", "constant/polyMesh", "owner", note);
    label_list(o, bin, owner);
    owner_text = std::move(o.text);
    TextOut n;
    foam_header(n, bin, "labelList", "constant/polyMesh", "neighbour", note);
    label_list(n, bin, neighbour);
    neighbour_text = std::move(n.text);
  }
  {
    TextOut o;
    foam_header(o, false, "polyBoundaryMesh", "constant/polyMesh", "boundary");
    o << order.patches.size() << "\n(\n";
    for (const OpenFoamPatch& p : order.patches)
      o << "    " << p.name << "\n    {\n        type            " << (p.code == kOuterBoundary ? "patch" : "wall")
        << ";\n        nFaces          " << p.n_faces << ";\n        startFace       " << p.start_face << ";\n    }\n";
    o << ")\n";
    boundary_text = std::move(o.text);
  }
  std::string control, schemes, solution;
  {
    TextOut o;
    foam_header(o, false, "dictionary", "system", "controlDict");
    o << "application     laplacianFoam;\nstartFrom       startTime;\nstartTime       0;\nstopAt          endTime;\n"
      << "endTime         1;\ndeltaT          1;\nwriteControl    timeStep;\nwriteInterval   1;\n"
      << "purgeWrite      0;\nwriteFormat     " << (bin ? "binary" : "ascii") << ";\nwritePrecision  15;\n"
      << "writeCompression off;\ntimeFormat      general;\ntimePrecision   6;\nrunTimeModifiable false;\n";
    control = std::move(o.text);
    TextOut s;
    foam_header(s, false, "dictionary", "system", "fvSchemes");
    s << "ddtSchemes\n{\n    default         steadyState;\n}\n\ngradSchemes\n{\n    default         Gauss linear;\n}\n\n"
      << "divSchemes\n{\n    default         none;\n}\n\nlaplacianSchemes\n{\n    default         Gauss linear corrected;\n}\n\n"
      << "interpolationSchemes\n{\n    default         linear;\n}\n\nsnGradSchemes\n{\n    default         corrected;\n}\n";
    schemes = std::move(s.text);
    TextOut v;
    foam_header(v, false, "dictionary", "system", "fvSolution");
    v << "solvers\n{\n    p\n    {\n        solver          PCG;\n        preconditioner  DIC;\n"
      << "        tolerance       1e-12;\n        relTol          0;\n    }\n}\n";
    solution = std::move(v.text);
  }

  const fs::path root(dir), poly = root / "constant" / "polyMesh", sys = root / "system";
  if (!StagedFiles::make_directory(poly.string(), &error) || !StagedFiles::make_directory(sys.string(), &error))
    return fail(error);
  StagedFiles files;
  const bool staged = files.stage((sys / "controlDict").string(), control) &&
                      files.stage((sys / "fvSchemes").string(), schemes) &&
                      files.stage((sys / "fvSolution").string(), solution) &&
                      files.stage((poly / "points").string(), points_text) &&
                      files.stage((poly / "faces").string(), faces_text) &&
                      files.stage((poly / "neighbour").string(), neighbour_text) &&
                      files.stage((poly / "boundary").string(), boundary_text) &&
                      files.stage((poly / "owner").string(), owner_text);
  if (!staged || !files.commit()) return fail(files.error());
  if (info) {
    *info = std::move(order);
    info->files = files.paths();
  }
  return {};
}

}  // namespace hm
