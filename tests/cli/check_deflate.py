#!/usr/bin/env python3
"""Checks deflate's 642-node result: Newton converged, the target reduced volume reached (the area is kept
by the area terms, the volume by the volume term), and the shape is biconcave (thinner at the centre than at
its thickest), as the paper's deflated start is; deflate.h5 holds the mesh and two frames (start, equilibrium),
the last one the positions of shape.csv.
usage: check_deflate.py OUT_DIR"""
import csv, json, os, sys

os.environ.setdefault("HDF5_USE_FILE_LOCKING", "FALSE")
import h5py  # noqa: E402

out = sys.argv[1]
s = json.load(open(out + "/summary.json"))
assert s["max_force_N"] <= 1e-16, s
assert abs(s["reduced_volume"] - s["volume_fraction_target"]) < 0.01, s
assert abs(s["area_over_sphere"] - 1) < 0.01, s
assert s["biconcave"] and s["thickness_centre_m"] < 0.5 * s["thickness_max_m"], s
rows = list(csv.DictReader(open(out + "/profile.csv")))
t = [float(r["thickness_m"]) for r in rows]
assert t[0] < max(t) and t[-1] < max(t), t  # a dimple in the middle and a rim that closes at the edge
shape = [[float(v) for v in r.values()] for r in csv.DictReader(open(out + "/shape.csv"))]
assert len(shape) == s["nodes"]
with h5py.File(out + "/deflate.h5", "r") as h5:
    frames = sorted(h5["frames"])
    assert len(frames) == 2, frames
    assert h5["mesh"]["triangles"].shape == (2 * s["nodes"] - 4, 3)
    x = h5["frames"][frames[-1]]["x"][:]
    assert x.shape == (s["nodes"], 3)
    assert max(abs(a - b) for row, ref in zip(x, shape) for a, b in zip(row, ref)) < 1e-15, "frame 1 != shape.csv"
# The profile is the surface's extent along vertical lines (averaged over 16 directions off the axis),
# recomputed here from the mesh's triangles: not the z-range of the nodes in a ring, which reads high at the rim.
import numpy as np  # noqa: E402
with h5py.File(out + "/deflate.h5", "r") as h5:
    tri = h5["mesh"]["triangles"][:]
    x = h5["frames"][sorted(h5["frames"])[-1]]["x"][:]
c = x.mean(axis=0)
A, B, C = x[tri[:, 0]], x[tri[:, 1]], x[tri[:, 2]]
det = (B[:, 0] - A[:, 0]) * (C[:, 1] - A[:, 1]) - (C[:, 0] - A[:, 0]) * (B[:, 1] - A[:, 1])


def thickness(px, py):
    with np.errstate(divide="ignore", invalid="ignore"):
        u = ((px - A[:, 0]) * (C[:, 1] - A[:, 1]) - (C[:, 0] - A[:, 0]) * (py - A[:, 1])) / det
        v = ((B[:, 0] - A[:, 0]) * (py - A[:, 1]) - (px - A[:, 0]) * (B[:, 1] - A[:, 1])) / det
    inside = (det != 0) & (u >= 0) & (v >= 0) & (u + v <= 1)
    z = (A[:, 2] + u * (B[:, 2] - A[:, 2]) + v * (C[:, 2] - A[:, 2]))[inside]
    return z.max() - z.min() if len(z) >= 2 else None


for r in rows:
    rho = float(r["rho_m"])
    ts = [thickness(c[0] + rho * np.cos(p), c[1] + rho * np.sin(p))
          for p in ([0.0] if rho == 0 else 2 * np.pi * (np.arange(16) + 0.5) / 16)]
    ts = [t for t in ts if t is not None]
    assert abs(np.mean(ts) - float(r["thickness_m"])) < 1e-12, (rho, np.mean(ts), r["thickness_m"])
assert abs(t[0] - s["thickness_centre_m"]) < 1e-14 and abs(max(t) - s["thickness_max_m"]) < 1e-14, s  # 9 digits
print(f"reduced volume {s['reduced_volume']:.3f}, area {s['area_over_sphere']:.4f} of the sphere's, thickness "
      f"{s['thickness_centre_m'] * 1e6:.2f} um at the centre, {s['thickness_max_m'] * 1e6:.2f} um at the rim")
