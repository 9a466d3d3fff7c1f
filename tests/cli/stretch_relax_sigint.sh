#!/usr/bin/env bash
# Ctrl-C on long stretch and relax runs (session 41; they left series.csv.tmp and no summary.json): exit code
# 130, series.csv and summary.json written with what was done ("interrupted": true), no .tmp file left.
# The signal is sent once the run has written a row (so its handler is in place, whatever the machine's load);
# a run still alive 120 s after it is killed and the test fails.
#   stretch_relax_sigint.sh BIN_DIR PYTHON3 OUT_DIR
set -u
bin=$1 python=$2 out=$3
rm -rf "$out" && mkdir -p "$out"
forces=$("$python" -c "print(','.join(str(i / 10) for i in range(2001)))")  # 0 .. 200 pN, 2001 forces
interrupt() {  # pid, the .tmp file to wait for; sets rc to the exit code (no $(...): wait needs this shell)
  local pid=$1 tmp=$2 k
  for k in $(seq 600); do  # up to 60 s for the first row
    [ -f "$tmp" ] && [ "$(wc -l < "$tmp")" -ge 2 ] && break
    kill -0 "$pid" 2> /dev/null || break
    sleep 0.1
  done
  kill -INT "$pid" 2> /dev/null
  for k in $(seq 1200); do
    kill -0 "$pid" 2> /dev/null || break
    sleep 0.1
  done
  kill -0 "$pid" 2> /dev/null && { kill -KILL "$pid"; echo "still running 120 s after SIGINT" >&2; }
  wait "$pid"
  rc=$?
}
check() {  # app folder rows_max exit_code
  local app=$1 dir=$2 max=$3 rc=$4
  [ "$rc" = 130 ] || { echo "$app: exit code $rc, expected 130"; exit 1; }
  [ -f "$dir/series.csv" ] && [ ! -e "$dir/series.csv.tmp" ] || { echo "$app: series.csv missing or .tmp left"; ls "$dir"; exit 1; }
  "$python" - "$dir" "$max" "$app" << 'PY' || exit 1
import csv, json, sys
d, most, app = sys.argv[1], int(sys.argv[2]), sys.argv[3]
rows = list(csv.DictReader(open(d + "/series.csv")))
s = json.load(open(d + "/summary.json"))
assert s["interrupted"] is True, s
assert 1 <= len(rows) < most, (app, len(rows))
print(f"ok: {app} interrupted with {len(rows)} rows in series.csv, summary.json interrupted = true")
PY
}
rc=0
"$bin/stretch" --set mesh.nodes=162 --forces-pN "$forces" --no-plot --quiet --out "$out/stretch" &
interrupt $! "$out/stretch/series.csv.tmp"
check stretch "$out/stretch" 2001 $rc
"$bin/relax" --set mesh.nodes=162 --duration-s 100 --no-plot --quiet --out "$out/relax" &
interrupt $! "$out/relax/series.csv.tmp"
check relax "$out/relax" 1000000 $rc
