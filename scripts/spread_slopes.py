#!/usr/bin/env python3
"""Local spreading exponents of spread runs: the least-squares slope of log r_cc against log (t − t_c) over
consecutive windows of the time since the contact's onset t_c (summary.json's contact_onset_s), from each run's
series.csv. One early exponent (spread's early_exponent, over 0.01–0.1 s) cannot tell a curve that slows down
through its window (the paper's crossover from t^1/2 to a slower law) from one that speeds up; these can.

  python3 scripts/spread_slopes.py OUT [OUT ...] [--edges-s 0.003,0.01,0.03,0.1,0.3,1]

Prints a CSV row per run: its folder, spread's early exponent, then the slope over each window [lo, hi) (empty
where a window holds fewer than three rows with contact), then r_cc (µm) at each edge, interpolated linearly in
the rows. A summary.json without contact_onset_s (a dcm before session 34) counts time from the run's start.
"""
import argparse
import csv
import json
import math
import os
import sys


def slope(points):
    """Least-squares slope of y against x; None with fewer than three points or one x."""
    n = len(points)
    if n < 3:
        return None
    sx = sum(p[0] for p in points)
    sy = sum(p[1] for p in points)
    sxx = sum(p[0] ** 2 for p in points)
    sxy = sum(p[0] * p[1] for p in points)
    d = n * sxx - sx * sx
    return None if not d > 1e-12 * n * sxx else (n * sxy - sx * sy) / d


def interpolate(t, r, at):
    """r at time `at` (linear between the rows around it); None outside the rows."""
    for k in range(1, len(t)):
        if t[k - 1] <= at <= t[k]:
            w = (at - t[k - 1]) / (t[k] - t[k - 1]) if t[k] > t[k - 1] else 0.0
            return r[k - 1] + w * (r[k] - r[k - 1])
    return None


def run_row(folder, edges):
    with open(os.path.join(folder, "series.csv")) as f:
        rows = list(csv.DictReader(f))
    with open(os.path.join(folder, "summary.json")) as f:
        summary = json.load(f)
    onset = summary.get("contact_onset_s") or 0.0
    t = [float(row["t_s"]) - onset for row in rows]
    r = [float(row["r_cc_m"]) for row in rows]
    slopes = []
    for k, (lo, hi) in enumerate(zip(edges[:-1], edges[1:])):
        last = k == len(edges) - 2  # windows [lo, hi): a row on an edge counts once; the last one includes hi
        pts = [(math.log(tk), math.log(rk)) for tk, rk in zip(t, r)
               if lo <= tk and (tk < hi or (last and tk == hi)) and tk > 0 and rk > 0]
        slopes.append(slope(pts))
    radii = [interpolate(t, r, e) for e in edges]
    return summary.get("early_exponent"), slopes, radii


def fmt(v, spec):
    return "" if v is None else format(v, spec)


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("runs", nargs="+", help="spread output folders (series.csv and summary.json)")
    ap.add_argument("--edges-s", default="0.003,0.01,0.03,0.1,0.3,1",
                    help="window edges in seconds since the contact's onset, increasing (default %(default)s)")
    a = ap.parse_args(argv)
    try:
        edges = [float(e) for e in a.edges_s.split(",")]
    except ValueError:
        sys.exit(f"spread_slopes: --edges-s = {a.edges_s!r}: give two or more numbers, e.g. 0.01,0.1")
    if len(edges) < 2 or any(not (e > 0) for e in edges) or any(b <= e for e, b in zip(edges, edges[1:])):
        sys.exit(f"spread_slopes: --edges-s = {a.edges_s!r}: give two or more increasing times above 0 s")
    names = [f"slope_{lo:g}_{hi:g}_s" for lo, hi in zip(edges[:-1], edges[1:])]
    print(",".join(["run", "early_exponent"] + names + [f"r_cc_um_at_{e:g}_s" for e in edges]))
    for folder in a.runs:
        try:
            early, slopes, radii = run_row(folder, edges)
        except (OSError, KeyError, ValueError, json.JSONDecodeError) as e:
            sys.exit(f"spread_slopes: {folder}: not a readable spread output ({e})")
        print(",".join([folder, fmt(early, ".3f")] + [fmt(s, ".3f") for s in slopes] +
                       [fmt(None if x is None else x * 1e6, ".3f") for x in radii]))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
