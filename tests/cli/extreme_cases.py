#!/usr/bin/env python3
"""The stiff and extreme cases of issue 8, run with apps/spread on a small cell.

extreme_cases.py SPREAD OUT_DIR [--nodes N] [--t-end S] [--only NAME,...]

Each case changes the scene of the default spreading run (scenes/default.toml physics, Table 1) in one way.
The run must either finish with finite output (exit 0; the table reports r_cc, the contact angle, steps and
what the step control did), or stop with exit code 3 and one line naming the step, the term, the node or
bond, and a remedy. Anything else fails: another exit code, a non-finite number in series.csv or
summary.json, a run past its time limit (a hang). Writes OUT_DIR/extreme_cases.md and .csv."""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import time

# name, what the paper's setting becomes, extra --set arguments, extra command-line arguments
CASES = [
    ("reference", "Table 1 (default scene physics)", [], []),
    ("E_x100", "cortex E × 100 (contact law)", ["cortex.E_Pa=80e6"], []),
    ("W_x100", "W × 100", ["contact.W_J_per_m2=0.1"], []),
    ("W_x0.01", "W × 0.01", ["contact.W_J_per_m2=1e-5"], []),
    ("h0_1nm", "h₀ = 1 nm", ["contact.h0_m=1e-9", "contact.start_gap_m=0.5e-9"], []),
    ("x_max_1.05", "x_max = 1.05", ["cortex.x_max=1.05"], []),
    ("k_b_x100", "k_b × 100", ["cortex.k_b_J=240e-19"], []),
    ("k_a_k_d_x100", "k_a and k_d × 100", ["cortex.k_a=0.6", "cortex.k_d=0.6"], []),
    ("dt_x10", "Δt × 10 (60 µs, fixed steps)", ["time.dt_s=60e-6"], []),
    ("dropped_1um", "dropped from 1 µm (gravity on)",
     ["contact.start_gap_m=1e-6", "body.gravity_m_per_s2=9.81", "time.t_end_s=1", "time.adaptive=true",
      "solver.cg_abs_tol_N=1e-20"], []),
    ("pressed_50nm", "pressed 50 nm into the plane (initial overlap)", ["contact.start_gap_m=-50e-9"], []),
    ("biconcave_flat_face", "biconcave cell landing on its flat face", ["mesh.shape=evans_fung"], []),
    ("nodes_40962", "40962 nodes (5 steps)", ["mesh.nodes=40962"], ["--max-steps", "5"]),
]


def finite_outputs(out):
    bad = []
    path = os.path.join(out, "series.csv")
    if os.path.exists(path):
        with open(path) as f:
            for row in csv.DictReader(f):
                for k, v in row.items():
                    if not math.isfinite(float(v)):
                        bad.append(f"series.csv {k} = {v} at t = {row['t_s']}")
                        break
    path = os.path.join(out, "summary.json")
    if os.path.exists(path):
        text = open(path).read()
        for word in ("NaN", "nan", "Infinity", "inf"):
            if word in text.replace("interrupted", ""):
                bad.append(f"summary.json contains {word}")
    return bad


def run_case(a, out, sets, extra):
    """Runs spread once; returns the table row (exit, wall_s, outcome, detail) and the problems found."""
    cmd = [a.spread, "--no-plot", "--quiet", "--out", out]
    for s in sets:
        cmd += ["--set", s]
    cmd += extra
    t0 = time.time()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=a.timeout)
        code, err = p.returncode, p.stderr.strip()
    except subprocess.TimeoutExpired:
        code, err = None, f"no result after {a.timeout:.0f} s"
    row = {"exit": code, "wall_s": round(time.time() - t0, 1), "outcome": "", "detail": ""}
    problems = finite_outputs(out)
    if code == 0:
        s = json.load(open(os.path.join(out, "summary.json")))
        row["outcome"] = "ran"
        row["detail"] = (f"t = {s['t_end_s']:.3g} s, r_cc = {s['r_cc_final_m'] * 1e6:.3f} µm, "
                         f"angle {s['contact_angle_deg']:.0f}°, {s['steps']} steps "
                         f"(halved {s['halved_steps']}, rejected {s['rejected_steps']}, "
                         f"Δt {s['dt_min_taken_s']:.2g}–{s['dt_max_taken_s']:.2g} s), "
                         f"mean CG {s['mean_cg_iterations']:.1f}, energy residual "
                         f"{s['energy_residual_relative']:.1e}")
    elif code == 3:
        row["outcome"] = "stopped (exit 3)"
        row["detail"] = err.replace("spread: numerical failure: ", "")
        lines = err.splitlines()
        if len(lines) != 1:
            problems.append(f"{len(lines)} lines on stderr")
        if "step" not in err or not any(w in err for w in ("node", "bond", "cell", "triangle")):
            problems.append("the message does not name the step and the node, bond or cell")
        if "try" not in err:
            problems.append("the message suggests no remedy")
    else:
        row["outcome"] = "FAILED"
        row["detail"] = err.splitlines()[-1] if err else ""
        problems.append(f"exit code {code}")
    return row, problems


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("spread")
    ap.add_argument("out")
    ap.add_argument("--nodes", type=int, default=162)
    ap.add_argument("--t-end", type=float, default=0.02)
    ap.add_argument("--timeout", type=float, default=600)
    ap.add_argument("--only", default="")
    a = ap.parse_args()
    only = set(a.only.split(",")) if a.only else None
    os.makedirs(a.out, exist_ok=True)
    rows, failures = [], []
    for name, what, sets, extra in CASES:
        if only and name not in only:
            continue
        base = [f"mesh.nodes={a.nodes}", f"time.t_end_s={a.t_end}", "output.checkpoint_every_s=0"]
        row, problems = run_case(a, os.path.join(a.out, name), base + sets, extra)
        row = {"case": name, "change": what, **row}
        if row["exit"] == 3 and "time.adaptive=true" not in sets:
            # The remedy the message suggests: error-controlled steps.
            remedy, more = run_case(a, os.path.join(a.out, name + "_adaptive"),
                                    base + sets + ["time.adaptive=true"], extra)
            row["outcome"] += "; adaptive: " + remedy["outcome"]
            row["detail"] += " || with time.adaptive = true: " + remedy["detail"]
            row["wall_s"] = round(row["wall_s"] + remedy["wall_s"], 1)
            problems += ["adaptive: " + p for p in more]
        if problems:
            failures.append(f"{name}: " + "; ".join(problems))
            row["outcome"] += " — " + "; ".join(problems)
        rows.append(row)
        print(f"{name:22s} {row['outcome']:18s} {row['wall_s']:7.1f} s  {row['detail']}", flush=True)
    with open(os.path.join(a.out, "extreme_cases.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    with open(os.path.join(a.out, "extreme_cases.md"), "w") as f:
        f.write(f"Spreading, {a.nodes} nodes, t_end = {a.t_end} s; command: "
                f"tests/cli/extreme_cases.py {a.spread} {a.out} --nodes {a.nodes} --t-end {a.t_end}\n\n")
        f.write("| case | change | outcome | result or message | wall |\n|---|---|---|---|---|\n")
        for r in rows:
            f.write(f"| {r['case']} | {r['change']} | {r['outcome']} | {r['detail']} | {r['wall_s']} s |\n")
    if failures:
        print("extreme cases FAILED:\n  " + "\n  ".join(failures))
        sys.exit(1)
    print(f"extreme cases: {len(rows)} cases, each ran or stopped cleanly")


if __name__ == "__main__":
    main()
