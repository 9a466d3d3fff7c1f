#!/usr/bin/env bash
# The main job: installs what is missing, builds, and runs the default scene.
# For now the main job builds the default cell mesh and reports its geometry (apps/geometry); extra
# arguments go to the app, e.g. scripts/main.sh --set mesh.shape=evans_fung.
set -euo pipefail
cd "$(dirname "$0")/.."
builddir=$(bash scripts/build.sh release geometry | tail -n 1)
exec "$builddir/bin/geometry" scenes/default.toml "$@"
