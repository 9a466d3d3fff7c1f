#!/usr/bin/env python3
"""The contact's onset at the steps' resolution (session 36), on a cell that gravity brings down onto the plane
inside the early window (it touches at ~0.04 s):
  check_onset.py drop CHECKPOINT   removes the onset tracker from a checkpoint, as one written before session 36
  check_onset.py check FULL OLD    FULL: the run as made; OLD: the same run continued from such a checkpoint
FULL's onset is found by the steps, after the rows' onset and before the first row with contact, and the early
exponent counted from it is the t^1/2 law's (0.5 within 0.01); OLD falls back on the rows' onset and says so."""
import json
import os
import sys

os.environ.setdefault("HDF5_USE_FILE_LOCKING", "FALSE")


def fail(msg):
    print("check_onset: " + msg)
    sys.exit(1)


def rows(d):
    t, r = [], []
    with open(os.path.join(d, "series.csv")) as f:
        head = f.readline().strip().split(",")
        it, ir = head.index("t_s"), head.index("r_cc_m")
        for line in f:
            v = line.split(",")
            t.append(float(v[it]))
            r.append(float(v[ir]))
    return t, r


def main():
    if sys.argv[1] == "drop":
        import h5py
        with h5py.File(sys.argv[2], "r+") as f:
            del f["arrays/app.contact_onset"]
        return 0
    full, old = (json.load(open(os.path.join(d, "summary.json"))) for d in sys.argv[2:4])
    t, r = rows(sys.argv[2])
    first = next(k for k in range(len(t)) if r[k] > 0)
    if any(x > 0 for x in r[first:]) and not all(x > 0 for x in r[first:]):
        fail("the contact came and went: not the case this test is made for")
    if not 0.01 < t[first] < 0.1:
        fail(f"the first contact at {t[first]} s is not inside the early window")
    onset = full["contact_onset_s"]
    # series.csv holds t with 9 digits, and since session 38 the onset may lie at the end of its step, a row's
    # time: the bounds hold to 1e-8 of the times
    if full["contact_onset_by"] != "steps" or not t[first - 1] * (1 - 1e-8) < onset <= t[first] * (1 + 1e-8):
        fail(f"onset {onset} by {full['contact_onset_by']}: not by the steps between the rows {t[first - 1]} "
             f"and {t[first]}")
    if not abs(full["early_exponent"] - 0.5) < 0.01:
        fail(f"early exponent {full['early_exponent']} from the onset, not the t^1/2 law's")
    if old["contact_onset_by"] != "rows" or abs(old["contact_onset_s"] - t[first - 1]) > 1e-8 * t[first - 1]:
        fail(f"the run continued from an older checkpoint: onset {old['contact_onset_s']} by "
             f"{old['contact_onset_by']}, not the rows' {t[first - 1]}")
    print(f"check_onset: onset {onset:.6g} s by the steps (rows: {t[first - 1]:.6g} .. {t[first]:.6g} s), "
          f"early exponent {full['early_exponent']:.4f} (from the rows' onset: {old['early_exponent']:.4f}; "
          f"the run's clock: {full['early_exponent_run_time']:.3f})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
