#!/usr/bin/env python3
"""Checks scripts/spread_slopes.py on a run folder of known law: r = sqrt(tau) until tau = 0.1 s and
r ∝ tau^(1/4) after it, tau the time since a contact onset of 2 ms. Each window's slope must be the law's to
the printed digits (it only is when time counts from the onset), r_cc at the edges the law's, and bad edges a
clear error.
check_spread_slopes.py SOURCE_DIR WORK_DIR"""
import json
import os
import subprocess
import sys


def law(tau):
    return 1e-6 * (tau ** 0.5 if tau <= 0.1 else 0.1 ** 0.5 * (tau / 0.1) ** 0.25)


def main(src, work):
    run = os.path.join(work, "slopes-run")
    os.makedirs(run, exist_ok=True)
    onset = 2e-3
    taus = [1e-3 * 10 ** (3 * k / 299) for k in range(300)] + [0.1, 0.3, 0.01, 0.03, 0.003]
    taus = sorted(set(taus))
    with open(os.path.join(run, "series.csv"), "w") as f:
        f.write("t_s,r_cc_m\n0,0\n" + "".join(f"{onset + tau!r},{law(tau)!r}\n" for tau in taus))
    with open(os.path.join(run, "summary.json"), "w") as f:
        json.dump({"contact_onset_s": onset, "early_exponent": 0.5}, f)
    script = os.path.join(src, "scripts", "spread_slopes.py")
    out = subprocess.run([sys.executable, script, run], capture_output=True, text=True)
    print(out.stdout, out.stderr)
    if out.returncode != 0:
        sys.exit(f"exit status {out.returncode}")
    head, row = [line.split(",") for line in out.stdout.strip().splitlines()]
    got = dict(zip(head, row))
    want = {"slope_0.003_0.01_s": 0.5, "slope_0.01_0.03_s": 0.5, "slope_0.03_0.1_s": 0.5, "slope_0.1_0.3_s": 0.25,
            "slope_0.3_1_s": 0.25, "r_cc_um_at_0.01_s": law(0.01) * 1e6, "r_cc_um_at_1_s": law(1.0) * 1e6}
    bad = [f"{k}: {got.get(k)} against {v:.3f}" for k, v in want.items()
           if k not in got or abs(float(got[k]) - v) > 1.5e-3]
    if bad:
        sys.exit("spread_slopes: " + "; ".join(bad))
    err = subprocess.run([sys.executable, script, run, "--edges-s", "0.1,0.05"], capture_output=True, text=True)
    if err.returncode == 0 or "--edges-s = '0.1,0.05': give two or more increasing times" not in err.stderr:
        sys.exit(f"decreasing edges: exit {err.returncode}, {err.stderr!r}")
    print("spread_slopes: every window's slope is the law's")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
