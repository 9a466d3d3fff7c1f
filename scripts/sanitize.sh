#!/usr/bin/env bash
# Builds the unit tests with AddressSanitizer + UndefinedBehaviorSanitizer against a Kokkos with bounds
# checking on every View access (preset sanitize, build-sanitize/), and runs them: any memory error, leak,
# undefined behaviour or out-of-bounds View access fails the run. Part of scripts/test.sh (CI).
#   scripts/sanitize.sh [gtest filter for dcm_unit_tests]   (dcm_io_tests always run in full)
# Without a filter every unit test runs: more than an hour on 2 cores (the finite-difference gradient and
# stability tests make millions of checked View accesses); scripts/test.sh passes the fast kernel suites.
set -euo pipefail
cd "$(dirname "$0")/.."
builddir=$(bash scripts/build.sh sanitize dcm_unit_tests dcm_io_tests | tail -n 1)
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export OMP_PROC_BIND=false OMP_NUM_THREADS=2
export DCM_FUZZ_SECONDS=${DCM_FUZZ_SECONDS:-20}
filter=${1:-*}
echo "[sanitize] dcm_io_tests (ASan + UBSan): scene parser and fuzzer, HDF5 output, checkpoints" >&2
"$builddir/bin/dcm_io_tests" --gtest_brief=1
echo "[sanitize] dcm_unit_tests --gtest_filter='$filter' (ASan + UBSan, Kokkos bounds checks)" >&2
"$builddir/bin/dcm_unit_tests" --gtest_filter="$filter" --gtest_brief=1
echo "[sanitize] clean: no sanitizer or bounds-check report" >&2
