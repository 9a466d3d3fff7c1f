#!/usr/bin/env python3
"""Checks that a spread run restarted with denser output follows the new cadence from the restart on:
check_restart_cadence.py DIR T_RESTART_S PER_DECADE FRAME_EVERY_S DT_S

DIR's series.csv must have a row no later than one new log interval (plus one step) after T_RESTART_S and
then rows at most one new interval apart; spread.h5 must have a frame no later than FRAME_EVERY_S (plus one
step) after T_RESTART_S and frames at most FRAME_EVERY_S (plus one step) apart after it. Before session 30 a
restart kept the next row and frame times the old cadence had set (its next frame could be past the end)."""
import csv
import os
import sys

os.environ.setdefault("HDF5_USE_FILE_LOCKING", "FALSE")
import h5py  # noqa: E402


def fail(msg):
    print("check_restart_cadence: " + msg)
    sys.exit(1)


def main():
    out = sys.argv[1]
    t0, per_decade, frame_every, dt = (float(a) for a in sys.argv[2:6])
    ratio = 10.0 ** (1.0 / per_decade)
    ts = [float(r["t_s"]) for r in csv.DictReader(open(os.path.join(out, "series.csv")))]
    after = [t for t in ts if t > t0 * (1 + 1e-12)]
    if not after:
        fail(f"no series row after the restart at {t0} s")
    prev = t0
    for t in after:
        if t > prev * ratio + dt * (1 + 1e-9):
            fail(f"series rows {prev} and {t} s are further apart than {per_decade:g} per decade allow "
                 f"(at most {prev * ratio + dt} s)")
        prev = t
    with h5py.File(os.path.join(out, "spread.h5"), "r") as f:
        times = sorted(float(g.attrs["time"]) for g in f["frames"].values())
    fa = [t for t in times if t > t0 * (1 + 1e-12)]
    prev = t0
    for t in fa:
        if t > prev + frame_every + dt * (1 + 1e-9):
            fail(f"frames at {prev} and {t} s are further apart than output.frame_every_s = {frame_every} s")
        prev = t
    if len(fa) < 2:
        fail(f"{len(fa)} frames after the restart at {t0} s; every {frame_every} s asks for more")
    print(f"check_restart_cadence: {len(after)} rows and {len(fa)} frames after the restart at {t0} s, "
          f"each within the new cadence ({per_decade:g} rows per decade, a frame every {frame_every} s)")


if __name__ == "__main__":
    main()
