#!/usr/bin/env bash
# Installs what dcm needs on Debian 12, idempotently.
#  - Debian packages: only when one is missing (then a single apt-get update + install).
#  - Kokkos: a user's Kokkos is used when Kokkos_ROOT (or DCM_KOKKOS_ROOT) points at an install with
#    OpenMP or CUDA. Otherwise Kokkos 3.4.1 (Serial + OpenMP) is built once from the source of Debian's
#    trilinos package into a cached prefix, "$DCM_CACHE/kokkos-3.4.1-openmp" (DCM_CACHE defaults to
#    ~/.cache/dcm). Later runs find the prefix and download or build nothing.
# Prints, as its last line, the Kokkos prefix to use.
set -euo pipefail

cache=${DCM_CACHE:-$HOME/.cache/dcm}
packages=(build-essential cmake pkg-config libeigen3-dev libhdf5-dev hdf5-tools libtomlplusplus-dev
  libcli11-dev libgtest-dev libgmock-dev libbenchmark-dev python3-matplotlib python3-h5py python3-numpy
  dpkg-dev ca-certificates openmpi-bin python3-mpi4py)

log() { echo "[deps] $*" >&2; }
as_root() { if [ "$(id -u)" = 0 ]; then "$@"; else sudo "$@"; fi; }

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  log "installing Debian packages: ${missing[*]}"
  as_root apt-get update -qq >&2
  DEBIAN_FRONTEND=noninteractive as_root apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
else
  log "Debian packages: all present"
fi

user_kokkos=${DCM_KOKKOS_ROOT:-${Kokkos_ROOT:-}}
if [ -n "$user_kokkos" ]; then
  log "using the Kokkos at $user_kokkos (from DCM_KOKKOS_ROOT/Kokkos_ROOT)"
  echo "$user_kokkos"
  exit 0
fi

# DCM_KOKKOS_VARIANT=bounds-check (scripts/build.sh debug|sanitize): the same Kokkos with bounds checking
# on every View access, in its own prefix.
variant=${DCM_KOKKOS_VARIANT:-release}
case "$variant" in
  release) prefix="$cache/kokkos-3.4.1-openmp" variant_flags=() ;;
  bounds-check) prefix="$cache/kokkos-3.4.1-openmp-boundscheck" variant_flags=(-DKokkos_ENABLE_DEBUG_BOUNDS_CHECK=ON) ;;
  *) log "error: DCM_KOKKOS_VARIANT = '$variant' is not allowed: choose release or bounds-check"; exit 2 ;;
esac
if [ -f "$prefix/.dcm-complete" ]; then
  log "Kokkos 3.4.1 (Serial+OpenMP, $variant): cached at $prefix"
  echo "$prefix"
  exit 0
fi

log "building Kokkos 3.4.1 (Serial+OpenMP, $variant) from Debian's trilinos source into $prefix"
work=$(mktemp -d "${TMPDIR:-/tmp}/dcm-kokkos.XXXXXX")
trap 'rm -rf "$work"' EXIT
# A private apt configuration that only knows a deb-src line: the system's apt set-up stays untouched.
mkdir -p "$work/apt/lists/partial" "$work/apt/cache/archives/partial" "$work/src"
echo "deb-src http://deb.debian.org/debian bookworm main" > "$work/apt/sources.list"
aptopts=(-o Dir::Etc::SourceList="$work/apt/sources.list" -o Dir::Etc::SourceParts=/dev/null
  -o Dir::State::Lists="$work/apt/lists" -o Dir::Cache="$work/apt/cache" -o APT::Sandbox::User=root)
apt-get "${aptopts[@]}" update -qq >&2
(cd "$work/src" && apt-get "${aptopts[@]}" -qq source --download-only trilinos > /dev/null)
tarball=$(ls "$work"/src/trilinos_*.orig.tar.* | head -n 1)
tar -xf "$tarball" -C "$work/src" --wildcards '*/packages/kokkos/*'
ksrc=$(ls -d "$work"/src/*/packages/kokkos | head -n 1)
mkdir -p "$cache"
buildlog="$cache/kokkos-3.4.1-$variant-build.log"
if ! { cmake -S "$ksrc" -B "$work/build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX="$prefix" \
         -DKokkos_ENABLE_SERIAL=ON -DKokkos_ENABLE_OPENMP=ON -DCMAKE_CXX_STANDARD=17 \
         -DCMAKE_POSITION_INDEPENDENT_CODE=ON -DBUILD_SHARED_LIBS=OFF "${variant_flags[@]}" &&
       cmake --build "$work/build" --parallel "$(nproc)" &&
       cmake --install "$work/build"; } > "$buildlog" 2>&1; then
  tail -n 30 "$buildlog" >&2
  log "error: the Kokkos build failed; full log in $buildlog"
  exit 1
fi
touch "$prefix/.dcm-complete"
log "Kokkos installed at $prefix"
echo "$prefix"
