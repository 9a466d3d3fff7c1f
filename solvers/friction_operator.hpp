#pragma once
// The friction operator Γ of the overdamped equation of motion Γ v = F (paper eqs. 25, 30-32), applied
// matrix-free:
//   (Γ v)_i = ζ_i v_i + Σ_{bonds b = (i, j)} c (n̂_b · (v_i − v_j)) n̂_b        (+ contact blocks, later)
// ζ_i = 6 π η r_cell / N_cell is the liquid (Stokes) drag spread over the cell's nodes (isotropic),
// c the Kelvin–Voigt dashpot coefficient of every bond (eq. 25), n̂_b the unit bond direction.
// Γ is symmetric positive definite: the drag part is ζ I with ζ > 0, each dashpot adds c (Bv)ᵀ(Bv) ≥ 0.
//
// Coefficients (n̂_b and each node's 3×3 diagonal block, inverted for the block-Jacobi preconditioner)
// are cached once per step by update(); apply() is a gather over each node's bonds (no atomics).
// Expectations (tests/test_solver.cpp): symmetric (uᵀΓw = wᵀΓu) and positive (vᵀΓv > 0) on random
// vectors; Γ·v for a rigid translation is ζ v; matches an assembled Eigen matrix.
#include "core/buffers.hpp"
#include "core/vec3.hpp"

namespace dcm {

template <class MemorySpace>
struct FrictionOperator {
  template <class T>
  using View = Kokkos::View<T, Kokkos::LayoutRight, MemorySpace>;
  using Vector = View<double* [3]>;

  View<double*> node_drag;          // ζ_i (N·s/m)
  double dashpot = 0;               // c (N·s/m); 0: Γ is diagonal
  View<double* [3]> bond_dir;       // n̂_b, cached per step
  View<double* [6]> block_inverse;  // inverse of each node's 3×3 diagonal block: xx, yy, zz, xy, xz, yz

  FrictionOperator() = default;
  FrictionOperator(const MeshBuffers<MemorySpace>& mesh, View<double*> drag, double c)
      : node_drag(drag),
        dashpot(c),
        bond_dir(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::friction::bond_dir"), mesh.n_bonds),
        block_inverse(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::friction::block_inverse"),
                      mesh.n_nodes) {}
};

// Inverse of the symmetric 3×3 matrix (a00, a11, a22, a01, a02, a12), same packing.
KOKKOS_INLINE_FUNCTION void invert_sym3(const double a[6], double out[6]) {
  const double c00 = a[1] * a[2] - a[5] * a[5], c01 = a[4] * a[5] - a[3] * a[2],
               c02 = a[3] * a[5] - a[4] * a[1];
  const double det = a[0] * c00 + a[3] * c01 + a[4] * c02;
  const double inv = 1.0 / det;
  out[0] = c00 * inv;
  out[1] = (a[0] * a[2] - a[4] * a[4]) * inv;
  out[2] = (a[0] * a[1] - a[3] * a[3]) * inv;
  out[3] = c01 * inv;
  out[4] = c02 * inv;
  out[5] = (a[3] * a[4] - a[0] * a[5]) * inv;
}

// Caches n̂_b and the inverted diagonal blocks ζ_i I + Σ_b c n̂_b n̂_bᵀ for the current positions.
template <class ExecutionSpace, class MemorySpace>
void update_friction(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                     const FrictionOperator<MemorySpace>& op) {
  const auto x = mesh.x;
  const auto bond = mesh.bond;
  const auto dir = op.bond_dir;
  Kokkos::parallel_for(
      "dcm::friction::bond_directions", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_bonds),
      KOKKOS_LAMBDA(const int b) {
        const Real3 d = load3(x, bond(b, 1)) - load3(x, bond(b, 0));
        const double len = norm(d);
        store3(dir, b, len > 0 ? (1.0 / len) * d : Real3{0, 0, 0});
      });
  const auto offsets = mesh.node_bond_offsets;
  const auto bonds = mesh.node_bonds;
  const auto drag = op.node_drag;
  const auto inverse = op.block_inverse;
  const double c = op.dashpot;
  Kokkos::parallel_for(
      "dcm::friction::block_jacobi", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
      KOKKOS_LAMBDA(const int i) {
        double a[6] = {drag(i), drag(i), drag(i), 0, 0, 0};
        for (int s = offsets(i); s < offsets(i + 1); ++s) {
          const Real3 n = load3(dir, bonds(s));
          a[0] += c * n.x * n.x;
          a[1] += c * n.y * n.y;
          a[2] += c * n.z * n.z;
          a[3] += c * n.x * n.y;
          a[4] += c * n.x * n.z;
          a[5] += c * n.y * n.z;
        }
        double inv[6];
        invert_sym3(a, inv);
        for (int k = 0; k < 6; ++k) inverse(i, k) = inv[k];
      });
}

// out = Γ v (eq. 32's right-hand side operator).
template <class ExecutionSpace, class MemorySpace>
void apply_friction(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                    const FrictionOperator<MemorySpace>& op,
                    const typename FrictionOperator<MemorySpace>::Vector& v,
                    const typename FrictionOperator<MemorySpace>::Vector& out) {
  const auto bond = mesh.bond;
  const auto offsets = mesh.node_bond_offsets;
  const auto bonds = mesh.node_bonds;
  const auto dir = op.bond_dir;
  const auto drag = op.node_drag;
  const double c = op.dashpot;
  Kokkos::parallel_for(
      "dcm::friction::apply", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
      KOKKOS_LAMBDA(const int i) {
        const Real3 vi = load3(v, i);
        Real3 acc = drag(i) * vi;
        for (int s = offsets(i); s < offsets(i + 1); ++s) {
          const int b = bonds(s);
          const int j = bond(b, 0) == i ? bond(b, 1) : bond(b, 0);
          const Real3 n = load3(dir, b);
          acc += (c * dot(n, vi - load3(v, j))) * n;  // eq. 25: dashpot along the bond
        }
        store3(out, i, acc);
      });
}

// out = P⁻¹ r with P the block diagonal of Γ.
template <class ExecutionSpace, class MemorySpace>
void apply_block_jacobi(const ExecutionSpace& space, const FrictionOperator<MemorySpace>& op,
                        const typename FrictionOperator<MemorySpace>::Vector& r,
                        const typename FrictionOperator<MemorySpace>::Vector& out) {
  const auto inv = op.block_inverse;
  Kokkos::parallel_for(
      "dcm::friction::precondition", Kokkos::RangePolicy<ExecutionSpace>(space, 0, r.extent(0)),
      KOKKOS_LAMBDA(const int i) {
        const double rx = r(i, 0), ry = r(i, 1), rz = r(i, 2);
        out(i, 0) = inv(i, 0) * rx + inv(i, 3) * ry + inv(i, 4) * rz;
        out(i, 1) = inv(i, 3) * rx + inv(i, 1) * ry + inv(i, 5) * rz;
        out(i, 2) = inv(i, 4) * rx + inv(i, 5) * ry + inv(i, 2) * rz;
      });
}

}  // namespace dcm
