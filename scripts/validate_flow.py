#!/usr/bin/python3
"""Reads an OPM Flow run of a HybridMesh deck back and prints it as JSON on stdout.

Usage: /usr/bin/python3 scripts/validate_flow.py OUTPUT_DIR NAME

OUTPUT_DIR is flow's --output-dir, NAME the deck name (NAME.DATA). Needs Debian's
python3-opm-common (hence /usr/bin/python3). Prints one JSON object:
  dims            [NX, NY, NZ] of the deck grid (EGRID)
  active          number of active cells
  report_steps    restart report steps found
  pressure        PRESSURE (bar) of the last report step, active-cell order
  wells           {NAME: {"WBHP", "WWPR", "WWIR"}} at the last summary time (sm3/day, bar)
  init            {"porv": global PORV (rm3), "poro", "depth", "tranx", "trany", "tranz": active order,
                   "trannnc": TRANNNC values, "nnc1", "nnc2": 1-based global indices (EGRID)}
Exit code 1 with a message on stderr when a file is missing or unreadable.
"""
import json
import os
import sys


def floats(array):
    return [float(v) for v in array]


def ints(array):
    return [int(v) for v in array]


def main(argv):
    if len(argv) != 3:
        sys.stderr.write("usage: validate_flow.py OUTPUT_DIR NAME\n")
        return 2
    out_dir, name = argv[1], argv[2]
    try:
        from opm.io.ecl import ERst, EclFile, ESmry
    except ImportError as e:  # wrong interpreter or package missing
        sys.stderr.write("validate_flow.py: cannot import opm.io.ecl (%s); run it with /usr/bin/python3\n" % e)
        return 1
    base = os.path.join(out_dir, name)
    for ext in (".UNRST", ".SMSPEC", ".INIT", ".EGRID"):
        if not os.path.isfile(base + ext):
            sys.stderr.write("validate_flow.py: missing %s\n" % (base + ext))
            return 1
    try:
        result = {}
        egrid = EclFile(base + ".EGRID")
        gridhead = egrid["GRIDHEAD"]
        result["dims"] = [int(gridhead[1]), int(gridhead[2]), int(gridhead[3])]
        actnum = egrid["ACTNUM"] if "ACTNUM" in [a[0] for a in egrid.arrays] else None
        result["active"] = int(sum(1 for a in actnum if a > 0)) if actnum is not None else \
            result["dims"][0] * result["dims"][1] * result["dims"][2]
        names = [a[0] for a in egrid.arrays]
        nnc1 = ints(egrid["NNC1"]) if "NNC1" in names else []
        nnc2 = ints(egrid["NNC2"]) if "NNC2" in names else []

        rst = ERst(base + ".UNRST")
        steps = list(rst.report_steps)
        result["report_steps"] = steps
        last = steps[-1]
        result["pressure"] = floats(rst["PRESSURE", last])

        smry = ESmry(base + ".SMSPEC")
        keys = list(smry.keys())
        wells = {}
        for key in keys:
            parts = key.split(":")
            if len(parts) == 2 and parts[0] in ("WBHP", "WWPR", "WWIR"):
                wells.setdefault(parts[1], {})[parts[0]] = float(smry[key][-1])
        result["wells"] = wells

        init = EclFile(base + ".INIT")
        init_names = [a[0] for a in init.arrays]
        res_init = {}
        for key, out_key in (("PORV", "porv"), ("PORO", "poro"), ("DEPTH", "depth"), ("TRANX", "tranx"),
                             ("TRANY", "trany"), ("TRANZ", "tranz"), ("TRANNNC", "trannnc")):
            res_init[out_key] = floats(init[key]) if key in init_names else []
        res_init["nnc1"] = nnc1
        res_init["nnc2"] = nnc2
        result["init"] = res_init
    except Exception as e:  # opm raises plain RuntimeError/ValueError on corrupt files
        sys.stderr.write("validate_flow.py: cannot read %s.*: %s\n" % (base, e))
        return 1
    json.dump(result, sys.stdout)
    sys.stdout.write("\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
