#!/usr/bin/env python3
"""Checks a spread run's output: check_spread.py OUT_DIR [--interrupted]

series.csv has the required columns and finite rows, r_cc grows, summary.json has the required keys and no
warnings, the energy balance residual is small against the powers, the HDF5 file opens and holds frames with
the node fields and a /series with every column and row of series.csv. With --interrupted: the summary says so
and the files are still valid."""
import csv
import json
import math
import os
import sys
import tomllib

os.environ.setdefault("HDF5_USE_FILE_LOCKING", "FALSE")
import h5py  # noqa: E402

REQUIRED = ["t_s", "r_cc_m", "contact_area_m2", "area_m2", "volume_m3", "cg_iterations", "dt_s"]
KEYS = ["r_cc_final_m", "contact_angle_deg", "early_exponent", "height_final_m", "steps", "wall_s",
        "mean_cg_iterations"]
FIELDS = ["cortex_tension_J_per_m2", "stretch", "normal_force_N", "normal_pressure_Pa"]


def fail(msg):
    print("check_spread: " + msg)
    sys.exit(1)


def per_decade_of(out):
    """output.series_per_decade of the run (the scene in spread.h5's attribute), or None without h5py/spread.h5."""
    try:
        import h5py
        with h5py.File(os.path.join(out, "spread.h5"), "r") as f:
            scene = f.attrs["scene"]
    except Exception:
        return None
    scene = scene.decode() if isinstance(scene, bytes) else str(scene)
    for line in scene.splitlines():
        key, _, value = line.partition("=")
        if key.strip() in ("series_per_decade", "output.series_per_decade"):
            return float(value.split("#")[0])
    return None


def main():
    out = sys.argv[1]
    interrupted = "--interrupted" in sys.argv
    with open(os.path.join(out, "series.csv")) as f:
        reader = csv.DictReader(f)
        for c in REQUIRED:
            if c not in reader.fieldnames:
                fail(f"series.csv has no column {c}")
        rows = list(reader)
    if len(rows) < (1 if interrupted else 5):
        fail(f"series.csv has {len(rows)} rows")
    for r in rows:
        for k, v in r.items():
            if not math.isfinite(float(v)):
                fail(f"non-finite {k} = {v} at t = {r['t_s']}")
    # Each row is a state the run kept: time moves forward, and a row's step starts no earlier than the row
    # before it ends (an adaptive step that takes the step before again, shorter, replaces that step's row).
    for a, b in zip(rows, rows[1:]):
        ta, tb, hb = float(a["t_s"]), float(b["t_s"]), float(b["dt_s"])
        if not tb > ta or tb - hb < ta - 1e-5 * hb - 1e-8 * tb:  # dt_s has 6 digits, t_s 9
            fail(f"row at t = {tb} s (dt_s = {hb}) after the row at t = {ta} s")
    # Log-spaced rows (output.series_per_decade): after the first ten steps, the step of each row starts
    # before the next sample time of the row before it (the first step that reaches it writes the row; until
    # session 29 the first step that started past it, so the rows lay up to a step apart beyond the spacing).
    per_decade = per_decade_of(out)
    if per_decade:
        factor = 10 ** (1 / per_decade)
        for a, b in zip(rows[10:], rows[11:]):
            ta, tb, hb = float(a["t_s"]), float(b["t_s"]), float(b["dt_s"])
            if tb - hb > ta * factor + 1e-5 * hb:
                fail(f"row at t = {tb} s (dt_s = {hb}): its step starts past the sample time {ta * factor} s "
                     f"after the row at t = {ta} s (series_per_decade = {per_decade}): a row was skipped")
    if not interrupted and not float(rows[-1]["r_cc_m"]) > float(rows[1]["r_cc_m"]):
        fail("r_cc did not grow")
    s = json.load(open(os.path.join(out, "summary.json")))
    for k in KEYS:
        if k not in s:
            fail(f"summary.json has no key {k}")
    # The run's last step writes a row: the series ends at t_end, and r_cc_final_m is its r_cc. A run stopped
    # by Ctrl-C or --max-steps too (since session 39): its series ends on the state it stopped in.
    if not math.isclose(float(rows[-1]["t_s"]), s["t_end_s"], rel_tol=1e-6):
        fail(f"series.csv ends at t = {rows[-1]['t_s']} s, the run at t_end_s = {s['t_end_s']} s")
    if not math.isclose(float(rows[-1]["r_cc_m"]), s["r_cc_final_m"], rel_tol=1e-6, abs_tol=1e-15):
        fail(f"summary.json r_cc_final_m = {s['r_cc_final_m']}, the last row {rows[-1]['r_cc_m']}")
    # r_cc_growth_last_tenth: r_cc's growth over the last tenth of the run, from the rows (linear between the
    # two around 0.9 t_end); null when no row lies at or before it.
    t = [float(r["t_s"]) for r in rows]
    rc = [float(r["r_cc_m"]) for r in rows]
    start = 0.9 * t[-1]
    before = [k for k in range(len(t)) if t[k] <= start]
    if "r_cc_growth_last_tenth" not in s:
        fail("summary.json has no key r_cc_growth_last_tenth")
    if before and rc[-1] > 0:
        k = before[-1]
        r_start = rc[k] + (start - t[k]) / (t[k + 1] - t[k]) * (rc[k + 1] - rc[k])
        expected = (rc[-1] - r_start) / rc[-1]
        if s["r_cc_growth_last_tenth"] is None or abs(s["r_cc_growth_last_tenth"] - expected) > 1e-6:
            fail(f"summary.json r_cc_growth_last_tenth = {s['r_cc_growth_last_tenth']}, the rows give {expected}")
    # The contact's onset (session 35): from the rows, the last row without contact before the last unbroken
    # run of rows with it, 0 when that run starts at the first row; since session 36 spread finds it at the
    # steps' resolution (contact_onset_by = "steps"), between that row and the run's first row. The early
    # exponent is the slope of log r against log (t − onset) over the rows 0.01–0.1 s (the window) after it.
    last = next((k for k in reversed(range(len(t))) if rc[k] > 0), None)
    first = last
    while first is not None and first > 0 and rc[first - 1] > 0:
        first -= 1
    onset = None if first is None else (0.0 if first == 0 else t[first - 1])
    if "contact_onset_s" not in s or "early_exponent_run_time" not in s or "contact_onset_by" not in s:
        fail("summary.json has no key contact_onset_s, contact_onset_by or early_exponent_run_time")
    if onset is not None and s["contact_onset_by"] == "steps":
        # series.csv holds t with 9 digits
        if not (onset * (1 - 1e-8) <= s["contact_onset_s"] < t[first] * (1 + 1e-8) or first == 0 == onset):
            fail(f"summary.json contact_onset_s = {s['contact_onset_s']} is not between the rows' onset {onset} "
                 f"and the run's first row {t[first]}")
        onset = s["contact_onset_s"]
    elif onset is not None and not math.isclose(s["contact_onset_s"], onset, rel_tol=1e-6, abs_tol=1e-15):
        fail(f"summary.json contact_onset_s = {s['contact_onset_s']}, the rows give {onset}")
    w = s.get("early_window_s")
    pts = [(math.log(t[k] - onset), math.log(rc[k])) for k in range(len(t))
           if onset is not None and w[0] <= t[k] - onset <= w[1] and t[k] > onset and rc[k] > 0]
    if len(pts) >= 3 and not interrupted:
        n, sx, sy = len(pts), sum(p[0] for p in pts), sum(p[1] for p in pts)
        sxx, sxy = sum(p[0] ** 2 for p in pts), sum(p[0] * p[1] for p in pts)
        slope = (n * sxy - sx * sy) / (n * sxx - sx * sx)
        # series.csv holds t with 9 digits: the slope from its rows agrees to ~1e-6
        if s["early_exponent"] is None or abs(s["early_exponent"] - slope) > 1e-4:
            fail(f"summary.json early_exponent = {s['early_exponent']}, the rows give {slope} from t = {onset} s")
    # The later regime (session 38): the same slope from the window's end to the last row, null with fewer than
    # three rows with contact there.
    if "late_exponent" not in s or "late_window_s" not in s:
        fail("summary.json has no key late_exponent or late_window_s")
    late = [(math.log(t[k] - onset), math.log(rc[k])) for k in range(len(t))
            if onset is not None and t[k] - onset >= w[1] and t[k] > onset and rc[k] > 0]
    if not interrupted:
        lw, reach_end = s["late_window_s"], (None if onset is None or not t else t[-1] - onset)
        # (a row within 9-digit rounding of the window's start may count either way)
        edge = sum(1 for k in range(len(t)) if onset is not None and rc[k] > 0 and t[k] > onset
                   and abs(t[k] - onset - w[1]) <= 1e-8 * max(1.0, t[k]))
        if not isinstance(s.get("late_window_rows"), int) or abs(s["late_window_rows"] - len(late)) > edge:
            fail(f"summary.json late_window_rows = {s.get('late_window_rows')}, the rows give {len(late)}")
        if reach_end is not None and reach_end > w[1] and (
                lw[0] != w[1] or lw[1] is None or abs(lw[1] - reach_end) > 1e-7 * max(1.0, t[-1])):
            fail(f"summary.json late_window_s = {lw}, expected [{w[1]}, {reach_end}]")
        if len(late) < 3 and s["late_exponent"] is not None:
            fail(f"summary.json late_exponent = {s['late_exponent']} from {len(late)} rows (fewer than three)")
        if len(late) >= 3:
            n, sx, sy = len(late), sum(p[0] for p in late), sum(p[1] for p in late)
            sxx, sxy = sum(p[0] ** 2 for p in late), sum(p[0] * p[1] for p in late)
            slope = (n * sxy - sx * sy) / (n * sxx - sx * sx)
            if s["late_exponent"] is None or abs(s["late_exponent"] - slope) > 1e-4:
                fail(f"summary.json late_exponent = {s['late_exponent']}, the rows give {slope} after {w[1]} s")
    # The window's end the rows reach: null unless the last row lies inside the window (counted from the onset).
    reach = None if onset is None or not t else t[-1] - onset
    cut = s.get("early_window_cut_at_s", "absent")
    # (series.csv holds t with 9 digits: within 1e-6 of the window's ends either answer is right)
    if reach is not None and w[0] * (1 + 1e-6) < reach < w[1] * (1 - 1e-6):
        if cut is None or cut == "absent" or abs(cut - reach) > 1e-7 * max(1.0, t[-1]):
            fail(f"summary.json early_window_cut_at_s = {cut}, the rows end {reach} s after the onset, inside "
                 f"the window {w}")
    elif cut is not None and (reach is None or not w[0] * (1 - 1e-6) < reach < w[1] * (1 + 1e-6)):
        fail(f"summary.json early_window_cut_at_s = {cut}; the rows end {reach} s after the onset, not inside {w}")
    if s.get("interrupted") != interrupted:
        fail(f"summary.json interrupted = {s.get('interrupted')}, expected {interrupted}")
    if not interrupted and not s["energy_residual_relative"] < 0.05:
        fail(f"energy residual {s['energy_residual_relative']} of the powers")
    if s.get("warnings") != []:
        fail(f"summary.json warnings = {s.get('warnings')}, expected none")
    # The nodes in range of the plane (session 32): the first row with the most of them is a row of the series,
    # and r_cc's growth since is measured from it.
    for k in ("contact_nodes_final", "contact_nodes_most", "contact_nodes_most_from_s",
              "r_cc_growth_since_contact_nodes_most_m", "mesh_edge_mean_m"):
        if k not in s:
            fail(f"summary.json has no key {k}")
    if s["contact_nodes_most"] is not None:
        if s["contact_nodes_most"] < s["contact_nodes_final"]:
            fail(f"contact_nodes_most {s['contact_nodes_most']} < contact_nodes_final {s['contact_nodes_final']}")
        at = [k for k in range(len(t)) if math.isclose(t[k], s["contact_nodes_most_from_s"], rel_tol=1e-6)]
        if not at:
            fail(f"contact_nodes_most_from_s = {s['contact_nodes_most_from_s']} is not the time of a row")
        if rc[at[0]] > 0 and not interrupted:
            g = rc[-1] - rc[at[0]]
            if not math.isclose(s["r_cc_growth_since_contact_nodes_most_m"], g, rel_tol=1e-5, abs_tol=1e-14):
                fail(f"r_cc_growth_since_contact_nodes_most_m = {s['r_cc_growth_since_contact_nodes_most_m']}, "
                     f"the rows give {g}")
    with h5py.File(os.path.join(out, "spread.h5"), "r") as h5:
        # A run that reached its end reports the scene's t_end itself, not the rounded sum of its steps.
        text = h5.attrs["scene"]
        scene = tomllib.loads(text.decode() if isinstance(text, bytes) else text)
        # contact_nodes_final: the nodes of the end state (the last frame) within contact.h0_m of the plane;
        # mesh_edge_mean_m: the mean edge of the mesh as placed (/mesh).
        x_end = h5["frames"][sorted(h5["frames"].keys())[-1]]["x"][:]
        plane_z, h0 = float(scene["contact"]["plane_z_m"]), float(scene["contact"]["h0_m"])
        near = int(sum(1 for p in x_end if p[2] - plane_z < h0))
        if near != s["contact_nodes_final"]:
            fail(f"summary.json contact_nodes_final = {s['contact_nodes_final']}, the last frame has {near}")
        x0, tri = h5["mesh"]["x"][:], h5["mesh"]["triangles"][:]
        edges = [math.dist(x0[a], x0[b]) for tr in tri for a, b in ((tr[0], tr[1]), (tr[1], tr[2]), (tr[2], tr[0]))]
        if not math.isclose(sum(edges) / len(edges), s["mesh_edge_mean_m"], rel_tol=1e-9):
            fail(f"mesh_edge_mean_m = {s['mesh_edge_mean_m']}, /mesh gives {sum(edges) / len(edges)}")
        t_end = float(scene["time"]["t_end_s"])
        if not interrupted and not s.get("stopped_at_max_steps") and not s.get("restarted_from") \
                and s["t_end_s"] != t_end:
            fail(f"summary.json t_end_s = {s['t_end_s']!r}, the scene's time.t_end_s = {t_end!r}")
        frames = list(h5["frames"].keys())
        if not frames:
            fail("no frames in spread.h5")
        for name in FIELDS:
            if name not in h5["frames"][frames[-1]]:
                fail(f"frame {frames[-1]} has no field {name}")
        for c in reader.fieldnames:
            if c not in h5["series"]:
                fail(f"spread.h5 /series has no column {c}")
            col = h5["series"][c][:]
            if len(col) != len(rows):
                fail(f"spread.h5 /series/{c} has {len(col)} rows, series.csv {len(rows)}")
            if not all(math.isclose(float(r[c]), float(v), rel_tol=1e-5, abs_tol=1e-30) for r, v in zip(rows, col)):
                fail(f"spread.h5 /series/{c} differs from series.csv")
    print(f"check_spread: {out}: {len(rows)} rows, {len(frames)} frames, r_cc {float(rows[-1]['r_cc_m']):.3g} m")


if __name__ == "__main__":
    main()
