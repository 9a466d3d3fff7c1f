#!/usr/bin/env bash
# Builds the unit and I/O tests with AddressSanitizer + UndefinedBehaviorSanitizer (preset sanitize,
# build-sanitize/, -O1, against the release Kokkos) and runs every one of them: any memory error, leak or
# undefined behaviour fails the run. Part of scripts/test.sh (CI).
#   scripts/sanitize.sh [gtest filter for dcm_unit_tests]   (default: all; dcm_io_tests always run in full)
# The unit tests run as two gtest shards side by side, one OpenMP thread each (the I/O tests use two threads):
# about 4 minutes on 2 cores. Kokkos' own bounds checks are the debug preset's (scripts/build.sh debug).
set -euo pipefail
cd "$(dirname "$0")/.."
builddir=$(bash scripts/build.sh sanitize dcm_unit_tests dcm_io_tests | tail -n 1)
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export OMP_PROC_BIND=false
export DCM_FUZZ_SECONDS=${DCM_FUZZ_SECONDS:-20}
filter=${1:-*}
echo "[sanitize] dcm_io_tests (ASan + UBSan, 2 threads): scene parser and fuzzer, HDF5 output, checkpoints" >&2
OMP_NUM_THREADS=2 "$builddir/bin/dcm_io_tests" --gtest_brief=1
shards=2
echo "[sanitize] dcm_unit_tests --gtest_filter='$filter' (ASan + UBSan, $shards shards of 1 thread)" >&2
logs=$(mktemp -d)
pids=()
for ((i = 0; i < shards; ++i)); do
  OMP_NUM_THREADS=1 GTEST_TOTAL_SHARDS=$shards GTEST_SHARD_INDEX=$i \
    "$builddir/bin/dcm_unit_tests" --gtest_filter="$filter" --gtest_brief=1 > "$logs/shard$i.log" 2>&1 &
  pids+=($!)
done
failed=0
for ((i = 0; i < shards; ++i)); do
  if ! wait "${pids[$i]}"; then failed=1; fi
  echo "[sanitize] shard $i:" >&2
  cat "$logs/shard$i.log" >&2
done
rm -rf "$logs"
if [ $failed != 0 ]; then
  echo "[sanitize] FAILED: see the shard logs above" >&2
  exit 1
fi
echo "[sanitize] clean: no sanitizer report in any unit or I/O test" >&2
