// Exact predicates for the Gabriel condition (paper 5.1). The header is CGAL-free; CGAL
// (EPICK, filtered exact predicates) is confined to gabriel_predicates.cpp.
#pragma once
#include "meshgen/core/vec3.hpp"

namespace hm {

/// True iff p lies strictly inside the sphere that has [a, b] as a diameter. The sign is
/// exact (CGAL::side_of_bounded_sphere with EPICK): a co-spherical p is NOT inside.
bool strictly_inside_diametral_sphere(Vec3 a, Vec3 b, Vec3 p);

/// True iff p lies strictly inside the smallest sphere through a, b and c (the sphere that
/// has the triangle's circumcircle as a great circle). Exact sign (EPICK).
bool strictly_inside_diametral_sphere(Vec3 a, Vec3 b, Vec3 c, Vec3 p);

}  // namespace hm
