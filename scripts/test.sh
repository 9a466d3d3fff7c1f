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
# Then every unit and I/O test again, built with ASan + UBSan (about 10 minutes with the build; session 19:
# build 6.8 min, tests 3.5 min).
if [ "${DCM_SKIP_SANITIZE:-0}" != 1 ]; then
  start=$SECONDS
  bash scripts/sanitize.sh
  echo "test.sh: the sanitizer build and run took $((SECONDS - start)) s" >&2
fi
