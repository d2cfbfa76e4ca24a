// Bends up to the documented limit (kMaxBendDegrees, docs/case-format.md): the default run meshes
// bends at the limit (long legs: the preferred 1.5 R fillet; short legs: the smallest, 1.3 R) and
// checks the validation's pass/fail pair; HM_LONG_TESTS=1 runs the bend sweep of
// docs/robustness.md (bends 90 degrees to the limit x drainage radius x inclination x fillet x
// caps x optimisation) and prints its table.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>

#include "meshgen/case/case_limits.hpp"
#include "sweep_support.hpp"

using namespace hm;
using namespace hm::testing;

namespace {

struct BendCase {
  double beta_deg = 90;    ///< bend
  double r_over_dx = 1;    ///< drainage radius / lateral cell size
  double inc_deg = 0;      ///< inclination of the first leg
  double plane_deg = 0;    ///< turn of the bend plane about the first leg
  bool short_legs = false; ///< legs just long enough for the smallest fillet (1.3 R) instead of 1.5 R
  bool caps = true;        ///< hemispherical caps (strict) or flat ends
  bool optimize = false;
};

// One bent well in uniform dx x dx x dx/2 cells (dx = 6 m), R = r_over_dx dx, 6 rings, 12 sectors,
// segment R / 2; the box leaves 1.5 R + 2 dx + R around the trajectory.
RealisticCase make_bend_case(const BendCase& b) {
  const double dx = 6, dz = 3, R = b.r_over_dx * dx, seg = 0.5 * R;
  const double beta = b.beta_deg * M_PI / 180, inc = b.inc_deg * M_PI / 180, phi = b.plane_deg * M_PI / 180;
  const Vec3 d1{std::sin(inc), 0, std::cos(inc)};
  const Vec3 e1 = std::abs(d1.z) < 0.9 ? normalized(cross(d1, Vec3{0, 0, 1})) : Vec3{0, 1, 0};
  const Vec3 e2 = cross(d1, e1);
  const Vec3 n = std::cos(phi) * e1 + std::sin(phi) * e2;
  const Vec3 d2 = std::cos(beta) * d1 + std::sin(beta) * n;
  // The fillet takes 1.5 R when the legs leave room, else down to 1.3 R (well_block.cpp,
  // plan_bends: a leg of t_min + segment / 4 leaves none beyond the straight half segment).
  const double t_min = 1.3 * R * std::tan(beta / 2), t_pref = 1.5 * R * std::tan(beta / 2);
  const double leg = b.short_legs ? t_min + 0.25 * seg : 1.5 * t_pref + 2 * R;
  const std::vector<Vec3> traj = {Vec3{0, 0, 0}, leg * d1, leg * d1 + leg * d2};
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (const Vec3& p : traj)
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
  const double m = 1.5 * R + 2 * dx + R;
  std::ostringstream os;
  os << "name: bend\nreservoir:\n";
  const double cell[3] = {dx, dx, dz};
  const char* key[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    os << "  " << key[a] << ": [";
    const double first = std::floor((lo[a] - m) / cell[a]) * cell[a] + 0.37 * cell[a];
    for (int k = 0;; ++k) {
      const double v = first + k * cell[a];
      os << (k ? ", " : "") << detail::num(v + (a == 2 ? 2000.0 : 0.0));
      if (v >= hi[a] + m) break;
    }
    os << "]\n";
  }
  os << "  permeability: [100, 100, 10]\ntransition: {dilation: 1.5, optimize: " << (b.optimize ? "true" : "false")
     << "}\nwells:\n- name: W1\n  bhp: 150\n  radius: 0.1\n  drainage_radius: " << detail::num(R)
     << "\n  rings: 6\n  sectors: 12\n  segment_length: " << detail::num(seg)
     << "\n  end_caps: " << (b.caps ? "hemisphere" : "flat") << "\n  trajectory:\n";
  for (const Vec3& p : traj)
    os << "  - [" << detail::num(p.x) << ", " << detail::num(p.y) << ", " << detail::num(p.z + 2000) << "]\n";
  RealisticCase rc;
  rc.yaml = os.str();
  rc.spec = parse_case(rc.yaml);
  rc.dx = dx, rc.dz = dz, rc.drainage_radius = R, rc.inclination_deg = b.inc_deg, rc.wells = 1, rc.bends = 1;
  char label[160];
  std::snprintf(label, sizeof label, "bend %.1f R/dx %.1f inc %.0f plane %.0f %s %s%s", b.beta_deg, b.r_over_dx,
                b.inc_deg, b.plane_deg, b.short_legs ? "fillet 1.3R" : "fillet 1.5R", b.caps ? "caps" : "flat",
                b.optimize ? " opt" : "");
  rc.label = label;
  return rc;
}

// The paper example (R = 8 m, 6 m cells) with its second leg turned by beta from the vertical.
std::string paper_with_bend(double beta_deg) {
  std::ifstream in(std::string(HM_SOURCE_DIR) + "/examples/paper_single_well.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  const double b = beta_deg * M_PI / 180;
  char second[80];
  std::snprintf(second, sizeof second, "[%.6f, 200, %.6f]", 200 + 30 * std::sin(b), 1040 + 30 * std::cos(b));
  const std::string old = "[222.981, 200, 1059.284]";
  yaml.replace(yaml.find(old), old.size(), second);
  return yaml;
}

}  // namespace

// At the limit, as a user types it (coordinates to 6 digits): the paper example's bend raised to the
// limit and a short-legged bend there (smallest fillet). (The paper example at 110-119 degrees, which
// failed the self-check, now meshes too: docs/transition.md, "Bends: the focal line".)
TEST(Bends, BendsAtTheLimitMeshAndPassTheSelfCheck) {
  RealisticCase paper;
  paper.spec = parse_case(paper_with_bend(kMaxBendDegrees));
  paper.spec.transition.optimize = false;  // time; the sweep runs both
  const CaseResult a = mesh_and_check(paper);
  EXPECT_EQ(a.outcome, Outcome::Meshed) << "paper example at " << kMaxBendDegrees << " degrees: " << a.reason;
  BendCase b;
  b.beta_deg = kMaxBendDegrees;
  b.short_legs = true;
  b.inc_deg = 45;
  b.plane_deg = 30;
  const RealisticCase rc = make_bend_case(b);
  const CaseResult r = mesh_and_check(rc);
  EXPECT_EQ(r.outcome, Outcome::Meshed) << rc.label << ": " << r.reason;
}

// The optimiser keeps the faces on the well's polygons above fvcheck's orthogonality bound, measured
// as the self-check does (transition site to the well cell's FV centre): before, it judged only the
// faces between two transition cells, and a move could take a flat end's outer-ring face below 45
// degrees, refused by the self-check at every angle of this sweep configuration (12 of 156 cases of
// the bend sweep, docs/transition.md).
TEST(Bends, OptimisedFlatEndKeepsItsPolygonFacesOrthogonalEnough) {
  for (const double beta : {30.0, 45.0}) {
    BendCase b;
    b.beta_deg = beta;
    b.r_over_dx = 1.4;
    b.inc_deg = 50;
    b.plane_deg = beta == 30.0 ? 333 : 117;
    b.short_legs = true;
    b.caps = false;
    b.optimize = true;
    const RealisticCase rc = make_bend_case(b);
    const CaseResult r = mesh_and_check(rc);
    EXPECT_EQ(r.outcome, Outcome::Meshed) << rc.label << ": " << r.reason;
  }
}

// A flat end 1.2 m before a gentle bend (a survey well clipped just before a station): the end
// segment would be 1.2 m less the bend's tangent, and the end faces of its outer ring cells fell
// below fvcheck's 45 degrees (24 degrees on the horizontal sweep's seed 20). The block drops the point:
// it runs straight from the end to the next one, and the mesh is sound (volume: the box less the
// exact hole of the block as built).
TEST(Bends, FlatEndJustBeforeABendDropsThePoint) {
  const double turn = 7.3 * M_PI / 180;
  auto axis = [](double lo, double hi, double h) {
    std::string a = "[";
    for (double v = lo; v <= hi + 1e-9; v += h) a += (a.size() > 1 ? ", " : "") + std::to_string(static_cast<int>(v));
    return a + "]";
  };
  char well[256];
  std::snprintf(well, sizeof well,
                "wells:\n  - {name: P1, trajectory: [[60, 100, 1030], [61.2, 100, 1030], [%.6f, %.6f, 1030]], radius: 0.1,"
                " drainage_radius: 8.5, rings: 6, sectors: 12, end_caps: flat, bhp: 150}\n",
                61.2 + 78.8 * std::cos(turn), 100 + 78.8 * std::sin(turn));
  const std::string yaml = "name: short_end_leg\nreservoir:\n  x: " + axis(0, 200, 10) + "\n  y: " + axis(0, 200, 10) +
                           "\n  z: " + axis(1000, 1060, 5) + "\n  permeability: [100, 100, 10]\n  porosity: 0.2\n" + well;
  RealisticCase rc;
  rc.spec = parse_case(yaml);
  rc.spec.transition.optimize = false;
  const CaseResult r = mesh_and_check(rc);
  EXPECT_EQ(r.outcome, Outcome::Meshed) << r.reason;
  const WellBlock block = make_well_block(rc.spec, 0, 12);
  ASSERT_EQ(block.trajectory.size(), 2u);  // the point 1.2 m from the end is gone
  EXPECT_EQ(block.trajectory.front(), rc.spec.wells[0].trajectory.front());
  EXPECT_EQ(block.trajectory.back(), rc.spec.wells[0].trajectory.back());
}

// Free sites on a bend's focal line: a nominal position within some sphere's clearance moves
// toward the line's middle to where the line leaves that sphere (transition_tips.cpp,
// kBendAxisShifts). Three cases of the bend sweep whose raw diagram failed conformity (free sites
// missing next to reservoir cells' spheres, the fans of wedge sites meeting on the line) mesh.
TEST(Bends, FocalLineFreeSitesStepOutOfBlockedPositions) {
  struct Sweep {
    double beta, r_over_dx, inc, plane;
    bool short_legs, caps;
  };
  for (const Sweep& c : {Sweep{45.0, 1.4, 0, 43, true, false}, Sweep{52.5, 0.6, 50, 110, false, true},
                         Sweep{60.0, 1.4, 50, 224, false, true}}) {
    BendCase b;
    b.beta_deg = c.beta;
    b.r_over_dx = c.r_over_dx;
    b.inc_deg = c.inc;
    b.plane_deg = c.plane;
    b.short_legs = c.short_legs;
    b.caps = c.caps;
    const RealisticCase rc = make_bend_case(b);
    const CaseResult r = mesh_and_check(rc);
    EXPECT_EQ(r.outcome, Outcome::Meshed) << rc.label << ": " << r.reason;
  }
}

// Validation: a bend at the limit passes, one degree above is refused naming the trajectory.
TEST(Bends, ValidationRefusesBendsAboveTheLimit) {
  EXPECT_NO_THROW(parse_case(paper_with_bend(kMaxBendDegrees)));
  try {
    parse_case(paper_with_bend(kMaxBendDegrees + 1));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("wells[0].trajectory: bend of 61 degrees at point 1 exceeds the 60-degree "
                                          "limit", 0), 0u)
        << e.what();
  }
}

// The bend sweep (docs/robustness.md, "Bends"): every combination of bend (HM_BEND_FROM, default 30
// degrees, to the limit kMaxBendDegrees in HM_BEND_STEP steps, default 2.5; to measure beyond the
// limit, raise kMaxBendDegrees, which validation applies, and rebuild), R / dx (0.6, 1.4), inclination of the first leg (0, 50, 90),
// fillet (1.5 R, 1.3 R); caps and flat ends alternate, the bend plane turns by 37 degrees per case,
// optimisation on for every fourth case. Prints one line per case (its index first) and a table per bend angle.
TEST(Bends, SweepTable) {
  const char* v = std::getenv("HM_LONG_TESTS");
  if (!(v && std::string(v) == "1")) GTEST_SKIP() << "long test: set HM_LONG_TESTS=1";
  const double step = std::getenv("HM_BEND_STEP") ? std::atof(std::getenv("HM_BEND_STEP")) : 2.5;
  const double from = std::getenv("HM_BEND_FROM") ? std::atof(std::getenv("HM_BEND_FROM")) : 30;
  // HM_BEND_DUMP=DIR: every case's file as DIR/bend_<index>.yaml (the index printed per case), for meshgen.
  const char* dump_dir = std::getenv("HM_BEND_DUMP");
  struct Row {
    int cases = 0, meshed = 0;
    std::map<Outcome, int> count;
  };
  std::map<double, Row> rows;
  int index = 0;
  for (double beta = from; beta <= kMaxBendDegrees + 1e-9; beta += step)
    for (double r : {0.6, 1.4})
      for (double inc : {0.0, 50.0, 90.0})
        for (bool short_legs : {false, true}) {
          BendCase b;
          b.beta_deg = beta, b.r_over_dx = r, b.inc_deg = inc, b.short_legs = short_legs;
          b.plane_deg = std::fmod(37.0 * index, 360.0);
          b.caps = index % 2 == 0;
          b.optimize = index % 4 == 1;
          ++index;
          const RealisticCase rc = make_bend_case(b);
          if (dump_dir) {
            std::ofstream yaml(std::string(dump_dir) + "/bend_" + std::to_string(index - 1) + ".yaml");
            yaml << rc.yaml;
            EXPECT_TRUE(yaml.good()) << "HM_BEND_DUMP: cannot write into " << dump_dir;
          }
          const CaseResult res = mesh_and_check_isolated(rc, 600);
          Row& row = rows[beta];
          ++row.cases;
          ++row.count[res.outcome];
          std::printf("[ bends     ] %d %s: %s %.2f s %s\n", index - 1, rc.label.c_str(), outcome_name(res.outcome), res.seconds,
                      res.reason.substr(0, 160).c_str());
          std::fflush(stdout);
        }
  std::printf("\n| bend (deg) | cases | meshed + fvcheck | written, checks fail | refused | failed | crash | hang |\n"
              "|---|---|---|---|---|---|---|---|\n");
  Row all;
  for (auto& [beta, row] : rows) {
    std::printf("| %.1f | %d | %d | %d | %d | %d | %d | %d |\n", beta, row.cases, row.count[Outcome::Meshed],
                row.count[Outcome::CheckFailed], row.count[Outcome::Refused], row.count[Outcome::Failed],
                row.count[Outcome::Crash], row.count[Outcome::Hang]);
    all.cases += row.cases;
    for (auto& [k, n] : row.count) all.count[k] += n;
  }
  std::printf("| all | %d | %d | %d | %d | %d | %d | %d |\n", all.cases, all.count[Outcome::Meshed],
              all.count[Outcome::CheckFailed], all.count[Outcome::Refused], all.count[Outcome::Failed],
              all.count[Outcome::Crash], all.count[Outcome::Hang]);
  EXPECT_EQ(all.count[Outcome::Meshed], all.cases);
}
