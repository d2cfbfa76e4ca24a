// fvcheck's K-non-orthogonality (face_k_nonorthogonality, docs/fvcheck.md): the angle between K n
// and the centre line in the metric of K^-1, on hand-made meshes with a known answer.
#include <gtest/gtest.h>

#include <cmath>

#include "fv_test_meshes.hpp"
#include "fvcheck/lib/report.hpp"
#include "meshgen/core/fv_quality.hpp"

using namespace hm;

namespace {

constexpr double kDeg = 180.0 / M_PI;

int interior_face(const PolyMesh& m) {
  for (int f = 0; f < m.n_faces(); ++f)
    if (m.face_neighbour[f] >= 0) return f;
  return -1;
}

}  // namespace

// Two unit boxes along x, K = (100, 100, 10): with the FV centres on the x axis the face is
// K-orthogonal (0); raising the second centre by dz gives atan(dz sqrt(kx / kz)), while the
// Euclidean non-orthogonality is atan(dz): the K metric sees the vertical offset 3.16 times larger.
TEST(KOrthogonality, OffsetCentreGivesTheAngleInTheMetricOfK) {
  PolyMesh m = fvtest::box_grid(2, 1, 1);
  const int f = interior_face(m);
  ASSERT_GE(f, 0);
  EXPECT_EQ(face_k_nonorthogonality(m, compute_geometry(m))[f], 0.0);
  const double dz = 0.05;
  m.cell_fv_center[m.face_neighbour[f]].z += dz;
  const MeshGeometry g = compute_geometry(m);
  EXPECT_NEAR(face_k_nonorthogonality(m, g)[f], std::atan(dz * std::sqrt(10.0)) * kDeg, 1e-12);
  EXPECT_NEAR(90.0 - face_orthogonality(m, g)[f], std::atan(dz) * kDeg, 1e-9);
  // Isotropic K: it is 90 - Q_O on every face.
  for (Vec3& k : m.cell_perm) k = {50, 50, 50};
  const std::vector<double> a = face_k_nonorthogonality(m, g), q = face_orthogonality(m, g);
  for (int i = 0; i < m.n_faces(); ++i) EXPECT_NEAR(a[i], 90.0 - q[i], 1e-9) << i;
}

// fvcheck's report: per-region statistics, and the orthogonality check in the K metric only for a
// mesh that says it was built in a permeability frame (metric_scale). Pass/fail pair on the same
// sheared pair of cells: K-orthogonal, it fails the Euclidean check at 45 degrees but passes the
// K-metric one.
TEST(KOrthogonality, OrthogonalityCheckIsInTheMeshsMetric) {
  PolyMesh m = fvtest::box_grid(2, 1, 1);
  for (Vec3& k : m.cell_perm) k = {100, 100, 1};
  // Shear the pair in x-z so that the shared face's normal is n ~ (1, 0, -t) while the centres
  // stay on the x axis; K n = (100, 0, -t) is then nearly parallel to d = (1, 0, 0).
  const double t = 2.0;  // face normal 63 degrees from d: Euclidean Q_O 26.6 < 45
  for (Vec3& p : m.nodes) p.x += t * p.z;
  for (Vec3& c : m.cell_fv_center) c.x += t * c.z;
  const MeshGeometry g = compute_geometry(m);
  const int f = interior_face(m);
  const double k_angle = face_k_nonorthogonality(m, g)[f];
  EXPECT_LT(k_angle, 45.0);
  EXPECT_LT(face_orthogonality(m, g)[f], 45.0);
  const FvReport euclid = run_fvcheck(m, CheckOptions{});
  EXPECT_FALSE(euclid.k_metric);
  EXPECT_GT(euclid.find("orthogonality")->violations, 0);
  m.metric_scale = {std::sqrt(100 / std::cbrt(1e4)), std::sqrt(100 / std::cbrt(1e4)), std::sqrt(1 / std::cbrt(1e4))};
  const FvReport kr = run_fvcheck(m, CheckOptions{});
  EXPECT_TRUE(kr.k_metric);
  EXPECT_EQ(kr.find("orthogonality")->violations, 0) << report_summary_text(kr);
  ASSERT_FALSE(kr.by_region.empty());
  EXPECT_NEAR(kr.by_region[0].k_angle_interior.max, k_angle, 1e-12);
}

// A mesh built in a permeability frame is judged in the metric of the K it was built for (the
// frame's, metric_scale); the report's K-non-orthogonality uses each cell's own K. The same sheared
// pair as above, the frame's K = (100, 100, 1), the second cell's rock isotropic: the frame metric
// sees the K-orthogonal face of the first cell's K on both sides (the check passes), the cells' own K
// see the second side at its Euclidean angle, 63 degrees (reported, not judged).
TEST(KOrthogonality, OrthogonalityCheckJudgesTheMetricTheMeshWasBuiltFor) {
  PolyMesh m = fvtest::box_grid(2, 1, 1);
  for (Vec3& k : m.cell_perm) k = {100, 100, 1};
  const double t = 2.0;
  for (Vec3& p : m.nodes) p.x += t * p.z;
  for (Vec3& c : m.cell_fv_center) c.x += t * c.z;
  m.metric_scale = {std::sqrt(100 / std::cbrt(1e4)), std::sqrt(100 / std::cbrt(1e4)), std::sqrt(1 / std::cbrt(1e4))};
  const MeshGeometry g = compute_geometry(m);
  const int f = interior_face(m);
  const double built_for = face_k_nonorthogonality(m, g)[f];  // every cell has the frame's K here
  EXPECT_NEAR(face_frame_nonorthogonality(m, g)[f], built_for, 1e-9);
  m.cell_perm[m.face_neighbour[f]] = {50, 50, 50};
  EXPECT_NEAR(face_frame_nonorthogonality(m, g)[f], built_for, 1e-9);
  const double own = face_k_nonorthogonality(m, g)[f];
  EXPECT_NEAR(own, 90.0 - face_orthogonality(m, g)[f], 1e-9);
  EXPECT_GT(own, 45.0);
  const FvReport r = run_fvcheck(m, CheckOptions{});
  EXPECT_TRUE(r.k_metric);
  EXPECT_EQ(r.find("orthogonality")->violations, 0) << report_summary_text(r);
  EXPECT_NEAR(r.k_angle_interior_all.max, own, 1e-9);
}
