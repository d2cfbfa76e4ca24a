// Transition mesh of one cavity (issue #3): synthetic cavities built in the test,
// assembled with the reservoir cells and the inner blocks through one MeshBuilder.
#include <gtest/gtest.h>

#include <cstdio>

#include "synthetic_cavity.hpp"

namespace hm::testing {
namespace {

const std::vector<double> kX{0, 8, 14, 19, 23, 27, 32, 38, 46};
const std::vector<double> kY{0, 5, 11, 16, 20, 25, 31, 36, 44};
const std::vector<double> kZ{0, 4, 9, 13, 16, 20, 24, 29, 35};

bool central(int i, int j, int k) { return i >= 2 && i <= 5 && j >= 2 && j <= 5 && k >= 2 && k <= 5; }

void print(const char* name, const Scene& sc, const Metrics& mt) {
  const TransitionReport& r = sc.transition.report;
  std::printf("[%s] cells %d faces %d vertices %d (new %d, identified %d) | sites in %d (boxes %d) out %d | "
              "corrections %d (iters %d) split %d empty-fix %d hidden %d snapped %d removed-faces %d merged-cells %d | "
              "orth min 90-%.1e mean 90-%.1e (n %d) res-min 90-%.1e | planarity %.2e convexity %.2e site-margin %.3e closure %.2e\n",
              name, mt.transition_cells, mt.transition_faces, mt.transition_nodes, r.free_vertices,
              r.identified_vertices, r.internal_sites, r.box_sites, r.external_sites, r.site_corrections,
              r.correction_iterations, r.split_boxes, r.emptiness_fixes, r.hidden_sites, r.snapped_vertices,
              r.removed_faces, r.merged_cells, 90 - mt.min_orth, 90 - mt.mean_orth, mt.n_orth, 90 - mt.min_orth_res,
              mt.max_planarity, mt.max_convexity, mt.min_site_margin, mt.max_closure);
  for (const std::string& n : r.notes) std::printf("   note: %s\n", n.c_str());
  for (const std::string& p : sc.report.problems) std::printf("   builder: %s\n", p.c_str());
}

// The properties every cavity must satisfy.
void expect_valid(const Scene& sc, const Metrics& mt, double planarity_tol) {
  EXPECT_TRUE(sc.report.ok);
  EXPECT_EQ(sc.report.unmatched_faces, 0);
  EXPECT_EQ(sc.report.misoriented_faces, 0);
  EXPECT_EQ(sc.report.overused_faces, 0);
  EXPECT_EQ(sc.report.degenerate_faces, 0);
  EXPECT_TRUE(mt.csr_ok);
  EXPECT_EQ(mt.bad_boundary_faces, 0);
  EXPECT_EQ(mt.polygons_not_once, 0);
  EXPECT_EQ(sc.transition.report.missing_polygons, 0);
  EXPECT_EQ(sc.transition.report.unmatched_external_faces, 0);
  EXPECT_LT(mt.max_closure, 1e-9);
  EXPECT_NEAR(mt.volume, sc.box_volume, 1e-9 * sc.box_volume);
  EXPECT_EQ(mt.negative_volumes, 0);
  EXPECT_LT(mt.max_planarity, planarity_tol);
  EXPECT_LT(mt.max_convexity, planarity_tol);
  EXPECT_GT(mt.min_site_margin, 0.0);
}

TEST(Transition, BoxInBox) {
  Scene sc;
  InnerBlock b;
  b.center = {23, 20, 16};
  b.half = 2.5;
  build_scene(sc, kX, kY, kZ, central, {b});
  const Metrics mt = measure(sc);
  print("box-in-box", sc, mt);
  expect_valid(sc, mt, 1e-9);
  EXPECT_NEAR(mt.min_orth, 90.0, 1e-9);
  EXPECT_NEAR(mt.min_orth_res, 90.0, 1e-9);
}

}  // namespace
}  // namespace hm::testing
