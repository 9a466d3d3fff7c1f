#!/usr/bin/env python3
"""Step cost against node count from several bench_step runs (markdown on stdout).

usage: scaling.py RUN.csv [RUN.csv ...] [--from 2562] [--to 40962]

On a shared 2-core VM a run's timings can be inflated by another guest for seconds at a time (the second
virtual CPU most of all), so one run does not measure the code. Noise on a timing only ever adds, so the
fastest of several runs taken at different times is the estimator used here; the column "spread" (slowest /
fastest whole step over the runs) shows how noisy the runs were. The diagonal scene (no CG) is the control:
its work is fixed, so its scaling and spread say how much to trust the others.

For each scene and thread count: the fastest whole step (µs, and ns per node) at every node count, and the
per-node ratio between --to and --from nodes (issue 6's target: within 1.3× of linear from 2562 to 40962).
"""
import csv, sys
from collections import defaultdict


def main():
    args = sys.argv[1:]
    if not args or any(a in ("-h", "--help") for a in args):
        print(__doc__)
        return 0 if args else 2
    lo, hi = 2562, 40962
    if "--from" in args:
        i = args.index("--from")
        lo = int(args[i + 1])
        del args[i:i + 2]
    if "--to" in args:
        i = args.index("--to")
        hi = int(args[i + 1])
        del args[i:i + 2]
    if not args:
        sys.exit(__doc__)
    steps = defaultdict(list)  # (scene, threads, nodes) -> [µs per step, one per run]
    cg = {}
    for path in args:
        for r in csv.DictReader(open(path)):
            if r["kernel"] != "step" or r["space"] != "OpenMP":
                continue
            key = (r["scene"], int(r["threads"]), int(r["nodes"]))
            steps[key].append(float(r["us_per_step"]))
            cg[key] = float(r["cg_iterations_per_step"])
    nodes = sorted({k[2] for k in steps})
    print(f"Fastest of {len(args)} runs ({', '.join(args)}); µs per step (ns per node), spread = slowest / fastest.")
    print()
    head = "| scene | threads | " + " | ".join(f"{n} nodes" for n in nodes) + f" | {hi} / {lo} per node |"
    print(head)
    print("|" + "---|" * (head.count("|") - 1))
    for scene, threads in sorted({(k[0], k[1]) for k in steps}, key=lambda s: (s[1], s[0])):
        cells, per_node = [], {}
        for n in nodes:
            runs = steps.get((scene, threads, n))
            if not runs:
                cells.append("")
                continue
            best = min(runs)
            per_node[n] = 1e3 * best / n
            cells.append(f"{best:.0f} ({per_node[n]:.0f}; CG {cg[(scene, threads, n)]:.2f}; "
                         f"spread {max(runs) / best:.2f})")
        ratio = f"{per_node[hi] / per_node[lo]:.2f}" if lo in per_node and hi in per_node else ""
        print(f"| {scene} | {threads} | " + " | ".join(cells) + f" | {ratio} |")


if __name__ == "__main__":
    sys.exit(main())
