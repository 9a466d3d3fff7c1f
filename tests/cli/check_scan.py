#!/usr/bin/env python3
"""Checks a finished scans/quick.toml run: every member done and in summary.csv and scan.h5, the paper's
Figure 5 direction for W (higher W spreads wider), r_cc_grid.png written, and member m002 (W = 2e-3)
equal to the same scene run alone by spread (series.csv byte for byte: same settings, same backend).
usage: check_scan.py SCAN_OUT ALONE_OUT"""
import csv, json, os, sys

import h5py

out, alone = sys.argv[1], sys.argv[2]
rows = {r["id"]: r for r in csv.DictReader(open(os.path.join(out, "summary.csv")))}
assert sorted(rows) == ["m000", "m001", "m002", "m003"], sorted(rows)
for r in rows.values():
    assert r["status"] == "done", r
    assert float(r["r_cc_final_m"]) > 0, r
r = {k: float(v["r_cc_final_m"]) for k, v in rows.items()}
assert r["m001"] < r["m000"] < r["m002"], ("higher W must spread wider", r)
assert float(rows["m001"]["contact.W_J_per_m2"]) == 0.5e-3 and rows["m000"]["contact.W_J_per_m2"] == ""
with h5py.File(os.path.join(out, "scan.h5"), "r") as f:
    for mid in rows:
        g = f["members"][mid]
        assert "series" in g and "final_frame" in g, mid
        assert abs(g.attrs["r_cc_final_m"] - r[mid]) <= 1e-15 * r[mid], mid
        assert g["final_frame"]["x"].shape == (162, 3), mid
        tri = g["final_frame"]["triangles"][()]
        assert tri.shape == (320, 3) and tri.min() == 0 and tri.max() == 161, (mid, tri.shape)
assert os.path.getsize(os.path.join(out, "r_cc_grid.png")) > 10000
# The plot's legend gives the base member's value of each swept key, read from its resolved scene.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "apps", "scan"))
import scan_plot  # noqa: E402
assert scan_plot.base_value(out, "m000", "contact.W_J_per_m2") == 1e-3
assert scan_plot.base_value(out, "m000", "cortex.k_b_J") == 240e-21
assert scan_plot.base_value(out, "m000", "no.such_key") is None
a = open(os.path.join(out, "members", "m002", "series.csv")).read()
b = open(os.path.join(alone, "series.csv")).read()
assert a == b, "member m002 differs from the same scene run alone"
print(f"4 members done; r_cc {r['m001']:.3e} < {r['m000']:.3e} < {r['m002']:.3e} m (W 0.5, 1, 2 mJ/m^2); "
      "m002 = the run alone, byte for byte")
