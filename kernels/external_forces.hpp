#pragma once
// External node forces (paper eq. 32's F_gravity and the optical-tweezers pull): a stored per-node force
// field added to the total. Conservative for a constant field: energy −Σ_i F_i · x_i.
#include "core/vec3.hpp"

namespace dcm {

template <class ExecutionSpace, class MemorySpace>
void add_external_forces(const ExecutionSpace& space,
                         const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& external,
                         const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& force) {
  Kokkos::parallel_for(
      "dcm::external::add", Kokkos::RangePolicy<ExecutionSpace>(space, 0, force.extent(0)),
      KOKKOS_LAMBDA(const int i) {
        for (int d = 0; d < 3; ++d) force(i, d) += external(i, d);
      });
}

// −Σ_i F_i · x_i
template <class ExecutionSpace, class MemorySpace>
double external_energy(const ExecutionSpace& space,
                       const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& external,
                       const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& x) {
  double e = 0;
  Kokkos::parallel_reduce(
      "dcm::external::energy", Kokkos::RangePolicy<ExecutionSpace>(space, 0, x.extent(0)),
      KOKKOS_LAMBDA(const int i, double& s) { s -= dot(load3(external, i), load3(x, i)); }, e);
  return e;
}

}  // namespace dcm
