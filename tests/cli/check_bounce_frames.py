#!/usr/bin/env python3
"""Checks bounce.h5 against the run's series: check_bounce_frames.py OUT_DIR FRAMES_PER_BOUNCE BOUNCES

bounce.h5 holds the perfect sphere and every triangulated ball (node_cell 0, 1, ...) in
FRAMES_PER_BOUNCE × BOUNCES + 1 frames; in every frame each object's centre (the mean of its icosphere nodes,
which is the centre by symmetry) minus R is the height of its lowest point in series.csv at that time (to 1e-3
of the drop height: series.csv's 2001 rows interpolated linearly miss up to a_max Δt²/8 of a contact phase's
curvature, 4e-7 m in the default 3-bounce run), the balls stay rigid (every node at distance R from the centre, 1e-9 relative), and the
XDMF companion references the file's frames. /series holds series.csv's columns."""
import csv
import os
import subprocess
import sys

os.environ.setdefault("HDF5_USE_FILE_LOCKING", "FALSE")
import h5py  # noqa: E402
import numpy  # noqa: E402


def main(argv):
    out, per_bounce, bounces = argv[1], int(argv[2]), int(argv[3])
    with open(os.path.join(out, "series.csv"), newline="") as f:
        rows = list(csv.reader(f))
    header, data = rows[0], numpy.array(rows[1:], dtype=float)
    with h5py.File(os.path.join(out, "bounce.h5"), "r") as h5:
        R, drop = float(h5["meta/radius_m"][()]), float(h5["meta/drop_height_m"][()])
        cell = h5["mesh/node_cell"][()]
        frames = sorted(h5["frames"].keys())
        if len(frames) != per_bounce * bounces + 1:
            print(f"{len(frames)} frames, expected {per_bounce * bounces + 1}")
            return 1
        for name in header:
            if name not in h5["series"] or len(h5["series"][name]) != len(data):
                print(f"/series/{name} missing or of the wrong length")
                return 1
        worst = 0.0
        for name in frames:
            g = h5["frames"][name]
            t, x = float(g.attrs["time"]), g["x"][()]
            for k in range(int(cell.max()) + 1):
                nodes = x[cell == k]
                centre = nodes.mean(axis=0)
                dist = numpy.linalg.norm(nodes - centre, axis=1)
                if numpy.abs(dist / R - 1).max() > 1e-9:
                    print(f"frame {name}, object {k}: not rigid (node distances {dist.min()}..{dist.max()} m)")
                    return 1
                h = numpy.interp(t, data[:, 0], data[:, 1 + k])
                worst = max(worst, abs(centre[2] - R - h))
        if worst > 1e-3 * drop:
            print(f"a frame's centre height differs from series.csv by {worst} m")
            return 1
    xdmf = subprocess.run([sys.executable, os.path.join(os.path.dirname(__file__), "..", "..", "scripts",
                                                        "check_xdmf.py"), os.path.join(out, "bounce.xmf")],
                          capture_output=True, text=True)
    if xdmf.returncode != 0:
        print(xdmf.stdout, xdmf.stderr)
        return 1
    print(f"ok: {len(frames)} frames of {int(cell.max()) + 1} objects agree with series.csv to {worst:.2e} m; "
          f"{xdmf.stdout.strip()}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
