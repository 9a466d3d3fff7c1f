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

// −Σ_i F_i · x_i, summed in the fixed order of node_sums (mesh.node_sums).
template <class ExecutionSpace, class MemorySpace>
double external_energy(const ExecutionSpace& space, const SumPlan<MemorySpace>& node_sums,
                       const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& external,
                       const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& x,
                       std::vector<double>* per_cell = nullptr) {
  return fixed_order_sum(
      "dcm::external::energy", space, node_sums,
      KOKKOS_LAMBDA(const int i) { return -dot(load3(external, i), load3(x, i)); }, per_cell);
}

}  // namespace dcm
