#!/usr/bin/env python3
"""Largest relative difference of r_cc(t) between spread runs and a reference run, on the reference's
rows (linear interpolation), as perf/work_precision.py measures it.

  python3 perf/compare_series.py REFERENCE_DIR RUN_DIR [RUN_DIR...] [--from-s 0.01,0.1]

REFERENCE_DIR and each RUN_DIR hold a spread series.csv. Prints, per run: the largest relative difference
over t >= each --from-s value, the time where it occurs, and the difference of the final r_cc.
"""
import argparse
import csv
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from work_precision import interpolate  # noqa: E402


def rows_of(d):
    path = os.path.join(d, "series.csv")
    if not os.path.exists(path):
        sys.exit(f"compare_series: {path}: no such file")
    with open(path) as f:
        return [(float(r["t_s"]), float(r["r_cc_m"])) for r in csv.DictReader(f)]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("reference")
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--from-s", default="0.01,0.1", help="comma-separated start times of the windows (s)")
    a = ap.parse_args()
    starts = [float(s) for s in a.from_s.split(",")]
    ref = rows_of(a.reference)
    print("run," + ",".join(f"max_rel_err_from_{s:g}s,at_t_s" for s in starts) + ",final_rel_diff")
    for d in a.runs:
        rows = rows_of(d)
        out = [d]
        for s in starts:
            grid = [(t, r) for t, r in ref if t >= s and r > 0]
            err, at = max((abs(interpolate(rows, t) - r) / r, t) for t, r in grid)
            out += [f"{err:.3e}", f"{at:.4g}"]
        out.append(f"{(rows[-1][1] - ref[-1][1]) / ref[-1][1]:.3e}")
        print(",".join(out))


if __name__ == "__main__":
    main()
