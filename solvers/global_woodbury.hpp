#pragma once
// The implicit volume stiffness (solvers/global_stiffness.hpp, eq. 29) in the preconditioner.
// The CG's operator is A = B + s u uᵀ per cell: B the friction and the other implicit terms, which the
// preconditioner P approximates (P ≈ B⁻¹: multigrid V-cycle or block-Jacobi), and the rank-one volume term
// with u = ∇V_c and s = Δt k_v/V*. P does not know it, and with long steps (adaptive stepping) its direction
// costs the CG extra iterations. The Sherman–Morrison–Woodbury identity gives the inverse of P⁻¹ + s u uᵀ
// from P alone:
//     M⁻¹ = P − w wᵀ / (1/s + uᵀw),   w = P u   (P symmetric),
// symmetric positive definite whenever P is (it is (P⁻¹ + s u uᵀ)⁻¹), so PCG stays PCG.
//   update_global_woodbury()   once per solve that applies the preconditioner (CortexModel::solve_velocity
//                              builds it on the first application), after the preconditioner's and the
//                              global stiffness's updates:
//                              w = P u (one application of P for all cells at once: P is block-diagonal per
//                              cell) and per cell 1/s + uᵀw
//   apply_global_woodbury()    after z = P r in the preconditioner: z −= w (wᵀr) / (1/s + uᵀw), per cell
// The global area term (eq. 28) is rank one too, but the same correction for it saved no iteration on the
// Hategan scene (4.70 CG per step to t = 0.3 s with and without it) and would cost a second application of P
// per step; it is left to the CG (docs/model/solver.md, "The volume term in the preconditioner").
// Off by default (solver.precondition_volume): with the multigrid the extra application of P per step costs
// about what it saves with long steps, and more than it saves at the paper's Δt (docs/model/solver.md).
// Expectations (tests/test_solver.cpp): P (r − s u uᵀ z) = z for z = M⁻¹ r, and fewer PCG iterations with a
// stiff volume term.
#include "core/buffers.hpp"
#include "core/cell_params.hpp"
#include "core/segmented_sum.hpp"
#include "core/vec3.hpp"
#include "solvers/global_stiffness.hpp"

namespace dcm {

template <class MemorySpace>
struct GlobalWoodbury {
  template <class T>
  using View = Kokkos::View<T, Kokkos::LayoutRight, MemorySpace>;
  View<double* [3]> w;      // P ∇V at every node
  View<double*> uw, scale;  // per cell: uᵀw, then 1 / (1/s + uᵀw) (0: the cell has no volume term)
  View<double*> wr;         // per cell scratch: wᵀ r
  GlobalWoodbury() = default;
  explicit GlobalWoodbury(const MeshBuffers<MemorySpace>& mesh)
      : w("dcm::woodbury::w", mesh.n_nodes),
        uw("dcm::woodbury::uw", mesh.n_cells),
        scale("dcm::woodbury::scale", mesh.n_cells),
        wr("dcm::woodbury::wr", mesh.n_cells) {}
};

namespace woodbury_detail {
// uᵀw per cell and the scales 1 / (1/coef + uᵀw), w = P u already stored in wb.w. Outside
// update_global_woodbury: a CUDA extended lambda may not sit in a function templated on a type local to
// another function (the caller's preconditioner lambda).
template <class ExecutionSpace, class MemorySpace>
void update_scales(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                   const GlobalStiffness<MemorySpace>& g, const GlobalWoodbury<MemorySpace>& wb) {
  const auto u = g.grad_volume, w = wb.w;
  segmented_sum<1>(
      "dcm::woodbury::uw", space, mesh.node_sums,
      KOKKOS_LAMBDA(const int i, double(&s)[1]) { s[0] += dot(load3(u, i), load3(w, i)); },
      PairOut<MemorySpace>{wb.uw, wb.uw});
  const auto coef = g.coef_volume, uw = wb.uw, scale = wb.scale;
  Kokkos::parallel_for(
      "dcm::woodbury::scale", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_cells),
      KOKKOS_LAMBDA(const int c) {  // a cell without the term (k_v = 0) takes no correction
        scale(c) = coef(c) > 0 ? 1.0 / (1.0 / coef(c) + uw(c)) : 0.0;
      });
}
}  // namespace woodbury_detail

// precondition(in, out): out = P in, for all cells (the caller's preconditioner, before this correction).
// Needs g.volume (a cell set with a volume term).
template <class ExecutionSpace, class MemorySpace, class Precondition>
void update_global_woodbury(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                            const GlobalStiffness<MemorySpace>& g, const GlobalWoodbury<MemorySpace>& wb,
                            const Precondition& precondition) {
  precondition(g.grad_volume, wb.w);
  woodbury_detail::update_scales(space, mesh, g, wb);
}

// z −= w (wᵀ r) / (1/s + uᵀw), for the rows of the active cells (z = P r on entry).
template <class ExecutionSpace, class MemorySpace, class Vector>
void apply_global_woodbury(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                           const GlobalWoodbury<MemorySpace>& wb, const Vector& r, const Vector& z,
                           const CellFlags<MemorySpace>& active = {}) {
  const auto w = wb.w;
  const auto node_cell = mesh.node_cell;
  segmented_sum<1>(
      "dcm::woodbury::dots", space, mesh.node_sums,
      KOKKOS_LAMBDA(const int i, double(&s)[1]) {
        if (skipped(active, node_cell(i))) return;
        s[0] += dot(load3(w, i), load3(r, i));
      },
      PairOut<MemorySpace>{wb.wr, wb.wr});
  const auto wr = wb.wr, scale = wb.scale;
  Kokkos::parallel_for(
      "dcm::woodbury::correct", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
      KOKKOS_LAMBDA(const int i) {
        const int c = node_cell(i);
        if (skipped(active, c)) return;
        store3(z, i, load3(z, i) - (scale(c) * wr(c)) * load3(w, i));
      });
}

}  // namespace dcm
