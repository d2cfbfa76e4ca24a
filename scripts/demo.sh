#!/usr/bin/env bash
# README command 1: install what is missing, build (Release) into build/, make the Python module
# importable by /usr/bin/python3, mesh the bundled default example (with its pictures) and list what
# was written.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
bash scripts/install-deps.sh
bash scripts/build.sh "$root/build"
# Python: put build/python (the module hybridmesh) on /usr/bin/python3's path with a .pth file in
# that interpreter's user site-packages, so that `/usr/bin/python3 -c "import hybridmesh"` works.
if [[ -x /usr/bin/python3 ]] && compgen -G "$root/build/python/hybridmesh*.so" >/dev/null; then
  if site=$(/usr/bin/python3 -c 'import site, sys; sys.exit(0 if site.ENABLE_USER_SITE else 1); ' 2>/dev/null &&
            /usr/bin/python3 -m site --user-site); then
    mkdir -p "$site"
    echo "$root/build/python" >"$site/hybridmesh.pth"
    echo "demo: /usr/bin/python3 imports hybridmesh from $root/build/python ($site/hybridmesh.pth)"
  else
    echo "demo: user site-packages disabled; use PYTHONPATH=$root/build/python /usr/bin/python3"
  fi
fi
case_file=${1:-examples/paper_single_well.yaml}
name=$(basename "$case_file" .yaml)
out="out/$name"
# --png: the pictures of docs/output-formats.md ("Pictures"), under xvfb-run when there is no display.
build/bin/meshgen "$case_file" -o "$out" --png
echo
echo "Wrote:"
ls -l "$out"
