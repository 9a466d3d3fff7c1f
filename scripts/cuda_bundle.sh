#!/usr/bin/env bash
# Packs dcm's CUDA build for a GPU machine that has an NVIDIA driver but not Debian's libraries (HDF5, toml++,
# CUDA 11.8's runtime): stripped binaries in DIR/bin, every library they load except the C and C++ runtimes
# in DIR/lib, and scripts/cuda_run.sh and scenes/ beside them. On the GPU machine: DIR/scripts/cuda_run.sh DIR/bin
#   scripts/cuda_bundle.sh DIR [TARGET...]   # targets default: dcm_unit_tests dcm_membrane_portable_tests bench_step spread
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 1 ] || { echo "usage: scripts/cuda_bundle.sh DIR [TARGET...]" >&2; exit 2; }
dir=$1
shift
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(dcm_unit_tests dcm_membrane_portable_tests bench_step spread)
bash scripts/build.sh cuda "${targets[@]}" > /dev/null
rm -rf "$dir" && mkdir -p "$dir/bin" "$dir/lib" "$dir/scripts"
for t in "${targets[@]}"; do strip -o "$dir/bin/$t" "build-cuda/bin/$t"; done
for b in "$dir"/bin/*; do ldd "$b" | awk '/=>/ {print $3}'; done | sort -u |
  grep -v -E '/(libc|libm|libdl|libpthread|librt|libgcc_s|libstdc\+\+)\.so' | xargs -r -I{} cp -L {} "$dir/lib/"
cp scripts/cuda_run.sh "$dir/scripts/" && cp -r scenes "$dir/"
echo "cuda_bundle: $(du -sh "$dir" | cut -f1) in $dir; run there: $dir/scripts/cuda_run.sh $dir/bin"
