// Dirichlet outer faces (docs/fvcheck.md, "Boundary faces"): the boundary value is taken at the
// face's boundary flux point, the foot of the perpendicular from the owner's FV centre, where the
// half-transmissibility ends. Then a linear pressure field is reproduced exactly in a cell whose FV
// centre is not above its faces' centroids; with the value at the centroids it is not.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "../fvcheck/fv_test_meshes.hpp"
#include "fvcheck/lib/transmissibility.hpp"
#include "meshgen/core/fv_quality.hpp"
#include "solver_demo/lib/tpfa.hpp"

using namespace hm;

namespace {

double p_linear(Vec3 x) { return 200 + 3 * x.x - 2 * x.y + 0.5 * x.z; }

// The pressure of the one cell of `m` with p_linear imposed on every face: from solve_tpfa, and
// from the same half-transmissibilities with the value taken at each face centroid instead.
struct OneCell {
  double solved = 0, at_centroids = 0, exact = 0;
};

OneCell solve_one_cell(PolyMesh m) {
  m.cell_perm[0] = {100, 100, 100};
  const MeshGeometry g = compute_geometry(m);
  FlowProblem pb;
  pb.mesh = &m;
  pb.geo = &g;
  pb.gravity = false;
  pb.outer_dirichlet = p_linear;
  const Transmissibilities tr = compute_transmissibilities(m, g);
  OneCell r;
  r.solved = solve_tpfa(pb, tr).pressure.at(0);
  double sum_t = 0, sum_tp = 0;
  for (int f = 0; f < m.n_faces(); ++f) {
    sum_t += tr.half_owner[f];
    sum_tp += tr.half_owner[f] * p_linear(g.face_centroid[f]);
  }
  r.at_centroids = sum_tp / sum_t;
  r.exact = p_linear(m.cell_fv_center[0]);
  return r;
}

}  // namespace

TEST(BoundaryDirichlet, LinearFieldIsExactWithTheValueAtTheFootPoint) {
  // A box with its FV centre off the middle, and the flat triangular prism of the fvcheck test
  // (Orthogonality.BoundaryFaceIsOrthogonalExactlyWhenTheCentreProjectsIntoIt), centre inside and
  // projecting into every face.
  const PolyMesh box = fvtest::prism({{0, 0}, {4, 0}, {4, 2}, {0, 2}}, 0, 1, {0.7, 1.6, 0.3});
  const PolyMesh sliver = fvtest::prism({{0, 0}, {10, 0}, {9, 0.5}}, 0, 1, {9.0, 0.3, 0.5});
  for (const PolyMesh* m : {&box, &sliver}) {
    const OneCell r = solve_one_cell(*m);
    std::printf("[ figures  ] exact %.12f, solved %.12f, value at the centroids %.6f\n", r.exact, r.solved,
                r.at_centroids);
    EXPECT_NEAR(r.solved, r.exact, 1e-10 * r.exact);
    // The same transmissibilities with the value at the face centroids miss the linear field.
    EXPECT_GT(std::fabs(r.at_centroids - r.exact), 1e-3);
  }
}
