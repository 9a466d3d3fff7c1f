#!/usr/bin/env bash
# --jobs 1 --chunk 2 holds when a member that resumes from a checkpoint is drawn while a batch fills: the partial
# batch starts, the resuming member waits for the free slot (before session 28 both started at once). A copy of
# app.scan_quick's folder with m000 removed (a new member) and m001 holding only a checkpoint (it resumes); a
# stand-in spread records when each run starts and ends.
#   scan_jobs_limit.sh SCAN PYTHON3 SOURCE_DIR QUICK_OUT OUT   (SCAN's folder holds spread)
set -u
scan=$1 py=$2 src=$3 quick=$4 out=$5
rm -rf "$out" "$out.runs" && cp -r "$quick" "$out" || exit 1
rm -rf "$out/members/m000" && rm -f "$out/members/m001/summary.json" && touch "$out/members/m001/checkpoint.h5" || exit 1
sed -e "s#\"../scenes/default.toml\"#\"$src/scenes/default.toml\"#" "$src/scans/quick.toml" > "$out.toml"
printf '#!/usr/bin/env bash\nfor a in "$@"; do [ "$a" = --check ] && exec "%s" "$@"; done\n' "$(dirname "$scan")/spread" > "$out.spread"
printf 'echo "start $(date +%%s.%%N) $*" >> "%s"; sleep 1; echo "end $(date +%%s.%%N)" >> "%s"\n' "$out.runs" "$out.runs" >> "$out.spread"
chmod +x "$out.spread"
"$scan" "$out.toml" --out "$out" --jobs 1 --chunk 2 --threads 1 --no-plot --quiet --spread "$out.spread" > "$out.log" 2>&1
"$py" - "$out.runs" <<'PY' || { cat "$out.log" "$out.runs"; exit 1; }
import sys
lines = [l.split() for l in open(sys.argv[1])]
assert len(lines) == 4 and any("--restart" in l for l in lines), lines  # m000 and m001's restart, one each
running = 0
for l in lines:
    running += 1 if l[0] == "start" else -1
    assert running <= 1, "two runs at once with --jobs 1: " + str(lines)
print("2 runs, one at a time (--jobs 1), the resuming member after the partial batch")
PY
