#!/usr/bin/env python3
"""Checks contact-probe's CSV against the run it probes: eq. 19 keeps each triangle's load (the three node
loads sum to it), the triangles' contact areas add up to the run's final contact area pi r_cc^2 (1%: one step apart), and
the output is plain CSV (header first, no comment line, no nan or -0).
usage: check_contact_probe.py PROBE.csv RUN_DIR"""
import csv, json, math, re, sys

probe, run = sys.argv[1], sys.argv[2]
lines = open(probe).read().splitlines()
assert lines and lines[0].startswith("triangle,"), f"stdout is not plain CSV: first line {lines[:1]}"
negative_zero = re.compile(r"-0(\.0*)?([eE][-+]?0+)?")
assert not any("nan" in line.lower() or any(negative_zero.fullmatch(f) for f in line.split(",")) for line in lines), \
    "nan or -0 in the CSV"
rows = list(csv.DictReader(lines))
assert rows, "no triangle in contact"
worst = 0.0
for r in rows:
    load = float(r["load_N"])
    f = [float(r[k]) for k in ("f0_N", "f1_N", "f2_N")]
    scale = max(abs(load), max(abs(v) for v in f), 1e-30)
    worst = max(worst, abs(sum(f) - load) / scale)
    assert int(r["regime"]) in (1, 2, 3, 4), r
    assert float(r["sphere_radius_m"]) > 0, r
assert worst < 1e-9, f"node loads do not add up to the triangle load: {worst:.2e}"
area = sum(float(r["contact_area_m2"]) for r in rows)
r_cc = json.load(open(run + "/summary.json"))["r_cc_final_m"]
# The run's r_cc comes from its last force evaluation, one Euler move before the checkpoint's positions.
assert abs(area - math.pi * r_cc**2) <= 1e-2 * area, (area, math.pi * r_cc**2)
print(f"{len(rows)} triangles in contact; eq. 19 sums to 1 in {worst:.1e}; contact area {area:.6e} m^2, pi r_cc^2 {math.pi * r_cc**2:.6e} m^2")
