// Test helper shared by several suites: a case file small enough to mesh in about a second.
#pragma once

namespace hm::test {

/// One vertical well (a few hundred cells) in a graded 10 x 10 x 10 grid.
inline const char* const kSmallCase = R"(name: small
reservoir:
  x: [0, 20, 40, 50, 55, 60, 65, 70, 80, 100, 120]
  y: [0, 20, 40, 50, 55, 60, 65, 70, 80, 100, 120]
  z: [1000, 1010, 1020, 1025, 1030, 1035, 1040, 1045, 1050, 1060, 1070]
  permeability: [100, 100, 10]
  porosity: 0.2
  initial_pressure: 200
wells:
  - name: P1
    trajectory: [[60, 60, 1027], [60, 60, 1043]]
    radius: 0.1
    drainage_radius: 3
    rings: 3
    sectors: 8
    segment_length: 4
    bhp: 150
)";

}  // namespace hm::test
