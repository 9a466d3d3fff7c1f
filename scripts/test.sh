#!/usr/bin/env bash
# Installs what is missing, builds everything (preset release; warnings are errors when CI=true), and runs
# the tests; then builds the unit and I/O tests with AddressSanitizer + UndefinedBehaviorSanitizer and runs
# all of them (scripts/sanitize.sh; DCM_SKIP_SANITIZE=1 skips this stage).
#   scripts/test.sh [ctest arguments...]   e.g. scripts/test.sh -L unit
set -euo pipefail
cd "$(dirname "$0")/.."
builddir=$(bash scripts/build.sh release | tail -n 1)
echo "test.sh: build done after ${SECONDS} s" >&2
start=$SECONDS
(cd "$builddir" && ctest --output-on-failure --parallel "$(nproc)" "$@")
echo "test.sh: ctest took $((SECONDS - start)) s" >&2
# Then every unit and I/O test again, built with ASan + UBSan (session 19's Intel VM: build 6.0 min, tests
# 3.5 min; session 20's Zen 5 VM: build 4.5 min, tests 2 min).
if [ "${DCM_SKIP_SANITIZE:-0}" != 1 ]; then
  start=$SECONDS
  bash scripts/sanitize.sh
  echo "test.sh: the sanitizer build and run took $((SECONDS - start)) s" >&2
fi
