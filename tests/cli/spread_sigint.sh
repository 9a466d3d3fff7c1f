#!/usr/bin/env bash
# Ctrl-C on a long spread run: exit code 130, valid files (check_spread.py --interrupted), a checkpoint, and a
# restart from it that continues the step count where the interrupted run stopped.
#   spread_sigint.sh SPREAD PYTHON3 CHECK_SPREAD_PY OUT_DIR
set -u
spread=$1 python=$2 check=$3 out=$4
rm -rf "$out"
"$spread" --set mesh.nodes=162 --set time.t_end_s=100 --no-plot --quiet --out "$out" &
pid=$!
sleep 4
kill -INT $pid
wait $pid
rc=$?
[ $rc = 130 ] || { echo "exit code $rc, expected 130"; exit 1; }
"$python" "$check" "$out" --interrupted || exit 1
[ -f "$out/checkpoint.h5" ] || { echo "no checkpoint after Ctrl-C"; exit 1; }
steps() { "$python" -c "import json,sys; print(json.load(open(sys.argv[1]))['steps'])" "$out/summary.json"; }
before=$(steps)
"$spread" --restart "$out/checkpoint.h5" --max-steps $((before + 20)) --no-plot --quiet || exit 1
after=$(steps)
[ "$after" = $((before + 20)) ] || { echo "restart ran to step $after, expected $((before + 20))"; exit 1; }
echo "ok: interrupted at step $before, restarted to step $after"
