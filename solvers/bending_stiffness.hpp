#pragma once
// Linearly implicit bending. Bending modes move nodes across the surface, which the bond dashpots (eq. 25)
// do not resist: only the Stokes drag 6πηr/N does, and on fine meshes their time constant drops far below
// the paper's Δt (forward Euler is unstable at 2562 nodes). Adding the Gauss–Newton part of the bending
// Hessian, Δt Σ_h k_b max(cos(θ_h − θ*_h), 0) ∇θ_h ∇θ_hᵀ (positive semi-definite), to the friction operator
// makes the step (Γ + Δt K_bend) v = F implicit in exactly these modes. Applied matrix-free: a hinge pass
// (s_h = g_h · v) and a gather over the node's hinges (no atomics), with g_h = sqrt(Δt k_b max(cos, 0)) ∇θ_h
// cached once per step.
#include "kernels/bending.hpp"

namespace dcm {

template <class MemorySpace>
struct BendingStiffness {
  Kokkos::View<double* [4][3], Kokkos::LayoutRight, MemorySpace> g;  // scaled ∇θ per hinge and role
  Kokkos::View<double*, Kokkos::LayoutRight, MemorySpace> s;         // per hinge scratch: g · v
  BendingStiffness() = default;
  explicit BendingStiffness(const MeshBuffers<MemorySpace>& mesh)
      : g("dcm::bending_stiffness::g", mesh.n_hinges), s("dcm::bending_stiffness::s", mesh.n_hinges) {}
};

template <class ExecutionSpace, class MemorySpace>
void update_bending_stiffness(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                              const HingeRest<MemorySpace>& rest, double k_b, double dt,
                              const BendingStiffness<MemorySpace>& bs) {
  const auto x = mesh.x;
  const auto hinge = mesh.hinge;
  const auto rest_trig = rest.rest_trig;
  const auto g = bs.g;
  Kokkos::parallel_for(
      "dcm::bending_stiffness::update", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_hinges),
      KOKKOS_LAMBDA(const int h) {
        double c, s;
        Real3 grad[4];
        hinge_trig_gradient(load3(x, hinge(h, 0)), load3(x, hinge(h, 1)), load3(x, hinge(h, 2)),
                            load3(x, hinge(h, 3)), c, s, grad);
        const double cos_d = c * rest_trig(h, 0) + s * rest_trig(h, 1);  // cos(theta - theta*)
        const double w = math::sqrt(dt * k_b * math::max(cos_d, 0.0));
        for (int a = 0; a < 4; ++a) {
          g(h, a, 0) = w * grad[a].x;
          g(h, a, 1) = w * grad[a].y;
          g(h, a, 2) = w * grad[a].z;
        }
      });
}

// out += Δt K_bend v.
template <class ExecutionSpace, class MemorySpace>
void apply_bending_stiffness(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                             const BendingStiffness<MemorySpace>& bs,
                             const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& v,
                             const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& out) {
  const auto hinge = mesh.hinge;
  const auto g = bs.g;
  const auto s = bs.s;
  Kokkos::parallel_for(
      "dcm::bending_stiffness::project", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_hinges),
      KOKKOS_LAMBDA(const int h) {
        double sum = 0;
        for (int a = 0; a < 4; ++a) {
          const int i = hinge(h, a);
          sum += g(h, a, 0) * v(i, 0) + g(h, a, 1) * v(i, 1) + g(h, a, 2) * v(i, 2);
        }
        s(h) = sum;
      });
  const auto offsets = mesh.node_hinge_offsets;
  const auto roles = mesh.node_hinge_roles;
  Kokkos::parallel_for(
      "dcm::bending_stiffness::gather", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
      KOKKOS_LAMBDA(const int i) {
        double o0 = 0, o1 = 0, o2 = 0;
        for (int k = offsets(i); k < offsets(i + 1); ++k) {
          const int h = roles(k) / 4, a = roles(k) % 4;
          o0 += s(h) * g(h, a, 0);
          o1 += s(h) * g(h, a, 1);
          o2 += s(h) * g(h, a, 2);
        }
        out(i, 0) += o0;
        out(i, 1) += o1;
        out(i, 2) += o2;
      });
}

}  // namespace dcm
