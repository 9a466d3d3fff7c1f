#pragma once
// Where a launch too small to share among threads runs. On the OpenMP backend each parallel launch is a
// fork and a join of the thread team (≈ 1.5 µs on one thread, 3.5 µs on two on the development VM, more
// when the two vCPUs lie on different dies), which is more than the work of a multigrid level of a few
// hundred rows or of the per-cell pass of a segmented sum. SmallLaunchSpace<OpenMP> is Kokkos::Serial when
// the build has it: the same kernels, run on the calling thread, in the same memory (HostSpace). Every
// other backend (CUDA, Serial itself) keeps its own space (kAvailable false).
//
//   on_small_space(space, n <= threshold, [&](const auto& s) { launch(s, ...); });
//
// The kernels must compute each work item independently (no reductions across items), so that the results
// are the same to the bit on either space.
#include <Kokkos_Core.hpp>

namespace dcm {

template <class ExecutionSpace>
struct SmallLaunchSpace {
  static constexpr bool kAvailable = false;
  using type = ExecutionSpace;
};
#if defined(KOKKOS_ENABLE_OPENMP) && defined(KOKKOS_ENABLE_SERIAL)
template <>
struct SmallLaunchSpace<Kokkos::OpenMP> {
  static constexpr bool kAvailable = true;
  using type = Kokkos::Serial;
};
#endif

// launch(space), or, when small and the backend has a SmallLaunchSpace, launch(that space) after the
// solve's space has finished its work (launch takes the space as a generic parameter).
template <class ExecutionSpace, class Launch>
void on_small_space(const ExecutionSpace& space, bool small, const Launch& launch) {
  if constexpr (SmallLaunchSpace<ExecutionSpace>::kAvailable) {
    if (small) {
      space.fence();
      const typename SmallLaunchSpace<ExecutionSpace>::type serial;
      launch(serial);
      serial.fence();
      return;
    }
  }
  launch(space);
}

}  // namespace dcm
