#!/usr/bin/env python3
"""Check that no output file of a dcm app holds a non-finite number.

usage: check_outputs_finite.py DIR [DIR ...]

Walks every DIR for the files the apps write (*.csv, *.json, *.h5) and reports each value that is
nan or inf: CSV fields (any spelling: nan, -nan, NaN, inf, -Infinity, ...), JSON numbers (Python's
reader accepts NaN/Infinity, which other readers refuse, and reads 1e999 as inf), and floating-point HDF5
datasets and attributes (needs h5py; without it the HDF5 files are counted as skipped). An app must report numerical trouble by name (step,
term, node), never write it as a number (DEVELOPERS.md). An empty field is not a number and passes.

Prints one line per problem (file, place, value) and a count; exit status 0 if none, 1 if any or if the
folders hold no such file at all (the tests that write them did not run), 2 on bad usage.
"""
import csv
import json
import math
import os
import sys

NON_FINITE = {"nan", "-nan", "+nan", "inf", "-inf", "+inf", "infinity", "-infinity", "+infinity"}


def is_non_finite_text(field):
    return field.strip().lower() in NON_FINITE


def check_csv(path, problems):
    with open(path, newline="", errors="replace") as f:
        for row_number, row in enumerate(csv.reader(f), start=1):
            for column, field in enumerate(row, start=1):
                if is_non_finite_text(field):
                    problems.append(f"{path}: row {row_number}, column {column}: {field.strip()}")


def check_json(path, problems):
    found = []

    def constant(name):  # called for NaN, Infinity, -Infinity
        found.append(name)
        return None

    def number(text):  # a literal too large for a double (1e999) reads as inf
        value = float(text)
        if not math.isfinite(value):
            found.append(text)
        return value

    with open(path, errors="replace") as f:
        text = f.read()
    try:
        json.loads(text, parse_constant=constant, parse_float=number)
    except ValueError as error:
        problems.append(f"{path}: not valid JSON ({error})")
        return
    for name in found:
        problems.append(f"{path}: {name}")


def check_h5(path, problems, h5py, numpy):
    def attributes(name, obj):  # of every group and dataset, the root included
        for key, value in obj.attrs.items():
            values = numpy.asarray(value)
            if values.dtype.kind in "fc" and not numpy.isfinite(values).all():
                problems.append(f"{path}: /{name} attribute {key}: {value}")

    def visit(name, obj):
        attributes(name, obj)
        if not isinstance(obj, h5py.Dataset) or obj.dtype.kind not in "fc":
            return
        data = numpy.asarray(obj[()])
        bad = ~numpy.isfinite(data)
        if bad.any():
            first = numpy.argwhere(bad)[0] if data.ndim else ()
            problems.append(f"{path}: /{name}: {int(bad.sum())} non-finite of {data.size}, "
                            f"first at index {tuple(int(i) for i in first)}")

    try:
        with h5py.File(path, "r") as f:
            attributes("", f)
            f.visititems(visit)
    except OSError as error:
        problems.append(f"{path}: cannot be read as HDF5 ({error})")


def main(argv):
    if len(argv) < 2 or argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        return 0 if len(argv) >= 2 else 2
    try:
        import h5py
        import numpy
    except ImportError:
        h5py = numpy = None
    os.environ.setdefault("HDF5_USE_FILE_LOCKING", "FALSE")
    problems = []
    counts = {"csv": 0, "json": 0, "h5": 0, "h5 skipped": 0}
    for root_dir in argv[1:]:
        if not os.path.isdir(root_dir):
            print(f"check_outputs_finite: {root_dir} is not a folder", file=sys.stderr)
            return 2
        for folder, _, files in os.walk(root_dir):
            for name in sorted(files):
                path = os.path.join(folder, name)
                if name.endswith(".csv"):
                    counts["csv"] += 1
                    check_csv(path, problems)
                elif name.endswith(".json"):
                    counts["json"] += 1
                    check_json(path, problems)
                elif name.endswith(".h5"):
                    if h5py is None:
                        counts["h5 skipped"] += 1
                    else:
                        counts["h5"] += 1
                        check_h5(path, problems, h5py, numpy)
    for line in problems:
        print(line)
    checked = ", ".join(f"{n} {kind}" for kind, n in counts.items() if n and kind != "h5 skipped")
    skipped = f" ({counts['h5 skipped']} HDF5 files skipped: no h5py)" if counts["h5 skipped"] else ""
    if not checked:  # nothing to check is not a pass: the app tests that write the outputs did not run
        print(f"check_outputs_finite: no CSV, JSON or HDF5 file under {' '.join(argv[1:])}{skipped}: run the app "
              f"tests first (ctest -R '^app[.]|^validation[.]')")
        return 1
    print(f"{checked} checked{skipped}, {len(problems)} non-finite values")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
