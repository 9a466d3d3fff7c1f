#!/usr/bin/env python3
"""Throughput of build/bin/scan for 1, 5 and 25 members at 642 and 2562 nodes (issue 7's table): each scan
is a one-parameter sweep of W (log-spaced 0.5–2 mJ/m²) around scenes/default.toml, 0.02 s at the paper's
fixed step, run with the default pool (members side by side, one thread each on 2 cores), or with --batch as
one batch (scan --chunk N --jobs 1: every member a cell of one model, all threads).
usage: perf/scan_rates.py [--out DIR] [--members 1,5,25] [--nodes 642,2562] [--batch]   (markdown table on stdout)"""
import argparse, csv, os, shutil, subprocess, time

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
ap.add_argument("--out", default=os.path.join("out", "scan_rates"))
ap.add_argument("--members", default="1,5,25")
ap.add_argument("--nodes", default="642,2562")
ap.add_argument("--batch", action="store_true", help="all members of a scan in one batch (scan --chunk N --jobs 1)")
a = ap.parse_args()
shutil.rmtree(a.out, ignore_errors=True)
os.makedirs(a.out)
print("| nodes | members | wall | cell-steps | cell-steps per second |\n|---|---|---|---|---|")
for nodes in [int(v) for v in a.nodes.split(",")]:
    for n in [int(v) for v in a.members.split(",")]:
        name = f"rate_{nodes}_{n}"
        path = os.path.join(a.out, name + ".toml")
        with open(path, "w") as f:
            f.write(f'name = "{name}"\nbase = "{root}/scenes/default.toml"\nmode = "grid"\n[set]\n'
                    f'"mesh.nodes" = {nodes}\n"time.t_end_s" = 0.02\n[sweep]\n'
                    f'"contact.W_J_per_m2" = {{start = 0.5e-3, stop = 2e-3, num = {n}, spacing = "log"}}\n')
        t0 = time.time()
        batch = ["--chunk", str(n), "--jobs", "1", "--threads", str(os.cpu_count() or 1)] if a.batch else []
        subprocess.run([os.path.join(root, "build", "bin", "scan"), path, "--out", os.path.join(a.out, name),
                        "--quiet", "--no-plot"] + batch, check=True)
        wall = time.time() - t0
        steps = sum(int(r["steps"]) for r in csv.DictReader(open(os.path.join(a.out, name, "summary.csv"))))
        print(f"| {nodes} | {n} | {wall:.1f} s | {steps} | {steps / wall:.0f} |", flush=True)
