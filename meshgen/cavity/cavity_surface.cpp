// The cavity boundary as an OpenMesh polygon mesh: manifold checks and .obj output.
// GCC 12 reports a false -Wmaybe-uninitialized inside OpenMesh's property vectors.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>

#include <charconv>
#include <cstdio>
#include <map>
#include <set>

#include "cavity.hpp"
#include "meshgen/core/text_file.hpp"

namespace hm {

namespace {

// Double-precision points: the .obj keeps the node coordinates exactly as meshed.
struct DoubleTraits : public OpenMesh::DefaultTraits {
  typedef OpenMesh::Vec3d Point;
};
using SurfaceMesh = OpenMesh::PolyMesh_ArrayKernelT<DoubleTraits>;

// Builds the OpenMesh surface; faces OpenMesh refuses (non-manifold) are counted.
SurfaceMesh to_openmesh(const Cavity& cavity, const std::vector<Vec3>& coords, int* refused) {
  SurfaceMesh mesh;
  std::map<int32_t, SurfaceMesh::VertexHandle> vh;
  for (int32_t v : cavity.vertices) {
    const Vec3 p = coords[v];
    vh[v] = mesh.add_vertex(SurfaceMesh::Point(p.x, p.y, p.z));
  }
  *refused = 0;
  for (const ConstrainedFace& f : cavity.faces) {
    std::vector<SurfaceMesh::VertexHandle> handles;
    for (int32_t v : f.nodes) handles.push_back(vh.at(v));
    if (!mesh.add_face(handles).is_valid()) ++*refused;
  }
  return mesh;
}

}  // namespace

std::vector<std::string> check_cavity_manifold(const Cavity& cavity, const std::vector<Vec3>& coords) {
  std::vector<std::string> problems;
  // Combinatorial closure: every directed edge appears once and its reverse once.
  std::map<std::pair<int32_t, int32_t>, int> directed;
  for (const ConstrainedFace& f : cavity.faces)
    for (size_t i = 0; i < f.nodes.size(); ++i) ++directed[{f.nodes[i], f.nodes[(i + 1) % f.nodes.size()]}];
  // An edge in a mirror plane may be open: the surface continues as its mirror image.
  auto in_mirror = [&](Vec3 a, Vec3 b) {
    for (const MirrorPlane& m : cavity.mirrors)
      if (a[m.axis] == m.value && b[m.axis] == m.value) return true;
    return false;
  };
  int open_edges = 0, overused = 0;
  for (const auto& [e, n] : directed) {
    if (n > 1) ++overused;
    if (!directed.count({e.second, e.first}) && !in_mirror(coords[e.first], coords[e.second])) ++open_edges;
  }
  if (open_edges) problems.push_back(std::to_string(open_edges) + " directed edges without their reverse (open surface)");
  if (overused) problems.push_back(std::to_string(overused) + " directed edges used by more than one face (non-manifold)");
  // OpenMesh refuses faces that would make a vertex or edge non-manifold.
  int refused = 0;
  SurfaceMesh mesh = to_openmesh(cavity, coords, &refused);
  if (refused) problems.push_back(std::to_string(refused) + " faces refused by OpenMesh (non-manifold vertex or edge)");
  int boundary_halfedges = 0;
  for (auto he : mesh.halfedges()) {
    if (!mesh.is_boundary(he)) continue;
    const auto a = mesh.point(mesh.from_vertex_handle(he)), b = mesh.point(mesh.to_vertex_handle(he));
    if (!in_mirror(Vec3{a[0], a[1], a[2]}, Vec3{b[0], b[1], b[2]})) ++boundary_halfedges;
  }
  if (boundary_halfedges) problems.push_back(std::to_string(boundary_halfedges) + " boundary half-edges (surface not closed)");
  for (auto v : mesh.vertices())
    if (!mesh.is_manifold(v)) { problems.push_back("non-manifold vertex"); break; }
  return problems;
}

// Written here rather than by OpenMesh: its OBJ writer goes through Vec3f (float32) points,
// which move field coordinates (UTM, 1e6-1e7 m) by decimetres. Shortest round-trip doubles.
bool write_cavity_surface(const Cavity& cavity, const std::vector<Vec3>& coords, const std::string& path,
                          Vec3 origin) {
  std::string text = "# cavity boundary: constrained polygons, normals into the cavity\n";
  std::map<int32_t, int> index;  // global node id -> 1-based .obj vertex index
  char buf[32];
  auto number = [&](double v) {
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    text.append(buf, r.ptr);
  };
  for (int32_t v : cavity.vertices) {
    index[v] = static_cast<int>(index.size()) + 1;
    const Vec3 p = coords[v] + origin;
    text += "v ";
    number(p.x);
    text += ' ';
    number(p.y);
    text += ' ';
    number(p.z);
    text += '\n';
  }
  for (const ConstrainedFace& f : cavity.faces) {
    text += 'f';
    for (int32_t v : f.nodes) text += ' ' + std::to_string(index.at(v));
    text += '\n';
  }
  std::string error;
  return write_text_file(path, text, &error);
}

}  // namespace hm
