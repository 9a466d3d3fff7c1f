#!/usr/bin/env bash
# scan stopped by SIGINT while its members run, then the same command again: it exits 130 first, then finishes
# the missing members only (those done are not run again; the interrupted one continues from its checkpoint),
# and the result equals an uninterrupted scan (summary.csv values, member series byte for byte).
#   scan_resume.sh SCAN PYTHON3 SCAN_FILE OUT FULL_OUT
set -u
scan=$1 py=$2 file=$3 out=$4 full=$5
rm -rf "$out"
"$scan" "$file" --out "$out" --jobs 1 --threads 1 --no-plot --quiet &
pid=$!
for _ in $(seq 1200); do  # stop once the first member is done and the second has started (60 s at most)
  [ -f "$out/members/m000/summary.json" ] && [ -f "$out/members/m001/spread.log" ] && break
  sleep 0.05
done
kill -INT $pid
wait $pid
code=$?
[ $code = 130 ] || { echo "interrupted scan: exit $code, expected 130"; exit 1; }
before=$(stat -c %Y "$out/members/m000/summary.json")
"$scan" "$file" --out "$out" --jobs 1 --threads 1 --no-plot > "$out.log" 2>&1 || { cat "$out.log"; exit 1; }
grep -q "[123] already done" "$out.log" || { echo "resume did not keep the finished members:"; cat "$out.log"; exit 1; }
[ "$(stat -c %Y "$out/members/m000/summary.json")" = "$before" ] || { echo "m000 was run again"; exit 1; }
"$py" - "$out" "$full" <<'PY' || exit 1
import csv, sys
out, full = sys.argv[1], sys.argv[2]
keys = ["r_cc_final_m", "steps", "height_final_m"]
a = {r["id"]: r for r in csv.DictReader(open(out + "/summary.csv"))}
b = {r["id"]: r for r in csv.DictReader(open(full + "/summary.csv"))}
assert sorted(a) == sorted(b)
for mid in a:
    assert a[mid]["status"] == "done", a[mid]
    for k in keys:
        assert a[mid][k] == b[mid][k], (mid, k, a[mid][k], b[mid][k])
    assert open(f"{out}/members/{mid}/series.csv").read() == open(f"{full}/members/{mid}/series.csv").read(), mid
print("resumed scan = uninterrupted scan:", ", ".join(f"{m} r_cc {a[m]['r_cc_final_m']}" for m in sorted(a)))
PY
