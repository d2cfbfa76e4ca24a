#include "gabriel_predicates.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

namespace hm {

namespace {
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
Kernel::Point_3 to_cgal(Vec3 p) { return Kernel::Point_3(p.x, p.y, p.z); }
}  // namespace

bool strictly_inside_diametral_sphere(Vec3 a, Vec3 b, Vec3 p) {
  return CGAL::side_of_bounded_sphere(to_cgal(a), to_cgal(b), to_cgal(p)) == CGAL::ON_BOUNDED_SIDE;
}

bool strictly_inside_diametral_sphere(Vec3 a, Vec3 b, Vec3 c, Vec3 p) {
  return CGAL::side_of_bounded_sphere(to_cgal(a), to_cgal(b), to_cgal(c), to_cgal(p)) == CGAL::ON_BOUNDED_SIDE;
}

}  // namespace hm
