#!/usr/bin/env python3
"""Plots of a spread run (apps/spread): r_cc.png, cells.png, side_views.png in the run's folder.

    python3 scripts/plot_spread.py [--quiet] OUT_DIR

r_cc.png    contact radius against time on log-log axes with a t^(1/2) guide, the fitted early slope and the
            slope from the early window's end to the run's end
            (paper Figure 4 style), and a dotted line where the last node came down when the contact grew by
            more than a mesh edge after it (stretching of the bound membrane)
cells.png   the cell at the frames nearest t = 0.1, 0.35, 0.9 s, coloured by the normal force per node
            (top, seen from below the plane, where the contact is) and the cortex tension of eq. 1 (bottom,
            seen from above) (paper Figure 6 style); a run that ends before 0.9 s shows the frames nearest
            the same fractions of its own end time (end × 0.1/0.9, 0.35/0.9, 1), each frame once and not the
            start (t = 0) unless it is the only frame; the
            colours span the 98th percentile of |value| and the colour bar's arrows say that values beyond it
            are drawn in its end colours
side_views.png  side views (x-z) of the cell at the frames nearest t = 0, 0.1, 0.35, 0.9 s and the end
            (paper Figure 1 style)
cells.png and side_views.png need the frames of spread.h5: a run with output.hdf5 = false gets r_cc.png only.
"""
import csv
import json
import os
import sys
import tomllib

os.environ.setdefault("HDF5_USE_FILE_LOCKING", "FALSE")
import h5py  # noqa: E402
import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def read_series(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def frames(h5):
    out = []
    for name in sorted(h5["frames"].keys()):
        g = h5["frames"][name]
        out.append((float(g.attrs["time"]) if "time" in g.attrs else float(name), g))
    return out


def nearest(frame_list, t):
    return min(frame_list, key=lambda f: abs(f[0] - t))


def draw_fit(ax, t, r, mask, color, label):
    """The least-squares power law through (t, r) over mask, drawn on log-log axes (nothing under two points)."""
    if mask.sum() < 2:
        return
    c = np.polyfit(np.log(t[mask]), np.log(r[mask]), 1)
    ax.loglog(t[mask], np.exp(np.polyval(c, np.log(t[mask]))), color + "-", lw=2.5, alpha=0.6, label=label)


def plot_rcc(out, s, summary):
    # Time counts from the contact's onset (summary.json contact_onset_s, as the early exponent does; 0 for a cell
    # placed in contact): a cell that needs a while to touch down (the Cuvelier set) shows its power law straight.
    onset = summary.get("contact_onset_s") or 0.0
    t, r = s["t_s"] - onset, s["r_cc_m"]
    # rows within the 9-digit rounding of the onset (the first sliver of contact can be the onset's own state,
    # since session 38) would stretch the log axis over ten decades: kept from 1e-7 of the run's length on
    keep = (t > 1e-7 * (s["t_s"].max() if len(s["t_s"]) else 0.0)) & (r > 0)
    fig, ax = plt.subplots(figsize=(5.5, 4.2))
    ax.loglog(t[keep], r[keep] * 1e6, "-", color="C0", label="dcm: r_cc(t)")
    if keep.any():
        t0, r0 = t[keep][len(t[keep]) // 4], r[keep][len(t[keep]) // 4] * 1e6
        tt = np.array([t[keep][0], t[keep][-1]])
        ax.loglog(tt, r0 * (tt / t0) ** 0.5, "k--", lw=0.8, label=r"$\propto t^{1/2}$")
        # the first contact can be a sliver of a triangle (1e-9 µm): keep three decades below the largest r_cc
        ax.set_ylim(bottom=max(r[keep].min(), 1e-3 * r[keep].max()) * 1e6 / 1.5)
    alpha = summary.get("early_exponent")
    w = summary.get("early_window_s", [])
    if alpha is not None and np.isfinite(alpha) and len(w) == 2:
        m = keep & (t >= w[0]) & (t <= w[1])  # the window counts from the onset too (since session 36)
        cut = summary.get("early_window_cut_at_s")  # the run ended inside the window
        end = f"{cut:.3g} s (run's end; window to {w[1]:g})" if cut is not None else f"{w[1]:g} s"
        draw_fit(ax, t, r * 1e6, m, "C3", f"fit over t - t_c = {w[0]:g}-{end}: slope {alpha:.2f}")
    # The later regime (since session 38): the slope from the early window's end to the run's end.
    late, lw = summary.get("late_exponent"), summary.get("late_window_s") or []
    if late is not None and np.isfinite(late) and len(lw) == 2 and None not in lw:
        m = keep & (t >= lw[0]) & (t <= lw[1])
        draw_fit(ax, t, r * 1e6, m, "C1", f"fit over t - t_c = {lw[0]:g}-{lw[1]:.3g} s: slope {late:.2f}")
    # Where the contact went on growing by stretching the bound membrane (spread's note; docs/model/contact_line.md,
    # "The line held at a node ring"): a dotted line at the time the last node came within h0 of the plane.
    since, t_last, edge = (summary.get(k) for k in ("r_cc_growth_since_contact_nodes_most_m",
                                                    "contact_nodes_most_from_s", "mesh_edge_mean_m"))
    if None not in (since, t_last, edge) and since > edge and t_last > onset:
        ax.axvline(t_last - onset, color="C2", ls=":", lw=1.2,
                   label=f"last node down ({t_last:.2g} s); then +{since * 1e6:.2f} µm by stretching")
    ax.set_xlabel(f"t − {onset:.3g} s (time since the contact began)" if onset > 0 else "t (s)")
    ax.set_ylabel(r"$r_{cc}$ (µm)")
    ax.set_title(f"{summary.get('scene', '')}: {summary.get('nodes', '')} nodes")
    ax.legend(fontsize=8)
    ax.grid(True, which="both", lw=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "r_cc.png"), dpi=130)
    plt.close(fig)


def distinct(frame_list, times):
    picks = []
    for t in times:
        f = nearest(frame_list, t)
        if all(abs(f[0] - p[0]) > 1e-12 for p in picks):
            picks.append(f)
    return picks


def plot_cells(out, h5, tri):
    fl = frames(h5)
    end = fl[-1][0]
    times = (0.1, 0.35, 0.9) if end >= 0.9 else tuple(end * f / 0.9 for f in (0.1, 0.35, 0.9))
    # The start (t = 0, the untouched sphere) only when no later frame is there: a short run's first time
    # (end × 0.1/0.9) is often nearer t = 0 than the next frame (the main job: 0.022 s with frames every 0.05 s).
    later = [f for f in fl if f[0] > 0]
    picks = distinct(later if later else fl, times)
    ncol = len(picks)
    fig = plt.figure(figsize=(4 * ncol, 7.5))
    for row, (field, label, cmap, elev) in enumerate(
            [("normal_force_N", "normal force (pN), adhesion > 0", "coolwarm", -30),
             ("cortex_tension_J_per_m2", "cortex tension (µN/m), tensile > 0", "viridis", 20)]):
        scale = 1e12 if field == "normal_force_N" else 1e6
        vals = [np.asarray(g[field]) * scale for _, g in picks]
        lim = max(np.percentile(np.abs(v), 98) for v in vals) or 1.0
        vmin, vmax = (-lim, lim) if field == "normal_force_N" else (min(v.min() for v in vals), lim)
        low, high = min(v.min() for v in vals) < vmin, max(v.max() for v in vals) > vmax
        extend = "both" if low and high else "min" if low else "max" if high else "neither"
        for col, ((t, g), v) in enumerate(zip(picks, vals)):
            x = np.asarray(g["x"]) * 1e6
            ax = fig.add_subplot(2, ncol, ncol * row + col + 1, projection="3d")
            face = v[tri].mean(axis=1)
            surf = ax.plot_trisurf(x[:, 0], x[:, 1], x[:, 2], triangles=tri, cmap=cmap, linewidth=0,
                                   antialiased=False)
            surf.set_array(face)
            surf.set_clim(vmin, vmax)
            ax.view_init(elev=elev, azim=-60)
            ax.set_box_aspect((np.ptp(x[:, 0]), np.ptp(x[:, 1]), max(np.ptp(x[:, 2]), 1e-3)))
            ax.set_title(f"t = {t:.3f} s" + (", from below" if elev < 0 else ""), fontsize=9)
            ax.set_axis_off()
            if col == ncol - 1:
                fig.colorbar(surf, ax=ax, shrink=0.6, label=label, extend=extend)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "cells.png"), dpi=110)
    plt.close(fig)


def plane_z(h5):
    """The substrate's height (m) from the scene the run stored (contact.plane_z_m, default 0)."""
    text = h5.attrs.get("scene", "")
    text = text.decode() if isinstance(text, bytes) else text
    try:
        return float(tomllib.loads(text).get("contact", {}).get("plane_z_m", 0.0))
    except (tomllib.TOMLDecodeError, ValueError):
        return 0.0


def plot_side_views(out, h5):
    fl = frames(h5)
    z_plane = plane_z(h5) * 1e6
    picks = distinct(fl, [0.0, 0.1, 0.35, 0.9, fl[-1][0]])
    fig, axes = plt.subplots(1, len(picks), figsize=(3.0 * len(picks), 3.0), sharey=True)
    axes = np.atleast_1d(axes)
    for ax, (t, g) in zip(axes, picks):
        x = np.asarray(g["x"]) * 1e6
        band = np.abs(x[:, 1]) < 0.25 * np.ptp(x[:, 1]) / 2 + 1e-9
        ax.plot(x[band, 0], x[band, 2], ".", ms=2, color="C0")
        ax.axhline(z_plane, color="k", lw=1)
        ax.set_aspect("equal")
        ax.set_title(f"t = {t:.3f} s", fontsize=9)
        ax.set_xlabel("x (µm)")
    axes[0].set_ylabel("z (µm)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "side_views.png"), dpi=130)
    plt.close(fig)


def main():
    args = sys.argv[1:]
    if any(a in ("-h", "--help") for a in args):
        print(__doc__.strip())
        return
    quiet = "--quiet" in args
    args = [a for a in args if a != "--quiet"]
    if len(args) != 1 or args[0].startswith("-"):
        sys.exit("usage: plot_spread.py [--quiet] OUT_DIR")
    out = args[0]
    s = read_series(os.path.join(out, "series.csv"))
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    plot_rcc(out, s, summary)
    wrote = [f"{out}/r_cc.png"]
    h5_path = os.path.join(out, "spread.h5")
    if os.path.exists(h5_path):
        with h5py.File(h5_path, "r") as h5:
            tri = np.asarray(h5["mesh"]["triangles"])
            plot_cells(out, h5, tri)
            plot_side_views(out, h5)
        wrote += [f"{out}/cells.png", f"{out}/side_views.png"]
    if not quiet:
        print("wrote " + ", ".join(wrote))


if __name__ == "__main__":
    main()
