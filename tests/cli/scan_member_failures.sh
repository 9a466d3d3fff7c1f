#!/usr/bin/env bash
# How scan reports members that end other than by finishing or by a numerical failure. A copy of app.scan_quick's
# folder with m001 and m002 removed (they run again) and a stand-in spread that, for the first run, ends m001
# with exit code 1 and m002 by SIGSEGV: scan exits 1 (not 3: no member failed numerically), names both on
# stderr, and summary.csv says "failed (exit 1)" and "failed (killed by signal 11)". Second run: m001 ended by
# SIGINT before spread's own handler (a Ctrl-C at its start) counts as interrupted (exit 130), m002 finishes.
# Third run: the real spread finishes m001, exit 0.
#   scan_member_failures.sh SCAN PYTHON3 SOURCE_DIR QUICK_OUT OUT   (SCAN's folder holds spread)
set -u
scan=$1 py=$2 src=$3 quick=$4 out=$5
spread="$(dirname "$scan")/spread"
rm -rf "$out" && cp -r "$quick" "$out" && rm -rf "$out/members/m001" "$out/members/m002" || exit 1
sed -e "s#\"../scenes/default.toml\"#\"$src/scenes/default.toml\"#" "$src/scans/quick.toml" > "$out.toml"
cat > "$out.spread" <<WRAP
#!/usr/bin/env bash
die() { exec "$py" -c "import os, signal; signal.signal(signal.SIG\$1, signal.SIG_DFL); os.kill(os.getpid(), signal.SIG\$1)"; }
for a in "\$@"; do [ "\$a" = --check ] && exec "$spread" "\$@"; done  # scan's checks (with --out too)
for a in "\$@"; do
  case "\$a" in
    */members/m001) [ "\$MODE" = crash ] && { echo "stand-in: exit 1" >&2; exit 1; }; [ "\$MODE" = int ] && die INT ;;
    */members/m002) [ "\$MODE" = crash ] && die SEGV ;;
  esac
done
exec "$spread" "\$@"
WRAP
chmod +x "$out.spread"
fail() { echo "FAIL: $*"; cat "$out.log"; cat "$out/summary.csv"; exit 1; }
status_of() { "$py" -c "import csv, sys; print({r['id']: r['status'] for r in csv.DictReader(open(sys.argv[1]))}[sys.argv[2]])" "$out/summary.csv" "$1"; }

MODE=crash "$scan" "$out.toml" --out "$out" --jobs 2 --threads 1 --no-plot --quiet --spread "$out.spread" > "$out.log" 2>&1
rc=$?
[ $rc = 1 ] || fail "crash run: exit $rc, expected 1"
grep -q "2 member(s) failed: m001 (exit 1), m002 (killed by signal 11)" "$out.log" || fail "crash run: no line naming the failed members"
[ "$(status_of m001)" = "failed (exit 1)" ] || fail "m001: $(status_of m001)"
[ "$(status_of m002)" = "failed (killed by signal 11)" ] || fail "m002: $(status_of m002)"
[ "$(status_of m000)" = done ] && [ "$(status_of m003)" = done ] || fail "m000/m003 not kept as done"

MODE=int "$scan" "$out.toml" --out "$out" --jobs 2 --threads 1 --no-plot --quiet --spread "$out.spread" > "$out.log" 2>&1
rc=$?
[ $rc = 130 ] || fail "SIGINT run: exit $rc, expected 130"
[ "$(status_of m001)" = interrupted ] || fail "m001 after SIGINT: $(status_of m001)"
[ "$(status_of m002)" = done ] || fail "m002 in the second run: $(status_of m002)"

"$scan" "$out.toml" --out "$out" --jobs 2 --threads 1 --no-plot --quiet > "$out.log" 2>&1
rc=$?
[ $rc = 0 ] || fail "third run: exit $rc, expected 0"
[ "$(status_of m001)" = done ] || fail "m001 in the third run: $(status_of m001)"
echo "exit 1 for a crashed member and a signalled one (both named), SIGINT at a member's start: interrupted (130), then done"
