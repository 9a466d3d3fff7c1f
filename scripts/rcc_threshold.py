#!/usr/bin/env python3
"""r_cc(t) of a spread run measured at a separation threshold of your choice, from its HDF5 frames.

spread's own r_cc comes from its contact law's contact area (for contact.law = "derjaguin": the part of the
plane-facing triangles below h0/sqrt(3)), so two runs with different ranges h0 measure contact at different
heights. This script measures every frame the same way: the area of the plane-facing triangles' projection
where the separation (linear over each triangle) is below --gap-m, and r_cc = sqrt(area / pi); then the
least-squares slope of log r_cc against log t over --window-s. Frames every output.frame_every_s; use a
small one (e.g. 0.002 s) for the early window.

  python3 scripts/rcc_threshold.py out/RUN/spread.h5 --gap-m 11.547e-9 [--window-s 0.01,0.1] [--plane-z-m 0]
"""
import argparse
import sys

import h5py
import numpy as np


def fraction_below(h, gap):
    """Fraction of each triangle's area where the linear field with corner values h (n x 3) is below gap."""
    h = np.sort(h, axis=1)
    h1, h2, h3 = h[:, 0], h[:, 1], h[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        low = (gap - h1) ** 2 / ((h2 - h1) * (h3 - h1))
        high = 1 - (h3 - gap) ** 2 / ((h3 - h1) * (h3 - h2))
    f = np.where(gap <= h1, 0.0, np.where(gap <= h2, low, np.where(gap < h3, high, 1.0)))
    return np.nan_to_num(f, nan=1.0)  # degenerate (equal corners) below gap: whole triangle


def rcc_series(path, gap, plane_z=0.0):
    with h5py.File(path, "r") as f:
        tri = f["mesh/triangles"][:]
        ts, rs = [], []
        for name in sorted(f["frames"].keys()):
            frame = f["frames"][name]
            p = frame["x"][:][tri]
            n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
            facing = n[:, 2] < 0
            area = np.sum(0.5 * np.abs(n[:, 2]) * facing * fraction_below(p[:, :, 2] - plane_z, gap))
            ts.append(frame.attrs["time"])
            rs.append(np.sqrt(area / np.pi))
    return np.array(ts), np.array(rs)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("h5", help="a spread run's spread.h5")
    ap.add_argument("--gap-m", type=float, required=True, help="separation threshold (m), > 0")
    ap.add_argument("--window-s", default="0.01,0.1", help="fit window t0,t1 (s); default 0.01,0.1")
    ap.add_argument("--plane-z-m", type=float, default=0.0, help="height of the plane (m); default 0")
    a = ap.parse_args()
    if not a.gap_m > 0:
        sys.exit(f"rcc_threshold.py: --gap-m = {a.gap_m} must be > 0")
    try:
        t0, t1 = (float(v) for v in a.window_s.split(","))
    except ValueError:
        sys.exit(f"rcc_threshold.py: --window-s = {a.window_s} must be two times t0,t1 (s)")
    ts, rs = rcc_series(a.h5, a.gap_m, a.plane_z_m)
    m = (ts >= t0 * (1 - 1e-9)) & (ts <= t1 * (1 + 1e-9)) & (rs > 0)
    if m.sum() < 3:
        sys.exit(f"rcc_threshold.py: {m.sum()} frames with contact in [{t0}, {t1}] s; need 3 (output.frame_every_s)")
    slope = np.polyfit(np.log(ts[m]), np.log(rs[m]), 1)[0]
    at = " / ".join(f"{np.interp(q, ts, rs) * 1e6:.3f}" for q in (t0, 0.5 * (t0 + t1), t1, ts[-1]))
    print(f"gap {a.gap_m:g} m: exponent {slope:.3f} over [{t0:g}, {t1:g}] s ({m.sum()} frames); "
          f"r_cc at {t0:g} / {0.5 * (t0 + t1):g} / {t1:g} / {ts[-1]:g} s = {at} um")


if __name__ == "__main__":
    main()
