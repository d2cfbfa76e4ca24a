// Small hand-made meshes for the fvcheck and VTU tests: boxes, prisms, a split-face
// (hanging node) configuration. Every cell is given as outward-oriented faces.
#pragma once
#include <gtest/gtest.h>

#include <vector>

#include "meshgen/core/geometry.hpp"
#include "meshgen/core/mesh_builder.hpp"

namespace fvtest {

using hm::CellAttributes;
using hm::CellFace;
using hm::MeshBuilder;
using hm::PolyMesh;
using hm::Vec3;

/// Outward faces of a hexahedral box with nodes n[0..7] (bit 0 = x, bit 1 = y, bit 2 = z).
inline std::vector<CellFace> box_faces(const int32_t n[8], int32_t patch = hm::kOuterBoundary) {
  return {{{n[0], n[2], n[3], n[1]}, patch}, {{n[4], n[5], n[7], n[6]}, patch},
          {{n[0], n[1], n[5], n[4]}, patch}, {{n[2], n[6], n[7], n[3]}, patch},
          {{n[0], n[4], n[6], n[2]}, patch}, {{n[1], n[3], n[7], n[5]}, patch}};
}

/// Adds the box [lo, hi] with fresh nodes; returns the cell id. Centre = box centre unless given.
inline int32_t add_box(MeshBuilder& b, Vec3 lo, Vec3 hi, int32_t region = hm::kReservoir, const Vec3* center = nullptr) {
  int32_t n[8];
  for (int c = 0; c < 8; ++c)
    n[c] = b.add_node({(c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z});
  CellAttributes at;
  at.region = region;
  at.fv_center = center ? *center : 0.5 * (lo + hi);
  return b.add_cell(box_faces(n), at);
}

inline PolyMesh finish_ok(MeshBuilder& b) {
  hm::BuildReport rep;
  PolyMesh m = b.finish(&rep);
  EXPECT_TRUE(rep.ok) << (rep.problems.empty() ? "" : rep.problems[0]);
  return m;
}

/// nx * ny * nz grid of unit boxes sharing nodes; regions cycle 0,1,2 by cell when mixed.
inline PolyMesh box_grid(int nx, int ny, int nz, bool mixed_regions = false) {
  MeshBuilder b;
  std::vector<int32_t> id((nx + 1) * (ny + 1) * (nz + 1));
  auto at = [&](int i, int j, int k) { return (k * (ny + 1) + j) * (nx + 1) + i; };
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) id[at(i, j, k)] = b.add_node({double(i), double(j), double(k)});
  int cell = 0;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i, ++cell) {
        int32_t n[8];
        for (int c = 0; c < 8; ++c) n[c] = id[at(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1))];
        std::vector<CellFace> f = box_faces(n);
        // Boundary patch only on the outer boundary; interior faces must be matched.
        const bool outer[6] = {k == 0, k == nz - 1, j == 0, j == ny - 1, i == 0, i == nx - 1};
        for (int q = 0; q < 6; ++q) f[q].patch = outer[q] ? hm::kOuterBoundary : hm::kInteriorFace;
        CellAttributes a;
        a.fv_center = {i + 0.5, j + 0.5, k + 0.5};
        a.region = mixed_regions ? cell % 3 : hm::kReservoir;
        a.perm = {100, 100, 10};
        a.porosity = 0.2;
        b.add_cell(f, a);
      }
  return finish_ok(b);
}

/// One convex cell from node coordinates and outward faces.
inline PolyMesh single_cell(const std::vector<Vec3>& pts, const std::vector<std::vector<int32_t>>& faces,
                            Vec3 center, int32_t patch = hm::kOuterBoundary) {
  MeshBuilder b;
  for (const Vec3& p : pts) b.add_node(p);
  std::vector<CellFace> f;
  for (const auto& v : faces) f.push_back({v, patch});
  CellAttributes a;
  a.fv_center = center;
  b.add_cell(f, a);
  return finish_ok(b);
}

/// Prism over a planar polygon (counter-clockwise seen from +z) between z0 and z1.
inline PolyMesh prism(const std::vector<std::pair<double, double>>& poly, double z0, double z1, Vec3 center) {
  const int n = static_cast<int>(poly.size());
  std::vector<Vec3> pts;
  for (auto [x, y] : poly) pts.push_back({x, y, z0});
  for (auto [x, y] : poly) pts.push_back({x, y, z1});
  std::vector<std::vector<int32_t>> faces;
  std::vector<int32_t> bottom, top;
  for (int i = n - 1; i >= 0; --i) bottom.push_back(i);
  for (int i = 0; i < n; ++i) top.push_back(n + i);
  faces.push_back(bottom);
  faces.push_back(top);
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    faces.push_back({i, j, n + j, n + i});
  }
  return single_cell(pts, faces, center);
}

/// Unit cube [0,1]^3 with top corner (1,1,1) lifted to z = 1 + t: a non-planar top face.
inline PolyMesh lifted_cube(double t) {
  std::vector<Vec3> pts;
  for (int c = 0; c < 8; ++c) pts.push_back({double(c & 1), double((c >> 1) & 1), double((c >> 2) & 1) + (c == 7 ? t : 0.0)});
  const int32_t n[8] = {0, 1, 2, 3, 4, 5, 6, 7};
  std::vector<std::vector<int32_t>> faces;
  for (const CellFace& f : box_faces(n)) faces.push_back(f.nodes);
  return single_cell(pts, faces, {0.5, 0.5, 0.5});
}

/// Cube A = [0,1]^3 next to B = [1,2]x[0,1]x[0,.5] and C = [1,2]x[0,1]x[.5,1]: the nodes
/// (1,0,.5) and (1,1,.5) of B and C hang on A's face x = 1. With split_a, A is split at
/// z = .5 as well and the mesh is conforming.
inline PolyMesh split_face_mesh(bool split_a) {
  MeshBuilder b;
  std::vector<Vec3> pts;
  auto node = [&](double x, double y, double z) {
    for (size_t i = 0; i < pts.size(); ++i)
      if (pts[i] == Vec3{x, y, z}) return static_cast<int32_t>(i);
    pts.push_back({x, y, z});
    return b.add_node({x, y, z});
  };
  auto box = [&](Vec3 lo, Vec3 hi) {
    int32_t n[8];
    for (int c = 0; c < 8; ++c) n[c] = node((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z);
    CellAttributes a;
    a.fv_center = 0.5 * (lo + hi);
    // The faces at x = 1 of B and C and of an unsplit A do not match: declare them boundary.
    std::vector<CellFace> f = box_faces(n, hm::kOuterBoundary);
    b.add_cell(f, a);
  };
  if (split_a) {
    box({0, 0, 0}, {1, 1, 0.5});
    box({0, 0, 0.5}, {1, 1, 1});
  } else {
    box({0, 0, 0}, {1, 1, 1});
  }
  box({1, 0, 0}, {2, 1, 0.5});
  box({1, 0, 0.5}, {2, 1, 1});
  return finish_ok(b);
}

}  // namespace fvtest
