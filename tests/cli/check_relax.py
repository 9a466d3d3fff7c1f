#!/usr/bin/env python3
"""Checks a relax output folder: series.csv ends at the run's end (summary t_end_s), and relaxation_time_s is
Hochmuth's form with the prefactor fixed at the first row, (λ − λ∞)/(λ + λ∞) = y0 exp(−t/t_c), fitted here
independently (least squares of log(y/y0) through the origin, rows from the start while y > 5% of y0).

usage: check_relax.py OUT
"""
import csv
import json
import math
import os
import sys


def fail(msg):
    print("check_relax: " + msg)
    sys.exit(1)


def main():
    out = sys.argv[1]
    rows = list(csv.DictReader(open(os.path.join(out, "series.csv"))))
    s = json.load(open(os.path.join(out, "summary.json")))
    if not math.isclose(float(rows[-1]["t_s"]), s["t_end_s"], rel_tol=1e-9):
        fail(f"series.csv ends at {rows[-1]['t_s']} s, the run at t_end_s = {s['t_end_s']} s")
    if not math.isclose(s["t_end_s"], s["steps"] * s["dt_s"], rel_tol=1e-12):
        fail(f"t_end_s = {s['t_end_s']} is not steps x dt_s")
    lam = s["lambda_inf"]
    t = [float(r["t_s"]) for r in rows]
    y = [(float(r["DA_m"]) / float(r["DT_m"]) - lam) / (float(r["DA_m"]) / float(r["DT_m"]) + lam) for r in rows]
    stt = sty = 0.0
    n = 0
    for ti, yi in zip(t, y):
        if not yi > 0.05 * y[0]:
            break
        stt += ti * ti
        sty += ti * math.log(yi / y[0])
        n += 1
    if n < 3:
        fail(f"only {n} rows above the fit floor")
    tc = -stt / sty
    if not (s["relaxation_time_s"] and math.isclose(s["relaxation_time_s"], tc, rel_tol=1e-6)):
        fail(f"relaxation_time_s = {s['relaxation_time_s']}, the fixed-prefactor fit of series.csv gives {tc}")
    print(f"check_relax: {out}: {len(rows)} rows to t = {t[-1]} s, t_c = {tc:.6g} s from {n} rows")


if __name__ == "__main__":
    main()
