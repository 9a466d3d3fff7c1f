#!/usr/bin/env python3
"""Two-thread speed-up per scene and node count, split by where the VM placed its two CPUs (markdown).

usage: speedup.py RUN.csv [RUN.csv ...] [--near-ns 250]

bench_step writes, on each two-thread row, the round trip of one cache line between the two OpenMP threads
(column thread_round_trip_ns). On a VM the host may move the virtual CPUs between dies from one minute to the
next: on session 23's 2-vCPU Zen 5 VM the round trip was 160-180 ns (same die) or 400-480 ns (two dies), and
a two-thread step at 10242 nodes took 10-15% longer on two dies (medians of the paired speed-ups
below). Mixing the two placements in one "fastest of
N runs" hides which one a number belongs to, so this script keeps them apart: for each scene and node count,
the fastest one-thread step over all runs, and the fastest two-thread step among the runs whose round trip was
below --near-ns ("near") and among the others ("far"), each with its speed-up and the number of runs behind it;
and, because the fastest of many one-thread runs against the fastest of few two-thread runs favours the one
thread, the median of the speed-ups paired within each run (one bench_step run times both thread counts a few
seconds apart).
"""
import csv
import statistics
import sys
from collections import defaultdict


def main():
    args = sys.argv[1:]
    if not args or any(a in ("-h", "--help") for a in args):
        print(__doc__)
        return 0 if args else 2
    near_ns = 250.0
    if "--near-ns" in args:
        i = args.index("--near-ns")
        near_ns = float(args[i + 1])
        del args[i:i + 2]
    one = defaultdict(list)  # (scene, nodes) -> one-thread µs per step, one per run
    two = defaultdict(lambda: {"near": [], "far": []})  # (scene, nodes) -> placement -> [(µs, round trip ns)]
    paired = defaultdict(lambda: {"near": [], "far": []})  # (scene, nodes) -> placement -> [1-thread / 2-thread]
    for path in args:
        in_run = {}  # (scene, nodes, threads) -> (µs, placement) of this run
        for r in csv.DictReader(open(path)):
            if r["kernel"] != "step" or r["space"] != "OpenMP":
                continue
            if "thread_round_trip_ns" not in r:
                sys.exit(f"speedup.py: {path} has no thread_round_trip_ns column (bench_step before session 23)")
            key = (r["scene"], int(r["nodes"]))
            us = float(r["us_per_step"])
            if int(r["threads"]) == 1:
                one[key].append(us)
                in_run[key + (1,)] = (us, None)
            elif int(r["threads"]) == 2:
                trip = float(r["thread_round_trip_ns"])
                placement = "near" if trip < near_ns else "far"
                two[key][placement].append((us, trip))
                in_run[key + (2,)] = (us, placement)
        for (scene, nodes, threads), (us, placement) in in_run.items():
            if threads == 2 and (scene, nodes, 1) in in_run:
                paired[(scene, nodes)][placement].append(in_run[(scene, nodes, 1)][0] / us)
    print(f"{len(args)} runs; two threads 'near' where the threads' cache-line round trip was below {near_ns:.0f} ns; "
          "µs per step, fastest run of each class (runs in the class, its round trip).")
    print()
    print("| scene | nodes | 1 thread | 2 threads near | speed-up near: fastest; paired median (min–max) | "
          "2 threads far | speed-up far: fastest; paired median (min–max) |")
    print("|---|---|---|---|---|---|---|")
    for key in sorted(set(one) | set(two)):
        base = min(one[key]) if one[key] else None
        cells = [f"{base:.0f} ({len(one[key])})" if base else ""]
        for placement in ("near", "far"):
            runs = two[key][placement]
            if not runs:
                cells += ["", ""]
                continue
            us, trip = min(runs)
            cells.append(f"{us:.0f} ({len(runs)}; {trip:.0f} ns)")
            ratios = paired[key][placement]
            pair = (f"; {statistics.median(ratios):.2f} ({min(ratios):.2f}–{max(ratios):.2f})" if ratios else "")
            cells.append(f"{base / us:.2f}{pair}" if base else "")
        print(f"| {key[0]} | {key[1]} | " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
