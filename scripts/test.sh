#!/usr/bin/env bash
# README command 2: install what is missing, build, run all tests (ctest), then the tests of our
# own code again in an AddressSanitizer + UndefinedBehaviorSanitizer build, then a short libFuzzer
# run of the VTU reader (clang, ASan+UBSan; HM_FUZZ_SECONDS, default 25).
# HM_SKIP_SANITIZE=1 skips the sanitizer build (local iteration only; CI runs it).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
bash scripts/install-deps.sh --validators
jobs=$(nproc 2>/dev/null || echo 2)

echo "== Release build and tests"
bash scripts/build.sh "$root/build"
(cd build && ctest --output-on-failure -j"$jobs")

if [[ "${HM_SKIP_SANITIZE:-0}" != "1" ]]; then
  echo "== ASan+UBSan build and tests"
  # -O1 -g1: quick to compile, line numbers in reports. The runs of third-party validators
  # (OPM Flow, OpenFOAM checkMesh, VTK) already ran in the Release pass; here our own code
  # is what the sanitizers watch, so those tests are left out.
  bash scripts/build.sh "$root/build-asan" -DHM_SANITIZE=ON -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" \
    -DCGAL_DO_NOT_WARN_ABOUT_CMAKE_BUILD_TYPE=TRUE
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  (cd build-asan && ctest --output-on-failure -j"$jobs" -E '^(Flow|OpenFoamMeshgen|CheckMesh|AsciiAndBinary/CheckMesh|Examples/CheckMesh|VtkValidation)')
fi

if [[ "${HM_SKIP_SANITIZE:-0}" != "1" ]]; then
  echo "== libFuzzer: fuzz_vtu (clang, ASan+UBSan) for ${HM_FUZZ_SECONDS:-25} s"
  cmake -S "$root" -B "$root/build-fuzz" -DHM_FUZZ=ON -DHM_BUILD_TESTS=OFF -DCMAKE_CXX_COMPILER=clang++ \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCGAL_DO_NOT_WARN_ABOUT_CMAKE_BUILD_TYPE=TRUE >/dev/null
  cmake --build "$root/build-fuzz" -j"$jobs" --target fuzz_vtu
  corpus=$(mktemp -d)
  cp "$root"/tests/fuzz/corpus_vtu/* "$corpus"/
  ASAN_OPTIONS=detect_leaks=1 "$root/build-fuzz/bin/fuzz_vtu" -max_total_time="${HM_FUZZ_SECONDS:-25}" \
    -max_len=65536 -rss_limit_mb=2048 "$corpus"
  rm -rf "$corpus"
fi
