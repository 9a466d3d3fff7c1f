#!/usr/bin/env bash
# The spreading runs behind docs/VALIDATION.md ("Spreading"): the paper scenes, the 642-node Hategan case
# for the mesh comparison, and one run per direction of the paper's Figure 5, in two queues of one thread
# each (2 cores). Output: out/validation/<run>/ (each a spread output folder). Takes about an hour.
# (The full paper scenes: build/bin/spread scenes/<scene>.toml.)
#   bash scripts/spread_validation.sh [QUEUE]    # QUEUE = 1, 2 or both (default)
set -euo pipefail
cd "$(dirname "$0")/.."
builddir=$(bash scripts/build.sh release spread | tail -n 1)
spread="$builddir/bin/spread"
out=out/validation
mkdir -p "$out"
run() {  # name, then the spread arguments
  local name=$1
  shift
  echo "== $name: $*"
  OMP_NUM_THREADS=1 "$spread" "$@" --quiet --out "$out/$name" > "$out/$name.log" 2>&1 || echo "   $name failed: $(tail -n 1 "$out/$name.log")"
}
# The 2562-node runs cost ~25 ms per step on one thread (35 steps/s): the Hategan case is run to 0.6 s here
# (its spreading has levelled off by then at 642 nodes), the biconcave comparison on 642 nodes.
queue1() {
  run hategan2004_sphered scenes/hategan2004_sphered.toml --set time.t_end_s=0.6
  run hategan2004_biconcave_642 scenes/hategan2004_biconcave.toml --set mesh.nodes=642 --set time.t_end_s=0.6
}
queue2() {
  local base=(scenes/hategan2004_sphered.toml --set mesh.nodes=642)
  run hategan2004_sphered_642 "${base[@]}"
  local short=("${base[@]}" --set time.t_end_s=0.3)
  run fig5_reference "${short[@]}"
  run fig5_W_x2 "${short[@]}" --set contact.W_J_per_m2=2e-3
  run fig5_gamma_n_half "${short[@]}" --set contact.gamma_n_N_s_per_m3=4e9
  run fig5_k_b_x2 "${short[@]}" --set cortex.k_b_J=480e-21
  run fig5_x_max_2.5 "${short[@]}" --set cortex.x_max=2.5
  run fig5_k_a_2e-3 "${short[@]}" --set cortex.k_a=2e-3
  run cuvelier2007 scenes/cuvelier2007.toml --set time.t_end_s=10
}
case "${1:-both}" in
  1) queue1 ;;
  2) queue2 ;;
  both) queue1 & queue2 & wait ;;
  *) echo "usage: $0 [1|2|both]" >&2; exit 2 ;;
esac
