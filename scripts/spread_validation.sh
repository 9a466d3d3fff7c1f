#!/usr/bin/env bash
# The spreading runs behind docs/VALIDATION.md ("Spreading"): the paper scenes, the 642-node Hategan case
# for the mesh comparison and one run per direction of the paper's Figure 5, with the paper's model and with
# dcm's contact-line setting, in two queues of one thread each (2 cores). Output: out/validation/<run>/ (each a spread output folder) and
# out/validation/report.md (scripts/spread_report.py: each claim of the paper, measured, and whether it holds;
# scripts/plot_validation.py draws the curves beside it, curves.png and cuvelier.png per setting;
# with QUEUE 1 or 2 the other queue's folders, possibly of older code, are judged too).
# Takes about 20 minutes on 2 cores (session 16: 20.4 min; session 27: see docs/VALIDATION.md).
# (The full paper scenes: build/bin/spread scenes/<scene>.toml.)
#   bash scripts/spread_validation.sh [QUEUE]    # QUEUE = 1, 2, both (default), cl (the contact-line runs,
#                                                # with and without the crease) or crease (the crease runs only)
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
continue_to() {  # run, new name, t_end: a copy of the finished run continued by spread --restart
  local from=$1 name=$2 t_end=$3
  echo "== $name: $from continued to $t_end s"
  rm -rf "${out:?}/$name"
  if [ -f "$out/$from/checkpoint.h5" ]; then
    cp -r "$out/$from" "$out/$name"
    OMP_NUM_THREADS=1 "$spread" --restart "$out/$name/checkpoint.h5" --set time.t_end_s="$t_end" --quiet \
      > "$out/$name.log" 2>&1 || echo "   $name failed: $(tail -n 1 "$out/$name.log")"
  else
    echo "   $name not run: $from has no checkpoint"
  fi
}
# The fixed-step runs (the paper's Δt): ~4 min for 642 nodes and ~10 min for 2562 on one thread (session 27).
# The Figure 5 runs use adaptive steps (tolerance 1e-9 m; its error is measured by perf/work_precision.py,
# docs/PERFORMANCE.md), 7-40 s each.
queue1() {
  run hategan2004_sphered scenes/hategan2004_sphered.toml
  run hategan2004_biconcave_642 scenes/hategan2004_biconcave.toml --set mesh.nodes=642
  # adaptive steps: ~3 min for the scene's 100 s (2 million fixed steps would take ~20 min); the early window,
  # 2-20 s after the onset, comes from the scene (output.early_window_from_s/_to_s, session 38)
  run cuvelier2007 scenes/cuvelier2007.toml --set time.adaptive=true --set time.error_tol_m=1e-9
}
queue2() {
  run hategan2004_sphered_642 scenes/hategan2004_sphered.toml --set mesh.nodes=642
  # the mesh claim's "final" radius where both meshes were continued to 2.4 s (session 34; 339 s on one thread)
  continue_to hategan2004_sphered_642 hategan2004_sphered_642_to_2.4s 2.4
  # Figure 5 on the paper's Hategan mesh, 2562 nodes (session 27; before, 642 nodes, where the touch-down's
  # scatter hid k_b's few per cent and the rings' quantisation gave k_a a 2% effect on the final radius).
  local fig5=(scenes/hategan2004_sphered.toml --set time.adaptive=true --set time.error_tol_m=1e-9)
  run fig5_reference "${fig5[@]}"
  continue_to fig5_reference fig5_reference_to_2.4s 2.4  # at rest after ~1 s? (the paper: stopped at 0.9 s)
  run fig5_W_x2 "${fig5[@]}" --set contact.W_J_per_m2=2e-3
  run fig5_gamma_n_half "${fig5[@]}" --set contact.gamma_n_N_s_per_m3=4e9
  run fig5_k_b_x2 "${fig5[@]}" --set cortex.k_b_J=480e-21
  run fig5_x_max_2.5 "${fig5[@]}" --set cortex.x_max=2.5
  run fig5_k_a_2e-3 "${fig5[@]}" --set cortex.k_a=2e-3
}
# dcm's contact-line setting (scenes/hategan2004_contact_line.toml: the Derjaguin law, k_a = k_d = 2e-4 N/m,
# the bound disc pinned (session 33), adaptive steps; docs/VALIDATION.md, "Spreading, session 30" and "session
# 33"): the same claims, each run 4-35 s on one thread; its Cuvelier run gets the same constants and pins.
queue_cl() {  # part (1 or 2), then the folder prefix and any extra spread arguments (the crease setting)
  local part=$1 p=${2:-cl_}
  shift 2 || shift $#
  local extra=("$@")
  local cl=(scenes/hategan2004_contact_line.toml "${extra[@]}")
  # The crease's fillet radius follows W and k_b, rho = sqrt(sqrt(3) k_b / 4W): W x 2, k_b x 2 and Cuvelier's W
  local rho_w=() rho_kb=() rho_cuv=()
  if [ "$p" = clc_ ]; then
    rho_w=(--set contact.crease_radius_m=7.21e-9) rho_kb=(--set contact.crease_radius_m=1.44e-8)
    rho_cuv=(--set contact.crease_radius_m=3.44e-8)
  fi
  local cl_cuvelier=(scenes/cuvelier2007.toml --set time.adaptive=true --set contact.law=derjaguin
    --set cortex.k_a=2e-4 --set cortex.k_d=2e-4 --set contact.pin_friction_N_s_per_m=1e-1
    "${extra[@]}" "${rho_cuv[@]}")
  case "$part" in
    1)
      run "${p}hategan2004_sphered" "${cl[@]}"
      continue_to "${p}hategan2004_sphered" "${p}hategan2004_sphered_to_2.4s" 2.4
      run "${p}hategan2004_sphered_642" "${cl[@]}" --set mesh.nodes=642
      continue_to "${p}hategan2004_sphered_642" "${p}hategan2004_sphered_642_to_2.4s" 2.4  # still spreading at 1.2 s
      run "${p}hategan2004_biconcave_642" "${cl[@]}" --set mesh.nodes=642 --set mesh.shape=evans_fung
      run "${p}cuvelier2007" "${cl_cuvelier[@]}"
      ;;
    2)
      run "${p}fig5_W_x2" "${cl[@]}" --set contact.W_J_per_m2=2e-3 "${rho_w[@]}"
      run "${p}fig5_gamma_n_half" "${cl[@]}" --set contact.gamma_n_N_s_per_m3=4e9
      run "${p}fig5_k_b_x2" "${cl[@]}" --set cortex.k_b_J=480e-21 "${rho_kb[@]}"
      run "${p}fig5_x_max_2.5" "${cl[@]}" --set cortex.x_max=2.5
      run "${p}fig5_k_a_third" "${cl[@]}" --set cortex.k_a=6.67e-5
      ;;
  esac
}
# dcm's crease experiment (session 34; kernels/contact_crease.hpp, docs/model/contact_line.md "The crease at
# the rim"): the contact-line setting with the fillet radius sqrt(sqrt(3) k_b / 4W) = 1.02e-8 m of Table 1's
# k_b and W (and of each run's W and k_b), folders clc_*.
crease=(--set contact.crease_radius_m=1.02e-8)
case "${1:-both}" in
  1) queue1; queue_cl 1 cl_; queue_cl 1 clc_ "${crease[@]}" ;;
  2) queue2; queue_cl 2 cl_; queue_cl 2 clc_ "${crease[@]}" ;;
  cl) { queue_cl 1 cl_; queue_cl 1 clc_ "${crease[@]}"; } & { queue_cl 2 cl_; queue_cl 2 clc_ "${crease[@]}"; } & wait ;;
  crease) queue_cl 1 clc_ "${crease[@]}" & queue_cl 2 clc_ "${crease[@]}" & wait ;;
  both) { queue1; queue_cl 1 cl_; queue_cl 1 clc_ "${crease[@]}"; } &
    { queue2; queue_cl 2 cl_; queue_cl 2 clc_ "${crease[@]}"; } & wait ;;
  *) echo "usage: $0 [1|2|cl|crease|both]" >&2; exit 2 ;;
esac
# The paper's claims against these runs (docs/VALIDATION.md "Status at a glance" holds the same rows).
py=$(command -v /usr/bin/python3 || command -v python3)  # Debian's, with h5py and numpy (scripts/deps.sh)
"$py" scripts/spread_report.py "$out" > "$out/report.md.tmp" && mv "$out/report.md.tmp" "$out/report.md"
echo "wrote $out/report.md: $(tail -n 1 "$out/report.md")"
# The curves behind the claims, a page per setting (<prefix>curves.png, <prefix>cuvelier.png; session 38).
"$py" scripts/plot_validation.py "$out"
