// Layers split near the wells for the permeability frame (meshgen/case/near_well_layers.hpp):
// which layers, into how many children, what the split grid keeps of the user's, and when
// nothing is split.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include "meshgen/case/case.hpp"
#include "meshgen/case/near_well_layers.hpp"
#include "meshgen/case/permeability_metric.hpp"

using namespace hm;

namespace {

// 4 m cells around a vertical well from z 1000 to 1040 (the accuracy cases' grid near the well),
// coarse layers far above and below.
std::string case_text(const std::string& metric, const std::string& perm, const std::string& trajectory,
                      const std::string& extra = "") {
  return "name: layers\nmetric: " + metric + R"(
reservoir:
  x: [0, 40, 60, 64, 68, 72, 76, 80, 84, 88, 92, 96, 100, 104, 108, 112, 116, 120, 124, 128, 132, 136, 140, 160, 200]
  y: [0, 40, 60, 64, 68, 72, 76, 80, 84, 88, 92, 96, 100, 104, 108, 112, 116, 120, 124, 128, 132, 136, 140, 160, 200]
  z: [900, 950, 970, 974, 978, 982, 986, 990, 994, 998, 1002, 1006, 1010, 1014, 1018, 1022, 1026, 1030, 1034, 1038, 1042, 1046, 1050, 1054, 1058, 1062, 1066, 1070, 1090, 1150]
  permeability: )" + perm + R"(
  porosity: 0.2
  initial_pressure: 200
)" + extra + R"(
wells:
  - name: W
    type: producer
    trajectory: )" + trajectory + R"(
    radius: 0.1
    drainage_radius: 8
    rings: 6
    sectors: 12
    segment_length: 4
    bhp: 150
)";
}

const char* kVertical = "[[100, 100, 1000], [100, 100, 1040]]";
const char* kHorizontal = "[[70, 100, 1020], [130, 100, 1020]]";

int children_sum(const std::vector<int>& c) { return std::accumulate(c.begin(), c.end(), 0); }

}  // namespace

TEST(NearWellLayers, TallScaledLayersWithinReachAreSplitTheOthersKeptBitForBit) {
  const CaseSpec user = parse_case(case_text("permeability", "[100, 100, 10]", kVertical, "  near_well_layer_aspect: 0"));
  CaseSpec cs = user;
  cs.reservoir.near_well_layer_aspect = 1.5;
  const std::vector<int> children = near_well_layer_children(cs);
  // Scaled frame of kv/kh 0.1: a 4 m layer is 8.6 m tall, a 4 m cell 2.7 m wide: 8.6 / (1.5 x 2.7) -> 3.
  const Vec3 s = permeability_frame(cs).scale;
  const double expected = std::ceil((4 / s.z) / (1.5 * 4 / s.x));
  ASSERT_EQ(expected, 3);
  const double reach = kLayerSplitReach * 1.5 * 8;  // 24 m around the trajectory
  for (size_t k = 0; k < children.size(); ++k) {
    const double z0 = cs.reservoir.z[k], z1 = cs.reservoir.z[k + 1];
    const bool near = z1 > 1000 - reach && z0 < 1040 + reach;  // every such layer is 4 m thick
    EXPECT_EQ(children[k], near ? 3 : 1) << "layer " << k << " [" << z0 << ", " << z1 << "]";
  }
  split_layers_near_wells(cs);
  ASSERT_EQ(cs.reservoir.z.size() - 1, static_cast<size_t>(children_sum(children)));
  // Every user plane is a plane of the split grid, unchanged.
  for (double z : user.reservoir.z)
    EXPECT_TRUE(std::binary_search(cs.reservoir.z.begin(), cs.reservoir.z.end(), z)) << z;
  // Strictly increasing planes; the children of the layer 1018-1022 are 4/3 m thick.
  for (size_t k = 0; k + 1 < cs.reservoir.z.size(); ++k) EXPECT_GT(cs.reservoir.z[k + 1], cs.reservoir.z[k]);
  const auto it = std::lower_bound(cs.reservoir.z.begin(), cs.reservoir.z.end(), 1018.0);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(*(it + c + 1) - *(it + c), 4.0 / 3, 1e-12);
  // A vertical well's segments are no taller than the thinnest split layer: 4 / 3 m.
  EXPECT_NEAR(cs.wells[0].segment_length, 4.0 / 3, 1e-12);
  ASSERT_FALSE(cs.notes.empty());
  EXPECT_NE(cs.notes.back().find("layers near the wells split"), std::string::npos) << cs.notes.back();
  // Already split: a second call changes nothing.
  CaseSpec again = cs;
  split_layers_near_wells(again);
  EXPECT_EQ(again.reservoir.z, cs.reservoir.z);
}

TEST(NearWellLayers, LoadCaseSplitsOnlyInAnAnisotropicPermeabilityFrame) {
  const size_t user_layers = 29;
  EXPECT_EQ(parse_case(case_text("euclidean", "[100, 100, 10]", kVertical)).reservoir.z.size() - 1, user_layers);
  EXPECT_EQ(parse_case(case_text("permeability", "[100, 100, 100]", kVertical)).reservoir.z.size() - 1, user_layers);
  EXPECT_EQ(parse_case(case_text("permeability", "[100, 100, 10]", kVertical, "  near_well_layer_aspect: 0"))
                    .reservoir.z.size() - 1,
            user_layers);
  const CaseSpec split = parse_case(case_text("permeability", "[100, 100, 10]", kVertical));
  EXPECT_GT(split.reservoir.z.size() - 1, user_layers);
  // kv/kh 0.01: 4 m layers are 18.6 m tall in the frame, 4 m cells 1.86 m wide: 7 children at aspect 1.5.
  const CaseSpec strong = parse_case(case_text("permeability", "[100, 100, 1]", kVertical));
  EXPECT_GT(strong.reservoir.z.size(), split.reservoir.z.size());
  const auto it = std::lower_bound(strong.reservoir.z.begin(), strong.reservoir.z.end(), 1018.0);
  EXPECT_NEAR(*(it + 1) - *it, 4.0 / 7, 1e-9);
}

TEST(NearWellLayers, AHorizontalWellKeepsItsSegmentsAndPerCellRockFollowsTheChildren) {
  CaseSpec cs = parse_case(case_text("permeability", "[100, 100, 1]", kHorizontal, "  near_well_layer_aspect: 0"));
  const size_t nx = cs.reservoir.x.size() - 1, ny = cs.reservoir.y.size() - 1, nz = cs.reservoir.z.size() - 1;
  const size_t n = nx * ny * nz;
  // Per-cell rock that names its layer: kz = 1 + k / 100.
  cs.reservoir.cell_permx.assign(n, 100);
  cs.reservoir.cell_permy.assign(n, 100);
  cs.reservoir.cell_poro.assign(n, 0.2);
  cs.reservoir.cell_permz.resize(n);
  for (size_t c = 0; c < n; ++c) cs.reservoir.cell_permz[c] = 1 + static_cast<double>(c / (nx * ny)) / 100;
  const ReservoirSpec user = cs.reservoir;
  cs.reservoir.near_well_layer_aspect = 1.5;
  split_layers_near_wells(cs);
  ASSERT_GT(cs.reservoir.z.size(), user.z.size());
  EXPECT_EQ(cs.wells[0].segment_length, 4.0);  // no segment spans a layer vertically
  // Each cell of the split grid has the rock of the user's cell holding its centre.
  const size_t layers = cs.reservoir.z.size() - 1;
  ASSERT_EQ(cs.reservoir.cell_permz.size(), nx * ny * layers);
  for (size_t k = 0; k < layers; ++k) {
    const double zc = 0.5 * (cs.reservoir.z[k] + cs.reservoir.z[k + 1]);
    const int user_cell = reservoir_cell_at(user, {50, 130, zc});
    const int cell = reservoir_cell_at(cs.reservoir, {50, 130, zc});
    EXPECT_EQ(reservoir_permeability(cs.reservoir, cell).z, reservoir_permeability(user, user_cell).z) << k;
  }
}
