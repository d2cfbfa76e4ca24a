// Case-file loader: round trip, defaults, one exact message per validation rule,
// robustness against malformed documents (only InputError, one-line messages).
#include <gtest/gtest.h>

#include <cmath>

#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "meshgen/case/case.hpp"
#include "meshgen/case/case_limits.hpp"
#include "meshgen/case/corner_point_path.hpp"
#include "meshgen/case/segment_distance.hpp"

using namespace hm;

namespace {

// Two vertical wells 40 m apart; margins: drainage 8 x dilation 1.5 = 12 m from each side.
const std::string kBase = R"(name: paper_single_well
reservoir:
  x: [0, 30, 55, 80, 100]
  y: [0, 25, 50, 75, 100]
  z: [0, 20, 40, 60]
  permeability: [100, 100, 10]
  porosity: 0.2
  initial_pressure: 200
wells:
  - name: P1
    type: producer
    trajectory: [[30, 50, 15], [30, 50, 45]]
    radius: 0.1
    drainage_radius: 8.0
    rings: 6
    sectors: 12
    segment_length: 4.0
    bhp: 150
  - name: I1
    type: injector
    trajectory: [[70, 50, 15], [70, 50, 45]]
    radius: 0.1
    drainage_radius: 8.0
    bhp: 250
)";

// Replaces the single occurrence of `from` in `text` (fails the test if it is not unique).
std::string with(const std::string& text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "'" << from << "' not in the text";
  if (at == std::string::npos) return text;
  EXPECT_EQ(text.find(from, at + 1), std::string::npos) << "'" << from << "' is not unique";
  return text.substr(0, at) + to + text.substr(at + from.size());
}

// The InputError message of parse_case(text), or "" when it succeeds. Any other
// exception type fails the test.
std::string error_of(const std::string& text) {
  try {
    parse_case(text);
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "non-InputError exception: " << e.what();
    return "<other exception>";
  } catch (...) {
    ADD_FAILURE() << "non-std exception";
    return "<other exception>";
  }
  return "";
}

std::string axis(size_t n) {
  std::string s = "[";
  for (size_t i = 0; i < n; ++i) s += (i ? ", " : "") + std::to_string(i);
  return s + "]";
}

}  // namespace

// ---------------------------------------------------------------- valid input

TEST(CaseValid, BaseCaseParses) { EXPECT_EQ(error_of(kBase), ""); }

TEST(CaseValid, FullCaseRoundTripsEveryField) {
  const std::string text = R"(name: full-case_2
reservoir:
  x: [-10, 0.5, 30, 1.25e2]
  y: [0, 40, 100]
  z: [1000, 1010, 1030, 1060]
  permeability: [150, 120, 12.5]
  porosity: 0.25
  initial_pressure: 210.5
wells:
  - name: INJ-1_a
    type: injector
    trajectory: [[50, 50, 1015], [55, 52, 1030], [60, 50, 1045]]
    radius: 0.08
    drainage_radius: 6.5
    rings: 5
    sectors: 16
    segment_length: 3.5
    bhp: 140
transition:
  dilation: 1.3
  optimize: false
  gamma: [0.1, 0.2, 0.45]
  omega_o: 88
  omega_p: 5
  expansion: 1.05
fluid: {viscosity: 0.5, density: 950, compressibility: 4.5e-5}
)";
  const CaseSpec cs = parse_case(text);
  EXPECT_EQ(cs.name, "full-case_2");
  EXPECT_EQ(cs.reservoir.x, (std::vector<double>{-10, 0.5, 30, 125}));
  EXPECT_EQ(cs.reservoir.y, (std::vector<double>{0, 40, 100}));
  EXPECT_EQ(cs.reservoir.z, (std::vector<double>{1000, 1010, 1030, 1060}));
  EXPECT_EQ(cs.reservoir.permeability, (Vec3{150, 120, 12.5}));
  EXPECT_EQ(cs.reservoir.porosity, 0.25);
  EXPECT_EQ(cs.reservoir.initial_pressure, 210.5);
  ASSERT_EQ(cs.wells.size(), 1u);
  const WellSpec& w = cs.wells[0];
  EXPECT_EQ(w.name, "INJ-1_a");
  EXPECT_EQ(w.type, WellType::Injector);
  ASSERT_EQ(w.trajectory.size(), 3u);
  EXPECT_EQ(w.trajectory[0], (Vec3{50, 50, 1015}));
  EXPECT_EQ(w.trajectory[1], (Vec3{55, 52, 1030}));
  EXPECT_EQ(w.trajectory[2], (Vec3{60, 50, 1045}));
  EXPECT_EQ(w.radius, 0.08);
  EXPECT_EQ(w.drainage_radius, 6.5);
  EXPECT_EQ(w.rings, 5);
  EXPECT_EQ(w.sectors, 16);
  EXPECT_EQ(w.segment_length, 3.5);
  EXPECT_EQ(w.bhp, 140);
  EXPECT_EQ(cs.transition.dilation, 1.3);
  EXPECT_FALSE(cs.transition.optimize);
  EXPECT_EQ(cs.transition.gamma, (std::array<double, 3>{0.1, 0.2, 0.45}));
  EXPECT_EQ(cs.transition.omega_o, 88);
  EXPECT_EQ(cs.transition.omega_p, 5);
  EXPECT_EQ(cs.transition.expansion, 1.05);
  EXPECT_EQ(cs.fluid.viscosity, 0.5);
  EXPECT_EQ(cs.fluid.density, 950);
  EXPECT_EQ(cs.fluid.compressibility, 4.5e-5);
}

TEST(CaseValid, DefaultsApplyWhenOptionalKeysAreAbsent) {
  const CaseSpec cs = parse_case(R"(name: minimal
reservoir: {x: [0, 100], y: [0, 100], z: [0, 50]}
)");
  const CaseSpec defaults;
  EXPECT_EQ(cs.reservoir.permeability, defaults.reservoir.permeability);
  EXPECT_EQ(cs.reservoir.porosity, defaults.reservoir.porosity);
  EXPECT_EQ(cs.reservoir.initial_pressure, defaults.reservoir.initial_pressure);
  EXPECT_TRUE(cs.wells.empty());
  EXPECT_EQ(cs.transition.dilation, defaults.transition.dilation);
  EXPECT_EQ(cs.transition.optimize, defaults.transition.optimize);
  EXPECT_EQ(cs.transition.gamma, defaults.transition.gamma);
  EXPECT_EQ(cs.transition.omega_o, defaults.transition.omega_o);
  EXPECT_EQ(cs.transition.omega_p, defaults.transition.omega_p);
  EXPECT_EQ(cs.transition.expansion, defaults.transition.expansion);
  EXPECT_EQ(cs.fluid.viscosity, defaults.fluid.viscosity);
  EXPECT_EQ(cs.fluid.density, defaults.fluid.density);
  EXPECT_EQ(cs.fluid.compressibility, defaults.fluid.compressibility);
  // The documented values (docs/case-format.md), so that a silent change of case.hpp shows up here.
  EXPECT_EQ(cs.reservoir.permeability, (Vec3{100, 100, 10}));
  EXPECT_EQ(cs.reservoir.porosity, 0.2);
  EXPECT_EQ(cs.transition.gamma, (std::array<double, 3>{0.05, 0.30, 0.40}));
}

TEST(CaseValid, WellDefaultsApplyWhenOptionalWellKeysAreAbsent) {
  const CaseSpec cs = parse_case(kBase);
  ASSERT_EQ(cs.wells.size(), 2u);
  const WellSpec defaults;
  const WellSpec& w = cs.wells[1];  // I1 gives only the required keys (+ type)
  EXPECT_EQ(w.rings, defaults.rings);
  EXPECT_EQ(w.sectors, defaults.sectors);
  EXPECT_EQ(w.segment_length, defaults.segment_length);
  EXPECT_EQ(w.type, WellType::Injector);
  const CaseSpec untyped = parse_case(with(kBase, "    type: injector\n", ""));
  EXPECT_EQ(untyped.wells[1].type, WellType::Producer);
}

TEST(CaseValid, NullOrEmptyOptionalBlocksMeanDefaults) {
  const std::string base = "name: a\nreservoir: {x: [0, 1], y: [0, 1], z: [0, 1]}\n";
  for (const char* extra : {"wells:\n", "wells: []\n", "transition:\n", "fluid:\n", "transition: {}\n"}) {
    SCOPED_TRACE(extra);
    EXPECT_EQ(error_of(base + extra), "");
  }
  EXPECT_TRUE(parse_case(base + "wells: []\n").wells.empty());
}

TEST(CaseValid, NumberSyntaxesAccepted) {
  const std::string base = "name: a\nreservoir: {x: [0, 1], y: [0, 1], z: [0, 1], porosity: P}\n";
  const std::vector<std::pair<std::string, double>> cases = {
      {"0.5", 0.5}, {".5", 0.5}, {"5e-1", 0.5}, {"+0.5", 0.5}, {"1", 1.0}, {"1.", 1.0}, {"!!float 0.5", 0.5}};
  for (const auto& [text, value] : cases) {
    SCOPED_TRACE(text);
    EXPECT_EQ(parse_case(with(base, "P", text)).reservoir.porosity, value);
  }
}

TEST(CaseValid, LoadCaseReadsAFile) {
  const std::string path = ::testing::TempDir() + "hm_test_case_load.yaml";
  {
    std::ofstream out(path);
    out << kBase;
  }
  const CaseSpec cs = load_case(path);
  std::remove(path.c_str());
  EXPECT_EQ(cs.name, "paper_single_well");
  ASSERT_EQ(cs.wells.size(), 2u);
  EXPECT_EQ(cs.wells[1].name, "I1");
  EXPECT_EQ(cs.wells[1].bhp, 250);
}

// The complete example in docs/case-format.md must be a valid case (keeps the doc honest).
TEST(CaseValid, DocumentationExampleIsValid) {
  std::ifstream in(std::string(HM_SOURCE_DIR) + "/docs/case-format.md");
  ASSERT_TRUE(in) << "docs/case-format.md missing";
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string doc = ss.str();
  const std::string marker = "<!-- complete example -->\n```yaml\n";
  const size_t begin = doc.find(marker);
  ASSERT_NE(begin, std::string::npos);
  const size_t end = doc.find("```", begin + marker.size());
  ASSERT_NE(end, std::string::npos);
  const std::string example = doc.substr(begin + marker.size(), end - begin - marker.size());
  EXPECT_EQ(error_of(example), "");
  const CaseSpec cs = parse_case(example);
  EXPECT_FALSE(cs.wells.empty());
}

// ---------------------------------------------------------------- file errors

TEST(CaseErrors, MissingFile) {
  try {
    load_case("/nonexistent_dir_hm/case.yaml");
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "case file: cannot open '/nonexistent_dir_hm/case.yaml'");
  }
}

TEST(CaseErrors, DirectoryIsNotACaseFile) {
  try {
    load_case(::testing::TempDir());
    FAIL() << "no exception";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind("case file: cannot ", 0), 0u) << msg;
  }
}

TEST(CaseErrors, YamlSyntaxError) {
  EXPECT_EQ(error_of("name: a\nreservoir: {x: [0, 1\n"),
            "case file: YAML error at line 3, column 1: end of sequence flow not found");
  EXPECT_EQ(error_of("name: a: b\n"), "case file: YAML error at line 1, column 8: illegal map value");
}

TEST(CaseErrors, NestingTooDeep) {
  const std::string msg = error_of(std::string(10000, '[') + std::string(10000, ']'));
  EXPECT_EQ(msg.rfind("case file: YAML error at line 1, column ", 0), 0u) << msg;
  EXPECT_NE(msg.find(": nested too deeply ("), std::string::npos) << msg;
}

TEST(CaseErrors, EmptyDocuments) {
  for (const char* text : {"", "# only a comment\n", "---\n", "~\n", "   \n\n"}) {
    SCOPED_TRACE(text);
    EXPECT_EQ(error_of(text), "case file: empty document");
  }
}

TEST(CaseErrors, SeveralDocuments) {
  EXPECT_EQ(error_of(kBase + "---\nname: b\n"), "case file: expected one YAML document, got 2");
}

// yaml-cpp 0.7's LoadAll never returns (and allocates without bound) on a stray ',' (found by
// tests/fuzz/fuzz_case); parse_case must refuse it. Before the fix this test hung.
TEST(CaseErrors, StrayCommaIsRefusedNotALoop) {
  EXPECT_EQ(error_of(","), "case file: YAML error at line 1, column 1: unexpected token (a ',' outside a [ ] or { } list?)");
  EXPECT_EQ(error_of(", nameNULL:h}at\n").rfind("case file: YAML error at line 1, column 1: unexpected token", 0), 0u);
  // After a complete document ("..." ends it) the comma stalls the second one: refused at its line.
  const std::string late = error_of(kBase + "...\n,\n");
  EXPECT_EQ(late.rfind("case file: YAML error at line ", 0), 0u) << late;
  EXPECT_NE(late.find(", column 1: unexpected token"), std::string::npos) << late;
  // The same text without the comma is a valid case (the pair of the test).
  EXPECT_NO_THROW(parse_case(kBase));
}

TEST(CaseErrors, TopLevelNotAMap) {
  EXPECT_EQ(error_of("[1, 2]\n"), "case file: expected a map with keys name, reservoir, ..., got a list");
  EXPECT_EQ(error_of("hello\n"), "case file: expected a map with keys name, reservoir, ..., got 'hello'");
}

// ---------------------------------------------------------------- keys

TEST(CaseErrors, UnknownKeyInTransition) {
  EXPECT_EQ(error_of(kBase + "transition:\n  dilaton: 1.2\n"),
            "transition.dilaton: unknown key (expected one of: dilation, optimize, gamma, omega_o, omega_p, "
            "expansion)");
}

TEST(CaseErrors, UnknownKeyAtEveryLevel) {
  EXPECT_EQ(error_of(kBase + "wellz: []\n"),
            "wellz: unknown key (expected one of: name, metric, reservoir, wells, transition, fluid)");
  EXPECT_EQ(error_of(with(kBase, "  porosity: 0.2\n", "  porosity: 0.2\n  poro: 0.2\n")),
            "reservoir.poro: unknown key (expected one of: x, y, z, grdecl, permeability, porosity, initial_pressure, near_well_cell_size, "
            "near_well_layer_aspect, upright_pillars, near_well_grading)");
  EXPECT_EQ(error_of(with(kBase, "    bhp: 250\n", "    bhp: 250\n    skin: 0\n")),
            "wells[1].skin: unknown key (expected one of: name, type, trajectory, survey, radius, drainage_radius, rings, "
            "sectors, segment_length, bhp, end_caps, perforations)");
  EXPECT_EQ(error_of(kBase + "fluid: {viscosity: 1, mu: 1}\n"),
            "fluid.mu: unknown key (expected one of: viscosity, density, compressibility)");
}

TEST(CaseValid, MetricKey) {
  EXPECT_EQ(parse_case(kBase).metric, MeshMetric::Euclidean);
  EXPECT_EQ(parse_case("metric: permeability\n" + kBase).metric, MeshMetric::Permeability);
  EXPECT_EQ(parse_case("metric: euclidean\n" + kBase).metric, MeshMetric::Euclidean);
}

TEST(CaseErrors, MetricKey) {
  EXPECT_EQ(error_of("metric: riemann\n" + kBase), "metric: expected permeability or euclidean, got 'riemann'");
  EXPECT_EQ(error_of("metric: [permeability]\n" + kBase), "metric: expected permeability or euclidean, got a list");
}

// Found by fuzz_case: a key that is not a plain name (empty, or starting with ": ") is quoted, so that the
// message still reads "key.path: reason".
TEST(CaseErrors, OddKeyIsQuoted) {
  EXPECT_EQ(error_of(kBase + "\"\": 1\n"),
            "'': unknown key (expected one of: name, metric, reservoir, wells, transition, fluid)");
  EXPECT_EQ(error_of(with(kBase, "  porosity: 0.2\n", "  porosity: 0.2\n  \"\": 0.2\n")).rfind("reservoir.'': unknown key", 0), 0u);
  EXPECT_EQ(error_of(kBase + "\": 1 \": 1\n"),
            "': 1 ': unknown key (expected one of: name, metric, reservoir, wells, transition, fluid)");
}

TEST(CaseErrors, DuplicateKey) {
  EXPECT_EQ(error_of(with(kBase, "  porosity: 0.2\n", "  porosity: 0.2\n  porosity: 0.3\n")),
            "reservoir.porosity: duplicate key");
}

TEST(CaseErrors, NonScalarKey) {
  EXPECT_EQ(error_of(kBase + "? [1, 2]\n: 3\n"), "case file: expected a key name, got a list");
  EXPECT_EQ(error_of(kBase + "transition: {[a]: 1}\n"), "transition: expected a key name, got a list");
}

TEST(CaseErrors, RequiredKeysMissing) {
  EXPECT_EQ(error_of(with(kBase, "name: paper_single_well\n", "")), "name: required key is missing");
  EXPECT_EQ(error_of("name: a\n"), "reservoir: required key is missing");
  EXPECT_EQ(error_of(with(kBase, "  y: [0, 25, 50, 75, 100]\n", "")), "reservoir.y: required key is missing");
  EXPECT_EQ(error_of(with(kBase, "    bhp: 250\n", "")), "wells[1].bhp: required key is missing");
  EXPECT_EQ(error_of(with(kBase, "    trajectory: [[70, 50, 15], [70, 50, 45]]\n", "")),
            "wells[1].trajectory: required key is missing");
}

// ---------------------------------------------------------------- types

TEST(CaseErrors, NotANumber) {
  EXPECT_EQ(error_of(with(kBase, "porosity: 0.2", "porosity: abc")), "reservoir.porosity: expected a number, got 'abc'");
  EXPECT_EQ(error_of(with(kBase, "porosity: 0.2", "porosity: '0.2'")),
            "reservoir.porosity: expected a number, got a quoted string '0.2'");
  EXPECT_EQ(error_of(with(kBase, "porosity: 0.2", "porosity:")), "reservoir.porosity: expected a number, got null");
  EXPECT_EQ(error_of(with(kBase, "porosity: 0.2", "porosity: [0.2]")),
            "reservoir.porosity: expected a number, got a list");
  EXPECT_EQ(error_of(with(kBase, "porosity: 0.2", "porosity: 0x10")), "reservoir.porosity: expected a number, got '0x10'");
}

TEST(CaseErrors, NanAndInfinityAreNotNumbers) {
  EXPECT_EQ(error_of(with(kBase, "porosity: 0.2", "porosity: .nan")), "reservoir.porosity: expected a number, got '.nan'");
  EXPECT_EQ(error_of(with(kBase, "porosity: 0.2", "porosity: .inf")), "reservoir.porosity: expected a number, got '.inf'");
  EXPECT_EQ(error_of(with(kBase, "porosity: 0.2", "porosity: nan")), "reservoir.porosity: expected a number, got 'nan'");
  EXPECT_EQ(error_of(with(kBase, "porosity: 0.2", "porosity: -inf")), "reservoir.porosity: expected a number, got '-inf'");
  EXPECT_EQ(error_of(with(kBase, "initial_pressure: 200", "initial_pressure: 1e400")),
            "reservoir.initial_pressure: expected a finite number, got 1e400");
}

TEST(CaseErrors, NotAnInteger) {
  EXPECT_EQ(error_of(with(kBase, "rings: 6", "rings: 2.5")), "wells[0].rings: expected an integer, got 2.5");
  EXPECT_EQ(error_of(with(kBase, "rings: 6", "rings: six")), "wells[0].rings: expected an integer, got 'six'");
  EXPECT_EQ(error_of(with(kBase, "sectors: 12", "sectors: 99999999999")),
            "wells[0].sectors: integer out of range, got 99999999999");
}

TEST(CaseErrors, NotABoolean) {
  EXPECT_EQ(error_of(kBase + "transition: {optimize: yes}\n"), "transition.optimize: expected true or false, got 'yes'");
  EXPECT_EQ(error_of(kBase + "transition: {optimize: 1}\n"), "transition.optimize: expected true or false, got 1");
}

TEST(CaseErrors, NotAString) {
  EXPECT_EQ(error_of(with(kBase, "name: paper_single_well", "name: [a]")), "name: expected a string, got a list");
  EXPECT_EQ(error_of(with(kBase, "name: P1", "name:")), "wells[0].name: expected a string, got null");
}

TEST(CaseErrors, WrongBlockTypes) {
  EXPECT_EQ(error_of("name: a\nreservoir: [1, 2]\n"), "reservoir: expected a map, got a list");
  EXPECT_EQ(error_of(kBase + "transition: 3\n"), "transition: expected a map, got 3");
  EXPECT_EQ(error_of("name: a\nreservoir: {x: [0, 1], y: [0, 1], z: [0, 1]}\nwells: {a: 1}\n"),
            "wells: expected a list of wells, got a map");
  EXPECT_EQ(error_of("name: a\nreservoir: {x: [0, 1], y: [0, 1], z: [0, 1]}\nwells: [P1]\n"),
            "wells[0]: expected a map, got 'P1'");
}

TEST(CaseErrors, WellType) {
  EXPECT_EQ(error_of(with(kBase, "type: producer", "type: producr")),
            "wells[0].type: expected producer or injector, got 'producr'");
}

// ---------------------------------------------------------------- reservoir

TEST(CaseErrors, AxisNotStrictlyIncreasing) {
  EXPECT_EQ(error_of(with(kBase, "x: [0, 30, 55, 80, 100]", "x: [0, 30, 55, 80, 70]")),
            "reservoir.x: not strictly increasing at index 4");
  EXPECT_EQ(error_of(with(kBase, "x: [0, 30, 55, 80, 100]", "x: [0, 30, 30, 80, 100]")),
            "reservoir.x: not strictly increasing at index 2");
}

TEST(CaseErrors, AxisTooShortOrNotAList) {
  EXPECT_EQ(error_of(with(kBase, "x: [0, 30, 55, 80, 100]", "x: [0]")), "reservoir.x: needs at least 2 values");
  EXPECT_EQ(error_of(with(kBase, "z: [0, 20, 40, 60]", "z: []")), "reservoir.z: needs at least 2 values");
  EXPECT_EQ(error_of(with(kBase, "y: [0, 25, 50, 75, 100]", "y: 100")), "reservoir.y: expected a list of numbers, got 100");
  EXPECT_EQ(error_of(with(kBase, "x: [0, 30, 55, 80, 100]", "x: [0, 30, a, 80, 100]")),
            "reservoir.x[2]: expected a number, got 'a'");
}

TEST(CaseErrors, AxisTooManyValues) {
  const std::string base = "name: a\nreservoir: {x: X, y: [0, 1], z: [0, 1]}\n";
  EXPECT_EQ(error_of(with(base, "X", axis(kMaxAxisValues))), "");
  EXPECT_EQ(error_of(with(base, "X", axis(kMaxAxisValues + 1))), "reservoir.x: at most 2000 values (got 2001)");
}

TEST(CaseErrors, TooManyReservoirCells) {
  // 1999 x 1999 x 5 = 19,980,005 cells is allowed, 1999 x 1999 x 6 is not.
  const std::string base = "name: a\nreservoir: {x: X, y: X, z: Z}\n";
  const std::string big = axis(2000);
  EXPECT_EQ(error_of(with(with(base, "Z", axis(6)), "x: X, y: X", "x: " + big + ", y: " + big)), "");
  EXPECT_EQ(error_of(with(with(base, "Z", axis(7)), "x: X, y: X", "x: " + big + ", y: " + big)),
            "reservoir: too many cells (1999 x 1999 x 6 = 23976006 > 20000000)");
}

TEST(CaseErrors, PermeabilityPorosityPressure) {
  EXPECT_EQ(error_of(with(kBase, "permeability: [100, 100, 10]", "permeability: [100, 0, 10]")),
            "reservoir.permeability[1]: must be > 0");
  EXPECT_EQ(error_of(with(kBase, "permeability: [100, 100, 10]", "permeability: [100, 100]")),
            "reservoir.permeability: expected 3 values [kx, ky, kz], got 2");
  EXPECT_EQ(error_of(with(kBase, "permeability: [100, 100, 10]", "permeability: 100")),
            "reservoir.permeability: expected a list of 3 numbers [kx, ky, kz], got 100");
  EXPECT_EQ(error_of(with(kBase, "porosity: 0.2", "porosity: 0")), "reservoir.porosity: must be in (0, 1]");
  EXPECT_EQ(error_of(with(kBase, "porosity: 0.2", "porosity: 1.01")), "reservoir.porosity: must be in (0, 1]");
  EXPECT_EQ(error_of(with(kBase, "porosity: 0.2", "porosity: 0.2\n  near_well_layer_aspect: 0.2")),
            "reservoir.near_well_layer_aspect: must be 0 (off) or in [0.5, 100]");
  EXPECT_EQ(error_of(with(kBase, "porosity: 0.2", "porosity: 0.2\n  near_well_layer_aspect: -1")),
            "reservoir.near_well_layer_aspect: must be 0 (off) or in [0.5, 100]");
  EXPECT_EQ(error_of(with(kBase, "porosity: 0.2", "porosity: 1")), "");
  EXPECT_EQ(error_of(with(kBase, "initial_pressure: 200", "initial_pressure: -1")),
            "reservoir.initial_pressure: must be > 0");
}

// Physical bounds (case_limits.hpp): the issue's permeability 1e300 wrote -nan into NNC and COMPDAT;
// each bound is checked just inside (accepted) and just outside (refused with the range).
TEST(CaseErrors, PhysicalValuesAreBounded) {
  EXPECT_EQ(error_of(with(kBase, "permeability: [100, 100, 10]", "permeability: [1e300, 100, 10]")),
            "reservoir.permeability[0]: must be <= 1e+09 mD (docs/case-format.md, Limits)");
  EXPECT_EQ(error_of(with(kBase, "permeability: [100, 100, 10]", "permeability: [1e9, 100, 10]")), "");
  EXPECT_EQ(error_of(with(kBase, "permeability: [100, 100, 10]", "permeability: [100, 100, 1e-10]")),
            "reservoir.permeability[2]: must be >= 1e-09 mD");
  EXPECT_EQ(error_of(with(kBase, "permeability: [100, 100, 10]", "permeability: [100, 100, 1e-9]")), "");
  EXPECT_EQ(error_of(with(kBase, "initial_pressure: 200", "initial_pressure: 1e6")),
            "reservoir.initial_pressure: must be <= 1e+05 bar (docs/case-format.md, Limits)");
  EXPECT_EQ(error_of(with(kBase, "bhp: 150", "bhp: 1e300")),
            "wells[0].bhp: must be <= 1e+05 bar (docs/case-format.md, Limits)");
  EXPECT_EQ(error_of(with(kBase, "    radius: 0.1\n    drainage_radius: 8.0\n    bhp: 250",
                          "    radius: 1e-4\n    drainage_radius: 8.0\n    bhp: 250")),
            "wells[1].radius: must be >= 0.001 m");
  EXPECT_EQ(error_of(with(kBase, "drainage_radius: 8.0\n    rings", "drainage_radius: 1e5\n    rings")),
            "wells[0].drainage_radius: must be <= 10000 m (docs/case-format.md, Limits)");
  EXPECT_EQ(error_of(with(kBase, "segment_length: 4.0", "segment_length: 1e6")),
            "wells[0].segment_length: must be <= 1e+05 m (docs/case-format.md, Limits)");
  EXPECT_EQ(error_of(kBase + "fluid: {viscosity: 1e300}\n"),
            "fluid.viscosity: must be <= 1e+09 cP (docs/case-format.md, Limits)");
  EXPECT_EQ(error_of(kBase + "fluid: {viscosity: 1e-5}\n"), "fluid.viscosity: must be >= 1e-04 cP");
  EXPECT_EQ(error_of(kBase + "fluid: {density: 1e300}\n"),
            "fluid.density: must be <= 1e+05 kg/m3 (docs/case-format.md, Limits)");
  EXPECT_EQ(error_of(kBase + "fluid: {compressibility: 2}\n"),
            "fluid.compressibility: must be <= 1 1/bar (docs/case-format.md, Limits)");
  EXPECT_EQ(error_of(with(kBase, "x: [0, 30,", "x: [-2e8, 30,")),
            "reservoir.x[0]: coordinates must be within +-1e+08 m (docs/case-format.md, Limits)");
}

TEST(CaseErrors, CaseName) {
  EXPECT_EQ(error_of(with(kBase, "name: paper_single_well", "name: paper well")), "name: must match [A-Za-z0-9_-]+");
  EXPECT_EQ(error_of(with(kBase, "name: paper_single_well", "name: ''")), "name: must match [A-Za-z0-9_-]+");
  EXPECT_EQ(error_of(with(kBase, "name: paper_single_well", "name: " + std::string(64, 'a'))), "");
  EXPECT_EQ(error_of(with(kBase, "name: paper_single_well", "name: " + std::string(65, 'a'))),
            "name: at most 64 characters");
}

// ---------------------------------------------------------------- wells

TEST(CaseErrors, WellName) {
  EXPECT_EQ(error_of(with(kBase, "name: P1", "name: P 1")), "wells[0].name: must match [A-Za-z0-9_-]+");
  EXPECT_EQ(error_of(with(kBase, "name: P1", "name: P1234567")), "");
  EXPECT_EQ(error_of(with(kBase, "name: P1", "name: P12345678")),
            "wells[0].name: at most 8 characters (Eclipse well names)");
}

TEST(CaseErrors, DuplicateWellName) {
  EXPECT_EQ(error_of(with(kBase, "name: I1", "name: P1")), "wells[1].name: duplicate of wells[0].name");
  EXPECT_EQ(error_of(with(kBase, "name: I1", "name: p1")),
            "wells[1].name: duplicate of wells[0].name (names are compared ignoring case, as in Eclipse decks)");
}

TEST(CaseErrors, WellRadius) {
  EXPECT_EQ(error_of(with(kBase, "    radius: 0.1\n    drainage_radius: 8.0\n    bhp: 250",
                          "    radius: 0\n    drainage_radius: 8.0\n    bhp: 250")),
            "wells[1].radius: must be > 0");
  EXPECT_EQ(error_of(with(kBase, "drainage_radius: 8.0\n    rings", "drainage_radius: 0.1\n    rings")),
            "wells[0].drainage_radius: must be > radius (0.1)");
  EXPECT_EQ(error_of(with(kBase, "drainage_radius: 8.0\n    rings", "drainage_radius: 0.05\n    rings")),
            "wells[0].drainage_radius: must be > radius (0.1)");
}

TEST(CaseErrors, WellDiscretisation) {
  EXPECT_EQ(error_of(with(kBase, "rings: 6", "rings: 0")), "wells[0].rings: must be >= 1");
  EXPECT_EQ(error_of(with(kBase, "rings: 6", "rings: 1")), "");
  EXPECT_EQ(error_of(with(kBase, "sectors: 12", "sectors: 2")), "wells[0].sectors: must be >= 3");
  EXPECT_EQ(error_of(with(kBase, "sectors: 12", "sectors: 3")), "");
  EXPECT_EQ(error_of(with(kBase, "segment_length: 4.0", "segment_length: 0")), "wells[0].segment_length: must be > 0");
  EXPECT_EQ(error_of(with(kBase, "bhp: 150", "bhp: 0")), "wells[0].bhp: must be > 0");
}

TEST(CaseErrors, TooManyWellCells) {
  // 30 m / 1e-5 m = 3,000,000 segments, + 2 x 4 latitude bands of the hemispherical end caps
  // (the default; hemisphere_cap_bands(12) = 4), x 6 rings x 12 sectors.
  EXPECT_EQ(error_of(with(kBase, "segment_length: 4.0", "segment_length: 1e-5")),
            "wells[0]: too many cells (6 x 12 x 3000008 = 216000576 rings x sectors x segments; at most 20000000 "
            "in the whole case)");
  // Flat ends: the segments only.
  EXPECT_EQ(error_of(with(kBase, "segment_length: 4.0", "segment_length: 1e-5\n    end_caps: flat")),
            "wells[0]: too many cells (6 x 12 x 3000000 = 216000000 rings x sectors x segments; at most 20000000 "
            "in the whole case)");
}

// Hemispherical caps grade the end layers like the rings (hemisphere_end_grading, at most
// `rings` layers per end): with 2000 rings that is 2 x 2000 layers more, which the budget counts
// (30 m / 4 m = 8 segments + 2 x (4 bands + 2000 layers) = 4016); with flat ends the same well
// is 2000 x 12 x 8 cells and passes.
TEST(CaseErrors, TooManyCellsCountsTheGradedEndLayers) {
  EXPECT_EQ(error_of(with(kBase, "rings: 6", "rings: 2000")),
            "wells[0]: too many cells (2000 x 12 x 4016 = 96384000 rings x sectors x segments; at most 20000000 "
            "in the whole case)");
  EXPECT_EQ(error_of(with(kBase, "rings: 6", "rings: 2000\n    end_caps: flat")), "");
  WellSpec w;
  w.radius = 0.1;
  w.drainage_radius = 8;
  w.rings = 2000;
  EXPECT_EQ(hemisphere_end_grading(w).size(), 2000u);  // capped at `rings`
  w.rings = 6;  // accuracy_vertical: r_k - r_w while the layer is thinner than a 4 m segment
  const std::vector<double> g = hemisphere_end_grading(w);
  ASSERT_EQ(g.size(), 5u);
  const double q = std::pow(80.0, 1.0 / 6);
  for (size_t k = 0; k < g.size(); ++k) EXPECT_NEAR(g[k], 0.1 * std::pow(q, k + 1.0) - 0.1, 1e-12);
  w.end_caps = EndCaps::Flat;
  EXPECT_TRUE(hemisphere_end_grading(w).empty());
}

TEST(CaseErrors, TrajectoryShape) {
  const std::string t = "trajectory: [[30, 50, 15], [30, 50, 45]]";
  EXPECT_EQ(error_of(with(kBase, t, "trajectory: [[30, 50, 15]]")), "wells[0].trajectory: needs at least 2 points");
  EXPECT_EQ(error_of(with(kBase, t, "trajectory: [30, 50, 15]")),
            "wells[0].trajectory[0]: expected a point [x, y, z], got 30");
  EXPECT_EQ(error_of(with(kBase, t, "trajectory: [[30, 50, 15], [30, 50]]")),
            "wells[0].trajectory[1]: expected 3 values [x, y, z], got 2");
  EXPECT_EQ(error_of(with(kBase, t, "trajectory: [[30, 50, 15], [30, 50, deep]]")),
            "wells[0].trajectory[1][2]: expected a number, got 'deep'");
  EXPECT_EQ(error_of(with(kBase, t, "trajectory: {a: 1}")),
            "wells[0].trajectory: expected a list of points [[x, y, z], ...], got a map");
}

TEST(CaseErrors, TrajectoryRepeatsPoint) {
  EXPECT_EQ(error_of(with(kBase, "[[30, 50, 15], [30, 50, 45]]", "[[30, 50, 15], [30, 50, 45], [30, 50, 45]]")),
            "wells[0].trajectory[2]: repeats the previous point");
  // Coming back to an earlier (not the previous) point's neighbourhood with bends within the limit
  // (30-60 degrees) is valid; turning straight back is a 180-degree bend, above the limit.
  EXPECT_EQ(error_of(with(kBase, "[[30, 50, 15], [30, 50, 45]]",
                          "[[30, 50, 15], [30, 50, 35], [35, 50, 43.660], [45, 50, 43.660], [50, 50, 35], "
                          "[50, 50, 15], [47, 50, 13]]")),
            "");
  EXPECT_EQ(error_of(with(kBase, "[[30, 50, 15], [30, 50, 45]]", "[[30, 50, 15], [30, 50, 45], [30, 50, 15]]")),
            "wells[0].trajectory: bend of 180 degrees at point 1 exceeds the 60-degree limit");
}

TEST(CaseErrors, TrajectoryOutsideTheReservoir) {
  // Only the part inside the box is meshed (meshed_trajectory.hpp); the block keeps
  // 0.25 x 8 = 2 m from a plane it does not end on: x >= 10 for a vertical well.
  const std::string t = "[[30, 50, 15], [30, 50, 45]]";
  EXPECT_EQ(error_of(with(kBase, t, "[[10, 50, 15], [10, 50, 45]]")), "");
  EXPECT_EQ(error_of(with(kBase, t, "[[9.5, 50, 15], [9.5, 50, 45]]")),
            "wells[0].trajectory: the radial block around leg 0 comes within 1.5 m of the reservoir side x min (x = 0); "
            "it must keep 2 m (0.25 x drainage_radius) from a boundary plane it does not end on, or cross the plane");
  // Through the top and the bottom, or from the top down; not at all inside.
  EXPECT_EQ(error_of(with(kBase, t, "[[30, 50, -10], [30, 50, 70]]")), "");
  EXPECT_EQ(error_of(with(kBase, t, "[[30, 50, -10], [30, 50, 40]]")), "");
  EXPECT_EQ(error_of(with(kBase, t, "[[30, 50, -20], [30, 50, -5]]")),
            "wells[0].trajectory: no part of it lies inside the reservoir");
  EXPECT_EQ(error_of(with(kBase, t, "[[30, 50, 10], [30, 50, -10], [40, 50, -10], [40, 50, 10]]")),
            "wells[0].trajectory: leaves the reservoir and comes back (leg 0); only one connected part inside can be "
            "meshed");
  EXPECT_EQ(error_of(with(kBase, t, "[[-10, 50, -10], [30, 50, 30]]")),
            "wells[0].trajectory: crosses the reservoir boundary at an edge or corner of the box (0, 50, 0); a well "
            "may cross one boundary plane at a time");
  EXPECT_EQ(error_of(with(kBase, t, "[[30, 50, 0], [40, 50, 0]]")),
            "wells[0].trajectory: runs along the reservoir top (z = 0); a well must lie inside the reservoir or cross "
            "its boundary");
  // Oblique crossing: the block ends (8 sin(a) + 0.5 x 8) / cos(a) m inside, which needs a leg that long.
  EXPECT_EQ(error_of(with(kBase, t, "[[30, 50, -10], [40, 50, 20]]")), "");
  EXPECT_EQ(error_of(with(kBase, t, "[[30, 50, -1], [31, 50, 1]]")),
            "wells[0].trajectory: the leg that crosses the reservoir top (z = 0) at 26.5651 degrees from its normal is "
            "too short to end the radial block inside (the block ends 8.47214 m from the crossing, the leg has "
            "1.11803 m inside)");
  // Hemispherical caps: they must keep the gap too (auto falls back to flat ends), and cannot
  // close an end on the boundary.
  const std::string caps = "    bhp: 150\n  - name: I1";
  EXPECT_EQ(error_of(with(kBase, t, "[[30, 50, 9], [30, 50, 45]]")), "");
  EXPECT_EQ(error_of(with(with(kBase, t, "[[30, 50, 9], [30, 50, 45]]"), caps,
                          "    bhp: 150\n    end_caps: hemisphere\n  - name: I1")),
            "wells[0].trajectory: the hemispherical cap at its start comes within 1 m of the reservoir top (z = 0); it "
            "must keep 2 m (0.25 x drainage_radius) from a boundary plane it does not end on, or cross the plane");
  EXPECT_EQ(error_of(with(with(kBase, t, "[[30, 50, -10], [30, 50, 45]]"), caps,
                          "    bhp: 150\n    end_caps: hemisphere\n  - name: I1")),
            "wells[0].end_caps: hemisphere caps need both ends of the trajectory inside the reservoir; this well "
            "crosses the reservoir boundary (use flat or auto)");
}

TEST(CaseErrors, WellsTooClose) {
  // Parallel vertical wells 10 m apart, drainage radii 8 + 8 = 16.
  const std::string t = "trajectory: [[70, 50, 15], [70, 50, 45]]";
  EXPECT_EQ(error_of(with(kBase, t, "trajectory: [[40, 50, 15], [40, 50, 45]]")),
            "wells[1].trajectory: too close to wells[0] (distance 10 m < 16 m = sum of drainage radii; radial "
            "grids may not overlap)");
  EXPECT_EQ(error_of(with(kBase, t, "trajectory: [[46.5, 50, 15], [46.5, 50, 45]]")), "");
  // Skew legs: a horizontal well passing P1's vertical axis 3 m to the side; the closest
  // points are (30, 50, 20) on P1 and (33, 50, 20) on I1.
  EXPECT_EQ(error_of(with(kBase, t, "trajectory: [[33, 20, 20], [33, 80, 20]]")),
            "wells[1].trajectory: too close to wells[0] (distance 3 m < 16 m = sum of drainage radii; radial "
            "grids may not overlap)");
  // The stronger rule: blocks overlapping without reaching the other wellbore (d = 12 > 8 + 0.1).
  EXPECT_EQ(error_of(with(kBase, t, "trajectory: [[42, 50, 15], [42, 50, 45]]")),
            "wells[1].trajectory: too close to wells[0] (distance 12 m < 16 m = sum of drainage radii; radial "
            "grids may not overlap)");
}

TEST(CaseErrors, TooManyWells) {
  std::string text = "name: a\nreservoir: {x: [0, 1], y: [0, 1], z: [0, 1]}\nwells:\n";
  for (size_t i = 0; i <= kMaxWells; ++i) text += "  - {}\n";
  EXPECT_EQ(error_of(text), "wells: at most 1000 wells (got 1001)");
}

TEST(CaseErrors, TooManyTrajectoryPoints) {
  std::string traj = "[";
  for (size_t i = 0; i <= kMaxTrajectoryPoints; ++i) traj += (i ? ", [50, 50, " : "[50, 50, ") + std::to_string(15 + i * 1e-3) + "]";
  traj += "]";
  EXPECT_EQ(error_of(with(kBase, "[[30, 50, 15], [30, 50, 45]]", traj)),
            "wells[0].trajectory: too many points (at most 10000 over all wells)");
}

// ---------------------------------------------------------------- transition and fluid

TEST(CaseErrors, TransitionRanges) {
  const auto bad = [&](const std::string& block) { return error_of(kBase + "transition: {" + block + "}\n"); };
  EXPECT_EQ(bad("dilation: 0.99"), "transition.dilation: must be >= 1");
  EXPECT_EQ(bad("dilation: 1"), "");
  const std::string gamma_msg = "transition.gamma: must satisfy 0 < G1 <= G2 <= G3 <= 0.5";
  EXPECT_EQ(bad("gamma: [0, 0.3, 0.4]"), gamma_msg);
  EXPECT_EQ(bad("gamma: [0.3, 0.2, 0.4]"), gamma_msg);
  EXPECT_EQ(bad("gamma: [0.1, 0.4, 0.3]"), gamma_msg);
  EXPECT_EQ(bad("gamma: [0.1, 0.3, 0.51]"), gamma_msg);
  EXPECT_EQ(bad("gamma: [0.5, 0.5, 0.5]"), "");
  EXPECT_EQ(bad("gamma: [0.1, 0.3]"), "transition.gamma: expected 3 values [G1, G2, G3], got 2");
  EXPECT_EQ(bad("omega_o: 79.9"), "transition.omega_o: must be in [80, 90] degrees");
  EXPECT_EQ(bad("omega_o: 90.1"), "transition.omega_o: must be in [80, 90] degrees");
  EXPECT_EQ(bad("omega_o: 80"), "");
  EXPECT_EQ(bad("omega_p: -1"), "transition.omega_p: must be in [0, 10] degrees");
  EXPECT_EQ(bad("omega_p: 10.5"), "transition.omega_p: must be in [0, 10] degrees");
  EXPECT_EQ(bad("omega_p: 0"), "");
  EXPECT_EQ(bad("expansion: 1"), "transition.expansion: must be in (1, 1.1]");
  EXPECT_EQ(bad("expansion: 1.11"), "transition.expansion: must be in (1, 1.1]");
  EXPECT_EQ(bad("expansion: 1.1"), "");
}

TEST(CaseErrors, FluidRanges) {
  EXPECT_EQ(error_of(kBase + "fluid: {viscosity: 0}\n"), "fluid.viscosity: must be > 0");
  EXPECT_EQ(error_of(kBase + "fluid: {density: -1}\n"), "fluid.density: must be > 0");
  EXPECT_EQ(error_of(kBase + "fluid: {compressibility: -1e-9}\n"), "fluid.compressibility: must be >= 0");
  EXPECT_EQ(error_of(kBase + "fluid: {compressibility: 0}\n"), "");
}

// ---------------------------------------------------------------- robustness

TEST(CaseRobustness, MalformedDocumentsGiveOneLineInputErrors) {
  const std::vector<std::string> docs = {
      "",
      "\n\n\n",
      "42\n",
      "- a\n- b\n",
      "[[1, 2], [3, 4]]\n",
      "name: a\nreservoir: 5\n",
      "name: a\nreservoir: {x: {a: 1}, y: [0, 1], z: [0, 1]}\n",
      "name: a\nreservoir: {x: [[0, 1]], y: [0, 1], z: [0, 1]}\n",
      "name: a\nreservoir: {x: [0, 1], y: [0, 1], z: [0, 1]}\nwells: [[1, 2]]\n",
      "name: a\nreservoir: {x: [0, 1], y: [0, 1], z: [0, 1]}\nwells: [{name: {a: b}}]\n",
      "name: a\nreservoir: {x: [0, 1], y: [0, 1], z: [0, 1]}\nwells: [~, ~]\n",
      "name: a\nreservoir: {x: [0, 1], y: [0, 1], z: [0, 1]}\nfluid: [1, 2, 3]\n",
      "name: a\nreservoir: ~\n",
      "name: ~\n",
      "name: réservoir\nreservoir: {x: [0, 1], y: [0, 1], z: [0, 1]}\n",
      "nâme: a\n",
      "\"na\\nme\": a\n",
      "name: a\nreservoir: {x: [0, 1], y: [0, 1], z: [0, 1]}\ntransition: {gamma: [[0.1], [0.2], [0.3]]}\n",
      "name: a\nreservoir: {x: &a [0, *a], y: [0, 1], z: [0, 1]}\n",
      "&r [*r]\n",
      "name: a\nreservoir: &r {x: *r, y: [0, 1], z: [0, 1]}\n",
      "name: !!binary aGVsbG8=\n",
      "\xff\xfe\x00\x41",
      "name: \x01\x02\n",
      std::string("name: a\0b\n", 10),
      "name: a\nreservoir: {x: [0, 1], y: [0, 1], z: [0, 1]}\nwells:\n  - name: P1\n    trajectory: [[0.5, 0.5, 0.5], "
      "[0.5, 0.5, 0.6]]\n    radius: 0.1\n    drainage_radius: 0.9\n    bhp: 100\n",
      "{{{{{{{{\n",
      "'unterminated\n",
      "key: [unbalanced}\n",
      "\t- tab indented\n",
      std::string(10000, '[') + std::string(10000, ']'),
      std::string(10000, '-') + " x\n",
  };
  for (size_t i = 0; i < docs.size(); ++i) {
    SCOPED_TRACE("document " + std::to_string(i));
    const std::string msg = error_of(docs[i]);
    EXPECT_NE(msg, "") << "accepted";
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    EXPECT_NE(msg.find(": "), std::string::npos) << msg;
  }
}

TEST(CaseRobustness, UserTextIsEchoedOnOneLine) {
  EXPECT_EQ(error_of("\"na\\nme\": a\n"),
            "'na\\nme': unknown key (expected one of: name, metric, reservoir, wells, transition, fluid)");
  EXPECT_EQ(error_of(with(kBase, "porosity: 0.2", "porosity: \"a\\tb\\x01\"")),
            "reservoir.porosity: expected a number, got 'a\\tb\\x01'");
  EXPECT_EQ(error_of(with(kBase, "porosity: 0.2", "porosity: " + std::string(100, 'q'))),
            "reservoir.porosity: expected a number, got '" + std::string(40, 'q') + "...'");
  EXPECT_EQ(error_of(with(kBase, "porosity: 0.2", "porosity: é")), "reservoir.porosity: expected a number, got 'é'");
}

// Deterministic mutation fuzzing of a valid case: whatever the damage, parse_case either
// succeeds or throws a one-line InputError.
TEST(CaseRobustness, MutatedCasesOnlyThrowInputError) {
  std::mt19937 rng(12345);
  const std::string alphabet = "[]{}:,-'\"#&*!|>? \n\t0123456789.eE+xyzabc~\xc3\xa9";
  int accepted = 0, rejected = 0;
  for (int iter = 0; iter < 3000; ++iter) {
    std::string text = kBase;
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits && !text.empty(); ++e) {
      const size_t at = rng() % text.size();
      switch (rng() % 4) {
        case 0: text.erase(at, 1 + rng() % 3); break;
        case 1: text.insert(at, 1, alphabet[rng() % alphabet.size()]); break;
        case 2: text[at] = alphabet[rng() % alphabet.size()]; break;
        default: {  // duplicate a chunk elsewhere
          const size_t len = 1 + rng() % 20;
          const std::string chunk = text.substr(at, len);
          text.insert(rng() % text.size(), chunk);
        }
      }
    }
    const std::string msg = error_of(text);
    if (msg.empty()) {
      ++accepted;
    } else {
      ++rejected;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
  }
  RecordProperty("accepted", accepted);
  RecordProperty("rejected", rejected);
  // Both outcomes occur, so the fuzzing explores valid and invalid documents.
  EXPECT_GT(accepted, 0);
  EXPECT_GT(rejected, 0);
}

// ---------------------------------------------------------------- segment distance

TEST(SegmentDistance, KnownConfigurations) {
  EXPECT_DOUBLE_EQ(segment_segment_distance({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}), 1.0);       // parallel
  EXPECT_DOUBLE_EQ(segment_segment_distance({0, 0, 0}, {1, 0, 0}, {3, 0, 0}, {4, 0, 0}), 2.0);       // collinear gap
  EXPECT_DOUBLE_EQ(segment_segment_distance({-1, 0, 0}, {1, 0, 0}, {0, -1, 2}, {0, 1, 2}), 2.0);     // skew crossing
  EXPECT_DOUBLE_EQ(segment_segment_distance({0, 0, 0}, {1, 0, 0}, {0.5, -1, 0}, {0.5, 1, 0}), 0.0);  // intersecting
  EXPECT_DOUBLE_EQ(segment_segment_distance({0, 0, 0}, {1, 0, 0}, {2, 1, 0}, {3, 5, 0}), std::sqrt(2.0));  // end-end
  EXPECT_DOUBLE_EQ(segment_segment_distance({0, 0, 0}, {0, 0, 0}, {0, 3, 4}, {0, 3, 4}), 5.0);       // two points
}

// Against brute-force sampling: the exact distance is <= every sampled distance and
// within the sampling resolution of the best one.
TEST(SegmentDistance, MatchesBruteForceSampling) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-5, 5);
  const int n = 200;
  for (int trial = 0; trial < 200; ++trial) {
    const Vec3 p0{u(rng), u(rng), u(rng)}, p1{u(rng), u(rng), u(rng)};
    Vec3 q0{u(rng), u(rng), u(rng)}, q1{u(rng), u(rng), u(rng)};
    if (trial % 4 == 0) q1 = q0 + (p1 - p0) * 0.7;  // parallel pairs too
    const double d = segment_segment_distance(p0, p1, q0, q1);
    double sampled = 1e300;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= n; ++j)
        sampled = std::min(sampled, norm((p0 + (p1 - p0) * (double(i) / n)) - (q0 + (q1 - q0) * (double(j) / n))));
    const double resolution = (norm(p1 - p0) + norm(q1 - q0)) / n;
    EXPECT_LE(d, sampled + 1e-12);
    EXPECT_GE(d, sampled - resolution);
  }
}

TEST(SegmentDistance, PolylineCutoffIsExactBelowAndBoundAbove) {
  const std::vector<Vec3> a{{0, 0, 0}, {10, 0, 0}, {10, 10, 0}};
  const std::vector<Vec3> b{{20, 5, 0}, {13, 5, 0}, {13, 5, 10}};
  EXPECT_DOUBLE_EQ(polyline_distance(a, b), 3.0);
  EXPECT_DOUBLE_EQ(polyline_distance(a, b, 3.5), 3.0);
  EXPECT_GE(polyline_distance(a, b, 2.0), 2.0);
}

// The inside test of the corner-point path cut (corner_point_path.hpp) on two stacked unit cubes: a
// point on the face between them is inside, one on the model's top is outside, one on its bottom is
// inside (a point on a face counts as the point just above it), and points off the faces as they are.
TEST(CornerPointPath, PointsOnFacesAreDecidedAsJustAboveThem) {
  CornerPointModel m;
  m.nx = 1, m.ny = 1, m.nz = 2;
  for (int J = 0; J < 2; ++J)
    for (int I = 0; I < 2; ++I) m.coord.insert(m.coord.end(), {double(I), double(J), 0.0, double(I), double(J), 2.0});
  m.zcorn.resize(16);
  for (int k = 0; k < 2; ++k) {
    for (int q = 0; q < 8; ++q) m.zcorn[zcorn_index(m, 0, 0, k, q)] = double(k + ((q >> 2) & 1));
    m.actnum.push_back(1);
  }
  const CornerPointInterior inside(m, Vec3{-1, -1, -1}, Vec3{2, 2, 3});
  EXPECT_TRUE(inside.contains({0.5, 0.5, 1}));    // the face between the cells
  EXPECT_FALSE(inside.contains({0.5, 0.5, 0}));   // the top (depth 0)
  EXPECT_TRUE(inside.contains({0.5, 0.5, 2}));    // the bottom
  EXPECT_TRUE(inside.contains({0.5, 0.5, 0.5}));
  EXPECT_TRUE(inside.contains({0.25, 0.75, 1.5}));
  EXPECT_FALSE(inside.contains({0.5, 0.5, -0.5}));
  EXPECT_FALSE(inside.contains({1.5, 0.5, 1.5}));
  m.actnum[1] = 0;  // the lower cell inactive: its top face is the model's bottom now
  const CornerPointInterior upper(m, Vec3{-1, -1, -1}, Vec3{2, 2, 3});
  EXPECT_TRUE(upper.contains({0.5, 0.5, 1}));
  EXPECT_FALSE(upper.contains({0.5, 0.5, 1.5}));
}

namespace {

// A model of 10 x 10 columns of 2 x 2 m on vertical pillars, its layers' depths `depths` (nz + 1
// values, equal ones making layers of zero thickness), every cell active.
CornerPointModel stacked_model(const std::vector<double>& depths) {
  CornerPointModel m;
  m.nx = m.ny = 10, m.nz = static_cast<int>(depths.size()) - 1;
  for (int J = 0; J <= m.ny; ++J)
    for (int I = 0; I <= m.nx; ++I)
      m.coord.insert(m.coord.end(), {2.0 * I, 2.0 * J, depths.front(), 2.0 * I, 2.0 * J, depths.back()});
  m.zcorn.resize(size_t(8) * m.nx * m.ny * m.nz);
  for (int k = 0; k < m.nz; ++k)
    for (int j = 0; j < m.ny; ++j)
      for (int i = 0; i < m.nx; ++i)
        for (int q = 0; q < 8; ++q) m.zcorn[zcorn_index(m, i, j, k, q)] = depths[k + ((q >> 2) & 1)];
  m.actnum.assign(size_t(m.nx) * m.ny * m.nz, 1);
  return m;
}

}  // namespace

// surface_clearance: the nearest node of the model's surface beside the path, less the drainage
// radius. A horizontal path 1.9 m under the top (0.4 m under an inner layer of zero thickness, which
// is no surface, and 2.6 m over the bottom, reached past a bottom layer of zero thickness): 1.9 - R.
// A cell made inactive beside the path brings its neighbours' faces 0.4 m from the axis; one
// beyond the path's end does not count (the block's end faces are sized where the path is clipped).
TEST(CornerPointPath, SurfaceClearanceIsTheNearestSurfaceNodeBesideThePath) {
  CornerPointModel m = stacked_model({0, 1.5, 1.5, 3, 4.5, 4.5});
  WellSpec ws;
  ws.drainage_radius = 1;
  ws.trajectory = {{4, 10, 1.9}, {17.5, 10, 1.9}};
  EXPECT_NEAR(surface_clearance(m, ws), 0.9, 1e-14);
  const int beyond_end = 9 + m.nx * (5 + m.ny * 2);  // x 18-20, y 10-12, z 1.5-3
  m.actnum[beyond_end] = 0;
  EXPECT_NEAR(surface_clearance(m, ws), 0.9, 1e-14);
  const int beside = 5 + m.nx * (5 + m.ny * 2);  // x 10-12, y 10-12, z 1.5-3
  m.actnum[beside] = 0;
  EXPECT_NEAR(surface_clearance(m, ws), -0.6, 1e-14);
  ws.trajectory = {{4, 10, 7}, {17.5, 10, 7}};  // 2.5 m under the bottom: no surface node within 2 R beside it
  EXPECT_EQ(surface_clearance(m, ws), INFINITY);
}

// fit_outer_faces: the user's values when the outer faces' diametral spheres (half the diagonal of a
// chord by a segment, about a circumcentre R cos(pi / sectors) from the axis) cannot reach the
// surface's nodes; else spheres kSurfaceGapMargin times inside the clearance whenever it says they fit,
// sectors raised before the segment is shortened, to at most 4 x; no fit only when even 4 x the
// sectors leave a chord as wide as the sphere allowed, or when the surface reaches into the block (a
// clearance <= 0: the user's values, unchanged).
TEST(CornerPointPath, OuterFacesAreFittedInsideTheSurfaceClearance) {
  int fitted = 0, raised = 0, refused = 0;
  for (double R : {3.0, 6.0, 15.0})
    for (int sectors : {8, 12, 13})
      for (double segment : {1.0, 4.0, 10.0})
        for (double clearance : {-1.0, 0.0, 0.05, 0.5, 1.5, 2.5, 4.0, 8.0}) {
          WellSpec ws;
          ws.drainage_radius = R, ws.sectors = sectors, ws.segment_length = segment;
          const OuterFaceFit fit = fit_outer_faces(ws, clearance);
          if (clearance <= 0) {  // the surface inside the block: nothing fits, nothing changes
            EXPECT_FALSE(fit.fits);
            EXPECT_EQ(fit.sectors, sectors);
            EXPECT_EQ(fit.segment_length, segment);
            continue;
          }
          const double allowed = clearance / kSurfaceGapMargin;
          auto chord = [R](int n) { return 2 * R * std::sin(M_PI / n); };
          const double sphere = 0.5 * std::hypot(chord(sectors), segment);
          if (R * std::cos(M_PI / sectors) + sphere <= R + clearance) {
            EXPECT_TRUE(fit.fits);
            EXPECT_EQ(fit.sectors, sectors);
            EXPECT_EQ(fit.segment_length, segment);
            continue;
          }
          EXPECT_GE(fit.sectors, sectors);
          EXPECT_LE(fit.sectors, 4 * sectors);
          if (!fit.fits) {
            ++refused;
            EXPECT_GE(chord(fit.sectors), 2 * allowed) << R << " " << sectors << " " << clearance;
            continue;
          }
          ++fitted, raised += fit.sectors > sectors;
          EXPECT_LE(0.5 * std::hypot(chord(fit.sectors), fit.segment_length), allowed * (1 + 1e-12));
          EXPECT_LE(fit.segment_length, segment);
          if (fit.sectors < 4 * sectors) {
            EXPECT_LE(chord(fit.sectors), std::sqrt(2.0) * allowed * (1 + 1e-12));
          }
          if (fit.sectors > sectors) {
            EXPECT_GT(chord(fit.sectors - (fit.sectors % 2 == 0 ? 2 : 1)), std::sqrt(2.0) * allowed);
          }
        }
  EXPECT_GT(fitted, 0);
  EXPECT_GT(raised, 0);
  EXPECT_GT(refused, 0);
}
