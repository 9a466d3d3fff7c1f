#!/usr/bin/env python3
"""Checks a bounce summary: check_bounce.py SUMMARY.json [HALVED_DT.json]

The keys the task names are there and consistent (one list of rebound heights per mesh, as many as the
reference's), the rebound heights are within 1e-3 of the perfect sphere's; with a second summary (the same
run with the time step halved), rebound heights, contact times and maximum overlaps agree to 1e-3."""
import json
import sys


def main(argv):
    s = json.load(open(argv[1]))
    for key in ("nodes", "rebound_heights_m", "reference_rebound_heights_m"):
        if key not in s:
            print(f"{argv[1]}: no key {key}")
            return 1
    ref = s["reference_rebound_heights_m"]
    if len(s["rebound_heights_m"]) != len(s["nodes"]) or not ref:
        print("one list of rebound heights per mesh expected")
        return 1
    for n, hs in zip(s["nodes"], s["rebound_heights_m"]):
        if len(hs) != len(ref):
            print(f"{n} nodes: {len(hs)} rebound heights, the reference has {len(ref)}")
            return 1
        for b, (h, r) in enumerate(zip(hs, ref)):
            if not abs(h / r - 1) < 1e-3:
                print(f"{n} nodes, bounce {b + 1}: rebound height {h} vs perfect sphere {r}")
                return 1
    if len(argv) > 2:
        t = json.load(open(argv[2]))
        for key in ("rebound_heights_m", "contact_time_s", "max_overlap_m"):
            a = [x for row in s[key] for x in (row if isinstance(row, list) else [row])]
            b = [x for row in t[key] for x in (row if isinstance(row, list) else [row])]
            for x, y in zip(a, b):
                if not abs(x - y) <= 1e-3 * max(abs(x), abs(y)):
                    print(f"{key}: {x} (dt) vs {y} (dt/2) differ by more than 0.1%")
                    return 1
    print("ok:", ", ".join(f"{n} nodes {hs}" for n, hs in zip(s["nodes"], s["rebound_heights_m"])), "reference", ref)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
