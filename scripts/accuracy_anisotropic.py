#!/usr/bin/env python3
"""The anisotropic near-well accuracy sweep of docs/accuracy.md ("Anisotropic permeability").

Runs `solver_demo --accuracy --metric M` on the four shipped accuracy cases at kv/kh = 1, 0.1
and 0.01 (and kx/ky = 3 at kv/kh = 0.1 for the horizontal well), levels 1..L, one run at a time
under `nice`, each into OUT/<M>/<case>_kvkh<R>_kxky<Q>/ (M = euclidean: today's mesh and the
Cartesian + Peaceman model; M = permeability: the K-orthogonal mesh), then prints the markdown
tables of the doc from the accuracy.json files. A run whose accuracy.json exists is not repeated
(the sweep can be resumed); --table-only only tabulates what is there. --cells adds, per
K-orthogonal run, where the level-1 error is: from its cells.csv, per region (well, transition,
reservoir) and distance along the trajectory to its nearer end, the largest |error| / drawdown
and the sum of the cells' exact-pressure residuals / exact rate (docs/anisotropy.md, session 8).

Usage: accuracy_anisotropic.py [--solver BUILD/bin/solver_demo] [--out DIR] [--levels L]
                               [--metrics euclidean,permeability] [--cases vertical,deviated45,...]
                               [--table-only] [--cells] [--markdown FILE]
"""
import argparse
import csv
import json
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CASES = ["vertical", "deviated45", "horizontal", "bent"]
RATIOS = [(1.0, 1.0), (0.1, 1.0), (0.01, 1.0)]
EXTRA = {"horizontal": [(0.1, 3.0)]}


def tag(v):
    return ("%g" % v).replace(".", "p")


def run_dir(out, metric, case, kv, kxky):
    return os.path.join(out, metric, "%s_kvkh%s_kxky%s" % (case, tag(kv), tag(kxky)))


def load(out, metric, case, kv, kxky):
    f = os.path.join(run_dir(out, metric, case, kv, kxky), "accuracy.json")
    return json.load(open(f)) if os.path.exists(f) else None


def failures(out, metric, case, kv, kxky):
    """level -> the first line of the solver's message, for the levels whose mesh failed."""
    f = os.path.join(run_dir(out, metric, case, kv, kxky), "failure.txt")
    got = {}
    if os.path.exists(f):
        for line in open(f):
            head, _, msg = line.partition(": ")
            got[int(head.split()[1])] = msg.strip()
    return got


def pct(v, signed=False):
    if v is None:
        return "-"
    return ("%+.3f %%" if signed else "%.3f %%") % (100 * v)


def model_cells(m):
    if m is None:
        return "-", "-", "-"
    return pct(m["rate_rel_error"], True), pct(m["near_well_pressure_rel_error"]), pct(m["l2_pressure_rel_error"])


def where(m):
    if m is None:
        return "-"
    w = m["worst_cell"]
    d = m["near_well_diagnostics"]
    side = "tip" if d["max_beyond_ends"] >= d["max_lateral"] else "lateral"
    return "%s, %s, %.2f m" % (w["region"], side, w["distance_to_trajectory"])


END_BINS = [("beyond the ends", None), ("0-2 m", 2.0), ("2-6 m", 6.0), ("6-12 m", 12.0), (">12 m", float("inf"))]


def cell_table(path, title):
    """Markdown: per region and distance to the nearer end, max |error| and sum of residuals."""
    acc = {}
    for r in csv.DictReader(open(path)):
        e = float(r["to_end"])
        b = 0 if e == 0 else next(i for i, (_, hi) in enumerate(END_BINS) if hi is not None and e < hi)
        v = acc.setdefault((r["region"], b), [0.0, 0.0])
        v[0] = max(v[0], abs(float(r["error"])))
        v[1] += float(r["residual"])
    out = ["%s: max abs error / sum of residuals" % title, "",
           "| region | " + " | ".join(n for n, _ in END_BINS) + " |", "|---|" + "---|" * len(END_BINS)]
    for reg in ("well", "transition", "reservoir"):
        row = ["%.3f %% / %+.3f %%" % (100 * acc[(reg, b)][0], 100 * acc[(reg, b)][1]) if (reg, b) in acc else "-"
               for b in range(len(END_BINS))]
        out.append("| %s | %s |" % (reg, " | ".join(row)))
    return "\n".join(out) + "\n"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--solver", default=os.path.join(ROOT, "build", "bin", "solver_demo"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "accuracy_anisotropic"))
    ap.add_argument("--levels", type=int, default=2)
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--metrics", default="euclidean,permeability")
    ap.add_argument("--table-only", action="store_true")
    ap.add_argument("--cells", action="store_true")
    ap.add_argument("--markdown", default="")
    a = ap.parse_args()
    runs = []
    for case in a.cases.split(","):
        for kv, kxky in RATIOS + EXTRA.get(case, []):
            runs.append((case, kv, kxky))
    if not a.table_only:
        for metric in a.metrics.split(","):
            for case, kv, kxky in runs:
                if metric == "permeability" and kv == 1 and kxky == 1:
                    continue  # isotropic: the permeability frame is the identity, the mesh is the Euclidean one
                d = run_dir(a.out, metric, case, kv, kxky)
                if os.path.exists(os.path.join(d, "accuracy.json")):
                    continue
                # A level whose mesh fails ends the run: the message goes to failure.txt and the
                # lower levels are run again without it.
                known = failures(a.out, metric, case, kv, kxky)  # a resumed sweep does not repeat them
                top = min([a.levels] + [lvl - 1 for lvl in known])
                for levels in range(top, 0, -1):
                    cmd = ["nice", a.solver, "--accuracy", os.path.join(ROOT, "examples", "accuracy_%s.yaml" % case),
                           "-o", d, "--levels", str(levels), "--metric", metric, "--kv-kh", "%g" % kv,
                           "--kx-ky", "%g" % kxky]
                    t0 = time.time()
                    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
                    print("%s %s kv/kh=%g kx/ky=%g levels %d: exit %d, %.0f s" % (
                        metric, case, kv, kxky, levels, r.returncode, time.time() - t0), flush=True)
                    if r.returncode == 0:
                        break
                    os.makedirs(d, exist_ok=True)
                    with open(os.path.join(d, "failure.txt"), "a") as f:
                        f.write("level %d: %s\n" % (levels, r.stdout.strip().splitlines()[0] if r.stdout.strip() else "?"))
    lines = ["| case | kv/kh | kx/ky | level | K-orth rate | K-orth near-well | K-orth L2 | Euclidean rate | "
             "Euclidean near-well | Euclidean L2 | Peaceman rate | Peaceman near-well | Peaceman L2 | cells (K-orth / Eucl. / Cart.) |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    diag = ["| case | kv/kh | kx/ky | level | K-orth worst (region, side, distance) | Euclidean worst |",
            "|---|---|---|---|---|---|"]
    failed = []
    for case, kv, kxky in runs:
        je, jk = load(a.out, "euclidean", case, kv, kxky), load(a.out, "permeability", case, kv, kxky)
        fe, fk = failures(a.out, "euclidean", case, kv, kxky), failures(a.out, "permeability", case, kv, kxky)
        if kv == 1 and kxky == 1:
            jk, fk = je, fe  # identity frame: the same mesh
        for lvl, msg in sorted(fk.items()):
            failed.append("- %s, kv/kh %g, kx/ky %g, level %d, K-orthogonal: %s" % (case, kv, kxky, lvl, msg))
        for lvl, msg in sorted(fe.items()):
            failed.append("- %s, kv/kh %g, kx/ky %g, level %d, Euclidean: %s" % (case, kv, kxky, lvl, msg))
        if je is None and jk is None:
            continue
        nlev = max(len(j["refinement"]) for j in (je, jk) if j is not None)
        for i in range(nlev):
            le = je["refinement"][i] if je is not None and i < len(je["refinement"]) else None
            lk = jk["refinement"][i] if jk is not None and i < len(jk["refinement"]) else None
            ko = lk["hybrid"] if lk else None
            eu = le["hybrid"] if le else None
            pc = (le or lk)["cartesian_peaceman"]
            factor = (le or lk)["factor"]
            cells = "%s / %s / %d" % (lk["hybrid_cells"] if lk else "-", le["hybrid_cells"] if le else "-",
                                      (le or lk)["cartesian_cells"])
            lines.append("| %s | %g | %g | %d | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
                (case, kv, kxky, factor) + model_cells(ko) + model_cells(eu) + model_cells(pc) + (cells,)))
            diag.append("| %s | %g | %g | %d | %s | %s |" % (case, kv, kxky, factor, where(ko), where(eu)))
    text = "\n".join(lines) + "\n\n" + "\n".join(diag) + "\n"
    if failed:
        text += "\nMesh failures (no row or a '-' where they are):\n\n" + "\n".join(failed) + "\n"
    if a.cells:
        for case, kv, kxky in runs:
            f = os.path.join(run_dir(a.out, "permeability", case, kv, kxky), "cells.csv")
            if os.path.exists(f):
                text += "\n" + cell_table(f, "%s, kv/kh %g, kx/ky %g, level 1, K-orthogonal" % (case, kv, kxky))
    print(text)
    if a.markdown:
        open(a.markdown, "w").write(text)


if __name__ == "__main__":
    main()
