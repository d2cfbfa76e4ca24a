#!/usr/bin/env python3
"""K-non-orthogonality of the shipped examples' near-well cells (docs/anisotropy.md, "Session 16").

Meshes each example as shipped (its `metric`, Euclidean by default) and again with `metric: permeability`
appended, runs fvcheck on each mesh and prints fvcheck's line "interior faces only" (degrees, max/mean:
all, reservoir, transition, well). The Reek examples are left out (minutes each).

Usage: scripts/k_orthogonality_table.py [BUILD_DIR] [EXAMPLE ...]   (BUILD_DIR default: build)
"""
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXAMPLES = ["accuracy_bent", "accuracy_deviated45", "accuracy_horizontal", "accuracy_vertical",
            "deviated_through_top", "horizontal_through_sides", "paper_single_well", "perforated_survey",
            "readme_example", "three_wells", "vertical_through", "layered_grdecl"]


def main(argv):
    build = argv[1] if len(argv) > 1 else os.path.join(ROOT, "build")
    examples = argv[2:] or EXAMPLES
    meshgen, fvcheck = os.path.join(build, "bin", "meshgen"), os.path.join(build, "bin", "fvcheck")
    with tempfile.TemporaryDirectory(prefix="hm_korth_") as tmp:
        for name in examples:
            # The case is copied next to its example so that relative paths (a GRDECL file) still resolve.
            text = open(os.path.join(ROOT, "examples", name + ".yaml")).read()
            for metric in ("as shipped", "permeability"):
                case = os.path.join(ROOT, "examples", ".korth_%d_%s.yaml" % (os.getpid(), name))
                with open(case, "w") as f:
                    f.write(text + ("\nmetric: permeability\n" if metric == "permeability" else ""))
                out = os.path.join(tmp, name + "_" + metric.replace(" ", "_"))
                try:
                    r = subprocess.run([meshgen, case, "-o", out, "--quiet"], capture_output=True, text=True)
                finally:
                    os.remove(case)
                if r.returncode != 0:
                    print("%-26s %-12s meshgen exit %d: %s" % (name, metric, r.returncode, r.stderr.strip()[-200:]))
                    continue
                f = subprocess.run([fvcheck, os.path.join(out, "mesh.vtu"), "--quiet"], capture_output=True, text=True)
                line = [l for l in f.stdout.splitlines() if "interior faces only" in l]
                print("%-26s %-12s %s" % (name, metric, line[0].split(":", 1)[1].strip() if line else "no figure"))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
