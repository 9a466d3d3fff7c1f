#!/usr/bin/env python3
"""Checks deflate's 642-node result: Newton converged, the target reduced volume reached (the area is kept
by the area terms, the volume by the volume term), and the shape is biconcave (thinner at the centre than at
its thickest), as the paper's deflated start is.
usage: check_deflate.py OUT_DIR"""
import csv, json, sys

out = sys.argv[1]
s = json.load(open(out + "/summary.json"))
assert s["max_force_N"] <= 1e-16, s
assert abs(s["reduced_volume"] - s["volume_fraction_target"]) < 0.01, s
assert abs(s["area_over_sphere"] - 1) < 0.01, s
assert s["biconcave"] and s["thickness_centre_m"] < 0.5 * s["thickness_max_m"], s
rows = list(csv.DictReader(open(out + "/profile.csv")))
t = [float(r["thickness_m"]) for r in rows]
assert t[0] < max(t) and t[-1] < max(t), t  # a dimple in the middle and a rim that closes at the edge
assert sum(1 for _ in open(out + "/shape.csv")) == s["nodes"] + 1
print(f"reduced volume {s['reduced_volume']:.3f}, area {s['area_over_sphere']:.4f} of the sphere's, thickness "
      f"{s['thickness_centre_m'] * 1e6:.2f} um at the centre, {s['thickness_max_m'] * 1e6:.2f} um at the rim")
