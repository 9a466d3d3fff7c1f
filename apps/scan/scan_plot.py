#!/usr/bin/env python3
"""Draws <scan out>/r_cc_grid.png: one panel per swept key (the paper's Figure 5 layout), r_cc(t) of its
members on log-log axes with a t^(1/2) guide; one_at_a_time scans add the base member in black.
usage: scan_plot.py OUT_DIR"""
import csv, json, math, os, sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def series(out, mid):
    t, r = [], []
    try:
        with open(os.path.join(out, "members", mid, "series.csv")) as f:
            for row in csv.DictReader(f):
                ti, ri = float(row["t_s"]), float(row["r_cc_m"])
                if ti > 0 and ri > 0:
                    t.append(ti)
                    r.append(ri * 1e6)
    except OSError:
        pass
    return t, r


def main():
    out = sys.argv[1]
    scan = json.load(open(os.path.join(out, "scan.json")))
    keys = scan["sweep_keys"]
    n = len(keys)
    cols = min(3, n)
    rows = math.ceil(n / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.4 * rows), squeeze=False)
    base = next((m for m in scan["members"] if not m["swept"]), None)
    for i, key in enumerate(keys):
        ax = axes[i // cols][i % cols]
        members = [m for m in scan["members"] if key in m["swept"]]
        cmap = plt.get_cmap("viridis")
        for j, m in enumerate(members):
            t, r = series(out, m["id"])
            if t:
                label = f"{m['swept'][key]:.3g}" if isinstance(m["swept"][key], float) else str(m["swept"][key])
                ax.loglog(t, r, color=cmap(j / max(1, len(members) - 1)), lw=1.3, label=label)
        if base:
            t, r = series(out, base["id"])
            if t:
                ax.loglog(t, r, color="k", lw=1.0, ls="--", label="base")
        all_t = [v for m in members for v in series(out, m["id"])[0]]
        if all_t:
            t0, t1 = min(all_t), max(all_t)
            ts = [t0 * (t1 / t0) ** (k / 20) for k in range(21)]
            ax.loglog(ts, [1.0 * (tt / 0.1) ** 0.5 for tt in ts], color="0.6", lw=0.8, ls=":", label="t^1/2")
        all_r = [v for m in members for v in series(out, m["id"])[1]]
        if all_r:  # the first touch-down (r_cc of nanometres) would squash the curves
            ax.set_ylim(bottom=max(min(all_r), 0.03 * max(all_r)), top=1.3 * max(all_r))
        ax.set_title(key, fontsize=9)
        ax.set_xlabel("t (s)")
        ax.set_ylabel("r_cc (µm)")
        ax.legend(fontsize=7)
    for i in range(n, rows * cols):
        axes[i // cols][i % cols].axis("off")
    fig.suptitle(f"scan {scan['name']} ({scan['mode']})", fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "r_cc_grid.png"), dpi=110)


if __name__ == "__main__":
    main()
