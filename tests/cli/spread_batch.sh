#!/bin/bash
# The batched engine end to end: spread --batch runs three members with different constants and end times as
# one model (162 nodes, adaptive steps through touch-down); each member's folder equals its run alone bit for
# bit (series.csv, HDF5 series and frames, summary.json but wall time: tests/cli/check_restart.py
# --independent); a batch member's checkpoint continues alone; a member that needs other kernels is refused
# with exit 2 and nothing written.
# usage: spread_batch.sh SPREAD PYTHON3 CHECK_RESTART_PY WORK_DIR
set -u
spread=$1 py=$2 check=$3 work=$4
rm -rf "$work" && mkdir -p "$work" || exit 1
base="--set mesh.nodes=162 --set time.adaptive=true --set time.t_end_s=0.03"
cat > "$work/members.txt" <<EOT
# three members: the base, more adhesion and an earlier end, stiffer bending with less substrate friction
$base --out "$work/batch/a"
$base --set contact.W_J_per_m2=2e-3 --set time.t_end_s=0.02 --out "$work/batch/b"
$base --set cortex.k_b_J=480e-21 --set contact.gamma_n_N_s_per_m3=4e9 --out "$work/batch/c"
EOT
OMP_NUM_THREADS=2 "$spread" --batch "$work/members.txt" --no-plot --quiet || { echo "batch failed"; exit 1; }
OMP_NUM_THREADS=1 "$spread" $base --out "$work/alone/a" --no-plot --quiet || exit 1
OMP_NUM_THREADS=1 "$spread" $base --set contact.W_J_per_m2=2e-3 --set time.t_end_s=0.02 --out "$work/alone/b" \
  --no-plot --quiet || exit 1
OMP_NUM_THREADS=1 "$spread" $base --set cortex.k_b_J=480e-21 --set contact.gamma_n_N_s_per_m3=4e9 \
  --out "$work/alone/c" --no-plot --quiet || exit 1
for m in a b c; do
  "$py" "$check" "$work/alone/$m" "$work/batch/$m" --independent || { echo "member $m differs from its run alone"; exit 1; }
done
# The members really differ (the constants reached their cells).
if cmp -s "$work/batch/a/series.csv" "$work/batch/c/series.csv"; then echo "members a and c are the same"; exit 1; fi
# A batch member's checkpoint is that of a run alone: it continues by itself to a later end.
OMP_NUM_THREADS=1 "$spread" --restart "$work/batch/b/checkpoint.h5" --set time.t_end_s=0.025 --no-plot --quiet \
  || { echo "restart of a batch member failed"; exit 1; }
# Members that need different kernels or settings cannot share a batch: exit 2, nothing written.
cat > "$work/bad.txt" <<EOT
$base --out "$work/bad/a"
$base --set mesh.nodes=642 --out "$work/bad/b"
EOT
out=$("$spread" --batch "$work/bad.txt" --quiet 2>&1); rc=$?
[ $rc -eq 2 ] || { echo "mixed mesh sizes: exit $rc, expected 2"; exit 1; }
echo "$out" | grep -q "mesh.nodes = 642" || { echo "mixed mesh sizes: message '$out'"; exit 1; }
[ ! -e "$work/bad" ] || { echo "a refused batch wrote $work/bad"; exit 1; }
# The adaptive contact-change limit is the stepper's, one for the batch: members that differ in it are refused.
cat > "$work/bad2.txt" <<EOT
$base --out "$work/bad2/a"
$base --set time.contact_change=0 --out "$work/bad2/b"
EOT
out2=$("$spread" --batch "$work/bad2.txt" --quiet 2>&1); rc=$?
[ $rc -eq 2 ] || { echo "mixed time.contact_change: exit $rc, expected 2"; exit 1; }
echo "$out2" | grep -q "time.contact_change = 0" || { echo "mixed time.contact_change: message '$out2'"; exit 1; }
[ ! -e "$work/bad2" ] || { echo "a refused batch wrote $work/bad2"; exit 1; }
echo "batch members equal their runs alone; restart of a member ok; mixed batches refused: $out / $out2"
