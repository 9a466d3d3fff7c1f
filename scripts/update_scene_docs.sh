#!/usr/bin/env bash
# Regenerates the table part of docs/SCENES.md from the scene schema (build/bin/geometry --list-keys).
set -euo pipefail
cd "$(dirname "$0")/.."
marker='<!-- generated below: do not edit by hand -->'
head=$(sed "/^$marker\$/q" docs/SCENES.md)
{ printf '%s\n' "$head"; build/bin/geometry --list-keys; } > docs/SCENES.md.tmp
mv docs/SCENES.md.tmp docs/SCENES.md
