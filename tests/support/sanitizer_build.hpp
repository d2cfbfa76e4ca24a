// Whether this test executable is scripts/test.sh's AddressSanitizer + UBSan build (HM_SANITIZE),
// where a realistic case costs 8-12 times its Release time. Sweeps and reproducers of several cases
// mesh a sample of their cases there: the sanitizers watch code paths, which the sample runs; the
// Release pass meshes every case and asserts every property (docs/testing.md, "The sanitizer pass").
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

namespace hm::test {

#ifdef HM_SANITIZER_BUILD
inline constexpr bool kSanitizerBuild = true;
#else
inline constexpr bool kSanitizerBuild = false;
#endif

// `cases` in the Release build; its first `sanitizer_count` under the sanitizers.
template <class T>
std::vector<T> sanitizer_sample(std::vector<T> cases, std::size_t sanitizer_count) {
  if (kSanitizerBuild && cases.size() > sanitizer_count) cases.resize(sanitizer_count);
  return cases;
}

// Seeds first..last in the Release build; first..first+sanitizer_count-1 under the sanitizers.
inline std::vector<unsigned> seed_range(unsigned first, unsigned last, std::size_t sanitizer_count) {
  std::vector<unsigned> seeds;
  for (unsigned s = first; s <= last; ++s) seeds.push_back(s);
  return sanitizer_sample(std::move(seeds), sanitizer_count);
}

}  // namespace hm::test
