#!/usr/bin/env python3
"""The contact angle of every frame of a spread run, as CSV on stdout: t_s,contact_angle_deg,
contact_angle_free_deg,cap_radius_m,cap_radius_free_m,height_m.

    python3 scripts/spread_angles.py OUT_DIR > angles.csv

spread's summary.json holds the angles of the last frame only; this fits every frame of OUT_DIR/spread.h5 the
same way (apps/spread/spread_fits.hpp; docs/model/spread.md "Contact angle"): a sphere fitted by algebraic least
squares, |x|² = 2 c·x + d, to
  contact_angle_deg       the nodes with z at or above the floor(0.05 (N - 1))-th lowest z (the paper's top 95%),
  contact_angle_free_deg  the nodes with z ≥ z_plane + 0.1 (z_max − z_plane) (the free membrane),
and θ = 180° − acos(h_c / R) with h_c the centre's height above the plane (contact.plane_z_m of the run's
scene): the interior angle, 180° for a sphere just touching. The last row equals summary.json's angles.
Needs numpy and h5py. Exit codes: 0 success, 2 bad input (no such folder or no frames).
"""
import argparse
import math
import os
import sys
import tomllib


def fit_cap(x, plane_z, free):
    import numpy as np
    z = x[:, 2]
    srt = np.sort(z)
    cut = plane_z + 0.1 * (srt[-1] - plane_z) if free else srt[int(0.05 * (len(z) - 1))]
    p = x[z >= cut]
    if len(p) < 4:
        return math.nan, math.nan
    a = np.column_stack([2 * p, np.ones(len(p))])
    b = (p ** 2).sum(axis=1)
    s = np.linalg.lstsq(a, b, rcond=None)[0]
    radius = math.sqrt(s[3] + s[0] ** 2 + s[1] ** 2 + s[2] ** 2)
    hc = s[2] - plane_z
    return 180.0 - math.degrees(math.acos(max(-1.0, min(1.0, hc / radius)))), radius


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("out_dir", help="a spread output folder (with spread.h5)")
    a = ap.parse_args()
    path = os.path.join(a.out_dir, "spread.h5")
    if not os.path.isfile(path):
        print(f"spread_angles.py: error: {path}: no such file (a spread run's folder, with output.hdf5 = true)",
              file=sys.stderr)
        return 2
    import h5py
    import numpy as np
    with h5py.File(path, "r") as f:
        text = f.attrs.get("scene", "")
        text = text.decode() if isinstance(text, bytes) else text
        plane_z = float(tomllib.loads(text).get("contact", {}).get("plane_z_m", 0.0)) if text else 0.0
        names = sorted(f["frames"]) if "frames" in f else []
        if not names:
            print(f"spread_angles.py: error: {path} has no frames", file=sys.stderr)
            return 2
        print("t_s,contact_angle_deg,contact_angle_free_deg,cap_radius_m,cap_radius_free_m,height_m")
        for name in names:
            g = f["frames"][name]
            x = np.asarray(g["x"])
            top, r_top = fit_cap(x, plane_z, False)
            free, r_free = fit_cap(x, plane_z, True)
            print(f"{float(g.attrs['time']):.12g},{top:.12g},{free:.12g},{r_top:.12g},{r_free:.12g},"
                  f"{x[:, 2].max() - plane_z:.12g}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
