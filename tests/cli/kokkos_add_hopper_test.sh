#!/usr/bin/env bash
# scripts/kokkos_add_hopper.sh on the two files it patches, copied from the cached Kokkos 3.4.1 source that
# scripts/deps.sh keeps: the three HOPPER90 lines land after their AMPERE86 lines, a second run changes nothing,
# a tree without those lines is refused unchanged. Skipped (77) when there is no cached source.
set -uo pipefail
script=$1
src=${DCM_CACHE:-$HOME/.cache/dcm}/kokkos-3.4.1-src
[ -f "$src/cmake/kokkos_arch.cmake" ] || { echo "no cached Kokkos source at $src: skipped"; exit 77; }
t=$(mktemp -d)
trap 'rm -rf "$t"' EXIT
mkdir -p "$t/k/cmake" "$t/bad/cmake"
cp "$src/cmake/kokkos_arch.cmake" "$src/cmake/KokkosCore_config.h.in" "$t/k/cmake/"
fail() { echo "FAILED: $*"; exit 1; }
bash "$script" "$t/k" || fail "exit code $? on the Kokkos 3.4.1 files"
grep -A1 '^KOKKOS_ARCH_OPTION(AMPERE86 ' "$t/k/cmake/kokkos_arch.cmake" | grep -q '^KOKKOS_ARCH_OPTION(HOPPER90 ' ||
  fail "no HOPPER90 option after AMPERE86's"
grep -A1 '^CHECK_CUDA_ARCH(AMPERE86 ' "$t/k/cmake/kokkos_arch.cmake" | grep -q '^CHECK_CUDA_ARCH(HOPPER90  sm_90)' ||
  fail "no sm_90 flag after AMPERE86's"
grep -A1 '^#cmakedefine KOKKOS_ARCH_AMPERE86' "$t/k/cmake/KokkosCore_config.h.in" |
  grep -q '^#cmakedefine KOKKOS_ARCH_HOPPER90' || fail "no config macro"
[ "$(diff "$src/cmake/kokkos_arch.cmake" "$t/k/cmake/kokkos_arch.cmake" | grep -c '^>')" = 2 ] || fail "not exactly two lines added"
cp -r "$t/k" "$t/k2"
bash "$script" "$t/k2" && diff -r "$t/k" "$t/k2" > /dev/null || fail "a second run changed the files"
sed '/AMPERE86/d' "$src/cmake/kokkos_arch.cmake" > "$t/bad/cmake/kokkos_arch.cmake"
cp "$src/cmake/KokkosCore_config.h.in" "$t/bad/cmake/"
cp -r "$t/bad" "$t/bad0"
bash "$script" "$t/bad" 2> "$t/err"
[ $? = 2 ] && grep -q "does not have Kokkos 3.4.1's AMPERE86 lines" "$t/err" || fail "a tree without AMPERE86 not refused"
diff -r "$t/bad" "$t/bad0" > /dev/null || fail "a refused tree was changed"
echo "kokkos_add_hopper: patched, idempotent, refuses a foreign tree"
