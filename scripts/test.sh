#!/usr/bin/env bash
# Installs what is missing, builds everything (preset release; warnings are errors when CI=true), and runs
# the tests; then builds the unit tests with AddressSanitizer + UndefinedBehaviorSanitizer against a
# bounds-checked Kokkos and runs them (scripts/sanitize.sh; DCM_SKIP_SANITIZE=1 skips this stage).
#   scripts/test.sh [ctest arguments...]   e.g. scripts/test.sh -L unit
set -euo pipefail
cd "$(dirname "$0")/.."
builddir=$(bash scripts/build.sh release | tail -n 1)
(cd "$builddir" && ctest --output-on-failure --parallel "$(nproc)" "$@")
# The five longest integration tests (about 50 of the 70 s the unit tests take in release) would take half
# an hour sanitized; they run in the release stage above. scripts/sanitize.sh alone runs everything.
heavy='CortexModel.ImplicitTensionIsStable*:TimeStepper.AdaptiveError*:PlaneContact.RigidSphere*'
heavy+=':CortexModel.ImplicitBendingIsStable*:Multigrid.IterationsWellBelow*'
if [ "${DCM_SKIP_SANITIZE:-0}" != 1 ]; then
  bash scripts/sanitize.sh "-$heavy"
fi
