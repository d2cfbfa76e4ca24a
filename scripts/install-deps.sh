#!/usr/bin/env bash
# Installs the Debian 12 packages HybridMesh needs; quiet and quick when all are present.
# Usage: scripts/install-deps.sh [--validators]   (--validators adds OPM Flow, OpenFOAM, VTK, clang for fuzzing)
set -euo pipefail
build_pkgs=(cmake g++ make libcgal-dev libeigen3-dev libopenmesh-dev libboost-graph-dev libgtest-dev
            libyaml-cpp-dev nlohmann-json3-dev libtbb-dev libopm-common-dev libvtk9-dev)
validator_pkgs=(python3-vtk9 libopm-simulators-bin python3-opm-common openfoam)
build_pkgs+=(pybind11-dev python3-dev python3-numpy)  # the Python module hybridmesh (docs/python.md)
# meshgen --png (the demo's pictures): VTK renders through GLX, on a virtual X server when there is no
# display (xvfb-run, which needs xauth), with Mesa's software OpenGL (docs/output-formats.md, "Pictures").
build_pkgs+=(libx11-dev xvfb xauth libgl1-mesa-dri libglx-mesa0)
validator_pkgs+=(clang libclang-rt-14-dev)           # libFuzzer + ASan targets of tests/fuzz (docs/fuzzing.md)
want=("${build_pkgs[@]}")
if [[ "${1:-}" == "--validators" ]]; then want+=("${validator_pkgs[@]}"); fi

missing=()
for p in "${want[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then missing+=("$p"); fi
done
if ((${#missing[@]} == 0)); then exit 0; fi

echo "install-deps: installing ${missing[*]}"
SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get -o DPkg::Lock::Timeout=600 update -qq
$SUDO apt-get -o DPkg::Lock::Timeout=600 install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
