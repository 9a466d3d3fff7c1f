#!/usr/bin/env python3
"""Checks that a restarted spread run equals an uninterrupted one: check_restart.py FULL_DIR RESTARTED_DIR
(with --independent: that two runs of the same scene, e.g. on 1 and on 2 threads, are the same)

series.csv byte for byte; the HDF5 /series columns, the frame times and every frame dataset bit for bit;
summary.json in every key but the wall time and the run's provenance (restarted_from, checkpoint)."""
import json
import os
import sys

os.environ.setdefault("HDF5_USE_FILE_LOCKING", "FALSE")
import h5py  # noqa: E402
import numpy as np  # noqa: E402

IGNORED = {"wall_s", "restarted_from", "checkpoint"}


def fail(msg):
    print("check_restart: " + msg)
    sys.exit(1)


def main():
    full, restarted = sys.argv[1], sys.argv[2]
    independent = "--independent" in sys.argv[3:]
    a = open(os.path.join(full, "series.csv"), "rb").read()
    b = open(os.path.join(restarted, "series.csv"), "rb").read()
    if a != b:
        fail(f"series.csv differs ({len(a)} against {len(b)} bytes)")
    sa = json.load(open(os.path.join(full, "summary.json")))
    sb = json.load(open(os.path.join(restarted, "summary.json")))
    if not independent and not sb.get("restarted_from"):
        fail("the second run was not restarted (summary.json restarted_from is empty)")
    for k in sorted(set(sa) | set(sb)):
        if k not in IGNORED and sa.get(k) != sb.get(k):
            fail(f"summary.json {k}: {sa.get(k)} against {sb.get(k)}")
    with h5py.File(os.path.join(full, "spread.h5"), "r") as fa, \
            h5py.File(os.path.join(restarted, "spread.h5"), "r") as fb:
        for k in fa["series"]:
            if not np.array_equal(fa["series"][k][()], fb["series"][k][()]):
                fail(f"/series/{k} differs")
        if list(fa["frames"]) != list(fb["frames"]):
            fail(f"frames {list(fa['frames'])} against {list(fb['frames'])}")
        for f in fa["frames"]:
            ga, gb = fa["frames"][f], fb["frames"][f]
            if ga.attrs["time"] != gb.attrs["time"] or sorted(ga) != sorted(gb):
                fail(f"frame {f}: time or fields differ")
            for d in ga:
                if not np.array_equal(ga[d][()], gb[d][()]):
                    fail(f"frame {f}/{d} differs")
    rows = a.count(b"\n") - 1
    print(f"check_restart: {restarted} equals {full}: {rows} series rows, {sa['steps']} steps, "
          f"{len(sb)} summary keys, r_cc_final_m {sa.get('r_cc_final_m')}")


if __name__ == "__main__":
    main()
