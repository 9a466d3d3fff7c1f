#!/usr/bin/env bash
# Runs an app on bad input and checks the failure policy: the expected exit code, exactly one line on
# stderr containing every expected fragment, and no output folder left behind.
#   expect_error.sh EXIT_CODE "FRAGMENT[|FRAGMENT...]" OUT_DIR -- COMMAND...
# OUT_DIR "-": the app writes no folder (no --out is passed, nothing to check).
set -u
want_code=$1 fragments=$2 out_dir=$3
shift 3
[ "$1" = "--" ] && shift
err=$(mktemp)
if [ "$out_dir" = - ]; then
  "$@" > /dev/null 2> "$err"
  code=$?
else
  rm -rf "$out_dir"
  "$@" --out "$out_dir" > /dev/null 2> "$err"
  code=$?
fi
fail=0
if [ "$code" != "$want_code" ]; then echo "exit code $code, expected $want_code"; fail=1; fi
lines=$(wc -l < "$err")
if [ "$lines" != 1 ]; then echo "stderr has $lines lines, expected 1:"; cat "$err"; fail=1; fi
IFS='|' read -r -a parts <<< "$fragments"
for p in "${parts[@]}"; do
  grep -qF -- "$p" "$err" || { echo "stderr lacks '$p': $(cat "$err")"; fail=1; }
done
if [ "$out_dir" != - ] && [ -e "$out_dir" ]; then echo "output folder $out_dir was created"; fail=1; fi
[ $fail = 0 ] && echo "ok: exit $code: $(cat "$err")"
rm -f "$err"
exit $fail
