#pragma once
// Two-level preconditioner: block-Jacobi plus an additive coarse correction on the six rigid-body modes
// of every cell, M⁻¹ = D⁻¹ + Z (ZᵀΓZ)⁻¹ Zᵀ, Z the translations and the rotations about the cell's
// drag-weighted centre x̄. Rigid motions do not stretch any bond (n̂_b · (ω × (x_i − x_j)) = 0 with
// n̂_b ∥ x_i − x_j), so ZᵀΓZ is the drag alone and block-diagonal per cell:
//   translation: Σ ζ_i I,   rotation: J = Σ ζ_i (|r_i|² I − r_i r_iᵀ),  r_i = x_i − x̄.
// Z (ZᵀΓZ)⁻¹ Zᵀ r is the rigid motion that the drag alone would give under the net force Σ r_i and torque
// Σ r_i × r-force: u = F / Σζ, ω = J⁻¹ T. M⁻¹ is SPD (a sum of an SPD and a PSD term).
// Per step: update_rigid_modes() after update_friction(); apply_rigid_two_level() is precondition(r, z).
#include "core/buffers.hpp"
#include "core/vec3.hpp"
#include "solvers/block_sparse.hpp"
#include "solvers/friction_operator.hpp"

namespace dcm {

template <class MemorySpace>
struct RigidModes {
  template <class T>
  using View = Kokkos::View<T, Kokkos::LayoutRight, MemorySpace>;
  View<double* [10]> cell;   // per cell: x̄ (3), 1 / Σζ, J⁻¹ (6, packed xx yy zz xy xz yz)
  View<double* [6]> coarse;  // per cell: u (3), ω (3) of the last application
  RigidModes() = default;
  explicit RigidModes(int n_cells)
      : cell(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::rigid::cell"), n_cells),
        coarse(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::rigid::coarse"), n_cells) {}
};

// Drag-weighted centre, total drag and rotational drag tensor of every cell (one team per cell).
template <class ExecutionSpace, class MemorySpace>
void update_rigid_modes(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                        const FrictionOperator<MemorySpace>& op, const RigidModes<MemorySpace>& rm) {
  using Policy = Kokkos::TeamPolicy<ExecutionSpace>;
  using Member = typename Policy::member_type;
  const auto x = mesh.x;
  const auto begin = mesh.cell_node_begin;
  const auto drag = op.node_drag;
  const auto cell = rm.cell;
  Kokkos::parallel_for(
      "dcm::rigid::update", Policy(space, mesh.n_cells, Kokkos::AUTO), KOKKOS_LAMBDA(const Member& team) {
        const int c = team.league_rank(), b = begin(c), e = begin(c + 1);
        const Real3 x0 = load3(x, b);  // moments about the first node: no cancellation far from the origin
        double m[10];                  // Σζ, Σζ d (3), Σζ d dᵀ (6), d = x − x0
        for (int k = 0; k < 10; ++k) {
          double s = 0;
          Kokkos::parallel_reduce(
              Kokkos::TeamThreadRange(team, b, e),
              [&](const int i, double& acc) {
                const Real3 d = load3(x, i) - x0;
                const double v[10] = {1,         d.x,       d.y,       d.z,       d.x * d.x,
                                      d.y * d.y, d.z * d.z, d.x * d.y, d.x * d.z, d.y * d.z};
                acc += drag(i) * v[k];
              },
              s);
          m[k] = s;
        }
        Kokkos::single(Kokkos::PerTeam(team), [&]() {
          const Real3 g{m[1] / m[0], m[2] / m[0], m[3] / m[0]};
          // Second moment about x̄: S = Σζ d dᵀ − Σζ g gᵀ; J = tr(S) I − S.
          const double s[6] = {m[4] - m[0] * g.x * g.x, m[5] - m[0] * g.y * g.y, m[6] - m[0] * g.z * g.z,
                               m[7] - m[0] * g.x * g.y, m[8] - m[0] * g.x * g.z, m[9] - m[0] * g.y * g.z};
          const double tr = s[0] + s[1] + s[2];
          const double j[6] = {tr - s[0], tr - s[1], tr - s[2], -s[3], -s[4], -s[5]};
          double jinv[6];
          invert_sym3(j, jinv);
          const Real3 centre = x0 + g;
          cell(c, 0) = centre.x;
          cell(c, 1) = centre.y;
          cell(c, 2) = centre.z;
          cell(c, 3) = 1.0 / m[0];
          for (int k = 0; k < 6; ++k) cell(c, 4 + k) = jinv[k];
        });
      });
}

// z = Q r (accumulate: z += Q r), Q = Z (ZᵀΓZ)⁻¹ Zᵀ the exact solve on the rigid modes.
template <class ExecutionSpace, class MemorySpace>
void apply_rigid_coarse(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                        const RigidModes<MemorySpace>& rm,
                        const typename FrictionOperator<MemorySpace>::Vector& r,
                        const typename FrictionOperator<MemorySpace>::Vector& z, bool accumulate) {
  using Policy = Kokkos::TeamPolicy<ExecutionSpace>;
  using Member = typename Policy::member_type;
  const auto x = mesh.x;
  const auto begin = mesh.cell_node_begin;
  const auto cell = rm.cell;
  const auto coarse = rm.coarse;
  Kokkos::parallel_for(
      "dcm::rigid::restrict", Policy(space, mesh.n_cells, Kokkos::AUTO), KOKKOS_LAMBDA(const Member& team) {
        const int c = team.league_rank(), b = begin(c), e = begin(c + 1);
        const Real3 centre{cell(c, 0), cell(c, 1), cell(c, 2)};
        double ft[6];  // net force F, net torque T about x̄
        for (int k = 0; k < 6; ++k) {
          double s = 0;
          Kokkos::parallel_reduce(
              Kokkos::TeamThreadRange(team, b, e),
              [&](const int i, double& acc) {
                const Real3 f = load3(r, i);
                const Real3 t = cross(load3(x, i) - centre, f);
                const double v[6] = {f.x, f.y, f.z, t.x, t.y, t.z};
                acc += v[k];
              },
              s);
          ft[k] = s;
        }
        Kokkos::single(Kokkos::PerTeam(team), [&]() {
          const double m = cell(c, 3);
          const Real3 w = sym3_times(cell(c, 4), cell(c, 5), cell(c, 6), cell(c, 7), cell(c, 8), cell(c, 9),
                                     Real3{ft[3], ft[4], ft[5]});
          coarse(c, 0) = m * ft[0];
          coarse(c, 1) = m * ft[1];
          coarse(c, 2) = m * ft[2];
          coarse(c, 3) = w.x;
          coarse(c, 4) = w.y;
          coarse(c, 5) = w.z;
        });
      });
  const auto node_cell = mesh.node_cell;
  Kokkos::parallel_for(
      "dcm::rigid::prolong", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
      KOKKOS_LAMBDA(const int i) {
        const int c = node_cell(i);
        const Real3 centre{cell(c, 0), cell(c, 1), cell(c, 2)};
        const Real3 u{coarse(c, 0), coarse(c, 1), coarse(c, 2)}, w{coarse(c, 3), coarse(c, 4), coarse(c, 5)};
        const Real3 q = u + cross(w, load3(x, i) - centre);
        store3(z, i, accumulate ? load3(z, i) + q : q);
      });
}

// z = D⁻¹ r + Q r (D: Γ's block diagonal, from update_friction): the additive two-level preconditioner.
template <class ExecutionSpace, class MemorySpace>
void apply_rigid_two_level(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                           const FrictionOperator<MemorySpace>& op, const RigidModes<MemorySpace>& rm,
                           const typename FrictionOperator<MemorySpace>::Vector& r,
                           const typename FrictionOperator<MemorySpace>::Vector& z) {
  apply_block_jacobi(space, op, r, z);
  apply_rigid_coarse(space, mesh, rm, r, z, true);
}

// Balanced (deflated, multiplicative) combination of the rigid-mode solve Q with an inner SPD
// preconditioner V (block-Jacobi or the multigrid V-cycle):
//   M⁻¹ = Q + (I − QΓ) V (I − ΓQ)
// symmetric (Q and Γ are) and positive definite when V is; rigid motions are solved exactly. Costs two
// applications of Γ more than V alone. inner(in, out) computes out = V in.
template <class MemorySpace>
struct DeflationWorkspace {
  using Vector = typename FrictionOperator<MemorySpace>::Vector;
  Vector y, t, u;
  DeflationWorkspace() = default;
  explicit DeflationWorkspace(int n)
      : y(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::rigid::y"), n),
        t(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::rigid::t"), n),
        u(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::rigid::u"), n) {}
};

namespace rigid_detail {
// out = a + s b on [n][3] Views (out may alias a or b). Outside apply_rigid_deflated: a CUDA extended lambda
// may not sit in a function templated on a type local to another function (the caller's inner lambda).
template <class ExecutionSpace, class Vector>
void add_scaled(const ExecutionSpace& space, const char* label, const Vector& a, double s, const Vector& b,
                const Vector& out) {
  Kokkos::parallel_for(
      label, Kokkos::RangePolicy<ExecutionSpace>(space, 0, static_cast<int>(out.extent(0))),
      KOKKOS_LAMBDA(const int i) { store3(out, i, load3(a, i) + s * load3(b, i)); });
}
}  // namespace rigid_detail

template <class ExecutionSpace, class MemorySpace, class Inner>
void apply_rigid_deflated(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                          const FrictionOperator<MemorySpace>& op, const RigidModes<MemorySpace>& rm,
                          Inner&& inner, const DeflationWorkspace<MemorySpace>& w,
                          const typename FrictionOperator<MemorySpace>::Vector& r,
                          const typename FrictionOperator<MemorySpace>::Vector& z) {
  const auto y = w.y, t = w.t, u = w.u;
  apply_rigid_coarse(space, mesh, rm, r, y, false);                       // y = Q r
  apply_friction(space, mesh, op, y, t);                                  // t = Γ Q r
  rigid_detail::add_scaled(space, "dcm::rigid::deflate", r, -1.0, t, t);  // t = (I − ΓQ) r
  inner(t, z);                                                            // z = V t
  apply_friction(space, mesh, op, z, u);                                  // u = Γ z
  rigid_detail::add_scaled(space, "dcm::rigid::combine", z, 1.0, y, z);   // z = Q r + V t
  apply_rigid_coarse(space, mesh, rm, u, t, false);                       // t = QΓ V t
  rigid_detail::add_scaled(space, "dcm::rigid::project", z, -1.0, t, z);
}

}  // namespace dcm
