#!/usr/bin/python3
"""Plot a stretch run against the optical-tweezers data (the paper's Figure 2a).

    /usr/bin/python3 scripts/plot_stretch.py OUT_DIR [--data ../shared/data/stretching]

Reads OUT_DIR/series.csv (F_N,DA_m,DT_m,...) and writes OUT_DIR/stretch.png: D_A and D_T against F
with Mills et al. 2004 (means and error bars) and Suresh et al. 2005.
"""
import argparse
import csv
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_csv(path):
    with open(path) as f:
        rows = [line for line in f if not line.startswith("#")]
    return list(csv.DictReader(rows))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out_dir")
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument("--data", default=os.path.join(here, "..", "..", "shared", "data", "stretching"))
    args = ap.parse_args()
    series = read_csv(os.path.join(args.out_dir, "series.csv"))
    f = [float(r["F_N"]) * 1e12 for r in series]
    da = [float(r["DA_m"]) * 1e6 for r in series]
    dt = [float(r["DT_m"]) * 1e6 for r in series]
    fig, ax = plt.subplots(figsize=(6, 4.5))
    mills = os.path.join(args.data, "mills2004.csv")
    if os.path.exists(mills):
        m = read_csv(mills)
        mf = [float(r["F_pN"]) for r in m]
        for key, lo, hi, color in (("DA_um", "DA_lo_um", "DA_hi_um", "C0"), ("DT_um", "DT_lo_um", "DT_hi_um", "C1")):
            y = [float(r[key]) for r in m]
            err = [[yy - float(r[lo]) for yy, r in zip(y, m)], [float(r[hi]) - yy for yy, r in zip(y, m)]]
            ax.errorbar(mf, y, yerr=err, fmt="o", color=color, mfc="none", capsize=3,
                        label=f"Mills 2004 {key[:2]}")
    else:
        print(f"plot_stretch.py: {mills} not found; the plot shows dcm's curves without Mills 2004 "
              "(pass --data DIR)", file=sys.stderr)
    suresh = os.path.join(args.data, "suresh2005.csv")
    if not os.path.exists(suresh):
        print(f"plot_stretch.py: {suresh} not found; the plot shows no Suresh 2005 points", file=sys.stderr)
    else:
        s = read_csv(suresh)
        ax.plot([float(r["F_pN"]) for r in s], [float(r["DA_um"]) for r in s], "s", color="C0", ms=4, alpha=0.5,
                label="Suresh 2005 DA")
        ax.plot([float(r["F_pN"]) for r in s], [float(r["DT_um"]) for r in s], "s", color="C1", ms=4, alpha=0.5,
                label="Suresh 2005 DT")
    ax.plot(f, da, "-", color="C0", lw=2, label="dcm D_A (axial)")
    ax.plot(f, dt, "-", color="C1", lw=2, label="dcm D_T (transverse)")
    ax.set_xlabel("stretching force F (pN)")
    ax.set_ylabel("diameter (µm)")
    summary_path = os.path.join(args.out_dir, "summary.json")
    nodes = json.load(open(summary_path)).get("nodes", "?") if os.path.exists(summary_path) else "?"
    ax.set_title(f"Optical-tweezers stretch of a red blood cell, {nodes} nodes")
    ax.legend(fontsize=8, ncol=2)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    out = os.path.join(args.out_dir, "stretch.png")
    fig.savefig(out, dpi=120)
    print(f"  wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
