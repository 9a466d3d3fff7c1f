#!/usr/bin/env python3
"""scan's latin_hypercube mode: check_scan_lhs.py SCAN_SCRIPT SPREAD SCAN_FILE

1. The design: for 2 to 60 samples and linear and log ranges, every key's range cut into `samples` equal strata
   (equal in log for log spacing) holds exactly one member, inside the range; another seed gives another
   design; the same seed the same one.
2. The scan file (tests/scans/lhs.toml, 12 samples): `scan --dry-run` lists 12 members m000..m011, the same list
   twice, each with both swept keys set."""
import importlib.machinery
import importlib.util
import math
import subprocess
import sys


def load(path):
    loader = importlib.machinery.SourceFileLoader("dcm_scan", path)
    spec = importlib.util.spec_from_loader("dcm_scan", loader)
    module = importlib.util.module_from_spec(spec)
    loader.exec_module(module)
    return module


def main(argv):
    scan_script, spread, scan_file = argv[1:4]
    scan = load(scan_script)
    ranges = {"a": (2.0, 5.0, "linear"), "b": (1e-19, 1e-17, "log")}
    for samples in (2, 3, 7, 60):
        for seed in (1, 2):
            members = scan.latin_hypercube(ranges, samples, seed)
            if len(members) != samples:
                return f"{samples} samples: {len(members)} members"
            for key, (lo, hi, spacing) in ranges.items():
                f = (lambda v: math.log(v)) if spacing == "log" else (lambda v: v)
                strata = sorted(int((f(m[key]) - f(lo)) / (f(hi) - f(lo)) * samples) for m in members)
                if strata != list(range(samples)):
                    return f"{samples} samples, seed {seed}, key {key}: strata {strata}"
                if not all(lo <= m[key] <= hi for m in members):
                    return f"{samples} samples, key {key}: a value outside [{lo}, {hi}]"
        if samples > 2 and scan.latin_hypercube(ranges, samples, 1) == scan.latin_hypercube(ranges, samples, 2):
            return f"{samples} samples: seeds 1 and 2 give the same design"
        if scan.latin_hypercube(ranges, samples, 5) != scan.latin_hypercube(ranges, samples, 5):
            return f"{samples} samples: the same seed gives two designs"
    runs = [subprocess.run([sys.executable, scan_script, scan_file, "--dry-run", "--spread", spread],
                           capture_output=True, text=True) for _ in range(2)]
    for r in runs:
        if r.returncode != 0:
            return f"scan --dry-run failed: {r.stderr.strip()}"
    lines = runs[0].stdout.strip().splitlines()
    if runs[0].stdout != runs[1].stdout:
        return "two dry runs of the same file list different members"
    if [line.split()[0] for line in lines] != [f"m{i:03d}" for i in range(12)]:
        return f"expected members m000..m011, got {[line.split()[0] for line in lines]}"
    if not all("--set contact.W_J_per_m2=" in line and "--set cortex.k_b_J=" in line for line in lines):
        return "a member without both swept keys"
    print(f"ok: latin hypercube strata hold one member each (2..60 samples); {len(lines)} members from {scan_file}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
