#!/usr/bin/env python3
"""Issue 7's throughput check: the members of a scan run one after another by the single-run app (spread with
all cores, as a user would run them), against the same members run by build/bin/scan (members side by side,
cores/jobs threads each). Prints both wall times, their ratio and cells·steps per second.

usage: perf/scan_throughput.py [SCAN.toml] [--out DIR] [--jobs N]   (default scans/throughput25.toml, out/throughput)
"""
import argparse, importlib.util, json, os, shutil, subprocess, sys, time

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
spec = importlib.util.spec_from_file_location("scan", os.path.join(root, "apps", "scan", "scan.py"))
scan_mod = importlib.util.module_from_spec(spec)
spec.loader.exec_module(scan_mod)

ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
ap.add_argument("scan_file", nargs="?", default=os.path.join(root, "scans", "throughput25.toml"))
ap.add_argument("--out", default=os.path.join("out", "throughput"))
ap.add_argument("--jobs", type=int, default=0)
a = ap.parse_args()
scan = scan_mod.load_scan(a.scan_file)
spread = os.path.join(root, "build", "bin", "spread")
shutil.rmtree(a.out, ignore_errors=True)
os.makedirs(a.out)
env = dict(os.environ, OMP_PROC_BIND="false")
env.pop("OMP_NUM_THREADS", None)  # the single-run app with all cores
steps = 0
t0 = time.time()
for m in scan["members"]:
    d = os.path.join(a.out, "alone", m["id"])
    subprocess.run(scan_mod.spread_cmd(spread, scan, m, d, ["--quiet", "--no-plot"]), env=env, check=True)
    steps += json.load(open(os.path.join(d, "summary.json")))["steps"]
alone = time.time() - t0
t0 = time.time()
cmd = [os.path.join(root, "build", "bin", "scan"), a.scan_file, "--out", os.path.join(a.out, "scan"), "--quiet",
       "--no-plot"] + (["--jobs", str(a.jobs)] if a.jobs else [])
subprocess.run(cmd, env=env, check=True)
scanned = time.time() - t0
n = len(scan["members"])
print(f"{scan['name']}: {n} members, {steps} cell-steps in all, {os.cpu_count()} cores")
print(f"  one after another (spread, all cores): {alone:.1f} s, {steps / alone:.0f} cell-steps/s")
print(f"  scan (members side by side):           {scanned:.1f} s, {steps / scanned:.0f} cell-steps/s")
print(f"  ratio scan / one after another: {scanned / alone:.2f} (issue 7's target: <= 0.8)")
