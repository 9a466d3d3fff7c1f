#!/usr/bin/env bash
# scripts/check_outputs_finite.py must report every non-finite value in tests/lint/outputs_nonfinite (a CSV
# with nan and -Infinity and an empty field, which passes; a JSON with NaN; a JSON with 1e999, which reads as
# inf) and in an HDF5 file made here (a dataset with a nan and an inf; a group attribute inf), and exit 1;
# and exit 1 on a folder with no output file at all.
# usage: outputs_finite_catches.sh PYTHON3 SOURCE_DIR WORK_DIR
set -u
python=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cp "$src/tests/lint/outputs_nonfinite/"* "$work/" || exit 1
"$python" -c "import h5py, numpy, sys
with h5py.File(sys.argv[1], 'w') as f:
    f['/frames/0/tension'] = numpy.array([1.0, numpy.nan, numpy.inf])
    f['/frames/0'].attrs['time'] = numpy.inf
    f['/mesh/triangles'] = numpy.array([0, 1, 2])
    f['/series/t_s'] = numpy.array([0.0, 0.1])" "$work/spread.h5" || exit 1
out=$(HDF5_USE_FILE_LOCKING=FALSE "$python" "$src/scripts/check_outputs_finite.py" "$work")
code=$?
echo "$out"
[ "$code" = 1 ] || { echo "exit status $code, expected 1"; exit 1; }
for p in 'series.csv: row 2, column 2: nan' 'series.csv: row 3, column 3: -Infinity' 'summary.json: NaN' \
  'big.json: 1e999' 'spread.h5: /frames/0/tension: 2 non-finite of 3, first at index (1,)' \
  'spread.h5: /frames/0 attribute time: inf' '1 csv, 2 json, 1 h5 checked, 6 non-finite values'; do
  grep -qF "$p" <<< "$out" || { echo "not reported: $p"; exit 1; }
done
[ "$(wc -l <<< "$out")" = 7 ] || { echo "extra lines reported"; exit 1; }
mkdir -p "$work/empty"
"$python" "$src/scripts/check_outputs_finite.py" "$work/empty" > /dev/null && { echo "an empty folder passed"; exit 1; }
exit 0
