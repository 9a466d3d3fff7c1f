#pragma once
// Linearly implicit bending. Bending modes move nodes across the surface, which the bond dashpots (eq. 25)
// do not resist: only the Stokes drag 6πηr/N does, and on fine meshes their time constant drops far below
// the paper's Δt (forward Euler is unstable at 2562 nodes). Adding the Gauss–Newton part of the bending
// Hessian, Δt Σ_h k_b max(cos(θ_h − θ*_h), 0) ∇θ_h ∇θ_hᵀ (positive semi-definite), to the friction operator
// makes the step (Γ + Δt K_bend) v = F implicit in exactly these modes. Applied matrix-free: a hinge pass
// (s_h = Δt k_b max(cos, 0) ∇θ_h · v) and a gather over the node's hinges (no atomics). ∇θ_h and cos(θ_h −
// θ*_h) are those the bending force pass of the same positions left in HingeRest (kernels/bending.hpp): like
// the forces, the stiffness belongs to the positions of the last compute_forces().
#include <vector>

#include "core/kokkos_compat.hpp"
#include "kernels/bending.hpp"

namespace dcm {

template <class MemorySpace>
struct BendingStiffness {
  Kokkos::View<double*, Kokkos::LayoutRight, MemorySpace> s;  // per hinge scratch: Δt k_b max(cos, 0) ∇θ · v
  // Δt k_b of the current step per cell (J·s)
  Kokkos::View<double*, Kokkos::LayoutRight, MemorySpace> dt_k_b;
  HostMirrorOf<Kokkos::View<double*, Kokkos::LayoutRight, MemorySpace>> dt_k_b_host;
  BendingStiffness() = default;
  explicit BendingStiffness(const MeshBuffers<MemorySpace>& mesh)
      : s("dcm::bending_stiffness::s", mesh.n_hinges),
        dt_k_b("dcm::bending_stiffness::dt_k_b", mesh.n_cells),
        dt_k_b_host(Kokkos::create_mirror_view(dt_k_b)) {}
};

// The stiffness of a step dt; ∇θ and cos(θ − θ*) come from the last add_bending_forces()
// (kernels/bending.hpp).
// k_b: the bending constant of every cell (J), one entry per cell (or one for all).
// dt: each cell's step (or one for all).
template <class MemorySpace>
void update_bending_stiffness(const std::vector<double>& k_b, const std::vector<double>& dt,
                              BendingStiffness<MemorySpace>& bs) {
  for (std::size_t c = 0; c < bs.dt_k_b_host.extent(0); ++c)
    bs.dt_k_b_host(c) = dt[dt.size() == 1 ? 0 : c] * k_b[k_b.size() == 1 ? 0 : c];
  Kokkos::deep_copy(bs.dt_k_b, bs.dt_k_b_host);
}
template <class MemorySpace>
void update_bending_stiffness(double k_b, double dt, BendingStiffness<MemorySpace>& bs) {
  update_bending_stiffness(std::vector<double>{k_b}, std::vector<double>{dt}, bs);
}

// out += Δt K_bend v.
template <class ExecutionSpace, class MemorySpace>
void apply_bending_stiffness(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                             const HingeRest<MemorySpace>& hinges, const BendingStiffness<MemorySpace>& bs,
                             const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& v,
                             const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& out,
                             const CellFlags<MemorySpace>& active = {}) {
  const auto hinge = mesh.hinge;
  const auto node_cell = mesh.node_cell;
  const auto g = hinges.hinge_grad;
  const auto cos_delta = hinges.hinge_cos_delta;
  const auto s = bs.s;
  const auto dt_k_b = bs.dt_k_b;
  const auto hinge_cell = mesh.hinge_cell;
  Kokkos::parallel_for(
      "dcm::bending_stiffness::project", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_hinges),
      KOKKOS_LAMBDA(const int h) {
        if (skipped(active, hinge_cell(h))) return;
        double sum = 0;
        for (int a = 0; a < 4; ++a) {
          const int i = hinge(h, a);
          sum += g(h, a, 0) * v(i, 0) + g(h, a, 1) * v(i, 1) + g(h, a, 2) * v(i, 2);
        }
        s(h) = dt_k_b(hinge_cell(h)) * math::max(cos_delta(h), 0.0) * sum;
      });
  const auto offsets = mesh.node_hinge_offsets;
  const auto roles = mesh.node_hinge_roles;
  Kokkos::parallel_for(
      "dcm::bending_stiffness::gather", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
      KOKKOS_LAMBDA(const int i) {
        if (skipped(active, node_cell(i))) return;
        double o0 = 0, o1 = 0, o2 = 0;
        for (int k = offsets(i); k < offsets(i + 1); ++k) {
          const int h = roles(k) >> 2, a = roles(k) & 3;  // 4 h + role, non-negative
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
