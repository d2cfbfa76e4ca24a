// libFuzzer target for the case-file parser (meshgen/case): any bytes -> parse_case.
// The contract (meshgen/case/case.hpp): a valid CaseSpec, or hm::InputError "key.path: reason";
// any other exception, a crash or a sanitizer report is a bug. An accepted case must satisfy
// the constraints docs/case-format.md lists (checked below: a parser that lets one through fails).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "meshgen/case/case.hpp"

namespace {

[[noreturn]] void bug(const char* what) {
  std::fprintf(stderr, "fuzz_case: accepted case violates: %s\n", what);
  std::abort();
}

bool increasing(const std::vector<double>& v) {
  if (v.size() < 2) return false;
  for (size_t i = 1; i < v.size(); ++i)
    if (!(v[i] > v[i - 1]) || !std::isfinite(v[i])) return false;
  return std::isfinite(v[0]);
}

void check_accepted(const hm::CaseSpec& cs) {
  if (cs.name.empty()) bug("name not empty");
  if (!increasing(cs.reservoir.x) || !increasing(cs.reservoir.y) || !increasing(cs.reservoir.z))
    bug("reservoir axes strictly increasing, >= 2 values");
  const hm::Vec3 k = cs.reservoir.permeability;
  if (!(k.x > 0 && k.y > 0 && k.z > 0)) bug("permeability > 0");
  if (!(cs.reservoir.porosity > 0 && cs.reservoir.porosity <= 1)) bug("porosity in (0, 1]");
  for (const hm::WellSpec& w : cs.wells) {
    if (w.name.empty()) bug("well name not empty");
    if (w.trajectory.size() < 2) bug("trajectory >= 2 points");
    if (!(w.radius > 0 && w.drainage_radius > w.radius)) bug("0 < radius < drainage_radius");
    if (w.rings < 1 || w.sectors < 3) bug("rings >= 1, sectors >= 3");
    if (!(w.segment_length > 0)) bug("segment_length > 0");
    for (double g : hm::hemisphere_end_grading(w))
      if (!(g > 0) || !std::isfinite(g)) bug("end grading positive and finite");
  }
  if (!(cs.transition.dilation >= 1)) bug("dilation >= 1");
  if (!(cs.fluid.viscosity > 0 && cs.fluid.density > 0)) bug("viscosity, density > 0");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    check_accepted(hm::parse_case(text));
  } catch (const hm::InputError& e) {
    const std::string msg = e.what();
    if (msg.find(": ") == std::string::npos || msg.find(": ") == 0) {
      std::fprintf(stderr, "fuzz_case: InputError without 'key.path: reason': %s\n", msg.c_str());
      std::abort();
    }
  }
  return 0;  // any other exception escapes: libFuzzer reports it as a crash
}
