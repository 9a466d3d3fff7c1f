#!/usr/bin/env bash
# Configures and builds dcm with a CMake preset (default: release) after making sure the dependencies are
# there (scripts/deps.sh). Idempotent: a second run only rebuilds what changed.
#   scripts/build.sh [PRESET] [TARGET...]
set -euo pipefail
cd "$(dirname "$0")/.."
preset=${1:-release}
shift || true
case "$preset" in
  release) builddir=build kokkos_variant=release ;;
  debug) builddir=build-debug kokkos_variant=bounds-check ;;
  sanitize) builddir=build-sanitize kokkos_variant=release ;;
  cuda) builddir=build-cuda kokkos_variant=cuda ;;
  *) echo "scripts/build.sh: unknown preset '$preset' (release, debug, sanitize, cuda)" >&2; exit 2 ;;
esac
# debug uses a Kokkos with bounds checking on every View access; sanitize the release Kokkos (ASan and UBSan
# instrument dcm's own code; the bounds checks would make the sanitized suite ~100x slower than release).
# cuda: Kokkos with CUDA (DCM_CUDA_ARCH, default AMPERE80; HOPPER90 for an H100/H200; scripts/deps.sh), dcm
# compiled by its nvcc_wrapper.
kokkos=$(DCM_KOKKOS_VARIANT=$kokkos_variant bash scripts/deps.sh | tail -n 1)
extra=()
if [ "$preset" = cuda ]; then
  source scripts/cuda_env.sh
  dcm_cuda_env
  extra=("-DCMAKE_CXX_COMPILER=$kokkos/bin/nvcc_wrapper")
fi
# Ninja (the presets' generator; scripts/deps.sh installs it): unlike Make it compiles a target's files while
# the libraries the target links are still being built, so the model's one long compile
# (solvers/cortex_model.cpp, docs/ARCHITECTURE.md "Compile once") runs beside the apps' and tests' files.
generator=Ninja
# Configure when there is no build yet, or the preset, the Kokkos, CI-ness (warnings as errors) or the
# generator changed.
stamp="$preset;$kokkos;ci=${CI:-false};$generator"
if [ ! -f "$builddir/CMakeCache.txt" ] || ! grep -qxF "DCM_CONFIGURED_FOR:STRING=$stamp" "$builddir/CMakeCache.txt"; then
  # CMake cannot switch a build folder to another generator: an earlier one's cache goes (one full build;
  # options set there by hand with -D go with it).
  if [ -f "$builddir/CMakeCache.txt" ] && ! grep -qxF "CMAKE_GENERATOR:INTERNAL=$generator" "$builddir/CMakeCache.txt"; then
    echo "scripts/build.sh: $builddir was configured for another generator (Make, before session 43); its" \
      "CMakeCache.txt and CMakeFiles/ are removed and it is configured again for $generator (one full build)" >&2
    rm -rf "$builddir/CMakeCache.txt" "$builddir/CMakeFiles"
  fi
  # -U Kokkos_DIR: a cached Kokkos_DIR from an earlier configure would win over the new Kokkos_ROOT.
  cmake --preset "$preset" -G "$generator" -U Kokkos_DIR -DKokkos_ROOT="$kokkos" \
    "-DDCM_CONFIGURED_FOR:STRING=$stamp" "${extra[@]}" >&2
fi
# A named target that a changed CMakeLists.txt just added needs the build system regenerated first.
if [ $# -gt 0 ] && [ -n "$(find . -name CMakeLists.txt -newer "$builddir/CMakeCache.txt" -not -path './build*' | head -n 1)" ]; then
  cmake -S . -B "$builddir" >&2 && touch "$builddir/CMakeCache.txt"
fi
targets=()
for t in "$@"; do targets+=(--target "$t"); done
cmake --build "$builddir" --parallel "$(nproc)" "${targets[@]}" >&2
echo "$builddir"
