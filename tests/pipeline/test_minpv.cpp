// The port of opm-grid 2022.10's MinpvProcessor (meshgen/case/minpv.hpp) on single columns, where what
// flow removes and connects can be read off: the cases that decide which pair is made. Against flow
// itself: tests/pipeline/test_grdecl.cpp and tests/exporters/test_flow_corner_point.cpp ("Minpv").
#include <gtest/gtest.h>

#include <utility>
#include <vector>

#include "meshgen/case/minpv.hpp"

using namespace hm;

namespace {

// One column of nz cells, 1 m thick, pore volume 10 but where `small` says 1; MINPV 5; all active.
MinpvInput column(const std::vector<int>& small, int nz = 6) {
  MinpvInput in;
  in.nx = in.ny = 1, in.nz = nz;
  in.thickness.assign(nz, 1.0);
  in.pore_volume.assign(nz, 10.0);
  for (int k : small) in.pore_volume[k] = 1.0;
  in.minpv.assign(nz, 5.0);
  in.actnum.assign(nz, 1);
  return in;
}

using Pairs = std::vector<std::pair<int64_t, int64_t>>;

}  // namespace

TEST(Minpv, OneSmallCellIsRemovedAndItsNeighboursConnected) {
  const MinpvResult r = opm_minpv(column({2}));
  EXPECT_EQ(r.removed, (std::vector<int64_t>{2}));
  EXPECT_EQ(r.connections, (Pairs{{1, 3}}));
}

TEST(Minpv, TwoSmallCellsInARowGiveOneConnectionAcrossBoth) {
  const MinpvResult r = opm_minpv(column({2, 3}));
  EXPECT_EQ(r.removed, (std::vector<int64_t>{2, 3}));
  EXPECT_EQ(r.connections, (Pairs{{1, 4}}));
}

TEST(Minpv, SmallCellsAtTheTopOrBottomAreRemovedWithoutAConnection) {
  const MinpvResult r = opm_minpv(column({0, 5}));
  EXPECT_EQ(r.removed, (std::vector<int64_t>{0, 5}));
  EXPECT_TRUE(r.connections.empty());
}

// Three small cells under the top cell: the connection joins the top cell to the first cell below them.
TEST(Minpv, SmallCellsUnderTheTopLayerConnectItToTheCellBelowThem) {
  const MinpvResult r = opm_minpv(column({1, 2, 3}));
  EXPECT_EQ(r.removed, (std::vector<int64_t>{1, 2, 3}));
  EXPECT_EQ(r.connections, (Pairs{{0, 4}}));
}

TEST(Minpv, InactiveThinCellsBelowAreSkippedWithPinchsThreshold) {
  MinpvInput in = column({2});
  in.actnum[3] = 0, in.thickness[3] = 0.1;  // inactive, thinner than PINCH's threshold: looked past
  in.z_tolerance = 0.2;
  const MinpvResult r = opm_minpv(in);
  EXPECT_EQ(r.connections, (Pairs{{1, 4}}));
  in.z_tolerance = 0;  // without PINCH the inactive cell stops the search: nothing to connect to
  EXPECT_TRUE(opm_minpv(in).connections.empty());
}
