#!/usr/bin/env bash
# A scan folder of scans/quick.toml (app.scan_quick), rerun with the W values changed and stopped by SIGINT
# while the first changed member runs (a stand-in spread that checks scenes but sleeps instead of running), so
# the second changed member is never launched and its folder still holds the old value's run: summary.csv and
# scan.h5 must not report that run's results for it, and must keep those of the unchanged members.
#   scan_stale.sh SCAN PYTHON3 SOURCE_DIR QUICK_OUT OUT   (SCAN's folder holds spread)
set -u
scan=$1 py=$2 src=$3 quick=$4 out=$5
rm -rf "$out" && cp -r "$quick" "$out" || exit 1
sed -e "s#\"../scenes/default.toml\"#\"$src/scenes/default.toml\"#" \
    -e 's#"contact.W_J_per_m2" = \[0.5e-3, 2e-3\]#"contact.W_J_per_m2" = [0.7e-3, 3e-3]#' \
    "$src/scans/quick.toml" > "$out.toml"
grep -q '0.7e-3, 3e-3' "$out.toml" || { echo "scan_stale.sh: the scan file was not changed"; exit 1; }
printf '#!/usr/bin/env bash\nfor a in "$@"; do [ "$a" = --check ] && exec "%s" "$@"; done\nexec sleep 60\n' \
  "$(dirname "$scan")/spread" > "$out.spread" && chmod +x "$out.spread"
"$scan" "$out.toml" --out "$out" --jobs 1 --threads 1 --no-plot --quiet --spread "$out.spread" > "$out.log" 2>&1 &
pid=$!
for _ in $(seq 600); do  # until the first changed member is launched (its folder cleared: no summary.json)
  [ -f "$out/members/m001/summary.json" ] || break
  sleep 0.05
done
sleep 0.5
kill -INT $pid
wait $pid
"$py" - "$out" "$quick" <<'PY' || { cat "$out.log"; exit 1; }
import csv, sys
import h5py
out, quick = sys.argv[1], sys.argv[2]
new = {r["id"]: r for r in csv.DictReader(open(out + "/summary.csv"))}
old = {r["id"]: r for r in csv.DictReader(open(quick + "/summary.csv"))}
changed = [m for m in new if new[m]["contact.W_J_per_m2"] not in ("", old[m]["contact.W_J_per_m2"])]
kept = [m for m in new if m not in changed]
assert len(changed) == 2 and len(kept) == 2, (changed, kept)
with h5py.File(out + "/scan.h5", "r") as h5:
    for m in changed:
        assert new[m]["r_cc_final_m"] == "", (m, new[m])
        assert "r_cc_final_m" not in h5["members"][m].attrs and "series" not in h5["members"][m], m
    for m in kept:
        assert new[m]["r_cc_final_m"] == old[m]["r_cc_final_m"] != "", (m, new[m], old[m])
        assert "series" in h5["members"][m], m
print("changed members", changed, "not reported; kept", kept)
PY
