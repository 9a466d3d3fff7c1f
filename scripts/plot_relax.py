#!/usr/bin/python3
"""Plot a relax run: D_A(t), D_T(t) and the Hochmuth relaxation fit (the paper's Figure 3, bottom).

    /usr/bin/python3 scripts/plot_relax.py OUT_DIR

Reads OUT_DIR/series.csv (t_s,DA_m,DT_m,...) and OUT_DIR/summary.json (lambda_inf, relaxation_time_s) and
writes OUT_DIR/relax.png: left, the diameters against time; right, y(t) = (λ − λ∞)/(λ + λ∞), λ = D_A/D_T, on a
log axis with the fitted y0 exp(−t/t_c) (fitted where y > 5% of y0, as apps/relax does) and the paper's
0.1–0.3 s range of relaxation times as dotted guides.
"""
import argparse
import csv
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out_dir")
    args = ap.parse_args()
    with open(os.path.join(args.out_dir, "series.csv")) as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    with open(os.path.join(args.out_dir, "summary.json")) as f:
        summary = json.load(f)
    t = [float(r["t_s"]) for r in rows]
    da = [float(r["DA_m"]) * 1e6 for r in rows]
    dt = [float(r["DT_m"]) * 1e6 for r in rows]
    lam_inf = float(summary["lambda_inf"])
    tc = float(summary["relaxation_time_s"])
    y = [(a / b - lam_inf) / (a / b + lam_inf) for a, b in zip(da, dt)]
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    left.plot(t, da, color="C0", label="D_A (axial)")
    left.plot(t, dt, color="C1", label="D_T (transverse)")
    left.set_xlabel("time after release (s)")
    left.set_ylabel("diameter (µm)")
    left.legend()
    left.grid(alpha=0.3)
    keep = [(ti, yi) for ti, yi in zip(t, y) if yi > 0]
    right.semilogy([k[0] for k in keep], [k[1] for k in keep], "o", ms=3, color="C2",
                   label="(λ − λ∞)/(λ + λ∞)")
    if y and y[0] > 0 and math.isfinite(tc) and tc > 0:
        y0, t_end = y[0], max(t)
        right.semilogy([0, t_end], [y0, y0 * math.exp(-t_end / tc)], "-", color="k",
                       label=f"fit: t_c = {tc:.3g} s")
        for guide in (0.1, 0.3):
            right.semilogy([0, t_end], [y0, y0 * math.exp(-t_end / guide)], ":", color="gray")
        right.axhline(0.05 * y0, color="gray", lw=0.5)
        right.text(0.02 * t_end, 0.055 * y0, "fit floor (5% of start)", fontsize=7, color="gray")
        right.set_ylim(0.8 * min(min(k[1] for k in keep), 0.05 * y0), 1.2 * y0)
    right.set_xlabel("time after release (s)")
    right.set_ylabel("(λ − λ∞)/(λ + λ∞), λ = D_A/D_T")
    right.set_title("dotted: t_c = 0.1 and 0.3 s (paper's range)", fontsize=8)
    right.legend(fontsize=8)
    right.grid(alpha=0.3, which="both")
    fig.suptitle(f"Relaxation, {summary.get('nodes', '?')} nodes")
    fig.tight_layout()
    out = os.path.join(args.out_dir, "relax.png")
    fig.savefig(out, dpi=120)
    print(f"  wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
