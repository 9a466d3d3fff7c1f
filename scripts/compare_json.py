#!/usr/bin/env python3
"""Compare the numbers of two flat JSON summaries: compare_json.py A.json B.json [REL_TOL] [--ignore KEY,...]

Exits 1 naming the first key whose values differ by more than REL_TOL (relative; default 1e-12)."""
import json
import sys


def main(argv):
    if any(a in ("-h", "--help") for a in argv[1:]):
        print(__doc__.strip())
        return 0
    args = [a for a in argv[1:] if not a.startswith("--ignore")]
    if len(args) not in (2, 3):
        sys.exit("usage: compare_json.py A.json B.json [REL_TOL] [--ignore=KEY,...]")
    ignore = set()
    for a in argv[1:]:
        if a.startswith("--ignore="):
            ignore |= set(a.split("=", 1)[1].split(","))
    a, b = (json.load(open(p)) for p in args[:2])
    tol = float(args[2]) if len(args) > 2 else 1e-12
    checked = 0
    for key in sorted(set(a) | set(b)):
        if key in ignore:
            continue
        if key not in a or key not in b:
            print(f"key {key} only in one file")
            return 1
        va, vb = a[key], b[key]
        if isinstance(va, (int, float)) and isinstance(vb, (int, float)):
            if abs(va - vb) > tol * max(abs(va), abs(vb)):
                print(f"{key}: {va!r} vs {vb!r} (relative difference above {tol})")
                return 1
            checked += 1
        elif va != vb:
            print(f"{key}: {va!r} vs {vb!r}")
            return 1
    print(f"{checked} numbers agree to {tol}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
