#!/usr/bin/env python3
"""Meshes a case from Python and looks at the mesh with numpy (docs/python.md).

    /usr/bin/python3 examples/python_mesh.py [CASE.yaml] [-o OUTDIR]

After `bash scripts/demo.sh` the module hybridmesh is on /usr/bin/python3's path. Exit code 0 when the
mesh passes fvcheck's checks and its volume is the box minus the wellbore holes, 1 otherwise, 2 for bad input.
"""
import argparse
import os
import sys

import numpy as np

import hybridmesh

here = os.path.dirname(os.path.abspath(__file__))
ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("case", nargs="?", default=os.path.join(here, "readme_example.yaml"))
ap.add_argument("-o", "--output", help="write mesh.vtu and the Eclipse deck there")
args = ap.parse_args()

try:
    case = hybridmesh.load_case(args.case)
    mesh = hybridmesh.build(case)
except hybridmesh.InputError as e:
    print(f"python_mesh: {e}", file=sys.stderr)
    sys.exit(2)

names = {0: "reservoir", 1: "transition", 2: "well"}
regions = np.bincount(mesh.cell_region, minlength=3)
print(f"{case.name}: {mesh.n_cells} cells ("
      + ", ".join(f"{regions[r]} {names[r]}" for r in range(3)) + f"), {mesh.n_faces} faces, {mesh.n_nodes} nodes")

faces_per_cell = np.diff(mesh.cell_face_ptr)
nodes_per_face = np.diff(mesh.face_node_ptr)
for r in range(3):
    sel = mesh.cell_region == r
    print(f"  {names[r]:10s} faces per cell {faces_per_cell[sel].min()}-{faces_per_cell[sel].max()}, "
          f"volume {mesh.volumes[sel].sum():.6g} m3")
print(f"  nodes per face {nodes_per_face.min()}-{nodes_per_face.max()}")

box = (case.x[-1] - case.x[0]) * (case.y[-1] - case.y[0]) * (case.z[-1] - case.z[0])
expected = box - mesh.wellbore_hole_volume
rel = abs(mesh.volumes.sum() - expected) / expected
print(f"  total volume {mesh.volumes.sum():.9g} m3, box minus wellbore holes {expected:.9g} m3 (rel. diff {rel:.1e})")

# Near-well transmissibilities: the wellbore faces carry the connection factors.
t = mesh.transmissibilities
wellbore = mesh.face_patch >= 1
interior = mesh.face_neighbour >= 0
print(f"  transmissibilities: interior {t[interior].min():.3g}..{t[interior].max():.3g}, "
      f"well connection factors sum {t[wellbore].sum():.4g} (cP.rm3/day/bar)")

report = hybridmesh.check(mesh)
failed = [name for name, c in report["checks"].items() if c.get("violations", 0)]
print("  fvcheck: " + ("all checks hold" if report["ok"] else "FAILED: " + ", ".join(failed)))

if args.output:
    for path in hybridmesh.export(mesh, args.output, ["vtu", "eclipse"]):
        print(f"  wrote {path}")

sys.exit(0 if report["ok"] and rel < 1e-9 else 1)
