#!/usr/bin/env bash
# Builds dcm from scratch in a folder of its own (preset release) and times every compile: one line per
# translation unit, slowest first, then the sum and the build's wall time. For work on the build's length
# (CI's budget, docs/ARCHITECTURE.md "Compile once"). The build uses every core, as CI does.
#   scripts/compile_times.sh BUILD_DIR     e.g. scripts/compile_times.sh /tmp/dcm-times (an earlier one is replaced)
# Internally the script is also the compiler launcher: scripts/compile_times.sh --launch LOG COMPILER ARGS...
set -euo pipefail
if [ "${1:-}" = --launch ]; then
  log=$2
  shift 2
  start=$(date +%s%N)
  rc=0
  "$@" || rc=$?
  src=unknown
  for a in "$@"; do case "$a" in *.cpp) src=$a ;; esac; done
  echo "$(( ($(date +%s%N) - start) / 1000000 )) $src" >> "$log"
  exit $rc
fi
usage() { sed -n '2,6p' "$0" | sed 's/^# \{0,1\}//'; }
case "${1:-}" in -h | --help) usage; exit 0 ;; esac
if [ $# -ne 1 ] || [ "${1#-}" != "$1" ]; then
  echo "scripts/compile_times.sh: expected one build folder, got '$*' (scripts/compile_times.sh --help)" >&2
  exit 2
fi
out=$(realpath -m "$1")
cd "$(dirname "$0")/.."
root=$(pwd)
if [ -e "$out" ] && [ ! -f "$out/.dcm-compile-times" ]; then
  echo "scripts/compile_times.sh: $out exists and is not an earlier compile_times.sh folder; give a new folder" >&2
  exit 2
fi
kokkos=$(DCM_KOKKOS_VARIANT=release bash scripts/deps.sh | tail -n 1)
rm -rf "$out"
mkdir -p "$out"
touch "$out/.dcm-compile-times"  # the mark that lets a later run replace this folder
log=$out/compile_times.log
generator=Ninja  # the presets' generator, as scripts/build.sh uses it
cmake --preset release -B "$out" -G "$generator" -U Kokkos_DIR -DKokkos_ROOT="$kokkos" \
  "-DCMAKE_CXX_COMPILER_LAUNCHER=$root/scripts/compile_times.sh;--launch;$log" > "$out/configure.log"
start=$(date +%s)
cmake --build "$out" --parallel "$(nproc)" > "$out/build.log" 2>&1 || { tail -n 30 "$out/build.log" >&2; exit 1; }
wall=$(( $(date +%s) - start ))
sort -rn "$log" | awk -v root="$root/" '{sub(root, "", $2); printf "%8.1f s  %s\n", $1 / 1000, $2; s += $1}
  END {printf "%8.1f s  sum over %d compiles\n", s / 1000, NR}'
echo "$wall s wall ($(nproc) cores, $generator)"
