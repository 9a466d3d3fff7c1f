#!/usr/bin/env bash
# scan under MPI on this machine (loopback): `mpirun -np 2 scan` gives the same scan.h5 and summary.csv as the
# single-process scan (bit for bit, wall times excepted), both with one shared output folder and with a private
# folder per rank (rank 1's member files then reach rank 0 through MPI); rank 1 really runs members; the same
# command again finds every member done and runs none.
#   scan_mpi.sh MPIRUN SCAN PYTHON3 COMPARE_PY SCAN_FILE OUT SINGLE_OUT
set -u
mpirun=$1 scan=$2 py=$3 compare=$4 file=$5 out=$6 single=$7
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
export HDF5_USE_FILE_LOCKING=FALSE
rm -rf "$out" "$out-private" "$out-private.rank1"
run() {  # run LOG ARGS...: mpirun -np 2 scan ARGS, its output in LOG
  local log=$1; shift
  "$mpirun" -np 2 "$scan" "$file" --jobs 1 --threads 1 --no-plot "$@" > "$log" 2>&1 || { cat "$log"; exit 1; }
  grep -q "2 MPI ranks" "$log" || { echo "not run as 2 MPI ranks:"; cat "$log"; exit 1; }
}
run "$out.log" --out "$out"
grep -q "^\[rank 1\] m0" "$out.log" || { echo "rank 1 ran no member:"; cat "$out.log"; exit 1; }
"$py" "$compare" "$single" "$out" || exit 1
DCM_SCAN_PRIVATE_DISKS=1 run "$out-private.log" --out "$out-private"
ls "$out-private.rank1/members"/m0*/summary.json > /dev/null 2>&1 || { echo "rank 1 wrote no member of its own"; exit 1; }
"$py" "$compare" "$single" "$out-private" || exit 1
run "$out-again.log" --out "$out"
grep -q "4 members, 4 already done" "$out-again.log" || { echo "the same command again ran members:"; cat "$out-again.log"; exit 1; }
grep -q "^\[rank" "$out-again.log" && { echo "the same command again ran members:"; cat "$out-again.log"; exit 1; }
echo "mpirun -np 2: same results as the single-process scan (shared and private folders); rerun ran nothing"
