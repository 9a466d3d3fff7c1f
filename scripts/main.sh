#!/usr/bin/env bash
# The main job: installs what is missing, builds, and runs the default scene: a short cell-spreading run
# (apps/spread, scenes/default.toml: a 642-node sphered red blood cell, Table 1 parameters, 0.2 s).
# Output: out/default/ (series.csv, summary.json, spread.h5/.xmf, r_cc.png, cells.png, side_views.png).
# Extra arguments go to the app, e.g. scripts/main.sh --set time.t_end_s=0.5 --out out/longer.
set -euo pipefail
cd "$(dirname "$0")/.."
builddir=$(bash scripts/build.sh release spread | tail -n 1)
exec "$builddir/bin/spread" scenes/default.toml "$@"
