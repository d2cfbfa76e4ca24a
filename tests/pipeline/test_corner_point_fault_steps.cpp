// Layers split at fault steps near the wells (meshgen/case/corner_point_fault_steps.hpp,
// docs/corner-point.md "Fault steps"). What can fail: which layers are split and only near a well,
// the children tile their parents, the two sides of the fault meet face to face afterwards (no fault
// face left, every child depth on a fault pillar is a depth of the other side), rock and multipliers
// are inherited as the keywords mean, and a well across a fraction-of-a-layer throw meshes soundly.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <set>

#include "../exporters/exporter_test_support.hpp"
#include "corner_point_test_models.hpp"
#include "model_cell_volumes.hpp"
#include "meshgen/case/corner_point_fault_steps.hpp"
#include "meshgen/case/grdecl.hpp"
#include "meshgen/case/segment_distance.hpp"
#include "meshgen/grids/corner_point_grid.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"
#include "meshgen/pipeline/local_frame.hpp"

using namespace hm;
using hmtest::TempDir;

namespace {

// 8 x 5 x 6 cells of 30 x 30 x 2 m, dipping, pillars leaning 10 degrees along x, a fault of 0.4 layer
// (0.8 m) on pillar line i = 4.
hmtest::LayeredModel faulted_model() {
  hmtest::LayeredModel g;
  g.nx = 8, g.ny = 5, g.nz = 6, g.dx = 30, g.dy = 30, g.dz = 2, g.dip_deg = 3, g.pillar_deg = 10;
  g.fault_i = 4, g.throw_m = 0.8;
  return g;
}

CornerPointModel read_model(const TempDir& tmp, const hmtest::LayeredModel& g) {
  std::ofstream(tmp.path / "M.GRDECL") << g.text();
  return read_corner_point_model((tmp.path / "M.GRDECL").string(), "reservoir.grdecl");
}

// Mesh volume per model cell (natural order), the model's cells meshed alone; and the fault faces.
std::vector<double> cell_volumes(const CornerPointModel& m, int64_t* fault_faces) {
  MeshBuilder scratch;
  *fault_faces = corner_point_cell_faces(m, std::vector<char>(m.actnum.size(), 1), scratch).fault_faces;
  return hmtest::model_cell_volumes(m);
}

// The split model r of m: the children's volumes
// sum to their parent's, there are cells near the well and beyond it, and beyond it a cell is whole in
// its first child, the others of zero thickness (not meshed).
void expect_children_tile_their_parents(const CornerPointModel& r, const FaultStepSplit& split,
                                        const std::vector<double>& parent_volume, const std::vector<double>& child_volume) {
  std::vector<double> sum(parent_volume.size(), 0.0);
  for (size_t c = 0; c < r.n_cells(); ++c) sum[r.parent_cell[c]] += child_volume[c];
  int near = 0, far = 0;
  for (size_t p = 0; p < parent_volume.size(); ++p) {
    EXPECT_NEAR(sum[p] / parent_volume[p], 1.0, 1e-12) << "model cell " << p;
    (split.near[p] ? near : far)++;
  }
  EXPECT_GT(near, 0);
  EXPECT_GT(far, 0);
  for (size_t c = 0; c < r.n_cells(); ++c) {
    const size_t p = static_cast<size_t>(r.parent_cell[c]);
    if (split.near[p]) continue;
    const size_t k = c / (size_t(r.nx) * r.ny);
    const bool first = k == 0 || r.parent_layer[k - 1] != r.parent_layer[k];
    EXPECT_NEAR(child_volume[c], first ? parent_volume[p] : 0.0, 1e-12 * parent_volume[p]) << "cell " << c;
  }
}

// On the faulted model's fault pillars (line i = 4), between the split model r's cells near the well:
// every child depth of one side within the range both sides span is a depth of the other side, and more
// than `least` such depths per pillar side. Returns how many pillar sides were compared.
int expect_near_depths_match_across_the_fault(const CornerPointModel& m, const CornerPointModel& r,
                                              const FaultStepSplit& split, int least) {
  int compared = 0;
  for (int J = 0; J <= m.ny; ++J)
    for (int j : {J - 1, J}) {
      if (j < 0 || j >= m.ny) continue;
      auto near_depths = [&](int i) {
        std::set<double> out;
        const int q = (4 > i ? 1 : 0) | (J > j ? 2 : 0);
        for (int k = 0; k < r.nz; ++k) {
          const size_t c = i + size_t(r.nx) * (j + size_t(r.ny) * k);
          if (!split.near[static_cast<size_t>(r.parent_cell[c])]) continue;
          out.insert(r.zcorn[zcorn_index(r, i, j, k, q)]), out.insert(r.zcorn[zcorn_index(r, i, j, k, 4 | q)]);
        }
        return out;
      };
      const std::set<double> left = near_depths(3), right = near_depths(4);
      if (left.empty() || right.empty()) continue;
      ++compared;
      const double lo = std::max(*left.begin(), *right.begin()), hi = std::min(*left.rbegin(), *right.rbegin());
      int matched = 0;
      for (const std::set<double>* side : {&left, &right})
        for (double z : *side)
          if (z >= lo && z <= hi) {
            EXPECT_TRUE(left.count(z) && right.count(z)) << "pillar (4, " << J << ") depth " << z;
            ++matched;
          }
      EXPECT_GT(matched, least) << "pillar (4, " << J << ")";
    }
  return compared;
}

}  // namespace

// A vertical well beside the fault asks for every layer it reaches to be split in two; a well far
// from the fault asks nothing.
TEST(FaultSteps, LayersNearAWellAcrossAFractionalThrowAreSplit) {
  TempDir tmp("cpsteps_children");
  const CornerPointModel m = read_model(tmp, faulted_model());
  // The fault's pillar line is at x = 120 at depth 1000 (leaning 10 degrees along x).
  const FaultStepSplit near = fault_step_children(m, {{{{125, 75, 1000}, {125, 75, 1012}}, 20}});
  ASSERT_EQ(near.children.size(), 6u);
  for (int k = 0; k < m.nz; ++k) EXPECT_EQ(near.children[k], 2) << "layer " << k;
  EXPECT_GT(near.steps, 0);
  const FaultStepSplit far = fault_step_children(m, {{{{15, 15, 1000}, {15, 15, 1012}}, 20}});
  EXPECT_FALSE(far.splits());
  // A whole-layer throw is no step.
  hmtest::LayeredModel whole = faulted_model();
  whole.throw_m = 2 * whole.dz;
  EXPECT_FALSE(fault_step_children(read_model(tmp, whole), {{{{125, 75, 1000}, {125, 75, 1012}}, 20}}).splits());
}

// A well that did not ask (no step within its reach) but has split cells of another well within reach
// gets its own cells split too, and so on from well to well: the edge between split and whole cells
// (a whole cell beside split ones carries their nodes in the middle of its face's edges) never runs
// through a cavity. Sweep seed 10 with three wells failed there: 34 wall triangles below 45 degrees
// (docs/corner-point.md, "Fault steps").
TEST(FaultSteps, WellsBesideSplitCellsGetTheirCellsSplitToo) {
  TempDir tmp("cpsteps_beside");
  const CornerPointModel m = read_model(tmp, faulted_model());
  const FaultStepRequest a{{{125, 75, 1000}, {125, 75, 1012}}, 20};  // beside the fault (x = 120): asks
  const FaultStepRequest b{{{70, 75, 1000}, {70, 75, 1012}}, 20};    // 50 m from it: A's split cells in reach
  const FaultStepRequest c{{{15, 75, 1000}, {15, 75, 1012}}, 20};    // in reach of B's cells only
  auto column_near = [&](const FaultStepSplit& s, int i) {
    bool any = false;
    for (int k = 0; k < m.nz; ++k) any = any || s.near[i + m.nx * (2 + m.ny * k)];
    return any;
  };
  const FaultStepSplit a_only = fault_step_children(m, {a});
  ASSERT_TRUE(a_only.splits());
  const FaultStepSplit a_c = fault_step_children(m, {a, c});
  const FaultStepSplit abc = fault_step_children(m, {a, b, c});
  const FaultStepSplit cba = fault_step_children(m, {c, b, a});
  EXPECT_EQ(abc.near, cba.near);
  EXPECT_EQ(abc.children, a_only.children);  // the same children per layer: only where they are cut grows
  for (int i : {0, 1}) {
    EXPECT_FALSE(column_near(a_only, i)) << i;  // fail half: A's split cells stop short of columns 0-1
    EXPECT_FALSE(column_near(a_c, i)) << i;     // and C alone does not reach them
    EXPECT_TRUE(column_near(abc, i)) << i;      // through B, C's cells are split too
  }
  // The invariant: every well's reach holds split cells only or whole cells only.
  const std::vector<std::pair<const FaultStepSplit*, std::vector<FaultStepRequest>>> runs{
      {&a_only, {a}}, {&a_c, {a, c}}, {&abc, {a, b, c}}};
  for (const auto& [s, given] : runs)
    for (const FaultStepRequest& w : given) {
      int split = 0, whole = 0;
      for (size_t cell = 0; cell < m.n_cells(); ++cell) {
        const std::array<Vec3, 8> corners = cell_corners(m, cell);
        Vec3 centre{0, 0, 0};
        for (const Vec3& q : corners) centre += q / 8.0;
        double radius = 0;
        for (const Vec3& q : corners) radius = std::max(radius, norm(q - centre));
        if (segment_segment_distance(centre, centre, w.path[0], w.path[1]) > w.reach + radius) continue;
        (s->near[cell] ? split : whole)++;
      }
      EXPECT_TRUE(split == 0 || whole == 0) << split << " split and " << whole << " whole cells in one well's reach";
    }
}

// The split model: children tile their parents, the parents' tops and bottoms are kept bit for bit,
// near the well the fault's two sides meet face to face, away from it a cell stays whole (its other
// children of zero thickness), rock and multipliers as the keywords mean.
TEST(FaultSteps, ChildrenTileTheirParentsAndMeetAcrossTheFault) {
  TempDir tmp("cpsteps_tile");
  CornerPointModel m = read_model(tmp, faulted_model());
  const int marked = 3 + m.nx * (2 + m.ny * 2);  // cell (3, 2, 2), beside the fault: +x, -y, +z and -z multipliers
  m.trans_mult[0][marked] = 0.5;
  m.trans_mult[3][marked] = 0.25;
  m.trans_mult[4][marked] = 0.125;
  m.trans_mult[5][marked] = 0.0625;
  const FaultStepSplit split = fault_step_children(m, {{{{125, 75, 1000}, {125, 75, 1012}}, 20}});
  const CornerPointModel r = layers_split_at_fault_steps(m, split);
  ASSERT_EQ(r.nz, 2 * m.nz);
  ASSERT_EQ(r.parent_layer.size(), size_t(r.nz));
  EXPECT_EQ(r.parent_nz, m.nz);
  check_corner_point_geometry(r, "split");

  int64_t faults_before = 0, faults_after = 0;
  const std::vector<double> parent_volume = cell_volumes(m, &faults_before), child_volume = cell_volumes(r, &faults_after);
  EXPECT_GT(faults_before, 0);
  std::printf("[ figures  ] fault faces: %lld before, %lld after (between cells near the well and the others)\n",
              static_cast<long long>(faults_before), static_cast<long long>(faults_after));
  expect_children_tile_their_parents(r, split, parent_volume, child_volume);

  // On the fault's pillars (line i = 4), between cells near the well: every child depth of one side is a
  // depth of the other side, within the range both sides span.
  expect_near_depths_match_across_the_fault(m, r, split, 4);

  for (size_t c = 0; c < r.n_cells(); ++c) {
    const int p = r.parent_cell[c], k = static_cast<int>(c / (size_t(r.nx) * r.ny));
    const bool first = k == 0 || r.parent_layer[k - 1] != r.parent_layer[k];
    const bool last = k + 1 == r.nz || r.parent_layer[k + 1] != r.parent_layer[k];
    bool at_bottom = true;  // the child ends at its parent's bottom (the last one; the first too away from the well)
    for (int q = 4; q < 8; ++q) at_bottom = at_bottom && corner(r, c, q) == corner(m, p, q);
    for (int q = 0; q < 8; ++q)
      if ((q < 4 && first) || (q >= 4 && last)) {
        EXPECT_EQ(corner(r, c, q), corner(m, p, q)) << c << " " << q;
      }
    EXPECT_EQ(r.permx[c], m.permx[p]);
    EXPECT_EQ(r.poro[c], m.poro[p]);
    EXPECT_EQ(r.actnum[c], m.actnum[p]);
    if (p != marked) {
      for (int d = 0; d < 6; ++d) EXPECT_EQ(r.trans_mult[d][c], 1.0);
      continue;
    }
    EXPECT_EQ(r.trans_mult[0][c], 0.5);
    EXPECT_EQ(r.trans_mult[3][c], 0.25);
    EXPECT_TRUE(split.near[p]);
    EXPECT_EQ(r.trans_mult[4][c], at_bottom ? 0.125 : 1.0);
    EXPECT_EQ(at_bottom, last);
    EXPECT_EQ(r.trans_mult[5][c], first ? 0.0625 : 1.0);
  }
}

// A throw of 0.96 layer leaves steps of 4 % of a layer (0.08 m) between the two sides' boundaries:
// too thin to split (kMinStepFraction), and a cavity vertex that near a wall face's corner lies in its
// diametral sphere (the horizontal sweep's seed 25: not Delaunay admissible). snap_thin_fault_steps
// moves one side's boundary onto the other's on the fault pillars within reach of a well: there every
// depth of one side within the range of both is a depth of the other or at least 5 % of a layer from
// all of them; pillars beyond reach keep their depths; no cell loses its thickness. A throw of 0.4
// layer has no thin step and nothing moves.
TEST(FaultSteps, ThinStepsNearAWellAreSnappedOntoTheOtherSide) {
  TempDir tmp("cpsteps_snap");
  hmtest::LayeredModel g = faulted_model();
  g.throw_m = 0.96 * g.dz;
  const CornerPointModel before = read_model(tmp, g);
  CornerPointModel m = before;
  const std::vector<FaultStepRequest> well{{{{125, 75, 1000}, {125, 75, 1012}}, 20}};
  const SnappedSteps snaps = snap_thin_fault_steps(m, well);
  std::printf("[ figures  ] 0.96-layer throw: %lld corners moved, at most %.4f m\n", static_cast<long long>(snaps.corners),
              snaps.largest);
  EXPECT_GT(snaps.corners, 0);
  EXPECT_NEAR(snaps.largest, 0.04 * g.dz, 1e-3);
  check_corner_point_geometry(m, "snapped");
  // Depths on fault pillar (4, J) of the columns on one side (i = 3) and the other (i = 4).
  auto side_depths = [](const CornerPointModel& model, int J, int i) {
    std::set<double> out;
    for (int j : {J - 1, J}) {
      if (j < 0 || j >= model.ny) continue;
      const int q = (4 > i ? 1 : 0) | (J > j ? 2 : 0);
      for (int k = 0; k < model.nz; ++k)
        out.insert(model.zcorn[zcorn_index(model, i, j, k, q)]), out.insert(model.zcorn[zcorn_index(model, i, j, k, 4 | q)]);
    }
    return out;
  };
  int near_pillars = 0, far_pillars = 0;
  for (int J = 0; J <= m.ny; ++J) {
    const Vec3 top = pillar_point(m, 4 + (m.nx + 1) * J, 1006);
    const bool near = segment_segment_distance(top, top, well[0].path[0], well[0].path[1]) <= well[0].reach - 2 * g.dz;
    const bool far = segment_segment_distance(top, top, well[0].path[0], well[0].path[1]) > well[0].reach + 2 * g.dz;
    if (far) {
      ++far_pillars;
      for (int i : {3, 4}) EXPECT_EQ(side_depths(m, J, i), side_depths(before, J, i)) << "pillar (4, " << J << ")";
    }
    if (!near) continue;
    ++near_pillars;
    const std::set<double> left = side_depths(m, J, 3), right = side_depths(m, J, 4);
    const double lo = std::max(*left.begin(), *right.begin()), hi = std::min(*left.rbegin(), *right.rbegin());
    int matched = 0;
    for (double z : left) {
      if (z < lo || z > hi) continue;
      double nearest = INFINITY;
      for (double w : right) nearest = std::min(nearest, std::fabs(w - z));
      EXPECT_TRUE(nearest == 0 || nearest >= kMinStepFraction * g.dz) << "pillar (4, " << J << ") depth " << z;
      matched += nearest == 0;
    }
    EXPECT_GT(matched, 2) << "pillar (4, " << J << ")";
  }
  EXPECT_GT(near_pillars, 0);
  EXPECT_GT(far_pillars, 0);
  CornerPointModel fractional = read_model(tmp, faulted_model());
  EXPECT_EQ(snap_thin_fault_steps(fractional, well).corners, 0);
}

// The permeability frame's split of `m` near `well` with this aspect, checked: the children tile their
// parents; near the well every child is no thicker than the split asks for; on the fault's pillars
// (line I = 4) every child depth of one side within the range both sides span is a depth of the other.
// Returns the children per layer.
std::vector<int> expect_frame_split_meets_across_the_fault(const CornerPointModel& m,
                                                           const std::vector<FaultStepRequest>& well, Vec3 scale,
                                                           double aspect) {
  const FaultStepSplit split = frame_layer_children(m, well, scale, aspect);
  EXPECT_TRUE(split.splits());
  EXPECT_NEAR(split.child_thickness, aspect * 20 * scale.z, 1e-5);  // the columns' plan edges: 30 m and a little
  const CornerPointModel r = layers_split_at_fault_steps(m, split);
  check_corner_point_geometry(r, "frame split");
  int64_t faults = 0;
  const std::vector<double> parent_volume = cell_volumes(m, &faults), child_volume = cell_volumes(r, &faults);
  expect_children_tile_their_parents(r, split, parent_volume, child_volume);
  for (size_t c = 0; c < r.n_cells(); ++c) {
    const size_t p = static_cast<size_t>(r.parent_cell[c]);
    if (!split.near[p]) continue;
    for (int q = 0; q < 4; ++q) {
      const double thick = corner(r, c, q + 4).z - corner(r, c, q).z;
      EXPECT_GE(thick, 0) << "cell " << c << " corner " << q;
      EXPECT_LE(thick, split.child_thickness * (1 + 1e-12)) << "cell " << c << " corner " << q;
    }
  }
  EXPECT_GT(expect_near_depths_match_across_the_fault(m, r, split, 10), 0);
  return split.children;
}

// The permeability frame's split (frame_layer_children; docs/anisotropy.md, "Corner-point models") of
// 2 m layers with a 0.8 m throw, beside a well; cells beyond reach stay whole. Children at most 0.889 m:
// 0.8 + 2 x 0.6 at the fault's pillars, 3 x 0.667 elsewhere. At most 1 m: 1 + 2 parts at the fault's
// pillars, 2 elsewhere and a third of zero thickness. A growth fault (2.5 m layers beyond it, 2 m before)
// gives the layers different counts of children (3 to 4) and each side at the fault its own intervals:
// still face to face. A frame that does not stretch the layers past the aspect splits nothing.
TEST(FaultSteps, FrameChildrenMeetAcrossTheFaultAndAreNoThickerThanAsked) {
  TempDir tmp("cpsteps_frame");
  const CornerPointModel m = read_model(tmp, faulted_model());
  const std::vector<FaultStepRequest> well{{{{125, 75, 1000}, {125, 75, 1012}}, 20}};
  const Vec3 scale{1.5, 1.5, 1 / 2.25};  // kv/kh 0.088: layers 3.4 times taller against the columns
  // 30 m columns, scaled 20 m wide: children at most aspect x 20 x 0.444 m thick.
  EXPECT_EQ(expect_frame_split_meets_across_the_fault(m, well, scale, 0.1), std::vector<int>(size_t(m.nz), 3));
  EXPECT_EQ(expect_frame_split_meets_across_the_fault(m, well, scale, 1 / (20 * scale.z)), std::vector<int>(size_t(m.nz), 3));
  hmtest::LayeredModel growth = faulted_model();
  growth.dz_beyond_fault = 2.5;
  const CornerPointModel g = read_model(tmp, growth);
  EXPECT_EQ(expect_frame_split_meets_across_the_fault(g, well, scale, 1 / (20 * scale.z)), (std::vector<int>{4, 3, 4, 3, 4, 3}));
  EXPECT_FALSE(frame_layer_children(m, well, scale, 1.5).splits());  // 20 m scaled wide, 4.5 m tall
}
