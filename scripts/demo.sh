#!/usr/bin/env bash
# README command 1: install what is missing, build (Release) into build/, mesh the bundled
# default example and list what was written.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
bash scripts/install-deps.sh
bash scripts/build.sh "$root/build"
case_file=${1:-examples/paper_single_well.yaml}
name=$(basename "$case_file" .yaml)
out="out/$name"
build/bin/meshgen "$case_file" -o "$out"
echo
echo "Wrote:"
ls -l "$out"
