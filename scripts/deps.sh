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
packages=(build-essential cmake ninja-build pkg-config libeigen3-dev libhdf5-dev hdf5-tools libtomlplusplus-dev
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
# DCM_KOKKOS_VARIANT=cuda (scripts/build.sh cuda): Serial + OpenMP + CUDA for the GPU architecture
# DCM_CUDA_ARCH (a Kokkos 3.4 arch name, default AMPERE80; VOLTA70, TURING75, AMPERE86, ...), compiled with
# Kokkos' nvcc_wrapper. It needs nvcc: in $CUDA_HOME/bin, on PATH or in /usr/local/cuda/bin, from CUDA 11.x
# (Kokkos 3.4.1 predates CUDA 12; with CUDA 12 or newer, point Kokkos_ROOT at a Kokkos 4.x). HOPPER90 (H100,
# H200; CUDA 11.8 compiles sm_90) is not one of Kokkos 3.4.1's names: it is added to a copy of the source
# (scripts/kokkos_add_hopper.sh). Kokkos 3.4.1 refuses to start when the device's compute capability has
# another major number than the code's, so AMPERE80 code does not run on a Hopper GPU.
variant=${DCM_KOKKOS_VARIANT:-release}
backends="Serial+OpenMP"
case "$variant" in
  release) prefix="$cache/kokkos-3.4.1-openmp" variant_flags=() ;;
  bounds-check) prefix="$cache/kokkos-3.4.1-openmp-boundscheck" variant_flags=(-DKokkos_ENABLE_DEBUG_BOUNDS_CHECK=ON) ;;
  cuda)
    arch=${DCM_CUDA_ARCH:-AMPERE80}
    case "$arch" in
      KEPLER35 | MAXWELL50 | PASCAL60 | PASCAL61 | VOLTA70 | VOLTA72 | TURING75 | AMPERE80 | AMPERE86 | HOPPER90) ;;
      *) log "error: DCM_CUDA_ARCH = '$arch' is not allowed: choose one of KEPLER35, MAXWELL50, PASCAL60, PASCAL61, VOLTA70, VOLTA72, TURING75, AMPERE80, AMPERE86 (Kokkos 3.4.1's names), HOPPER90 (added by this script)"; exit 2 ;;
    esac
    source "$(dirname "$0")/cuda_env.sh"
    dcm_cuda_env
    nvcc=$DCM_NVCC
    if [ -z "$nvcc" ]; then
      log "error: DCM_KOKKOS_VARIANT=cuda needs nvcc (the CUDA toolkit), and none is on PATH, in \$CUDA_HOME/bin or /usr/local/cuda/bin. On Debian 12: add 'non-free' to the apt components, then apt-get install nvidia-cuda-toolkit g++-11"
      exit 2
    fi
    nvcc_major=$("$nvcc" --version | sed -n 's/.*release \([0-9]*\)\..*/\1/p')
    if [ "${nvcc_major:-0}" -ge 12 ]; then
      log "error: $nvcc is CUDA $nvcc_major; Kokkos 3.4.1 builds with CUDA 11.x only. Set CUDA_HOME to a CUDA 11 toolkit (Debian 12: nvidia-cuda-toolkit, CUDA_HOME=/usr), or point Kokkos_ROOT at your own Kokkos 4.x with CUDA"
      exit 2
    fi
    prefix="$cache/kokkos-3.4.1-cuda-$arch" backends="Serial+OpenMP+CUDA ($arch)"
    variant_flags=(-DKokkos_ENABLE_CUDA=ON -DKokkos_ENABLE_CUDA_LAMBDA=ON "-DKokkos_ARCH_$arch=ON") ;;
  *) log "error: DCM_KOKKOS_VARIANT = '$variant' is not allowed: choose release, bounds-check or cuda"; exit 2 ;;
esac
if [ -f "$prefix/.dcm-complete" ]; then
  log "Kokkos 3.4.1 ($backends, $variant): cached at $prefix"
  echo "$prefix"
  exit 0
fi

work=$(mktemp -d "${TMPDIR:-/tmp}/dcm-kokkos.XXXXXX")
trap 'rm -rf "$work"' EXIT
# The Kokkos source: DCM_KOKKOS_SRC (a Kokkos 3.4.1 source tree, for a machine without network), else the copy
# kept in the cache by an earlier build, else Debian's trilinos source package (downloaded once).
srccache="$cache/kokkos-3.4.1-src"
if [ -n "${DCM_KOKKOS_SRC:-}" ]; then
  [ -f "$DCM_KOKKOS_SRC/CMakeLists.txt" ] || { log "error: DCM_KOKKOS_SRC = '$DCM_KOKKOS_SRC' is not a Kokkos source tree (no CMakeLists.txt)"; exit 2; }
  ksrc=$DCM_KOKKOS_SRC
  log "building Kokkos 3.4.1 ($backends, $variant) from $ksrc into $prefix"
elif [ -f "$srccache/CMakeLists.txt" ]; then
  ksrc=$srccache
  log "building Kokkos 3.4.1 ($backends, $variant) from the cached source $ksrc into $prefix"
else
  log "building Kokkos 3.4.1 ($backends, $variant) from Debian's trilinos source into $prefix"
  # A private apt configuration that only knows a deb-src line: the system's apt set-up stays untouched.
  mkdir -p "$work/apt/lists/partial" "$work/apt/cache/archives/partial" "$work/src"
  echo "deb-src http://deb.debian.org/debian bookworm main" > "$work/apt/sources.list"
  aptopts=(-o Dir::Etc::SourceList="$work/apt/sources.list" -o Dir::Etc::SourceParts=/dev/null
    -o Dir::State::Lists="$work/apt/lists" -o Dir::Cache="$work/apt/cache" -o APT::Sandbox::User=root)
  apt-get "${aptopts[@]}" update -qq >&2
  (cd "$work/src" && apt-get "${aptopts[@]}" -qq source --download-only trilinos > /dev/null)
  tarball=$(ls "$work"/src/trilinos_*.orig.tar.* | head -n 1)
  tar -xf "$tarball" -C "$work/src" --wildcards '*/packages/kokkos/*'
  mkdir -p "$cache"
  rm -rf "$srccache.tmp" && cp -r "$(ls -d "$work"/src/*/packages/kokkos | head -n 1)" "$srccache.tmp" &&
    mv "$srccache.tmp" "$srccache"
  ksrc=$srccache
fi
mkdir -p "$cache"
buildlog="$cache/kokkos-3.4.1-$variant-build.log"
# HOPPER90: Kokkos 3.4.1 with the architecture added (scripts/kokkos_add_hopper.sh), in a copy of the source;
# the cached source stays as Debian ships it.
if [ "$variant" = cuda ] && [ "$arch" = HOPPER90 ]; then
  cp -r "$ksrc" "$work/kokkos-hopper"
  ksrc="$work/kokkos-hopper"
  bash "$(dirname "$0")/kokkos_add_hopper.sh" "$ksrc" || { log "error: could not add HOPPER90 to $ksrc"; exit 1; }
fi
# With CUDA, Kokkos and every code that includes it compile through Kokkos' nvcc_wrapper (installed to
# $prefix/bin).
[ "$variant" = cuda ] && variant_flags+=("-DCMAKE_CXX_COMPILER=$ksrc/bin/nvcc_wrapper")
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
