#!/usr/bin/env bash
# Installs what is missing, builds everything (preset release; warnings are errors when CI=true), and runs
# the tests; then builds the unit tests with AddressSanitizer + UndefinedBehaviorSanitizer against a
# bounds-checked Kokkos and runs them (scripts/sanitize.sh; DCM_SKIP_SANITIZE=1 skips this stage).
#   scripts/test.sh [ctest arguments...]   e.g. scripts/test.sh -L unit
set -euo pipefail
cd "$(dirname "$0")/.."
builddir=$(bash scripts/build.sh release | tail -n 1)
(cd "$builddir" && ctest --output-on-failure --parallel "$(nproc)" "$@")
# Sanitized, the unit tests run 10-50 times slower (ASan, UBSan and a bounds check on every View access):
# CI runs the kernel suites (mesh, geometry, curvature, single terms, friction, PCG, contact law and kernels,
# quadrature, backends; about a minute), every I/O test, and the release stage above runs everything.
kernels='Topology.*:Icosphere.*:EvansFung.*:TriangleCurvature.*:VolumeConstraint.*:FenePowSingleBond.*'
kernels+=':BendingSingleHinge.*:BendingTetrahedron.*:FenePow.*:FrictionOperator.*:Pcg.*:QuadratureRules.*'
kernels+=':ContactDistribution.*:MaugisDugdale*:PlaneContactEdges.*:Backends.*'
if [ "${DCM_SKIP_SANITIZE:-0}" != 1 ]; then
  bash scripts/sanitize.sh "$kernels"
fi
