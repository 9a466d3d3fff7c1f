#!/usr/bin/env python3
# (Written during session 4 to find what sets the final contact angle; docs/VALIDATION.md "Spreading".)
"""Analyse a dcm spread run: final (or chosen) frame -> cap fit, A/A*, V/V*, pressure, tensions,
Young-Dupre angles, bond extensions, and the uniform-strain spherical-cap energy minimum.

usage: spread_angle_analysis.py RUN_DIR [--frame K|--time T] [--json]
Pure python (no numpy on this VM); reads spread.h5 with h5dump.
"""
import json, math, os, re, subprocess, sys


def h5(path, dset):
    out = subprocess.run(["h5dump", "-y", "-w", "0", "-m", "%.17g", "-d", dset, path],
                         capture_output=True, text=True, check=True).stdout
    body = out.split("DATA {", 1)[1].split("}", 1)[0]
    return [float(v) for v in re.split(r"[,\s]+", body) if v.strip()]


def h5_attr(path, name):
    out = subprocess.run(["h5dump", "-a", name, path], capture_output=True, text=True).stdout
    return out


def frame_times(path):
    out = subprocess.run(["h5dump", "-A", "-g", "/frames", path], capture_output=True, text=True).stdout
    times = {}
    for m in re.finditer(r'GROUP "(\d{6})".*?ATTRIBUTE "time".*?DATA \{\s*\(0\): ([-0-9.eE+]+)', out, re.S):
        times[m.group(1)] = float(m.group(2))
    return times


def scene_params(path):
    txt = h5_attr(path, "/scene")
    p = {}
    section = ""
    for line in txt.splitlines():
        line = line.strip().lstrip('(0): "')
        m = re.match(r"\[(\w+)\]", line)
        if m:
            section = m.group(1)
            continue
        m = re.match(r"(\w+) = ([^#]+?)\s*(#|$)", line)
        if m:
            v = m.group(2).strip().strip('"')
            try:
                v = float(v)
            except ValueError:
                pass
            p[section + "." + m.group(1)] = v
    return p


def sub(a, b): return (a[0] - b[0], a[1] - b[1], a[2] - b[2])
def cross(a, b): return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
def dot(a, b): return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
def norm(a): return math.sqrt(dot(a, a))


def measures(x, tris):
    areas, vol = [], 0.0
    for (i, j, k) in tris:
        c = cross(sub(x[j], x[i]), sub(x[k], x[i]))
        areas.append(0.5 * norm(c))
        vol += dot(x[i], cross(x[j], x[k])) / 6
    return areas, vol


def solve(a, b):
    n = len(b)
    m = [row[:] + [b[i]] for i, row in enumerate(a)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(m[r][c]))
        m[c], m[p] = m[p], m[c]
        for r in range(n):
            if r != c:
                f = m[r][c] / m[c][c]
                for k in range(c, n + 1):
                    m[r][k] -= f * m[c][k]
    return [m[i][n] / m[i][i] for i in range(n)]


def fit_cap(x, plane_z=0.0, cut=None):
    n = len(x)
    zs = sorted(p[2] for p in x)
    if cut is None:
        cut = zs[int(0.05 * (n - 1))]
    else:
        cut = plane_z + cut
    # scale to um for conditioning
    s = 1e6
    ata = [[0.0] * 4 for _ in range(4)]
    atb = [0.0] * 4
    for p in x:
        if p[2] < cut:
            continue
        q = (p[0] * s, p[1] * s, p[2] * s)
        row = (2 * q[0], 2 * q[1], 2 * q[2], 1.0)
        rhs = q[0] ** 2 + q[1] ** 2 + q[2] ** 2
        for i in range(4):
            atb[i] += row[i] * rhs
            for j in range(4):
                ata[i][j] += row[i] * row[j]
    c = solve(ata, atb)
    R = math.sqrt(c[3] + c[0] ** 2 + c[1] ** 2 + c[2] ** 2) / s
    hc = c[2] / s - plane_z
    ang = math.pi - math.acos(max(-1, min(1, hc / R)))
    return R, hc, math.degrees(ang)


def yd_angle(W, sigma):
    if sigma <= 0:
        return 0.0  # no tension: complete wetting
    c = W / sigma - 1
    if c >= 1:
        return 0.0
    if c <= -1:
        return 180.0
    return math.degrees(math.acos(c))


def bond_force(d, ds, ks, xmax):
    dm = xmax * ds
    kc = ks * ds ** 3 / (1 - 1 / xmax ** 2)
    return ks * d / (1 - (d / dm) ** 2) - kc / d ** 2


def bond_energy(d, ds, ks, xmax):
    dm = xmax * ds
    kc = ks * ds ** 3 / (1 - 1 / xmax ** 2)
    return -(ks / 2) * dm ** 2 * math.log(1 - (d / dm) ** 2) + kc / d


def cap_shape(a, th):
    Rc = a / math.sin(th)
    h = Rc * (1 - math.cos(th))
    V = math.pi * h * h * (3 * Rc - h) / 3
    A = 2 * math.pi * Rc * h + math.pi * a * a
    return A, V, h, Rc


def cap_minimum(P, A0, V0, bond_rest):
    """Energy minimum over spherical caps (a, theta) with uniform area strain: area terms, volume term,
    bonds uniformly stretched by sqrt(A/A0), minus W pi a^2."""
    ka, kd, kv, W = P["cortex.k_a"], P["cortex.k_d"], P["cortex.k_v"], P["contact.W_J_per_m2"]
    ks, xmax = P["cortex.k_s_N_per_m"], P["cortex.x_max"]
    # bond rest lengths histogram (coarse) for the uniform-stretch bond energy
    e0 = sum(bond_energy(d, d, ks, xmax) for d in bond_rest)

    def E(a, th):
        A, V, h, Rc = cap_shape(a, th)
        lam = math.sqrt(A / A0)
        if lam >= xmax * 0.999999:
            return float("inf")
        eb = sum(bond_energy(lam * d, d, ks, xmax) for d in bond_rest[::8]) * 8 - e0
        return (ka + kd) * (A - A0) ** 2 / (2 * A0) + kv * (V - V0) ** 2 / (2 * V0) - W * math.pi * a * a + eb

    best = None
    # coarse grid then refine
    R0 = (3 * V0 / (4 * math.pi)) ** (1 / 3)
    for th_deg in [t * 1.0 for t in range(20, 178, 2)]:
        for af in [i * 0.05 for i in range(1, 61)]:
            a = af * R0
            e = E(a, math.radians(th_deg))
            if best is None or e < best[0]:
                best = (e, a, th_deg)
    e, a, th = best
    da, dth = 0.05 * R0, 2.0
    for _ in range(40):
        improved = False
        for (xa, xt) in [(a + da, th), (a - da, th), (a, th + dth), (a, th - dth)]:
            if xa <= 0 or not (1 < xt < 179):
                continue
            ee = E(xa, math.radians(xt))
            if ee < e:
                e, a, th, improved = ee, xa, xt, True
        if not improved:
            da /= 2
            dth /= 2
    A, V, h, Rc = cap_shape(a, math.radians(th))
    return {"theta_deg": th, "a_m": a, "A_ratio": A / A0, "V_ratio": V / V0, "height_m": h}


def analyse(run, frame=None, time=None, cap_overrides=None):
    path = os.path.join(run, "spread.h5")
    P = scene_params(path)
    times = frame_times(path)
    keys = sorted(times)
    if frame is None:
        if time is None:
            key = keys[-1]
        else:
            key = min(keys, key=lambda k: abs(times[k] - time))
    else:
        key = "%06d" % frame
    t = times[key]
    tri_flat = [int(v) for v in h5(path, "/mesh/triangles")]
    tris = [tuple(tri_flat[3 * i:3 * i + 3]) for i in range(len(tri_flat) // 3)]
    x0f = h5(path, "/mesh/x")
    x0 = [tuple(x0f[3 * i:3 * i + 3]) for i in range(len(x0f) // 3)]
    xf = h5(path, "/frames/%s/x" % key)
    x = [tuple(xf[3 * i:3 * i + 3]) for i in range(len(xf) // 3)]
    plane_z = P.get("contact.plane_z_m", 0.0)
    h0 = P["contact.h0_m"]
    ka, kd, kv, W = P["cortex.k_a"], P["cortex.k_d"], P["cortex.k_v"], P["contact.W_J_per_m2"]
    ks, xmax = P["cortex.k_s_N_per_m"], P["cortex.x_max"]

    a0, V0 = measures(x0, tris)
    a1, V = measures(x, tris)
    A0, A = sum(a0), sum(a1)
    R, hc, ang = fit_cap(x, plane_z)
    height = max(p[2] for p in x) - plane_z
    Rf, hcf, angf = fit_cap(x, plane_z, cut=0.1 * height)  # free membrane only: nodes above 10% of the height
    Rf5, hcf5, angf5 = fit_cap(x, plane_z, cut=0.05 * height)  # "top 95%" read as the top 95% of the height
    adhered = [p[2] - plane_z < h0 for p in x]
    free_t = [ti for ti, tr in enumerate(tris) if not all(adhered[i] for i in tr)]
    cont_t = [ti for ti, tr in enumerate(tris) if all(adhered[i] for i in tr)]
    A_free = sum(a1[t] for t in free_t)
    A_free0 = sum(a0[t] for t in free_t)
    A_cont = sum(a1[t] for t in cont_t)
    A_cont0 = sum(a0[t] for t in cont_t)
    eps_free = sum(a1[t] - a0[t] for t in free_t) / A_free0 if free_t else 0.0  # = <A_t/A_t*-1> weighted by A_t*
    eps_cont = (A_cont / A_cont0 - 1) if cont_t else float("nan")
    # base radius from adhered nodes
    adh = [p for p, ad in zip(x, adhered) if ad]
    r_adh = max(math.hypot(p[0], p[1]) for p in adh) if adh else 0.0
    cx = sum(p[0] for p in x) / len(x)
    cy = sum(p[1] for p in x) / len(x)
    r_adh = max(math.hypot(p[0] - cx, p[1] - cy) for p in adh) if adh else 0.0

    # bonds
    edges = set()
    for (i, j, k) in tris:
        for (u, v) in ((i, j), (j, k), (k, i)):
            edges.add((min(u, v), max(u, v)))
    edges = sorted(edges)
    ratios, virial_free, bond_rest = [], 0.0, []
    worst = (0, None)
    rim = []
    for (i, j) in edges:
        ds = norm(sub(x0[i], x0[j]))
        d = norm(sub(x[i], x[j]))
        bond_rest.append(ds)
        r = d / (xmax * ds)
        ratios.append(r)
        if r > worst[0]:
            worst = (r, (i, j))
        if not (adhered[i] and adhered[j]):
            virial_free += bond_force(d, ds, ks, xmax) * d
    sigma_bonds_free = virial_free / (2 * A_free) if A_free > 0 else 0.0
    ratios_sorted = sorted(ratios)
    wi, wj = worst[1]
    zw = 0.5 * (x[wi][2] + x[wj][2]) - plane_z
    rw = 0.5 * (math.hypot(x[wi][0] - cx, x[wi][1] - cy) + math.hypot(x[wj][0] - cx, x[wj][1] - cy))

    p = kv * (1 - V / V0)
    sigma_p = p * R / 2
    sigma_A = (ka + kd) * (A / A0 - 1)
    sigma_A_free = kd * (A / A0 - 1) + ka * eps_free
    sigma_tot_free = sigma_A_free + sigma_bonds_free
    res = {
        "run": os.path.basename(run.rstrip("/")), "frame": key, "t_s": t,
        "k_a": ka, "k_d": kd, "k_v": kv, "W": W,
        "gamma_t": P["contact.gamma_t_N_s_per_m3"], "gamma_n": P["contact.gamma_n_N_s_per_m3"],
        "cap_R_m": R, "cap_centre_h_m": hc, "angle_deg": ang, "height_m": height,
        "angle_fit_above10pct_deg": angf, "angle_fit_above5pct_deg": angf5, "cap_R_above10pct_m": Rf,
        "n_adhered": sum(adhered),
        "r_adhered_m": r_adh,
        "A_ratio": A / A0, "V_ratio": V / V0, "A_contact_m2": A_cont,
        "eps_free": eps_free, "eps_contact": eps_cont,
        "p_Pa": p, "sigma_p": sigma_p, "sigma_A": sigma_A, "sigma_A_free": sigma_A_free,
        "sigma_bonds_free": sigma_bonds_free, "sigma_tot_free": sigma_tot_free,
        "theta_YD_p": yd_angle(W, sigma_p), "theta_YD_A": yd_angle(W, sigma_A),
        "theta_YD_free": yd_angle(W, sigma_tot_free),
        "laplace_2sigma_over_R": 2 * sigma_tot_free / R,
        "bond_max_over_dmax": worst[0], "bond_p99_over_dmax": ratios_sorted[int(0.99 * (len(ratios) - 1))],
        "bond_mean_over_dmax": sum(ratios) / len(ratios),
        "worst_bond_z_m": zw, "worst_bond_r_m": rw,
    }
    res["cap_min"] = cap_minimum({**P, **(cap_overrides or {})}, A0, V0, bond_rest)
    return res


if __name__ == "__main__":
    import argparse
    ap = argparse.ArgumentParser(description=__doc__.strip().split("\n\n")[0])
    ap.add_argument("run", help="a spread output folder (its spread.h5)")
    which = ap.add_mutually_exclusive_group()
    which.add_argument("--frame", type=int, help="frame index (default: the last)")
    which.add_argument("--time", type=float, help="the frame nearest this time (s)")
    ap.add_argument("--json", action="store_true", help="print JSON instead of a table")
    ap.add_argument("--k-a", type=float, help="cortex.k_a (N/m) for the cap-energy minimum instead of the run's")
    ap.add_argument("--k-d", type=float, help="cortex.k_d (N/m) for the cap-energy minimum instead of the run's")
    a = ap.parse_args()
    if not os.path.isfile(os.path.join(a.run, "spread.h5")):
        sys.exit(f"spread_angle_analysis: {a.run} has no spread.h5 (a spread output folder with frames)")
    over = {k: v for k, v in (("cortex.k_a", a.k_a), ("cortex.k_d", a.k_d)) if v is not None}
    if any(not v >= 0 for v in over.values()):
        sys.exit(f"spread_angle_analysis: --k-a / --k-d must be 0 or more N/m, got {over}")
    r = analyse(a.run, a.frame, a.time, over)
    if a.json:
        print(json.dumps(r, indent=1))
    else:
        for k, v in r.items():
            print(f"{k:24s} {v}")
