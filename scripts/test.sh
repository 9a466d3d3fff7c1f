#!/usr/bin/env bash
# Installs what is missing, builds everything (preset release; warnings are errors
# when CI=true), and runs the tests.
#   scripts/test.sh [ctest arguments...]   e.g. scripts/test.sh -L unit
set -euo pipefail
cd "$(dirname "$0")/.."
builddir=$(bash scripts/build.sh release | tail -n 1)
cd "$builddir"
ctest --output-on-failure --parallel "$(nproc)" "$@"
