#pragma once
// The substrate guard (`contact.guard_depth_m`, `contact.guard_stiffness_Pa_per_m`; dcm's, session 42; not in
// the paper; docs/model/contact.md, "The substrate guard"). The substrate is a solid: no part of a cell may
// pass through it. The paper's contact law acts only on rounded triangles that face the plane, so a membrane
// that buckles near the contact line and turns over below the plane feels nothing there and can fold into
// the substrate (0.3–0.5 µm with soft area terms, docs/VALIDATION.md, sessions 40–41). Per node i at the
// depth d_i = −(x_i − p)·n̂ below the plane (p, unit n̂ towards the cells), beyond the guard depth d_g:
//
//   E_i = ½ k_g A_i (d_i − d_g)²,   F_i = −∂E_i/∂x_i = k_g A_i (d_i − d_g) n̂   (d_i > d_g; 0 otherwise),
//
// A_i the node's area in the start shape (fixed, so that F is E's exact gradient;
// tests/test_substrate_guard.cpp), k_g in Pa/m (a pressure per metre of depth past d_g). d_g lies well below
// the depth at which the contact law holds a bound membrane (about 30 nm for Table 1), so that a run that
// does not fold never feels the guard and computes the same bits as without it. The energy is counted with
// the cortex energy (CortexModel::energy()), so spread's energy balance holds; the solve takes the guard
// linearly implicit (Δt k_g A_i n̂n̂ᵀ on the node's diagonal block, FrictionOperator::node_guard), so a stiff
// guard does not limit the step.
#include "core/buffers.hpp"
#include "core/cell_params.hpp"
#include "core/segmented_sum.hpp"
#include "core/vec3.hpp"
#include "kernels/plane_contact_triangle.hpp"

namespace dcm {

struct SubstrateGuard {
  double depth = 0;      // m, d_g
  double stiffness = 0;  // Pa/m, k_g; 0: off
  Plane plane;
};

// How far node x lies past the guard depth (m; 0 above it).
KOKKOS_INLINE_FUNCTION double guard_excess(const SubstrateGuard& g, Real3 x) {
  const Real3 n = (1.0 / norm(g.plane.normal)) * g.plane.normal;
  const double excess = -dot(x - g.plane.point, n) - g.depth;
  return excess > 0 ? excess : 0.0;
}

// force += F_i; stiffness(i) = k_g A_i where the guard acts, 0 elsewhere (N/m: what the solve takes
// implicit).
template <class ExecutionSpace, class MemorySpace, class Guards>
void add_substrate_guard_forces(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                                const Guards& guards,
                                const Kokkos::View<double*, Kokkos::LayoutRight, MemorySpace>& area,
                                const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& force,
                                const Kokkos::View<double*, Kokkos::LayoutRight, MemorySpace>& stiffness) {
  const auto x = mesh.x;
  const auto node_cell = mesh.node_cell;
  Kokkos::parallel_for(
      "dcm::contact::substrate_guard", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
      KOKKOS_LAMBDA(const int i) {
        const SubstrateGuard g = cell_value(guards, node_cell(i));
        const double excess = guard_excess(g, load3(x, i));
        if (!(excess > 0)) {
          stiffness(i) = 0;
          return;
        }
        const double k = g.stiffness * area(i);
        const Real3 n = (1.0 / norm(g.plane.normal)) * g.plane.normal;
        const Real3 f = (k * excess) * n;
        force(i, 0) += f.x;
        force(i, 1) += f.y;
        force(i, 2) += f.z;
        stiffness(i) = k;
      });
}

// Σ_i E_i (J).
template <class ExecutionSpace, class MemorySpace, class Guards>
double substrate_guard_energy(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                              const Guards& guards,
                              const Kokkos::View<double*, Kokkos::LayoutRight, MemorySpace>& area,
                              std::vector<double>* per_cell = nullptr) {
  const auto x = mesh.x;
  const auto node_cell = mesh.node_cell;
  return fixed_order_sum(
      "dcm::contact::substrate_guard_energy", space, mesh.node_sums,
      KOKKOS_LAMBDA(const int i) {
        const SubstrateGuard g = cell_value(guards, node_cell(i));
        const double excess = guard_excess(g, load3(x, i));
        return 0.5 * g.stiffness * area(i) * excess * excess;
      },
      per_cell);
}

}  // namespace dcm
