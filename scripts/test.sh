#!/usr/bin/env bash
# README command 2: install what is missing, build, run all tests (ctest), then the same
# tests in an AddressSanitizer + UndefinedBehaviorSanitizer build.
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
  bash scripts/build.sh "$root/build-asan" -DHM_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  (cd build-asan && ctest --output-on-failure -j"$jobs")
fi
