// Gabriel condition on a set of edges and points (paper 5.1): an edge is Gabriel when
// its diametral sphere contains no point of the set strictly inside. Used on a well
// block's outer surface; reusable for reservoir-edge / well-point checks of a cavity.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "meshgen/core/vec3.hpp"

namespace hm {

/// Point p lies strictly inside the diametral sphere of edge (a, b). Ids index `nodes`.
struct GabrielViolation {
  int32_t a = -1, b = -1;  ///< the edge, a < b
  int32_t p = -1;          ///< the offending point
};

/// Every (edge, point) pair with the point strictly inside the edge's diametral sphere
/// (exact predicate), the edge's own endpoints excluded. Sorted by (a, b, p). Edges are
/// taken as given (pass distinct edges); repeated point ids are merged.
/// Points are found with a k-d tree: O((E + P) log P + violations), not O(E * P).
std::vector<GabrielViolation> gabriel_violations(const std::vector<Vec3>& nodes,
                                                 const std::vector<std::array<int32_t, 2>>& edges,
                                                 const std::vector<int32_t>& points);

/// Same, with the edges = the distinct edges of the polygons and the points = their
/// distinct vertices (a closed surface such as a well block's outer surface).
std::vector<GabrielViolation> gabriel_violations(const std::vector<Vec3>& nodes,
                                                 const std::vector<std::vector<int32_t>>& polygons);

/// A point strictly inside the diametral sphere of a polygon's fan triangle.
struct FaceGabrielViolation {
  int32_t polygon = -1;  ///< index into the polygons given
  int32_t p = -1;        ///< the offending point
};

/// Face version of the Gabriel condition: every (polygon, point) pair with the point
/// strictly inside the smallest sphere through a fan triangle (v0, v_i, v_{i+1}) of the
/// polygon (exact predicate), the polygon's own vertices excluded. For a co-circular
/// polygon all fan triangles share that sphere (the polygon's diametral sphere); a
/// polygon passes only if each of its triangles does. Sorted by (polygon, p).
std::vector<FaceGabrielViolation> face_gabriel_violations(const std::vector<Vec3>& nodes,
                                                          const std::vector<std::vector<int32_t>>& polygons,
                                                          const std::vector<int32_t>& points);

}  // namespace hm
