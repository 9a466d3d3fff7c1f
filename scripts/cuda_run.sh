#!/usr/bin/env bash
# Runs dcm's CUDA build on a machine with an NVIDIA GPU: the unit tests (default execution space Cuda), the
# step benchmark (Cuda and OpenMP rows, per kernel with fences, then whole steps unfenced) and the paper's
# hategan2004_sphered scene (adaptive steps, 1e-8 m) for its time to solution. Each part has its own time
# limit, so a slow part leaves the others' results. Logs and CSVs go to OUT_DIR (default out/cuda-run).
#   scripts/cuda_run.sh [BIN_DIR [OUT_DIR]]     # BIN_DIR default build-cuda/bin (scripts/build.sh cuda)
# Limits in seconds, from the environment: UNIT_S (120), BENCH_S (150), BENCH2_S (60), SPREAD_S (90).
# A bundle made by scripts/cuda_bundle.sh holds its own libraries in lib/ beside bin/; they are used.
set -uo pipefail
# Paths given are taken from the caller's folder; then the work runs in the folder above this script (the
# repository, or the bundle), where scenes/ is.
abs() { case "$1" in /*) echo "$1" ;; *) echo "$PWD/$1" ;; esac; }
bin=${1:+$(abs "$1")}
out=${2:+$(abs "$2")}
cd "$(dirname "$0")/.."
bin=${bin:-$PWD/build-cuda/bin}
out=${out:-$PWD/out/cuda-run}
[ -x "$bin/dcm_unit_tests" ] || { echo "cuda_run: $bin/dcm_unit_tests does not exist (build with scripts/build.sh cuda)" >&2; exit 2; }
nvidia-smi -L > /dev/null 2>&1 || { echo "cuda_run: no NVIDIA GPU visible (nvidia-smi -L fails); nothing run" >&2; exit 2; }
mkdir -p "$out"
if [ -d "$bin/../lib" ]; then export LD_LIBRARY_PATH="$(cd "$bin/../lib" && pwd):${LD_LIBRARY_PATH:-}"; fi
export OMP_PROC_BIND=false CUDA_CACHE_MAXSIZE=2147483648
threads=$(nproc)
log=$out/log.txt
: > "$log"
say() { echo "$*" | tee -a "$log"; }
part() {  # part NAME LIMIT_S COMMAND...: runs it, logs its exit code and seconds
  local name=$1 limit=$2 t0=$SECONDS rc
  shift 2
  say "== $name"
  timeout "$limit" "$@" >> "$log" 2>&1
  rc=$?
  say "-- $name: exit code $rc, $((SECONDS - t0)) s$([ $rc = 124 ] && echo " (stopped at the ${limit} s limit)")"
}
{ date; nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm --format=csv
  lscpu | grep -E "Model name|^CPU\(s\)"; } >> "$log" 2>&1
for b in "$bin"/*; do
  [ -x "$b" ] && [ -f "$b" ] && ldd "$b" 2>/dev/null | grep "not found" | sed "s|^|$(basename "$b"): |" | tee -a "$log"
done
part "membrane tests, portable build" 60 env OMP_NUM_THREADS="$threads" "$bin/dcm_membrane_portable_tests"
part "unit tests" "${UNIT_S:-120}" env OMP_NUM_THREADS="$threads" "$bin/dcm_unit_tests" \
  --gtest_output="xml:$out/unit.xml"
grep -E "^\[  (PASSED|FAILED) |tests ran" "$log" | tee "$out/unit_summary.txt"
say "== bench_step (per kernel, fenced)"
timeout "${BENCH_S:-150}" "$bin/bench_step" --levels 3,4,5,6 --scenes stretch,spread --threads "1,2,$threads" \
  --no-serial --steps 20 --warmup 5 --repeat 2 > "$out/bench_step.csv" 2>> "$log"
say "-- exit code $?"
say "== bench_step (whole steps, unfenced)"
timeout "${BENCH2_S:-60}" "$bin/bench_step" --levels 3,4,5,6 --scenes stretch,spread --threads "$threads" \
  --no-serial --no-kernel-times --steps 20 --warmup 5 --repeat 2 > "$out/bench_unfenced.csv" 2>> "$log"
say "-- exit code $?"
cat "$out/bench_unfenced.csv" >> "$log"
part "spread hategan2004_sphered (adaptive, 1e-8 m)" "${SPREAD_S:-90}" "$bin/spread" scenes/hategan2004_sphered.toml \
  --set time.adaptive=true --set time.error_tol_m=1e-8 --quiet --out "$out/hategan2004_sphered"
tail -n 25 "$log"
