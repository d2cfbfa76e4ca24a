#!/usr/bin/env bash
# README command 2: install what is missing, check the module layers, build, run all tests (ctest),
# run the libFuzzer targets for a short while (clang tree build-fuzz/), then the tests of our own code
# again in an AddressSanitizer + UndefinedBehaviorSanitizer build.
# HM_SKIP_SANITIZE=1 skips the sanitizer build (local iteration only; CI runs it).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
bash scripts/install-deps.sh --validators
jobs=$(nproc 2>/dev/null || echo 2)

echo "== Module layers (scripts/check_layers.py)"
python3 scripts/check_layers.py --self-test >/dev/null
python3 scripts/check_layers.py

echo "== Release build and tests"
bash scripts/build.sh "$root/build"
(cd build && ctest --output-on-failure -j"$jobs")

echo "== Fuzz targets (clang, libFuzzer + ASan/UBSan; HM_FUZZ_SECONDS=${HM_FUZZ_SECONDS:-25} s each)"
# A separate clang tree that builds only the fuzz targets and the libraries they need.
cmake -S "$root" -B "$root/build-fuzz" -DCMAKE_CXX_COMPILER=clang++ -DHM_FUZZ=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" -DHM_FUZZ_SECONDS="${HM_FUZZ_SECONDS:-25}" \
  -DCGAL_DO_NOT_WARN_ABOUT_CMAKE_BUILD_TYPE=TRUE >/dev/null
cmake --build "$root/build-fuzz" -j"$jobs" --target fuzz_targets
(cd build-fuzz && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --output-on-failure -j"$jobs")

if [[ "${HM_SKIP_SANITIZE:-0}" != "1" ]]; then
  echo "== ASan+UBSan build and tests"
  # -O1 -g1: quick to compile, line numbers in reports. The runs of third-party validators
  # (OPM Flow, OpenFOAM checkMesh, VTK) already ran in the Release pass; here our own code
  # is what the sanitizers watch, so those tests are left out; so are the pictures (MeshPictures: VTK's
  # OpenGL rendering through Mesa under Xvfb, whose own allocations LeakSanitizer would report).
  bash scripts/build.sh "$root/build-asan" -DHM_SANITIZE=ON -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" \
    -DCGAL_DO_NOT_WARN_ABOUT_CMAKE_BUILD_TYPE=TRUE
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  export LSAN_OPTIONS=suppressions="$root/tests/lsan.supp":print_suppressions=0  # third-party leaks only
  # Also left out here, run in the Release pass: the slowest tests under ASan, whose code paths smaller
  # tests that stay here run (docs/testing.md, "The sanitizer pass", says which and why). The sweeps and
  # reproducers of several cases mesh a sample of them here (tests/support/sanitizer_build.hpp).
  asan_long='CornerPointSweep\.CiHorizontalSeed2.*|SiteOptimizer\.SliverPass.*|NearWellRefinement\.(ThinLayersInCoarseCellsMesh|Reek.*)|PermeabilityFrameMesh\.KOrthogonalNearTheWell.*|MeshgenReekExample\..*|CornerPointWells\.Reek.*|LocalFrame\.Optimised.*'
  asan_long+='|PermeabilityFrameMesh\.ReservoirNodesAreTheUsers.*'
  asan_long+='|CornerPointSweep\.CiSubsetMeshesSoundly|RealisticSweep\.ShrinkWaveAlongALongWellConverges|CornerPointWells\.(WellAcrossAFaultOfTenMetres|SecondWellBesideTheFirstOnesChildren)MeshesSoundly|RealisticSweep\.FlatEndsWithLargeRingRatio.*|RealisticSweep\.SkewnessRoundsGoOnWhileTheyMakeProgress|RealisticSweep\.StalledSkewnessRoundsGetASecondChance'
  (cd build-asan && ctest --output-on-failure -j"$jobs" \
    -E "^(Flow|OpenFoamMeshgen|CheckMesh|AsciiAndBinary/CheckMesh|Examples/CheckMesh|VtkValidation|MeshPictures|Examples/VtkAgreement|VtkAgreement|$asan_long)")
fi
