#pragma once
// Linearly implicit treatment of the cell-wide constraints (global area, eq. 28; volume, eq. 29).
// Their energies k (X − X*)² / (2X*) act on one collective mode per cell, which the bond dashpots hardly
// resist: with explicit forces, forward Euler at the paper's Δt is unstable for stiff k. Adding the
// Gauss–Newton part of their Hessian, Δt · (k/X*) ∇X ∇Xᵀ (rank one per cell, positive semi-definite), to
// the friction operator makes the step
//     (Γ + Δt K_global) v = F(x_n),   x_{n+1} = x_n + Δt v
// implicit in exactly these modes; Γ + Δt K_global stays symmetric positive definite, and applying it
// costs one reduction per cell and constraint. The preconditioner can get the volume term by the
// Sherman–Morrison identity (solvers/global_woodbury.hpp, solver.precondition_volume, off by default); the
// area term, which saved no iteration that way, is left to the CG (a rank-one change costs it at most an
// iteration or two).
#include "core/cell_params.hpp"
#include "core/geometry.hpp"
#include "core/vec3.hpp"

namespace dcm {

template <class MemorySpace>
struct GlobalStiffness {
  template <class T>
  using View = Kokkos::View<T, Kokkos::LayoutRight, MemorySpace>;
  View<double*[3]> grad_area, grad_volume;  // ∇A_c and ∇V_c at every node (of its cell)
  View<double*> coef_area, coef_volume;     // Δt k / X* per cell (N·s/m³ resp. N·s/m⁵ times m²...)
  View<double*> dot_area, dot_volume;       // per cell scratch: ∇X · v
  bool area = false, volume = false;

  GlobalStiffness() = default;
  GlobalStiffness(const MeshBuffers<MemorySpace>& mesh, bool with_area, bool with_volume)
      : grad_area("dcm::global::grad_area", with_area ? mesh.n_nodes : 0),
        grad_volume("dcm::global::grad_volume", with_volume ? mesh.n_nodes : 0),
        coef_area("dcm::global::coef_area", mesh.n_cells),
        coef_volume("dcm::global::coef_volume", mesh.n_cells),
        dot_area("dcm::global::dot_area", mesh.n_cells),
        dot_volume("dcm::global::dot_volume", mesh.n_cells),
        area(with_area),
        volume(with_volume) {}
};

// Gradients ∇A (Σ_t ½ n_t × (x_k − x_j)) and ∇V (Σ_t A_t n_t / 3) at every node for the current geometry,
// and the coefficients Δt k / X*. rest_area, rest_volume: the cells' rest values.
// k_d, k_v: one value each or CellTables (PerCell::table(), core/cell_params.hpp).
template <class ExecutionSpace, class MemorySpace, class KD, class KV, class DT>
void update_global_stiffness(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                             const GeometryBuffers<MemorySpace>& geo,
                             const Kokkos::View<double*, Kokkos::LayoutRight, MemorySpace>& rest_area,
                             const Kokkos::View<double*, Kokkos::LayoutRight, MemorySpace>& rest_volume,
                             const KD& k_d, const KV& k_v, const DT& dt,
                             const GlobalStiffness<MemorySpace>& g) {
  const auto x = mesh.x;
  const auto tri = mesh.tri;
  const auto offsets = mesh.node_tri_offsets;
  const auto corners = mesh.node_tri_corners;
  const auto area = geo.tri_area;
  const auto normal = geo.tri_normal;
  const auto grad_area = g.grad_area, grad_volume = g.grad_volume;
  const bool with_area = g.area, with_volume = g.volume;
  Kokkos::parallel_for(
      "dcm::global::gradients", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
      KOKKOS_LAMBDA(const int i) {
        Real3 ga{0, 0, 0}, gv{0, 0, 0};
        for (int s = offsets(i); s < offsets(i + 1); ++s) {
          const int t = corners(s) / 3, c = corners(s) % 3;
          const Real3 n = load3(normal, t);
          ga += 0.5 * cross(n, load3(x, tri(t, (c + 2) % 3)) - load3(x, tri(t, (c + 1) % 3)));
          gv += (area(t) / 3.0) * n;
        }
        if (with_area) store3(grad_area, i, ga);
        if (with_volume) store3(grad_volume, i, gv);
      });
  const auto coef_area = g.coef_area, coef_volume = g.coef_volume;
  Kokkos::parallel_for(
      "dcm::global::coefficients", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_cells),
      KOKKOS_LAMBDA(const int c) {
        coef_area(c) = with_area ? cell_value(dt, c) * cell_value(k_d, c) / rest_area(c) : 0.0;
        coef_volume(c) = with_volume ? cell_value(dt, c) * cell_value(k_v, c) / rest_volume(c) : 0.0;
      });
}

// out += Δt K_global v.
template <class ExecutionSpace, class MemorySpace>
void apply_global_stiffness(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                            const GlobalStiffness<MemorySpace>& g,
                            const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& v,
                            const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& out,
                            const CellFlags<MemorySpace>& active = {}) {
  const auto grad_area = g.grad_area, grad_volume = g.grad_volume;
  const bool with_area = g.area, with_volume = g.volume;
  const auto node_cell = mesh.node_cell;
  segmented_sum<2>(
      "dcm::global::dots", space, mesh.node_sums,
      KOKKOS_LAMBDA(const int i, double(&s)[2]) {
        if (skipped(active, node_cell(i))) return;
        const Real3 vi = load3(v, i);
        if (with_area) s[0] += dot(load3(grad_area, i), vi);
        if (with_volume) s[1] += dot(load3(grad_volume, i), vi);
      },
      PairOut<MemorySpace>{g.dot_area, g.dot_volume});
  const auto coef_area = g.coef_area, coef_volume = g.coef_volume, dot_area = g.dot_area,
             dot_volume = g.dot_volume;
  Kokkos::parallel_for(
      "dcm::global::apply", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
      KOKKOS_LAMBDA(const int i) {
        const int c = node_cell(i);
        if (skipped(active, c)) return;
        Real3 add{0, 0, 0};
        if (with_area) add += (coef_area(c) * dot_area(c)) * load3(grad_area, i);
        if (with_volume) add += (coef_volume(c) * dot_volume(c)) * load3(grad_volume, i);
        for (int d = 0; d < 3; ++d) out(i, d) += (d == 0 ? add.x : d == 1 ? add.y : add.z);
      });
}

}  // namespace dcm
