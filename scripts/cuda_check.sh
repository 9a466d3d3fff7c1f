#!/usr/bin/env bash
# Compiles all of dcm (library, apps, tests, benchmarks) against a CUDA Kokkos, to show that the kernels are
# device-clean: no host function called from device code, no lambda form CUDA rejects. It runs nothing (a
# GPU is not needed to compile). Fails when the build fails or nvcc warns that dcm's own kernels call host
# code; the same warnings from tests (host-only Eigen reference solves) are listed, not counted.
#   scripts/cuda_check.sh            # CUDA_HOME and DCM_CUDA_ARCH as for scripts/build.sh cuda
# Needs a CUDA 11 toolkit for Kokkos 3.4.1 (Debian 12: add the non-free component to apt, then
# apt-get install nvidia-cuda-toolkit g++-11, and run with CUDA_HOME=/usr). ~15 min on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
log=$(mktemp "${TMPDIR:-/tmp}/dcm-cuda-check.XXXXXX")
trap 'rm -f "$log"' EXIT
start=$(date +%s)
# From scratch, so that every file's warnings are seen.
if [ -f build-cuda/CMakeCache.txt ]; then cmake --build build-cuda --target clean > /dev/null 2>&1 || true; fi
if ! bash scripts/build.sh cuda > "$log" 2>&1; then
  grep -E "error" "$log" | sort | uniq -c | sort -rn | head -n 40 >&2 || true
  echo "cuda_check: the CUDA build failed (errors above; rerun scripts/build.sh cuda for the full log)" >&2
  exit 1
fi
# Each nvcc warning is a block up to the next blank line; a host call from device code counts against dcm
# unless the block's instantiation chain starts in tests/ (host-only reference code there).
python3 - "$log" "$start" << 'PY'
import re, sys, time
text = open(sys.argv[1], errors="replace").read()
pattern = re.compile(r"calling a (constexpr )?__host__ function.*from a __host__ __device__ function")
own, test_only = [], 0
for block in re.split(r"\n\s*\n", text):
    if not pattern.search(block):
        continue
    if "/tests/" in block:
        test_only += 1
    else:
        own.append(block.strip())
if own:
    print("\n\n".join(own), file=sys.stderr)
    print(f"cuda_check: {len(own)} host call(s) from device code in dcm's kernels (above)", file=sys.stderr)
    sys.exit(1)
cache = open("build-cuda/CMakeCache.txt").read()
kokkos = re.search(r"Kokkos_DIR:PATH=(.*)", cache).group(1)
print(f"cuda_check: dcm compiles with CUDA (Kokkos at {kokkos}); {test_only} host-call warning(s), all in "
      f"host-only test code; {time.time() - float(sys.argv[2]):.0f} s")
PY
