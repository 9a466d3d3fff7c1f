#!/usr/bin/env python3
"""compare_scans.py A B: two scan outputs hold the same results. Every dataset and attribute of A/scan.h5 equals
B/scan.h5's, bit for bit (wall times excepted), and summary.csv agrees in every column but wall_s. Exit 1 on the
first difference, naming it."""
import csv, sys

import h5py
import numpy as np

TIMING = {"wall_s"}


def items(path):
    out = {}

    def visit(name, obj):
        for k, v in obj.attrs.items():
            if k not in TIMING:
                out[f"{name}@{k}"] = v
        if isinstance(obj, h5py.Dataset):
            out[name] = obj[()]
    with h5py.File(path, "r") as f:
        for k, v in f.attrs.items():
            out[f"@{k}"] = v
        f.visititems(visit)
    return out


def same(x, y):
    x, y = np.asarray(x), np.asarray(y)
    if x.shape != y.shape or x.dtype != y.dtype:
        return False
    if x.dtype.kind == "f":
        return np.array_equal(x, y, equal_nan=True)
    return np.array_equal(x, y)


a, b = sys.argv[1], sys.argv[2]
ia, ib = items(a + "/scan.h5"), items(b + "/scan.h5")
if sorted(ia) != sorted(ib):
    print("scan.h5: different contents:", sorted(set(ia) ^ set(ib))[:10])
    sys.exit(1)
for k in ia:
    if not same(ia[k], ib[k]):
        print(f"scan.h5: {k} differs")
        sys.exit(1)
ra = list(csv.DictReader(open(a + "/summary.csv")))
rb = list(csv.DictReader(open(b + "/summary.csv")))
if len(ra) != len(rb) or not ra:
    print(f"summary.csv: {len(ra)} rows against {len(rb)}")
    sys.exit(1)
for x, y in zip(ra, rb):
    for k in x:
        if k not in TIMING and x[k] != y.get(k):
            print(f"summary.csv: member {x['id']} {k}: {x[k]} against {y.get(k)}")
            sys.exit(1)
    if x["status"] != "done":
        print(f"member {x['id']}: status {x['status']}")
        sys.exit(1)
print(f"same results: {len(ia)} datasets and attributes of scan.h5, {len(ra)} members of summary.csv "
      f"(r_cc_final_m {', '.join(r['r_cc_final_m'] for r in ra)})")
