// Perforated intervals (wells[i].perforations): the case keys are validated with the key and the
// reason; in the mesh, exactly the wellbore faces whose centre's measured depth lies in an
// interval stay on the well's patch, the others are closed walls, and only cells with an open
// face get a connection factor. Shipped case: examples/perforated_survey.yaml (a survey well
// entering through the top, perforated over md 75-100 m).
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "fvcheck/lib/checks.hpp"
#include "fvcheck/lib/transmissibility.hpp"
#include "meshgen/pipeline/hybrid_mesh.hpp"
#include "meshgen/pipeline/perforations.hpp"

namespace {

using namespace hm;

CaseSpec example(const std::string& name) { return load_case(std::string(HM_SOURCE_DIR) + "/examples/" + name + ".yaml"); }

std::string one_well_case(const std::string& well_extra) {
  return "name: p\n"
         "reservoir: {x: [0, 10, 20, 30, 40], y: [0, 10, 20, 30, 40], z: [1000, 1010, 1020, 1030, 1040],\n"
         "            permeability: [100, 100, 10], porosity: 0.2, initial_pressure: 200}\n"
         "wells:\n"
         "  - {name: P1, trajectory: [[20, 20, 1005], [20, 20, 1035]], radius: 0.1, drainage_radius: 4,\n"
         "     bhp: 150" + well_extra + "}\n";
}

std::string error_of(const std::string& yaml) {
  try {
    parse_case(yaml);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(Perforations, BadIntervalsAreInputErrorsNamingTheKey) {
  const std::string key = "wells[0].perforations";
  const struct {
    const char* extra;
    const char* path;
    const char* reason;
  } cases[] = {
      {", perforations: []", "", "non-empty list"},
      {", perforations: [[5, 3]]", "[0]", "greater than md_from"},
      {", perforations: [[-1, 3]]", "[0]", ">= 0"},
      {", perforations: [[5, 31]]", "[0]", "beyond the end of the path (md 30 m)"},
      {", perforations: [[5, 10], [8, 12]]", "[1]", "overlaps"},
      {", perforations: [[5, 10, 12]]", "[0]", "[md_from, md_to]"},
  };
  for (const auto& c : cases) {
    const std::string e = error_of(one_well_case(c.extra));
    EXPECT_NE(e.find(key + c.path), std::string::npos) << c.extra << " -> " << e;
    EXPECT_NE(e.find(c.reason), std::string::npos) << c.extra << " -> " << e;
  }
  // The pass half: two disjoint intervals, the second ending at the path's end.
  EXPECT_EQ(error_of(one_well_case(", perforations: [[0, 10], [10, 30]]")), "(accepted)");
}

TEST(Perforations, SurveyDepthsAreItsStationsTrajectoryDepthsItsLength) {
  const CaseSpec cs = example("perforated_survey");
  const std::vector<double> md = well_measured_depths(cs.wells[0]);
  const std::vector<double> stations = {0, 10, 15, 20, 25, 30, 35, 40, 110};
  ASSERT_EQ(md.size(), stations.size());
  for (size_t i = 0; i < md.size(); ++i) EXPECT_EQ(md[i], stations[i]);
  const std::vector<double> inj = well_measured_depths(cs.wells[1]);
  ASSERT_EQ(inj.size(), 2u);
  EXPECT_DOUBLE_EQ(inj[1], 80.0);
}

TEST(Perforations, OnlyWellboreFacesInsideTheIntervalStayOpen) {
  const CaseSpec cs = example("perforated_survey");
  const HybridMesh h = build_hybrid_mesh(cs);
  ASSERT_TRUE(h.build_report.ok);
  for (const CheckResult& c : {check_conformity(h.mesh, h.geometry), check_closure(h.mesh, h.geometry),
                               check_convexity(h.mesh, h.geometry), check_volume(h.mesh, h.geometry)})
    EXPECT_TRUE(c.ok()) << c.name << ": " << c.violations;

  const WellSpec& p1 = cs.wells[0];
  const std::vector<double> md = well_measured_depths(p1);
  double open_area = 0, closed_area = 0;
  int open = 0, closed = 0, injector_closed = 0;
  for (int f = 0; f < h.mesh.n_faces(); ++f) {
    const int32_t p = h.mesh.face_patch[f];
    if (p == closed_wellbore_patch(1)) ++injector_closed;
    const bool is_open = p == wellbore_patch(0), is_closed = p == closed_wellbore_patch(0);
    if (!is_open && !is_closed) continue;
    const double d = measured_depth_at(p1, md, h.geometry.face_centroid[f]);
    const bool inside = d >= 75 && d <= 100;
    EXPECT_EQ(is_open, inside) << "face " << f << " at md " << d;
    (is_open ? open_area : closed_area) += norm(h.geometry.face_area[f]);
    (is_open ? open : closed) += 1;
  }
  EXPECT_GT(open, 0);
  EXPECT_GT(closed, 0);
  EXPECT_EQ(injector_closed, 0);  // no perforations key: the whole path inside is open
  // 25 m perforated of a 12-gon wellbore: the open area is 25 m of its perimeter, to the
  // resolution of one 5 m segment at each end of the interval.
  const double perimeter = 12 * 2 * p1.radius * std::sin(M_PI / 12);
  EXPECT_NEAR(open_area / perimeter, 25.0, 2 * p1.segment_length);

  // Connections: exactly the cells with an open face, each with a positive factor.
  const Transmissibilities t = compute_transmissibilities(h.mesh, h.geometry);
  const auto cf = well_connection_factors(h.mesh, t, 2);
  std::set<int32_t> open_cells;
  for (int f = 0; f < h.mesh.n_faces(); ++f)
    if (h.mesh.face_patch[f] == wellbore_patch(0)) open_cells.insert(h.mesh.face_owner[f]);
  std::set<int32_t> connected;
  for (const auto& [cell, factor] : cf[0]) {
    connected.insert(cell);
    EXPECT_GT(factor, 0);
  }
  EXPECT_EQ(connected, open_cells);
  EXPECT_EQ(t.negative, 0);
}

TEST(Perforations, AnIntervalOutsideTheReservoirIsRefused) {
  CaseSpec cs = example("perforated_survey");
  cs.wells[0].perforations = {{20, 40}};  // above the top (the well enters at md ~ 65)
  try {
    build_hybrid_mesh(cs);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("wells[0].perforations"), std::string::npos) << e.what();
  }
}

}  // namespace
