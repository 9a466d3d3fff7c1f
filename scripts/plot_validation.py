#!/usr/bin/env python3
"""The spreading validation's curves side by side, one PNG per setting (paper Figure 4/5 style).

usage: plot_validation.py [--quiet] [DIR]     (default out/validation)

Reads the runs that scripts/spread_validation.sh writes into DIR (each a spread output folder: summary.json and
series.csv) and writes, for each setting that scripts/spread_report.py judges (the paper's model, dcm's
contact-line setting, the crease experiment; prefixes "", cl_, clc_):

  <prefix>curves.png   r_cc against the time since the contact's onset, log-log, in six panels:
                       (a) 642 against 2562 nodes (the mesh claim: similar early dynamics, different final radii;
                       the runs continued to 2.4 s where they exist), (b) biconcave against sphered (642 nodes),
                       (c)-(f) the Figure 5 directions against the reference: W × 2, γ_n / 2, k_b × 2, x_max 2.5
                       and the k_a run; every panel with a t^(1/2) guide
  <prefix>cuvelier.png the Cuvelier set's r_cc with its early and late fits (summary.json early_exponent and
                       late_exponent)

A panel whose runs are missing says so; a setting none of whose runs exist is left out. Exit status 0, or 2 if
DIR does not exist.
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import spread_report  # noqa: E402  (the runs' names per setting and the loader)
from plot_spread import draw_fit  # noqa: E402  (the fitted power law, as r_cc.png draws it)


def curve(run):
    """(t − onset, r_cc in µm) of a finished run's rows with contact, or None."""
    if not isinstance(run, tuple):
        return None
    summary, (t, r) = run
    onset = summary.get("contact_onset_s") or 0.0
    t_run = np.asarray(t)
    t, r = t_run - onset, np.asarray(r) * 1e6
    keep = (t > 1e-7 * (t_run.max() if len(t_run) else 0.0)) & (r > 0)  # not the onset's own 9-digit rounding
    return (t[keep], r[keep]) if keep.any() else None


def panel(ax, title, lines):
    """lines: (label, run, style); missing runs are named in the panel."""
    shown, absent = [], []
    for label, run, style in lines:
        c = curve(run)
        if c is None:
            absent.append(label)
            continue
        ax.loglog(c[0], c[1], style, lw=1.4, label=label)
        shown.append(c)
    if shown:
        t0 = min(c[0][0] for c in shown)
        t1 = max(c[0][-1] for c in shown)
        ref = shown[0]
        i = len(ref[0]) // 4
        tt = np.array([max(t0, 1e-4), t1])
        ax.loglog(tt, ref[1][i] * (tt / ref[0][i]) ** 0.5, "k--", lw=0.7, label=r"$\propto t^{1/2}$")
        top = max(c[1].max() for c in shown)
        ax.set_ylim(bottom=max(min(c[1].min() for c in shown), 1e-2 * top) / 1.5, top=top * 1.5)
    if absent:
        ax.text(0.03, 0.03, "not run: " + ", ".join(absent), transform=ax.transAxes, fontsize=7, color="C3")
    ax.set_title(title, fontsize=9)
    ax.set_xlabel("t − t_c (s)", fontsize=8)
    ax.set_ylabel(r"$r_{cc}$ (µm)", fontsize=8)
    ax.grid(True, which="both", lw=0.3)
    ax.tick_params(labelsize=7)
    if shown:
        ax.legend(fontsize=7)


def plot_setting(folder, setting, prefix):
    names = setting["runs"]
    runs = {role: spread_report.load(folder, name) for role, name in names.items()}
    if all(v is None for v in runs.values()):
        return []

    def longest(role, continued):  # a run continued to 2.4 s holds the whole curve
        return runs[continued] if isinstance(runs.get(continued), tuple) else runs[role]

    fig, axes = plt.subplots(2, 3, figsize=(13, 8))
    ref = runs["fig5_reference"]
    panel(axes[0, 0], "(a) mesh: 642 against 2562 nodes",
          [("2562 nodes", longest("hategan2004_sphered", "at_rest"), "C0-"),
           ("642 nodes", longest("hategan2004_sphered_642", "at_rest_642"), "C1-")])
    panel(axes[0, 1], "(b) biconcave against sphered, 642 nodes",
          [("sphered", runs["hategan2004_sphered_642"], "C0-"),
           ("biconcave", runs["hategan2004_biconcave_642"], "C3-")])
    for ax, (role, label) in zip(axes.flat[2:], [("fig5_W_x2", "W × 2"), ("fig5_gamma_n_half", "γ_n / 2"),
                                                 ("fig5_k_b_x2", "k_b × 2"), ("fig5_x_max_2.5", "x_max 2.5")]):
        panel(ax, f"Figure 5: {label}", [("reference", ref, "C0-"), (label, runs[role], "C3-")])
    # the k_a run shares the x_max panel's row: drawn into (f) beside x_max as a third line
    c = curve(runs["fig5_k_a"])
    if c is not None:
        axes[1, 2].loglog(c[0], c[1], "C2:", lw=1.4, label=names["fig5_k_a"].replace(prefix + "fig5_", ""))
        axes[1, 2].legend(fontsize=7)
        axes[1, 2].set_title("Figure 5: x_max 2.5; the k_a run (no effect)", fontsize=9)
    fig.suptitle(setting["title"], fontsize=9)
    fig.tight_layout()
    out = []
    path = os.path.join(folder, prefix + "curves.png")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    out.append(path)

    cuv = runs["cuvelier2007"]
    c = curve(cuv)
    if c is not None:
        s = cuv[0]
        fig, ax = plt.subplots(figsize=(5.5, 4.2))
        panel(ax, f"Cuvelier set ({names['cuvelier2007']})", [("r_cc", cuv, "C0-")])
        for key, window, color in (("early_exponent", s.get("early_window_s"), "C3"),
                                   ("late_exponent", s.get("late_window_s"), "C1")):
            slope = s.get(key)
            if slope is None or not window or None in window:
                continue
            m = (c[0] >= window[0]) & (c[0] <= window[1])
            draw_fit(ax, c[0], c[1], m, color, f"{window[0]:g}–{window[1]:.3g} s: slope {slope:.2f}")
        ax.legend(fontsize=7)
        fig.tight_layout()
        path = os.path.join(folder, prefix + "cuvelier.png")
        fig.savefig(path, dpi=120)
        plt.close(fig)
        out.append(path)
    return out


def main(argv):
    args = argv[1:]
    if args and args[0] in ("-h", "--help"):
        print(__doc__.strip())
        return 0
    quiet = "--quiet" in args
    args = [a for a in args if a != "--quiet"]
    if len(args) > 1:
        print("usage: plot_validation.py [--quiet] [DIR]", file=sys.stderr)
        return 2
    folder = args[0] if args else "out/validation"
    if not os.path.isdir(folder):
        print(f"plot_validation: {folder} is not a folder (make it with bash scripts/spread_validation.sh)",
              file=sys.stderr)
        return 2
    prefixes = ["", "cl_", "clc_"]
    written = []
    for prefix, setting in zip(prefixes, spread_report.SETTINGS):
        written += plot_setting(folder, setting, prefix)
    if not quiet:
        for path in written:
            print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
