#!/usr/bin/env python3
"""How a spread run's contact grows: by more membrane coming down, or by the bound membrane stretching.

For every frame of OUT/spread.h5 (or every K-th with --every K) it prints the time, the nodes within contact.h0_m
of the plane ("in range"), the radius of the outermost of them about their centre, the largest and the mean
node stretch among them (the frames' `stretch`: mean d/d* of the node's bonds; x_max is the FENE limit) and the
mean stretch of the other nodes, and how far the bound membrane slid: the largest in-plane displacement, since
the frame printed before, of the nodes inside the bound disc in both (every triangle around them within h0 of
the plane; the rim's nodes are left out). A contact radius that grows while the count stays the same is the bound
membrane being stretched outward (docs/model/contact_line.md, "The line held at a node ring"). The plane and
h0 come from the scene stored in the file. With pins (contact.pin_friction_N_s_per_m) the bound membrane
does not slide.

With --bonds it prints instead, for the last frame, the bond stretch d/d* by where the bond lies: between a rim
node (in range, with a triangle not wholly in range) and a node inside the bound disc, along the rim, inside the
disc, and in the free membrane (both ends out of range). d* is each bond's length in /mesh/x divided by
cortex.bond_prestretch; the node means of d/d* are checked against the frame's `stretch`.

  python3 scripts/contact_rings.py out/RUN [--every 4]
  python3 scripts/contact_rings.py out/RUN --bonds
"""
import argparse
import os
import signal
import sys
import tomllib

os.environ.setdefault("HDF5_USE_FILE_LOCKING", "FALSE")
import h5py  # noqa: E402
import numpy as np  # noqa: E402


def disc_interior(near, tri):
    """The nodes in range whose every triangle lies wholly in range (the bound disc without its rim)."""
    inside = np.ones(len(near), dtype=bool)
    np.logical_and.at(inside, tri.ravel(), np.repeat(near[tri].all(axis=1), 3))
    return inside


def bond_table(g, tri, rest_x, plane_z, h0):
    """The bond stretch of frame g by where the bond lies (rim-inside, rim, inside, free)."""
    x = g["x"][:]
    near = x[:, 2] - plane_z < h0
    inside = disc_interior(near, tri)
    rim = near & ~inside
    e = np.unique(np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1), axis=0)
    s = np.linalg.norm(x[e[:, 0]] - x[e[:, 1]], axis=1) / np.linalg.norm(rest_x[e[:, 0]] - rest_x[e[:, 1]], axis=1)
    node_sum, node_count = np.zeros(len(x)), np.zeros(len(x))
    for end in (0, 1):
        np.add.at(node_sum, e[:, end], s)
        np.add.at(node_count, e[:, end], 1)
    off = np.abs(node_sum / node_count - g["stretch"][:]).max()
    if off > 1e-6:
        sys.exit(f"contact_rings: the rest lengths from /mesh/x do not give the frame's stretch (off by {off:.3g});"
                 " this run's rest shape is not its first mesh")
    print(f"t_s,{g.attrs['time']:.6g}")
    print("bonds,count,stretch_mean,stretch_max")
    for name, m in (("rim_to_inside", rim[e].any(axis=1) & inside[e].any(axis=1)), ("rim", rim[e].all(axis=1)),
                    ("inside", inside[e].all(axis=1)), ("free", (~near[e]).all(axis=1))):
        print(f"{name},{int(m.sum())},{s[m].mean() if m.any() else float('nan'):.4f},"
              f"{s[m].max() if m.any() else float('nan'):.4f}")


def main():
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # `| head` ends the output quietly
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", help="a spread output folder (holding spread.h5)")
    ap.add_argument("--every", type=int, default=1, help="print every K-th frame (and the last); default 1")
    ap.add_argument("--bonds", action="store_true", help="the last frame's bond stretch by where the bond lies")
    a = ap.parse_args()
    if a.every < 1:
        sys.exit(f"contact_rings: --every = {a.every}, allowed: 1 or more")
    path = os.path.join(a.out, "spread.h5")
    try:
        f = h5py.File(path, "r")
    except OSError as e:
        sys.exit(f"contact_rings: {path}: {e}")
    with f:
        text = f.attrs["scene"]
        scene = tomllib.loads(text.decode() if isinstance(text, bytes) else text)
        plane_z, h0 = float(scene["contact"]["plane_z_m"]), float(scene["contact"]["h0_m"])
        names = sorted(f["frames"].keys())
        if not names:
            sys.exit(f"contact_rings: {path} has no frames")
        if a.bonds:
            prestretch = float(scene.get("cortex", {}).get("bond_prestretch", 1.0))
            bond_table(f["frames"][names[-1]], f["mesh/triangles"][:], f["mesh/x"][:] / prestretch, plane_z, h0)
            return
        picked = names[::a.every] + ([names[-1]] if (len(names) - 1) % a.every else [])
        print("t_s,nodes_in_range,outer_radius_m,stretch_max_in_range,stretch_mean_in_range,stretch_mean_free,"
              "bound_slide_max_m")
        tri = f["mesh/triangles"][:]
        x_before = near_before = None
        for name in picked:
            g = f["frames"][name]
            x, s = g["x"][:], g["stretch"][:]
            near = x[:, 2] - plane_z < h0
            if near.any():
                c = x[near, :2].mean(axis=0)
                r = np.hypot(x[near, 0] - c[0], x[near, 1] - c[1]).max()
                s_max, s_mean = s[near].max(), s[near].mean()
            else:
                r = s_max = s_mean = float("nan")
            s_free = s[~near].mean() if (~near).any() else float("nan")
            inside = disc_interior(near, tri)
            both = inside & near_before if near_before is not None else np.zeros_like(near)
            slide = np.hypot(*(x[both, :2] - x_before[both, :2]).T).max() if both.any() else float("nan")
            x_before, near_before = x, inside
            print(f"{g.attrs['time']:.6g},{int(near.sum())},{r:.6g},{s_max:.4f},{s_mean:.4f},{s_free:.4f},{slide:.4g}")


if __name__ == "__main__":
    main()
