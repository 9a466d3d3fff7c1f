#!/usr/bin/env python3
"""Draws <scan out>/r_cc_grid.png: one panel per swept key (the paper's Figure 5 layout), r_cc(t) of its
members on log-log axes against the time since each member's contact began (summary.json contact_onset_s, as
spread's r_cc.png) with a t^(1/2) guide; one_at_a_time scans add the base member in black. A member
that did not finish (summary.csv's status: failed, interrupted) is drawn dashed up to where it stopped, marked x
there, its status in the legend. A
latin_hypercube scan (every member varies every key) colours all members in each panel by that key's value
(dark: low, yellow: high) and also draws sensitivity.png: the final r_cc and the free-fit contact angle of
every member against each swept key (from summary.csv).
The base member's legend entry gives its value of the panel's key (from its spread.h5's resolved scene).
usage: scan_plot.py OUT_DIR"""
import csv, json, math, os, sys

import matplotlib

os.environ.setdefault("HDF5_USE_FILE_LOCKING", "FALSE")
matplotlib.use("Agg")
import matplotlib.pyplot as plt


def onset(out, mid):
    """The member's contact onset, as r_cc.png counts time: summary.json's contact_onset_s; for a member without
    one (failed, interrupted) the last row without contact before its rows with contact, as spread finds it
    from the rows; 0 when neither is known."""
    try:
        with open(os.path.join(out, "members", mid, "summary.json")) as f:
            value = json.load(f).get("contact_onset_s")
            if value is not None:
                return float(value)
    except (OSError, ValueError, TypeError):
        pass
    try:
        with open(os.path.join(out, "members", mid, "series.csv")) as f:
            rows = [(float(r["t_s"]), float(r["r_cc_m"])) for r in csv.DictReader(f)]
    except (OSError, ValueError, KeyError):
        return 0.0
    before = 0.0
    for t, r in rows:
        if r > 0:
            return before
        before = t
    return 0.0


def base_value(out, mid, key):
    """The value of scene key `key` in the member's resolved scene (spread.h5's root attribute `scene`), or
    None where the file or the key cannot be read: the legend's base then says no value."""
    try:
        import h5py
        import tomllib
        with h5py.File(os.path.join(out, "members", mid, "spread.h5"), "r") as f:
            text = f.attrs["scene"]
        value = tomllib.loads(text.decode() if isinstance(text, bytes) else str(text))
        for part in key.split("."):
            value = value[part]
        return value
    except Exception:  # a missing file, no h5py, a key the scene lacks: the label without the value
        return None


def series(out, mid):
    """r_cc (µm) against the time since the member's contact began (s), as spread's r_cc.png and its
    early_exponent count it."""
    t, r = [], []
    t0 = onset(out, mid)
    try:
        with open(os.path.join(out, "members", mid, "series.csv")) as f:
            for row in csv.DictReader(f):
                ti, ri = float(row["t_s"]) - t0, float(row["r_cc_m"])
                if ti > 0 and ri > 0:
                    t.append(ti)
                    r.append(ri * 1e6)
    except OSError:
        pass
    return t, r


def main():
    if len(sys.argv) == 2 and sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        sys.exit(0)
    if len(sys.argv) != 2:
        print("scan_plot.py: error: give one scan output folder (usage: scan_plot.py OUT_DIR)", file=sys.stderr)
        sys.exit(2)
    out = sys.argv[1]
    try:
        scan = json.load(open(os.path.join(out, "scan.json")))
    except (OSError, ValueError) as e:
        print(f"scan_plot.py: {out}: no readable scan.json ({e}): give a scan's output folder", file=sys.stderr)
        sys.exit(2)
    keys = scan["sweep_keys"]
    n = len(keys)
    cols = min(3, n)
    rows = math.ceil(n / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.4 * rows), squeeze=False)
    base = next((m for m in scan["members"] if not m["swept"]), None)
    status = {}  # a member that did not finish: its curve is the part it ran, drawn dashed and marked x
    try:
        with open(os.path.join(out, "summary.csv")) as f:
            status = {r["id"]: r["status"] for r in csv.DictReader(f)}
    except (OSError, KeyError):
        pass
    unfinished = lambda mid: status.get(mid, "done") != "done"
    note = lambda mid: f" ({status[mid]})" if unfinished(mid) else ""
    for i, key in enumerate(keys):
        ax = axes[i // cols][i % cols]
        members = [m for m in scan["members"] if key in m["swept"]]
        if scan["mode"] == "latin_hypercube":
            members.sort(key=lambda m: m["swept"][key])
        cmap = plt.get_cmap("viridis")
        for j, m in enumerate(members):
            t, r = series(out, m["id"])
            if t:
                label = f"{m['swept'][key]:.3g}" if isinstance(m["swept"][key], float) else str(m["swept"][key])
                colour = cmap(j / max(1, len(members) - 1))
                ax.loglog(t, r, color=colour, lw=1.3, ls=(0, (2, 2)) if unfinished(m["id"]) else "-",
                          label=label + note(m["id"]) if len(members) <= 8 or unfinished(m["id"]) else None)
                if unfinished(m["id"]):
                    ax.plot(t[-1], r[-1], "x", color=colour, ms=7, mew=1.5)
        if base:
            t, r = series(out, base["id"])
            if t:
                v = base_value(out, base["id"], key)
                shown = "" if v is None else f" ({v:.3g})" if isinstance(v, float) else f" ({v})"
                ax.loglog(t, r, color="k", lw=1.0, ls="--", label="base" + shown + note(base["id"]))
                if unfinished(base["id"]):
                    ax.plot(t[-1], r[-1], "x", color="k", ms=7, mew=1.5)
        all_t = [v for m in members for v in series(out, m["id"])[0]]
        if all_t:
            t0, t1 = min(all_t), max(all_t)
            ts = [t0 * (t1 / t0) ** (k / 20) for k in range(21)]
            ax.loglog(ts, [1.0 * (tt / 0.1) ** 0.5 for tt in ts], color="0.6", lw=0.8, ls=":", label="t^1/2")
        all_r = [v for m in members for v in series(out, m["id"])[1]]
        if all_r:  # the first touch-down (r_cc of nanometres) would squash the curves
            bottom = max(min(all_r), 0.03 * max(all_r))
            ax.set_ylim(bottom=bottom, top=1.3 * max(all_r))
            shown = [tt for m in members + ([base] if base else []) for tt, rr in zip(*series(out, m["id"]))
                     if rr >= bottom]
            if shown:  # and the time axis from where the first curve enters the panel
                ax.set_xlim(left=min(shown) / 1.5)
        ax.set_title(key + (" (colour: low to high)" if len(members) > 8 else ""), fontsize=9)
        ax.set_xlabel("t − contact onset (s)")
        ax.set_ylabel("r_cc (µm)")
        ax.legend(fontsize=7)
    for i in range(n, rows * cols):
        axes[i // cols][i % cols].axis("off")
    fig.suptitle(f"scan {scan['name']} ({scan['mode']})", fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "r_cc_grid.png"), dpi=110)
    if scan["mode"] == "latin_hypercube":
        sensitivity(scan, out)


def sensitivity(scan, out):
    """sensitivity.png: final r_cc (top row) and free-fit contact angle (bottom row) against each swept key."""
    with open(os.path.join(out, "summary.csv")) as f:
        rows = [r for r in csv.DictReader(f) if r["status"] == "done"]
    keys = scan["sweep_keys"]
    fig, axes = plt.subplots(2, len(keys), figsize=(3.8 * len(keys), 6.0), squeeze=False)
    for i, key in enumerate(keys):
        pts = [(float(r[key]), float(r["r_cc_final_m"]) * 1e6, float(r["contact_angle_free_deg"] or "nan"))
               for r in rows if r[key] and r["r_cc_final_m"]]
        for row, (what, unit) in enumerate((("final r_cc", "µm"), ("contact angle (free fit)", "°"))):
            ax = axes[row][i]
            ax.plot([p[0] for p in pts], [p[1 + row] for p in pts], "o", ms=4)
            values = [p[0] for p in pts if p[0] > 0]
            if values and min(values) > 0 and max(values) / min(values) >= 3:
                ax.set_xscale("log")
            ax.tick_params(labelsize=7)
            ax.set_xlabel(key, fontsize=8)
            ax.set_ylabel(f"{what} ({unit})", fontsize=8)
    fig.suptitle(f"scan {scan['name']}: {len(rows)} members (latin hypercube)", fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "sensitivity.png"), dpi=110)


if __name__ == "__main__":
    main()
