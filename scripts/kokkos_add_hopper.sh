#!/usr/bin/env bash
# Adds the NVIDIA Hopper architecture (HOPPER90: H100, H200; nvcc flag sm_90, which CUDA 11.8 compiles) to a
# Kokkos 3.4.1 source tree, which knows architectures up to AMPERE86: an option, its nvcc flag and its config
# macro, three lines. Kokkos 3.4.1 refuses to start on a device whose compute capability has another major
# number than the code's, so AMPERE80 code does not run on Hopper. Used by scripts/deps.sh on a copy of the
# source (DCM_CUDA_ARCH=HOPPER90); fails, changing nothing, when the tree does not look like Kokkos 3.4.1.
#   scripts/kokkos_add_hopper.sh KOKKOS_SOURCE_DIR
set -euo pipefail
src=${1:?usage: scripts/kokkos_add_hopper.sh KOKKOS_SOURCE_DIR}
arch=$src/cmake/kokkos_arch.cmake
config=$src/cmake/KokkosCore_config.h.in
for f in "$arch" "$config"; do
  [ -f "$f" ] || { echo "kokkos_add_hopper: $f does not exist (not a Kokkos source tree)" >&2; exit 2; }
done
if grep -q HOPPER90 "$arch"; then echo "kokkos_add_hopper: $src has HOPPER90 already" >&2; exit 0; fi
if [ "$(grep -c -E '^(KOKKOS_ARCH_OPTION|CHECK_CUDA_ARCH)\(AMPERE86 ' "$arch")" != 2 ] ||
  ! grep -q '^#cmakedefine KOKKOS_ARCH_AMPERE86' "$config"; then
  echo "kokkos_add_hopper: $src does not have Kokkos 3.4.1's AMPERE86 lines to add HOPPER90 after" >&2
  exit 2
fi
sed -i -e '/^KOKKOS_ARCH_OPTION(AMPERE86 /a KOKKOS_ARCH_OPTION(HOPPER90        GPU  "NVIDIA Hopper generation CC 9.0")' \
  -e '/^CHECK_CUDA_ARCH(AMPERE86 /a CHECK_CUDA_ARCH(HOPPER90  sm_90)' "$arch"
sed -i '/^#cmakedefine KOKKOS_ARCH_AMPERE86/a #cmakedefine KOKKOS_ARCH_HOPPER90' "$config"
