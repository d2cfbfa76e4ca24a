// Limits of hemispherical end caps (meshgen/grids/well_block.cpp, make_gabriel_well_block):
// with few sectors and close rings a ring cell's FV centre (at sqrt(r_in r_out)) falls outside
// its outer chord; flat ends were protected by the end faces' Gabriel rule, caps have none, so
// the sectors are raised until every radial cell holds its centre. A cap that reaches another
// part of its own block is refused with its own reason.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "meshgen/grids/well_block.hpp"

using namespace hm;

namespace {

CaseSpec one_well(std::vector<Vec3> trajectory, int rings, int sectors, EndCaps ends) {
  CaseSpec cs;
  cs.name = "limits";
  cs.reservoir.x = {0, 100};
  cs.reservoir.y = {0, 100};
  cs.reservoir.z = {0, 100};
  WellSpec w;
  w.name = "W1";
  w.trajectory = std::move(trajectory);
  w.radius = 0.1;
  w.drainage_radius = 4;
  w.rings = rings;
  w.sectors = sectors;
  w.segment_length = 4;
  w.end_caps = ends;
  cs.wells.push_back(w);
  return cs;
}

// Cells whose FV centre is not strictly on the inner side of each face's plane (plane through
// the face's first node, normal from its first three nodes: every block face is planar).
int cells_not_holding_their_centre(const WellBlock& b) {
  int bad = 0;
  for (size_t c = 0; c < b.cell_faces.size(); ++c) {
    const Vec3 x = b.cell_attrs[c].fv_center;
    bool inside = true;
    for (const CellFace& f : b.cell_faces[c]) {
      const Vec3 p0 = b.nodes[f.nodes[0]], p1 = b.nodes[f.nodes[1]], p2 = b.nodes[f.nodes[2]];
      inside = inside && dot(cross(p1 - p0, p2 - p0), x - p0) < 0;
    }
    bad += !inside;
  }
  return bad;
}

}  // namespace

TEST(EndCapLimits, FewSectorsAreRaisedUntilEveryCellHoldsItsCentre) {
  struct Case {
    int rings, sectors, expected;  // expected: the smallest n with cos(pi / n) > 1 / sqrt(q), rounded up to even
  };
  for (const Case k : {Case{3, 3, 4}, Case{8, 4, 6}}) {
    const CaseSpec cs = one_well({{50, 50, 42}, {50, 50, 58}}, k.rings, k.sectors, EndCaps::Hemisphere);
    SCOPED_TRACE(std::to_string(k.rings) + " rings, " + std::to_string(k.sectors) + " sectors");
    // The fail half: the block with the requested sectors has cells that miss their centre.
    EXPECT_GT(cells_not_holding_their_centre(make_well_block(cs, 0, k.sectors)), 0);
    const WellBlock b = make_gabriel_well_block(cs, 0);
    EXPECT_EQ(b.sectors, k.expected);
    EXPECT_EQ(cells_not_holding_their_centre(b), 0);
    const double q = std::pow(40.0, 1.0 / k.rings);
    EXPECT_GT(std::cos(M_PI / b.sectors), 1 / std::sqrt(q));
    ASSERT_EQ(b.notes.size(), 1u);
    EXPECT_EQ(b.notes[0], "wells[0] (W1): sectors raised from " + std::to_string(k.sectors) + " to " +
                              std::to_string(k.expected) + " so that every radial cell holds its FV centre");
  }
  // 12 sectors and 6 rings need nothing.
  const WellBlock ok = make_gabriel_well_block(one_well({{50, 50, 42}, {50, 50, 58}}, 6, 12, EndCaps::Hemisphere), 0);
  EXPECT_EQ(ok.sectors, 12);
  EXPECT_TRUE(ok.notes.empty());
}

// A hook whose last leg comes back toward the first: its end cap (drainage radius beyond the end
// point) reaches the first leg's block. More sectors cannot help, so it is refused at once.
TEST(EndCapLimits, CapReachingItsOwnBlockIsRefusedWithTheReason) {
  const std::vector<Vec3> hook = {{30, 50, 40}, {30, 50, 60}, {50, 50, 60}, {50, 50, 45}, {37, 50, 45}};
  try {
    make_gabriel_well_block(one_well(hook, 3, 12, EndCaps::Hemisphere), 0);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find("wells[0] (W1): the outer surface of the radial block is not Gabriel next to a hemispherical "
                        "end cap ("),
              0u)
        << what;
    EXPECT_NE(what.find("use a smaller drainage_radius or end_caps: flat"), std::string::npos) << what;
  }
}
