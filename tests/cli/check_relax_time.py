#!/usr/bin/env python3
"""The paper's relaxation experiment on 162 nodes (Δt 50 µs), Table 1's c in both readings:
  check_relax_time.py SURFACE_VISCOSITY_OUT BOND_OUT
With c the membrane's shear viscosity (the default) t_c lies in the paper's 0.1-0.3 s (Hochmuth's t_c = η/μ);
with c per bond the dashpots are √3/4 as strong and, the drag being negligible against them, t_c scales with
them: the ratio of the two times is √3/4 within 2%."""
import json, math, os, sys


def tc(out):
    with open(os.path.join(out, "summary.json")) as f:
        return json.load(f)["relaxation_time_s"]


def main():
    surface, bond = tc(sys.argv[1]), tc(sys.argv[2])
    ratio, expected = bond / surface, math.sqrt(3) / 4
    print(f"check_relax_time: t_c = {surface:.4g} s (c as surface viscosity), {bond:.4g} s (c per bond); "
          f"ratio {ratio:.4f}, √3/4 = {expected:.4f}")
    ok = 0.1 <= surface <= 0.3 and abs(ratio / expected - 1) < 0.02
    if not ok:
        print("check_relax_time: FAIL: t_c outside the paper's 0.1-0.3 s or the ratio off √3/4 by 2% or more")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
