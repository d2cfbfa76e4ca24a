// libFuzzer target for the VTU reader (VTK's XML reader + our conversion to a PolyMesh):
// every input must come back as ok or as a one-line error, without a crash, a leak or
// undefined behaviour (built with -fsanitize=fuzzer,address,undefined; docs/output-formats.md).
// Build: cmake -DHM_FUZZ=ON -DCMAKE_CXX_COMPILER=clang++ ...; run: fuzz_vtu tests/fuzz/corpus_vtu
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "exporters/vtu/vtu_reader.hpp"
#include "meshgen/core/geometry.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const hm::ReadResult r = hm::read_vtu_buffer(std::string(reinterpret_cast<const char*>(data), size));
  if (!r.ok) {
    if (r.error.empty() || r.error.find('\n') != std::string::npos) std::abort();  // one line, always
    return 0;
  }
  // A mesh that came back is usable: its CSR arrays hold, and its geometry can be computed.
  if (!hm::check_csr_invariants(r.mesh).ok && r.build.ok) std::abort();
  if (hm::check_csr_invariants(r.mesh).ok) (void)hm::compute_geometry(r.mesh);
  return 0;
}
