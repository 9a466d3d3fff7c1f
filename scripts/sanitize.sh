#!/usr/bin/env bash
# Builds the unit and I/O tests with AddressSanitizer + UndefinedBehaviorSanitizer (preset sanitize,
# build-sanitize/, -O1, against the release Kokkos) and runs every one of them: any memory error, leak or
# undefined behaviour that UBSan checks fails the run (all of -fsanitize=undefined but its null and alignment
# checks, unless configured with -DDCM_SANITIZE_TYPE_CHECKS=ON: docs/ARCHITECTURE.md, "CI's length").
# Part of scripts/test.sh (CI).
#   scripts/sanitize.sh [gtest filter for dcm_unit_tests]   (default: all; dcm_io_tests always run in full)
# The tests run in two lanes side by side (below): about 2 minutes on 2 cores (session 20). Kokkos' own bounds checks are
# the debug preset's (scripts/build.sh debug).
set -euo pipefail
cd "$(dirname "$0")/.."
builddir=$(bash scripts/build.sh sanitize dcm_unit_tests dcm_io_tests | tail -n 1)
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export OMP_PROC_BIND=false
export DCM_FUZZ_SECONDS=${DCM_FUZZ_SECONDS:-20}
filter=${1:-*}
# Two lanes, one per core, one OpenMP thread each (the I/O tests: two). The two slowest unit tests under the
# sanitizers share a lane with a quarter of the other unit tests; the I/O tests and the other three quarters
# make the second lane. Session 20 (Zen 5 VM), with both slow tests on the multigrid preconditioner: 40 and
# 20 s alone, 63-83 s together while the other lane runs; the rest of the unit tests about 90 s, the I/O tests
# 16 s. gtest's own two shards put both slow tests in one shard (106 s against 41 s). A failing part of a lane
# does not stop the lane's other parts. With a filter the unit tests run as two gtest shards.
slow_a=CortexModel.ImplicitTensionIsStableWhereExplicitTensionIsNot
slow_b=TimeStepper.AdaptiveErrorFollowsTheTolerance
unit() {  # gtest filter, then shard index and count (or nothing)
  if [ $# -eq 3 ]; then
    OMP_NUM_THREADS=1 GTEST_TOTAL_SHARDS=$3 GTEST_SHARD_INDEX=$2 \
      "$builddir/bin/dcm_unit_tests" --gtest_filter="$1" --gtest_brief=1
  else
    OMP_NUM_THREADS=1 "$builddir/bin/dcm_unit_tests" --gtest_filter="$1" --gtest_brief=1
  fi
}
io() {
  echo "[sanitize] dcm_io_tests (2 threads): scene parser and fuzzer, HDF5 output, checkpoints"
  OMP_NUM_THREADS=2 "$builddir/bin/dcm_io_tests" --gtest_brief=1
}
if [ "$filter" = "*" ]; then
  rest="*-$slow_a:$slow_b"
  lane0() {
    local rc=0
    unit "$slow_a:$slow_b" || rc=1
    unit "$rest" 0 4 || rc=1
    return $rc
  }
  lane1() {
    local rc=0
    io || rc=1
    unit "$rest" 1 4 || rc=1
    unit "$rest" 2 4 || rc=1
    unit "$rest" 3 4 || rc=1
    return $rc
  }
else
  lane0() { unit "$filter" 0 2; }
  lane1() {
    local rc=0
    io || rc=1
    unit "$filter" 1 2 || rc=1
    return $rc
  }
fi
echo "[sanitize] dcm_unit_tests --gtest_filter='$filter' and dcm_io_tests (ASan + UBSan) in two lanes" >&2
logs=$(mktemp -d)
lane0 > "$logs/lane0.log" 2>&1 &
pid0=$!
lane1 > "$logs/lane1.log" 2>&1 &
pid1=$!
failed=0
wait $pid0 || failed=1
wait $pid1 || failed=1
for i in 0 1; do
  echo "[sanitize] lane $i:" >&2
  cat "$logs/lane$i.log" >&2
done
rm -rf "$logs"
if [ $failed != 0 ]; then
  echo "[sanitize] FAILED: see the lane logs above" >&2
  exit 1
fi
echo "[sanitize] clean: no sanitizer report in any unit or I/O test" >&2
