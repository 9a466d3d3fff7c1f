#!/usr/bin/env bash
# A scan folder of scans/quick.toml (app.scan_quick) whose members were run by an earlier dcm (member.json without
# the model version, as before session 29 changed how Table 1's c is read): rerun with the same scan file, every
# member is a new run, and while the new runs fail (a stand-in spread that checks scenes, then exits 1) no old
# result is reported.   scan_physics_changed.sh SCAN PYTHON3 SOURCE_DIR QUICK_OUT OUT   (SCAN's folder holds spread)
set -u
scan=$1 py=$2 src=$3 quick=$4 out=$5
rm -rf "$out" && cp -r "$quick" "$out" || exit 1
"$py" - "$out" <<'PY' || exit 1
import glob, json, sys
for path in glob.glob(sys.argv[1] + "/members/*/member.json"):
    m = json.load(open(path))
    assert m.pop("physics", None) is not None, path  # the current scan records it
    json.dump(m, open(path, "w"))
PY
sed -e "s#\"../scenes/default.toml\"#\"$src/scenes/default.toml\"#" "$src/scans/quick.toml" > "$out.toml"
printf '#!/usr/bin/env bash\nfor a in "$@"; do [ "$a" = --check ] && exec "%s" "$@"; done\nexit 1\n' \
  "$(dirname "$scan")/spread" > "$out.spread" && chmod +x "$out.spread"
"$scan" "$out.toml" --out "$out" --jobs 1 --threads 1 --no-plot --spread "$out.spread" > "$out.log" 2>&1
grep -q "4 members, 0 already done" "$out.log" || { cat "$out.log"; echo "members of an earlier dcm taken as done"; exit 1; }
grep -q "an earlier dcm" "$out.log" || { cat "$out.log"; echo "no word on the earlier dcm"; exit 1; }
"$py" - "$out" <<'PY' || { cat "$out.log"; exit 1; }
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1] + "/summary.csv")))
assert len(rows) == 4, rows
for r in rows:
    assert r["r_cc_final_m"] == "" and r["status"] != "done", r
print("4 members of an earlier dcm run again; no old result reported")
PY
