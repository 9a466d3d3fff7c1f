#pragma once
// The friction operator Γ of the overdamped equation of motion Γ v = F (paper eqs. 25, 30-32), applied
// matrix-free:
//   (Γ v)_i = ζ_i v_i + Σ_{bonds b = (i, j)} c (n̂_b · (v_i − v_j)) n̂_b
//           + Σ_{triangles t ∋ i in contact} β_ti Γ_t Σ_{j ∈ t} β_tj v_j                   (substrate)
// ζ_i = 6 π η r_cell / N_cell is the liquid (Stokes) drag spread over the cell's nodes (isotropic),
// c the Kelvin–Voigt dashpot coefficient of every bond (eq. 25), n̂_b the unit bond direction.
// Optionally a transverse part c_t (I − n̂n̂ᵀ) per bond: c_t = c makes the bond friction c (v_i − v_j), the
// form written in the paper's eq. 32 (it damps out-of-plane and shear relative motion, which eq. 25 does
// not, but also rigid rotations). Each bond block M_b = c n̂n̂ᵀ + c_t (I − n̂n̂ᵀ) is positive semi-definite,
// so Γ = ζ I + Σ_b [M_b −M_b; −M_b M_b] is symmetric positive definite.
//
// Substrate friction (MODEL.md section 5): Γ_t = A^C_t [γ_n n̂n̂ᵀ + γ_t (I − n̂n̂ᵀ)] acts on the velocity of
// the triangle's contact point Σ_j β_tj v_j, spread back with the same weights β (those of the contact force,
// kernels/plane_contact.hpp): the blocks β_ti β_tj Γ_t are symmetric positive semi-definite ("consistent").
// The "lumped" alternative (row-sum lumping, as for a lumped mass matrix) puts w_ti Γ_t on each corner's own
// velocity, w_ti = max(β_ti, 0) / Σ_k max(β_tk, 0): the same force on a rigidly moving triangle, but every
// node in contact is damped, not only the contact point; diagonal blocks only (docs/model/spread.md).
//
// The substrate guard (kernels/substrate_guard.hpp), taken linearly implicit: node_guard(i) n̂n̂ᵀ on node i's
// diagonal block, node_guard(i) = Δt k_g A_i where the guard acts (0 elsewhere; empty View: no guard).
//
// Coefficients (n̂_b and each node's 3×3 diagonal block, inverted for the block-Jacobi preconditioner)
// are cached once per step by update(); apply() is a gather over each node's bonds (no atomics).
// Expectations (tests/test_solver.cpp): symmetric (uᵀΓw = wᵀΓu) and positive (vᵀΓv > 0) on random
// vectors; Γ·v for a rigid translation is ζ v; matches an assembled Eigen matrix.
#include <array>
#include <vector>

#include "core/buffers.hpp"
#include "core/kokkos_compat.hpp"
#include "core/vec3.hpp"
#include "kernels/plane_contact.hpp"

namespace dcm {

template <class MemorySpace>
struct FrictionOperator {
  template <class T>
  using View = Kokkos::View<T, Kokkos::LayoutRight, MemorySpace>;
  using Vector = View<double* [3]>;

  View<double*> node_drag;          // ζ_i (N·s/m)
  double dashpot = 0;               // c (N·s/m), along the bond (eq. 25)
  double dashpot_transverse = 0;    // c_t (N·s/m), across the bond; c = c_t = 0: Γ is diagonal
  View<double* [3]> bond_dir;       // n̂_b, cached per step
  View<double* [6]> block_inverse;  // inverse of each node's 3×3 diagonal block: xx, yy, zz, xy, xz, yz
  // Linearly implicit bonds (solvers/cortex_model.hpp): Δt·k'(d_b) per bond, added to the axial dashpot
  // coefficient, so the operator is Γ + Δt K_bonds (same structure, SPD: k' > 0). Empty: none.
  View<double*> bond_stiffness_dt;

  // Substrate friction; off (no kernels) unless enable_substrate_friction() was called.
  bool substrate = false;
  double gamma_n = 0, gamma_t = 0;  // N·s/m³
  Real3 substrate_normal{0, 0, 1};
  bool substrate_lumped = false;   // w_ti Γ_t on each node instead of β_ti β_tj Γ_t (see above)
  View<double* [3]> tri_beta;      // β per triangle corner (shared with the contact buffers)
  View<double*> tri_contact_area;  // the area each triangle's friction acts on (m²)
  View<double* [3]> tri_scratch;   // Γ_t Σ_j β_tj v_j per triangle
  // Pinning (the paper's option): nodes whose triangles all lie fully in the contact get pin_friction I.
  double pin_friction = 0;  // N·s/m; 0: off
  View<int*> tri_regime;    // ContactRegime per triangle (shared with the contact buffers)
  // The substrate guard's Δt k_g A_i per node along substrate_normal (N·s/m); empty: none.
  View<double*> node_guard;

  // The coefficients the kernels read, per cell: c, c_t, γ_n, γ_t, pin (FrictionCoef). update_friction()
  // fills them from the scalars above, or from cell_rows when set (a batch of cells with different
  // constants: core/cell_params.hpp); Γ has no coupling between cells either way.
  View<double* [5]> cell_coef;
  HostMirrorOf<View<double* [5]>> cell_coef_host;  // staging, kept (no allocation per step)
  std::vector<std::array<double, 5>> cell_rows;

  FrictionOperator() = default;
  FrictionOperator(const MeshBuffers<MemorySpace>& mesh, View<double*> drag, double c, double c_t = 0)
      : node_drag(drag),
        dashpot(c),
        dashpot_transverse(c_t),
        bond_dir(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::friction::bond_dir"), mesh.n_bonds),
        block_inverse(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::friction::block_inverse"),
                      mesh.n_nodes),
        cell_coef("dcm::friction::cell_coef", mesh.n_cells),
        cell_coef_host(Kokkos::create_mirror_view(cell_coef)) {}
};

// The bond dashpot coefficient of a membrane with in-plane shear viscosity eta (N·s/m = Pa·s·m). A triangular
// network of axial dashpots c_b (eq. 25) deforms with shear viscosity √3 c_b / 4 and second (Lamé) viscosity
// the same, the lattice factors of its springs' μ = λ = √3 k / 4, so that Hochmuth's relaxation time η/μ is
// c_b / k. Dashpots on the whole relative velocity (eq. 32's c_b (v_i − v_j)) give a pure in-plane strain
// rate the shear viscosity √3 c_b / 2 (no second viscosity) and also damp tilt and rotation, which a
// membrane's viscosity does not. dcm reads Table 1's c this way by default (cortex.c_reading =
// surface_viscosity; docs/MODEL.md, "Table 1's c"). Both checked against the continuum membrane's dissipation
// on the icosphere in tests/test_solver.cpp.
inline double bond_dashpot_of_surface_viscosity(double eta, bool relative) {
  const double sqrt3 = 1.7320508075688772;
  return relative ? 2.0 * eta / sqrt3 : 4.0 * eta / sqrt3;
}

enum FrictionCoef : int { kDashpot = 0, kDashpotTransverse = 1, kGammaN = 2, kGammaT = 3, kPin = 4 };

// Fills op.cell_coef (from cell_rows, or the scalars for every cell).
template <class MemorySpace>
void sync_friction_coefficients(const FrictionOperator<MemorySpace>& op) {
  const auto h = op.cell_coef_host;
  for (std::size_t c = 0; c < h.extent(0); ++c) {
    const std::array<double, 5> uniform{op.dashpot, op.dashpot_transverse, op.gamma_n, op.gamma_t,
                                        op.pin_friction};
    const std::array<double, 5>& row = op.cell_rows.empty() ? uniform : op.cell_rows.at(c);
    for (int k = 0; k < 5; ++k) h(c, k) = row[k];
  }
  Kokkos::deep_copy(op.cell_coef, h);
}

// Switches the substrate blocks on; beta and area are read at every update()/apply() (the contact kernel
// refreshes them each step).
template <class MemorySpace>
void enable_substrate_friction(FrictionOperator<MemorySpace>& op,
                               Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace> beta,
                               Kokkos::View<double*, Kokkos::LayoutRight, MemorySpace> area, double gamma_n,
                               double gamma_t, Real3 normal, bool lumped = false) {
  op.substrate = true;
  op.substrate_lumped = lumped;
  op.gamma_n = gamma_n;
  op.gamma_t = gamma_t;
  op.substrate_normal = (1.0 / norm(normal)) * normal;
  op.tri_beta = beta;
  op.tri_contact_area = area;
  op.tri_scratch = Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>("dcm::friction::tri_scratch",
                                                                               beta.extent(0));
}

// The same from the contact buffers of kernels/plane_contact.hpp; pin_friction > 0 also pins the nodes whose
// triangles all lie fully in the contact (their regime, refreshed by the contact kernel each step).
// area_weights (with lumped): each corner's share is its barycentric coordinate of the friction area's
// centroid (ContactBuffers::tri_area_weight) instead of that of the centre of pressure (β).
template <class MemorySpace>
void enable_substrate_friction(FrictionOperator<MemorySpace>& op, const ContactBuffers<MemorySpace>& contact,
                               double gamma_n, double gamma_t, Real3 normal, double pin_friction = 0,
                               bool lumped = false, bool area_weights = false) {
  enable_substrate_friction(op, lumped && area_weights ? contact.tri_area_weight : contact.tri_beta,
                            contact.tri_friction_area, gamma_n, gamma_t, normal, lumped);
  op.pin_friction = pin_friction;
  op.tri_regime = contact.tri_regime;
}

// y = Γ_t u with Γ_t = A [γ_n n̂n̂ᵀ + γ_t (I − n̂n̂ᵀ)].
KOKKOS_INLINE_FUNCTION Real3 substrate_block_times(Real3 n, double area, double gamma_n, double gamma_t,
                                                   Real3 u) {
  const double un = dot(n, u);
  return area * (gamma_t * u + ((gamma_n - gamma_t) * un) * n);
}

// The lumped weight of corner k of triangle t: max(β_tk, 0) / Σ_m max(β_tm, 0) (0 if all are ≤ 0).
template <class BetaView>
KOKKOS_INLINE_FUNCTION double lumped_weight(const BetaView& beta, int t, int k) {
  const double b0 = beta(t, 0) > 0 ? beta(t, 0) : 0.0, b1 = beta(t, 1) > 0 ? beta(t, 1) : 0.0,
               b2 = beta(t, 2) > 0 ? beta(t, 2) : 0.0, sum = b0 + b1 + b2;
  const double bk = k == 0 ? b0 : (k == 1 ? b1 : b2);
  return sum > 0 ? bk / sum : 0.0;
}

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

// blk += sign · (c n̂n̂ᵀ + c_t (I − n̂n̂ᵀ)), packed xx, yy, zz, xy, xz, yz.
KOKKOS_INLINE_FUNCTION void add_dashpot_block(Real3 n, double c, double c_t, double sign, double blk[6]) {
  const double a = sign * (c - c_t), d = sign * c_t;
  blk[0] += a * n.x * n.x + d;
  blk[1] += a * n.y * n.y + d;
  blk[2] += a * n.z * n.z + d;
  blk[3] += a * n.x * n.y;
  blk[4] += a * n.x * n.z;
  blk[5] += a * n.y * n.z;
}

// The substrate friction and pin coefficients of a FrictionOperator, captured by value into kernels:
// add_block(i, j, blk) adds the (i, j) block of Σ_t β_ti β_tj Γ_t (+ the pin on the diagonal of a node fully
// in contact), j a node of one of i's triangles or i itself. Used by block-Jacobi and the multigrid's level
// 0.
template <class MemorySpace>
struct SubstrateBlocks {
  template <class T>
  using View = Kokkos::View<T, Kokkos::LayoutRight, MemorySpace>;
  bool on = false, lumped = false;
  View<double* [5]> coef;  // per cell (FrictionCoef)
  View<int*> node_cell;
  Real3 normal{0, 0, 1};
  View<int* [3]> tri;
  View<int*> tri_offsets, corners, regime;
  View<double* [3]> beta;
  View<double*> area;
  View<double*> guard;  // FrictionOperator::node_guard (empty: none)

  KOKKOS_INLINE_FUNCTION void add_block(int i, int j, double blk[6]) const {
    if (i == j && guard.extent(0) > 0 && guard(i) > 0)
      add_dashpot_block(normal, guard(i), 0.0, 1.0, blk);  // the substrate guard, Δt k_g A_i n̂n̂ᵀ
    if (!on || (lumped && i != j)) return;                 // lumped: diagonal blocks only
    const int cell = node_cell(i);
    const double gamma_n = coef(cell, kGammaN), gamma_t = coef(cell, kGammaT), pin = coef(cell, kPin);
    for (int q = tri_offsets(i); q < tri_offsets(i + 1); ++q) {
      const int t = corners(q) / 3;
      const double a = area(t);
      if (!(a > 0)) continue;
      if (lumped) {
        if (i == j) {
          const double w = lumped_weight(beta, t, corners(q) % 3) * a;
          add_dashpot_block(normal, w * gamma_n, w * gamma_t, 1.0, blk);  // w_ti Γ_t
        }
        continue;
      }
      for (int k = 0; k < 3; ++k)
        if (tri(t, k) == j) {
          const double w = beta(t, corners(q) % 3) * beta(t, k) * a;
          add_dashpot_block(normal, w * gamma_n, w * gamma_t, 1.0, blk);  // β_ti β_tj Γ_t
        }
    }
    if (i == j && pin > 0 && node_fully_in_contact(i, tri_offsets, corners, regime)) {
      blk[0] += pin;
      blk[1] += pin;
      blk[2] += pin;
    }
  }
};

template <class MemorySpace>
SubstrateBlocks<MemorySpace> substrate_blocks(const MeshBuffers<MemorySpace>& mesh,
                                              const FrictionOperator<MemorySpace>& op) {
  SubstrateBlocks<MemorySpace> s;
  s.on = op.substrate;
  s.lumped = op.substrate_lumped;
  s.coef = op.cell_coef;
  s.node_cell = mesh.node_cell;
  s.normal = op.substrate_normal;
  s.tri = mesh.tri;
  s.tri_offsets = mesh.node_tri_offsets;
  s.corners = mesh.node_tri_corners;
  s.regime = op.tri_regime;
  s.beta = op.tri_beta;
  s.area = op.tri_contact_area;
  s.guard = op.node_guard;
  return s;
}

// Caches n̂_b and the inverted diagonal blocks ζ_i I + Σ_b c n̂_b n̂_bᵀ for the current positions
// (block_inverse = false: n̂_b only, for a caller that preconditions with the multigrid, which inverts its
// own diagonal blocks).
template <class ExecutionSpace, class MemorySpace>
void update_friction(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                     const FrictionOperator<MemorySpace>& op, bool block_inverse = true) {
  sync_friction_coefficients(op);
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
  if (!block_inverse) return;
  const auto offsets = mesh.node_bond_offsets;
  const auto bonds = mesh.node_bonds;
  const auto drag = op.node_drag;
  const auto inverse = op.block_inverse;
  const auto coef = op.cell_coef;
  const auto node_cell = mesh.node_cell;
  const auto substrate = substrate_blocks(mesh, op);
  const auto bond_k = op.bond_stiffness_dt;
  const bool stiff = bond_k.extent(0) > 0;
  Kokkos::parallel_for(
      "dcm::friction::block_jacobi", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
      KOKKOS_LAMBDA(const int i) {
        const double c = coef(node_cell(i), kDashpot), c_t = coef(node_cell(i), kDashpotTransverse);
        double a[6] = {drag(i), drag(i), drag(i), 0, 0, 0};
        for (int s = offsets(i); s < offsets(i + 1); ++s)
          add_dashpot_block(load3(dir, bonds(s)), c + (stiff ? bond_k(bonds(s)) : 0.0), c_t, 1.0, a);
        substrate.add_block(i, i, a);  // β² Γ_t and the pin
        double inv[6];
        invert_sym3(a, inv);
        for (int k = 0; k < 6; ++k) inverse(i, k) = inv[k];
      });
}

// out = Γ v (eq. 32's right-hand side operator).
// active (optional): only the rows of these cells (core/cell_params.hpp).
template <class ExecutionSpace, class MemorySpace>
void apply_friction(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                    const FrictionOperator<MemorySpace>& op,
                    const typename FrictionOperator<MemorySpace>::Vector& v,
                    const typename FrictionOperator<MemorySpace>::Vector& out,
                    const CellFlags<MemorySpace>& active = {}) {
  const auto bond = mesh.bond;
  const auto offsets = mesh.node_bond_offsets;
  const auto bonds = mesh.node_bonds;
  const auto dir = op.bond_dir;
  const auto drag = op.node_drag;
  const auto coef = op.cell_coef;
  const auto node_cell = mesh.node_cell;
  const auto tri_cell = mesh.tri_cell;
  const bool substrate = op.substrate, lumped = op.substrate_lumped;
  const auto tri_offsets = mesh.node_tri_offsets;
  const auto corners = mesh.node_tri_corners;
  const auto beta = op.tri_beta;
  const auto scratch = op.tri_scratch;
  const auto regime = op.tri_regime;
  const auto bond_k = op.bond_stiffness_dt;
  const bool stiff = bond_k.extent(0) > 0;
  const auto contact_area = op.tri_contact_area;
  const Real3 sn = op.substrate_normal;
  const auto guard = op.node_guard;
  const bool guarded = guard.extent(0) > 0;
  if (substrate && !lumped) {  // u_t = Γ_t Σ_j β_tj v_j for the triangles in contact
    const auto tri = mesh.tri;
    Kokkos::parallel_for(
        "dcm::friction::substrate_triangles", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_tris),
        KOKKOS_LAMBDA(const int t) {
          if (skipped(active, tri_cell(t))) return;
          const double area = contact_area(t);
          Real3 u{0, 0, 0};
          if (area > 0) {
            for (int k = 0; k < 3; ++k) u += beta(t, k) * load3(v, tri(t, k));
            const int cell = tri_cell(t);
            u = substrate_block_times(sn, area, coef(cell, kGammaN), coef(cell, kGammaT), u);
          }
          store3(scratch, t, u);
        });
  }
  Kokkos::parallel_for(
      "dcm::friction::apply", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
      KOKKOS_LAMBDA(const int i) {
        const int cell = node_cell(i);
        if (skipped(active, cell)) return;
        const double c = coef(cell, kDashpot), c_t = coef(cell, kDashpotTransverse);
        const Real3 vi = load3(v, i);
        Real3 acc = drag(i) * vi;
        for (int s = offsets(i); s < offsets(i + 1); ++s) {
          const int b = bonds(s);
          const int j = bond(b, 0) == i ? bond(b, 1) : bond(b, 0);
          const Real3 n = load3(dir, b), dv = vi - load3(v, j);
          const double along = dot(n, dv);
          acc += ((c + (stiff ? bond_k(b) : 0.0)) * along) * n;  // eq. 25: dashpot along the bond
          if (c_t != 0) acc += c_t * (dv - along * n);  // optional transverse part (eq. 32's c (v_i − v_j))
        }
        if (substrate && lumped) {
          for (int k = tri_offsets(i); k < tri_offsets(i + 1); ++k) {
            const int t = corners(k) / 3;
            const double area = contact_area(t);
            if (area > 0)
              acc += substrate_block_times(sn, lumped_weight(beta, t, corners(k) % 3) * area,
                                           coef(cell, kGammaN), coef(cell, kGammaT), vi);
          }
        } else if (substrate) {
          for (int k = tri_offsets(i); k < tri_offsets(i + 1); ++k) {
            const int t = corners(k) / 3;
            acc += beta(t, corners(k) % 3) * load3(scratch, t);
          }
        }
        const double pin = coef(cell, kPin);
        if (pin > 0 && node_fully_in_contact(i, tri_offsets, corners, regime)) acc += pin * vi;
        if (guarded && guard(i) > 0) acc += (guard(i) * dot(sn, vi)) * sn;  // the substrate guard
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
