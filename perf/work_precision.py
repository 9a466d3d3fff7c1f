#!/usr/bin/env python3
"""Error against run time for apps/spread (issue 6, "Error against run time").

Runs one scene with a list of settings (fixed steps of 1x, 2x, 4x, ... the paper's dt, adaptive tolerances,
quadrature orders, CG tolerances), each against a tight reference run of the same mesh (fixed steps of a
quarter of the paper's dt), and reports the largest relative error of r_cc(t) over t >= --from-s, against
the wall time. Writes <out>/work_precision.csv and <out>/work_precision.png.

  python3 perf/work_precision.py [--scene scenes/hategan2004_sphered.toml] [--set mesh.nodes=642]
                                 [--t-end 0.3] [--out out/work_precision] [--threads 1]
"""
import argparse
import csv
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def run(spread, scene, sets, out, threads, t_end, per_decade):
    args = [spread, scene, "--quiet", "--no-plot", "--out", out, "--set", f"time.t_end_s={t_end}",
            "--set", f"output.series_per_decade={per_decade}"]
    for s in sets:
        args += ["--set", s]
    env = dict(os.environ, OMP_NUM_THREADS=str(threads))
    if not os.path.exists(os.path.join(out, "summary.json")):
        r = subprocess.run(args, env=env, capture_output=True, text=True)
        if r.returncode != 0:  # a setting the scene cannot run with: reported in the table, not fatal
            return None, (r.stderr.strip().splitlines() or [f"exit {r.returncode}"])[-1]
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    with open(os.path.join(out, "series.csv")) as f:
        rows = [(float(r["t_s"]), float(r["r_cc_m"])) for r in csv.DictReader(f)]
    return summary, rows


def interpolate(rows, t):
    lo, hi = 0, len(rows) - 1
    if t <= rows[0][0]:
        return rows[0][1]
    if t >= rows[-1][0]:
        return rows[-1][1]
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if rows[mid][0] <= t:
            lo = mid
        else:
            hi = mid
    (t0, r0), (t1, r1) = rows[lo], rows[hi]
    return r0 + (r1 - r0) * (t - t0) / (t1 - t0)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scene", default=os.path.join(ROOT, "scenes/hategan2004_sphered.toml"))
    ap.add_argument("--set", action="append", default=[], help="scene override for every run")
    ap.add_argument("--t-end", type=float, default=0.3)
    ap.add_argument("--from-s", type=float, default=0.01, help="errors over t >= this (s)")
    ap.add_argument("--late-from-s", type=float, default=0.1,
                    help="a second error over t >= this (s): after the early touch-down events")
    ap.add_argument("--dt", type=float, default=6e-6, help="the paper's dt of the scene (s)")
    ap.add_argument("--out", default=os.path.join(ROOT, "out/work_precision"))
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--spread", default=os.path.join(ROOT, "build/bin/spread"))
    ap.add_argument("--per-decade", type=int, default=400, help="series rows per decade of time")
    ap.add_argument("--reference-factor", type=float, default=0.25,
                    help="the reference run's fixed dt as a multiple of --dt (default 1/4; 1: the paper-settings run)")
    ap.add_argument("--only", default="", help="comma-separated run names to do (default: all; reference is always run)")
    ap.add_argument("--variants-adaptive", default="",
                    help="run the quadrature and CG-tolerance cases with adaptive steps at this tolerance (m) "
                         "instead of the paper's fixed dt (long scenes)")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    dt = a.dt
    cases = [("reference", "fixed", [f"time.dt_s={dt * a.reference_factor}"])]
    for m in (1, 2, 4, 8, 16):
        cases.append((f"fixed_dt_x{m}", "fixed dt", [f"time.dt_s={dt * m}"]))
    for tol in ("1e-8", "3e-9", "1e-9"):
        cases.append((f"adaptive_{tol}", "adaptive", ["time.adaptive=true", f"time.error_tol_m={tol}",
                                                       f"time.dt_s={dt}"]))
    if a.variants_adaptive:
        base, how = ["time.adaptive=true", f"time.error_tol_m={a.variants_adaptive}", f"time.dt_s={dt}"], \
            f"adaptive {a.variants_adaptive}"
    else:
        base, how = [f"time.dt_s={dt}"], "paper dt"
    for q in (1, 3, 7, 16):
        cases.append((f"quadrature_{q}", f"quadrature ({how})", [f"contact.quadrature_points={q}"] + base))
    for tol in ("1e-12", "1e-10"):
        cases.append((f"cg_abs_tol_{tol}", f"CG tolerance ({how})", [f"solver.cg_abs_tol_N={tol}"] + base))
    if a.only:
        keep = set(a.only.split(",")) | {"reference"}
        unknown = keep - {c[0] for c in cases}
        if unknown:
            sys.exit(f"work_precision: --only: unknown run '{sorted(unknown)[0]}' (runs: {', '.join(c[0] for c in cases)})")
        cases = [c for c in cases if c[0] in keep]
    results, failed = {}, {}
    for name, family, sets in cases:
        print(f"== {name}: {' '.join(sets)}", flush=True)
        summary, rows = run(a.spread, a.scene, a.set + sets, os.path.join(a.out, name), a.threads, a.t_end,
                            a.per_decade)
        if summary is None:
            print(f"   failed: {rows}", flush=True)
            failed[name] = (family, sets, rows)
            continue
        results[name] = (family, sets, summary, rows)
    ref_rows = results["reference"][3]
    def max_error(rows, start):
        grid = [t for t, r in ref_rows if t >= start and r > 0]
        return max(abs(interpolate(rows, t) - interpolate(ref_rows, t)) / interpolate(ref_rows, t) for t in grid)

    table = []
    for name, (family, sets, summary, rows) in results.items():
        err = max_error(rows, a.from_s)
        late = max_error(rows, a.late_from_s)
        final_err = abs(rows[-1][1] - ref_rows[-1][1]) / ref_rows[-1][1]
        table.append(dict(run=name, family=family, settings=" ".join(sets), steps=summary["steps"],
                          wall_s=summary["wall_s"], mean_cg=summary["mean_cg_iterations"],
                          max_rel_error_r_cc=err, max_rel_error_r_cc_late=late, final_rel_error_r_cc=final_err,
                          r_cc_final_m=rows[-1][1]))
    with open(os.path.join(a.out, "work_precision.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(table[0].keys()))
        w.writeheader()
        w.writerows(table)
    print("| run | settings | steps | wall (s) | mean CG | max rel. error of r_cc, t >= %g s | t >= %g s | at the end |"
          % (a.from_s, a.late_from_s))
    print("|---|---|---|---|---|---|---|---|")
    for r in table:
        print(f"| {r['run']} | `{r['settings']}` | {r['steps']} | {r['wall_s']:.1f} | {r['mean_cg']:.1f} | "
              f"{r['max_rel_error_r_cc']:.2e} | {r['max_rel_error_r_cc_late']:.2e} | {r['final_rel_error_r_cc']:.2e} |")
    for name, (family, sets, message) in failed.items():
        print(f"| {name} | `{' '.join(sets)}` | stopped | | | {message} | | |")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("work_precision: matplotlib missing, no PNG", file=sys.stderr)
        return
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.6))
    markers = {"fixed dt": "o-", "adaptive": "s-", "quadrature": "^", "CG tolerance": "v"}
    for ax, key, start in ((axes[0], "max_rel_error_r_cc", a.from_s), (axes[1], "max_rel_error_r_cc_late", a.late_from_s)):
        for family, style in markers.items():
            pts = [(r["wall_s"], max(r[key], 1e-6), r["run"]) for r in table if r["family"].split(" (")[0] == family]
            if not pts:
                continue
            label = next(r["family"] for r in table if r["family"].split(" (")[0] == family)
            ax.plot([p[0] for p in pts], [p[1] for p in pts], style, label=label)
            for x, y, n in pts:
                ax.annotate(n.replace("fixed_dt_", "").replace("adaptive_", "").replace("quadrature_", "q")
                            .replace("cg_abs_tol_", "cg "), (x, y), fontsize=7, textcoords="offset points",
                            xytext=(3, 3))
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("wall time (s)")
        ax.set_ylabel(f"max relative error of r_cc(t), t >= {start} s")
        ax.set_title(f"{os.path.basename(a.scene)} {' '.join(a.set)}, t_end = {a.t_end} s", fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "work_precision.png"), dpi=120)
    print(f"wrote {a.out}/work_precision.csv, work_precision.png")


if __name__ == "__main__":
    main()
