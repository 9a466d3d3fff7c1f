# Sourced by scripts/deps.sh and scripts/build.sh (cuda): finds nvcc and sets the environment that Kokkos'
# nvcc_wrapper needs. dcm_cuda_env sets DCM_NVCC to nvcc's path (empty if none) — looked up in $CUDA_HOME/bin,
# then on PATH, then in /usr/local/cuda/bin — puts its folder first on PATH, and, since nvcc 11.x accepts host
# compilers up to GCC 11 (Debian 12's default is GCC 12), sets NVCC_WRAPPER_DEFAULT_COMPILER=g++-11 when that
# compiler is there and the variable is not set.
dcm_cuda_env() {
  DCM_NVCC=""
  if [ -n "${CUDA_HOME:-}" ] && [ -x "$CUDA_HOME/bin/nvcc" ]; then DCM_NVCC="$CUDA_HOME/bin/nvcc"; fi
  if [ -z "$DCM_NVCC" ]; then DCM_NVCC=$(command -v nvcc || true); fi
  if [ -z "$DCM_NVCC" ] && [ -x /usr/local/cuda/bin/nvcc ]; then DCM_NVCC=/usr/local/cuda/bin/nvcc; fi
  if [ -n "$DCM_NVCC" ]; then export PATH="$(dirname "$DCM_NVCC"):$PATH"; fi
  if [ -z "${NVCC_WRAPPER_DEFAULT_COMPILER:-}" ] && command -v g++-11 > /dev/null; then
    export NVCC_WRAPPER_DEFAULT_COMPILER=g++-11
  fi
}
