#pragma once
// Block-sparse symmetric matrices with symmetric 3×3 blocks (CSR over nodes), for the assembled coarse
// levels of the multigrid preconditioner (solvers/multigrid.hpp): y = A x, r = b − A x, the inverted
// diagonal blocks and damped block-Jacobi steps. Blocks are packed xx, yy, zz, xy, xz, yz like
// FrictionOperator::block_inverse. Every block of Γ (ζ I and c n̂n̂ᵀ) is symmetric, and so is every
// Galerkin product of them with the scalar prolongation P ⊗ I₃.
#include "core/vec3.hpp"
#include "solvers/friction_operator.hpp"

namespace dcm {

template <class MemorySpace>
struct BlockCsr {
  template <class T>
  using View = Kokkos::View<T, Kokkos::LayoutRight, MemorySpace>;
  int n_rows = 0, nnz = 0;
  View<int*> row_offsets;  // n_rows + 1
  View<int*> cols;         // nnz, sorted within a row
  View<int*> diag_slot;    // n_rows: the slot of (i, i)
  View<double* [6]> values;
  View<double* [6]> diag_inverse;  // inverse of each diagonal block, for the smoother
  View<int*> row_cell;             // the cell of each row (the blocks never couple two cells)
};

KOKKOS_INLINE_FUNCTION Real3 sym3_times(const double a0, const double a1, const double a2, const double a3,
                                        const double a4, const double a5, const Real3 v) {
  return {a0 * v.x + a3 * v.y + a4 * v.z, a3 * v.x + a1 * v.y + a5 * v.z, a4 * v.x + a5 * v.y + a2 * v.z};
}

// Row i of A x: one gather over the row's blocks.
template <class Offsets, class Cols, class Values, class Vector>
KOKKOS_INLINE_FUNCTION Real3 block_row_times(const Offsets& off, const Cols& cols, const Values& val,
                                             const Vector& x, int i) {
  Real3 acc{0, 0, 0};
  for (int s = off(i); s < off(i + 1); ++s)
    acc += sym3_times(val(s, 0), val(s, 1), val(s, 2), val(s, 3), val(s, 4), val(s, 5), load3(x, cols(s)));
  return acc;
}

// out = b − A x, the residual (b = nullptr: out = A x, the product; the velocity solve's operator where the
// multigrid's level 0 holds it, solvers/cortex_model.hpp).
// active (optional): only the rows of these cells (core/cell_params.hpp; needs row_cell).
template <class ExecutionSpace, class MemorySpace, class Vector>
void block_csr_residual(const ExecutionSpace& space, const BlockCsr<MemorySpace>& a, const Vector* b,
                        const Vector& x, const Vector& out, const CellFlags<MemorySpace>& active = {}) {
  const auto row_cell = a.row_cell;
  const auto off = a.row_offsets;
  const auto cols = a.cols;
  const auto val = a.values;
  const bool residual = b != nullptr;
  const Vector rhs = residual ? *b : Vector();
  Kokkos::parallel_for(
      residual ? "dcm::bsr::residual" : "dcm::bsr::multiply",
      Kokkos::RangePolicy<ExecutionSpace>(space, 0, a.n_rows), KOKKOS_LAMBDA(const int i) {
        if (skipped(active, row_cell(i))) return;
        const Real3 ax = block_row_times(off, cols, val, x, i);
        store3(out, i, residual ? load3(rhs, i) - ax : ax);
      });
}
template <class ExecutionSpace, class MemorySpace, class Vector>
void block_csr_residual(const ExecutionSpace& space, const BlockCsr<MemorySpace>& a, const Vector& b,
                        const Vector& x, const Vector& out, const CellFlags<MemorySpace>& active = {}) {
  block_csr_residual(space, a, &b, x, out, active);
}

// out = A x.
template <class ExecutionSpace, class MemorySpace, class Vector>
void block_csr_multiply(const ExecutionSpace& space, const BlockCsr<MemorySpace>& a, const Vector& x,
                        const Vector& out, const CellFlags<MemorySpace>& active = {}) {
  block_csr_residual(space, a, static_cast<const Vector*>(nullptr), x, out, active);
}

// Inverts every diagonal block (the block-Jacobi smoother's D⁻¹).
template <class ExecutionSpace, class MemorySpace>
void block_csr_invert_diagonal(const ExecutionSpace& space, const BlockCsr<MemorySpace>& a) {
  const auto diag = a.diag_slot;
  const auto val = a.values;
  const auto inv = a.diag_inverse;
  Kokkos::parallel_for(
      "dcm::bsr::invert_diagonal", Kokkos::RangePolicy<ExecutionSpace>(space, 0, a.n_rows),
      KOKKOS_LAMBDA(const int i) {
        const int s = diag(i);
        const double blk[6] = {val(s, 0), val(s, 1), val(s, 2), val(s, 3), val(s, 4), val(s, 5)};
        double out[6];
        invert_sym3(blk, out);
        for (int k = 0; k < 6; ++k) inv(i, k) = out[k];
      });
}

// x = ω D⁻¹ r: a damped block-Jacobi step from x = 0 (the smoother's first sweep; block-Jacobi itself with
// ω = 1).
template <class ExecutionSpace, class MemorySpace, class Vector>
void block_jacobi_step(const ExecutionSpace& space, const BlockCsr<MemorySpace>& a, double omega,
                       const Vector& r, const Vector& x, const CellFlags<MemorySpace>& active = {}) {
  const auto inv = a.diag_inverse;
  const auto row_cell = a.row_cell;
  Kokkos::parallel_for(
      "dcm::bsr::jacobi_step", Kokkos::RangePolicy<ExecutionSpace>(space, 0, a.n_rows),
      KOKKOS_LAMBDA(const int i) {
        if (skipped(active, row_cell(i))) return;
        store3(x, i,
               omega *
                   sym3_times(inv(i, 0), inv(i, 1), inv(i, 2), inv(i, 3), inv(i, 4), inv(i, 5), load3(r, i)));
      });
}

// out = in + ω D⁻¹ (b − A in): one damped block-Jacobi sweep in one pass over the rows (the residual is not
// stored). in and out must be different vectors. Rows of skipped cells keep out's values.
template <class ExecutionSpace, class MemorySpace, class Vector>
void block_jacobi_sweep(const ExecutionSpace& space, const BlockCsr<MemorySpace>& a, double omega,
                        const Vector& b, const Vector& in, const Vector& out,
                        const CellFlags<MemorySpace>& active = {}) {
  const auto inv = a.diag_inverse;
  const auto row_cell = a.row_cell;
  const auto off = a.row_offsets;
  const auto cols = a.cols;
  const auto val = a.values;
  Kokkos::parallel_for(
      "dcm::bsr::jacobi_sweep", Kokkos::RangePolicy<ExecutionSpace>(space, 0, a.n_rows),
      KOKKOS_LAMBDA(const int i) {
        if (skipped(active, row_cell(i))) return;
        const Real3 r = load3(b, i) - block_row_times(off, cols, val, in, i);
        const Real3 dz =
            omega * sym3_times(inv(i, 0), inv(i, 1), inv(i, 2), inv(i, 3), inv(i, 4), inv(i, 5), r);
        store3(out, i, load3(in, i) + dz);
      });
}

}  // namespace dcm
