#!/usr/bin/env bash
# A scan folder of scans/quick.toml (app.scan_quick) rerun with the same values after what makes its members
# another model's run: MODE base, a base scene whose content changed (a comment added; member.json records the
# base's SHA-256); MODE physics, members of an earlier dcm (member.json without the model version, as before
# session 29 changed how Table 1's c is read). Every member is a new run, and while the new runs fail (a stand-in
# spread that checks scenes, then exits 1) no old result is reported for any member.
#   scan_base_changed.sh SCAN PYTHON3 SOURCE_DIR QUICK_OUT OUT MODE   (SCAN's folder holds spread)
set -u
scan=$1 py=$2 src=$3 quick=$4 out=$5 mode=$6
rm -rf "$out" && cp -r "$quick" "$out" || exit 1
if [ "$mode" = base ]; then
  { cat "$src/scenes/default.toml"; echo "# edited after the scan ran"; } > "$out.scene.toml"
  word="another base scene"
else
  "$py" - "$out" <<'PY' || exit 1
import glob, json, sys
for path in glob.glob(sys.argv[1] + "/members/*/member.json"):
    m = json.load(open(path))
    assert m.pop("physics", None) is not None, path  # the current scan records it
    json.dump(m, open(path, "w"))
PY
  cp "$src/scenes/default.toml" "$out.scene.toml"
  word="an earlier dcm"
fi
sed -e "s#\"../scenes/default.toml\"#\"$out.scene.toml\"#" "$src/scans/quick.toml" > "$out.toml"
grep -q "$out.scene.toml" "$out.toml" || { echo "scan_base_changed.sh: the scan file was not changed"; exit 1; }
printf '#!/usr/bin/env bash\nfor a in "$@"; do [ "$a" = --check ] && exec "%s" "$@"; done\nexit 1\n' \
  "$(dirname "$scan")/spread" > "$out.spread" && chmod +x "$out.spread"
"$scan" "$out.toml" --out "$out" --jobs 1 --threads 1 --no-plot --spread "$out.spread" > "$out.log" 2>&1
grep -q "4 members, 0 already done" "$out.log" || { cat "$out.log"; echo "members taken as done"; exit 1; }
grep -q "$word" "$out.log" || { cat "$out.log"; echo "no word on the change ($word)"; exit 1; }
"$py" - "$out" <<'PY' || { cat "$out.log"; exit 1; }
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1] + "/summary.csv")))
assert len(rows) == 4, rows
for r in rows:
    assert r["r_cc_final_m"] == "" and r["status"] != "done", r
print("4 members run again; no old result reported")
PY
