#pragma once
// In-plane elasticity of the cortex: FENE + POW per bond (paper eqs. 21-24, L = 2; MODEL.md section 3).
//
// Bond b = (i, j), length d = |x_i - x_j|, rest length d* (the bond's length in the rest shape),
// d_max = x_max d*. Energy (eq. 21 plus the POW energy whose force magnitude is eq. 23):
//   U(d)  = -(k_s / 2) d_max^2 ln(1 - d^2 / d_max^2) + k_c / d               (L = 2: k_c / ((L-1) d^(L-1)))
//   U'(d) =  k_s d / (1 - d^2 / d_max^2) - k_c / d^2                           (N)
//   k_c   =  k_s d*^3 / (1 - d*^2 / d_max^2) = k_s d*^3 / (1 - 1 / x_max^2)   (eq. 24, N m^2)
// U'(d*) = 0: every bond is force-free at its rest length. The force on node i is
//   F_i = -U'(d) (x_i - x_j) / d,   F_j = -F_i,
// i.e. FENE (|eq. 22|) pulls the nodes together, POW (eq. 23) pushes them apart; U' > 0 (attraction)
// for d > d*, U' < 0 (repulsion) for d < d*. Units: k_s N/m (Table 1's "J" is a typo), x_max 1.
//
// FENE diverges at d -> d_max. A bond with d >= d_max, d <= 0 or d not finite contributes no force and
// no NaN; instead its index is written into the `overstretched` flag (first one wins) for the host to
// report. Its energy is +infinity.
//
// Expectations (tests/test_bonds_bending.cpp): F = -grad U (central differences), F = 0 at the rest
// shape, zero net force and torque, U'(d) = |eq. 22| - eq. 23 for a single bond, the flag at
// 1.0001 d_max, the same result on Serial and OpenMP.
#include <limits>
#include <vector>

#include "core/buffers.hpp"
#include "core/cell_params.hpp"
#include "core/vec3.hpp"

namespace dcm {

struct FenePowParams {
  double k_s = 3.2e-6;  // FENE stretching constant (N/m)
  double x_max = 2.05;  // maximal stretch d_max / d* (1)
};

// Rest state of the bonds: d* per bond (m).
template <class MemorySpace>
struct BondRest {
  Kokkos::View<double*, Kokkos::LayoutRight, MemorySpace> rest_length;
};

// dU/dd of one bond (N): |F_FENE| - F_POW, eqs. 22-24 with L = 2.
KOKKOS_INLINE_FUNCTION double fene_pow_force_magnitude(double d, double d_rest, double k_s, double x_max) {
  const double d_max2 = x_max * x_max * d_rest * d_rest;
  const double k_c = k_s * d_rest * d_rest * d_rest / (1 - 1 / (x_max * x_max));  // eq. 24
  return k_s * d / (1 - d * d / d_max2) - k_c / (d * d);
}

// dF/dd of one bond (N/m): its axial stiffness, positive for every 0 < d < d_max (the FENE part grows
// without bound as d → d_max; the POW part adds 2 k_c / d³).
KOKKOS_INLINE_FUNCTION double fene_pow_axial_stiffness(double d, double d_rest, double k_s, double x_max) {
  const double d_max2 = x_max * x_max * d_rest * d_rest;
  const double k_c = k_s * d_rest * d_rest * d_rest / (1 - 1 / (x_max * x_max));
  const double q = 1 - d * d / d_max2;
  return k_s * (1 + d * d / d_max2) / (q * q) + 2 * k_c / (d * d * d);
}

// The stiffness a linearly implicit step uses for a bond (N/m): the larger of the tangent k'(d) and the
// secant from d to half-way to d_max, (F(d_h) − F(d)) / (d_h − d), d_h = d + (d_max − d)/2. FENE stiffens
// without bound, so a step with the tangent alone overshoots towards d_max when the bond is pulled from
// below; with the secant, a pull up to F(d_h) − F(d) moves the bond at most half-way (in one dimension).
KOKKOS_INLINE_FUNCTION double fene_pow_implicit_stiffness(double d, double d_rest, double k_s, double x_max) {
  const double tangent = fene_pow_axial_stiffness(d, d_rest, k_s, x_max);
  const double d_half = d + 0.5 * (x_max * d_rest - d);
  if (!(d_half > d)) return tangent;
  const double secant = (fene_pow_force_magnitude(d_half, d_rest, k_s, x_max) -
                         fene_pow_force_magnitude(d, d_rest, k_s, x_max)) /
                        (d_half - d);
  return secant > tangent ? secant : tangent;
}

// U of one bond (J), eq. 21 + k_c / d; only for 0 < d < d_max.
KOKKOS_INLINE_FUNCTION double fene_pow_bond_energy(double d, double d_rest, double k_s, double x_max) {
  const double d_max2 = x_max * x_max * d_rest * d_rest;
  const double k_c = k_s * d_rest * d_rest * d_rest / (1 - 1 / (x_max * x_max));
  return -0.5 * k_s * d_max2 * math::log(1 - d * d / d_max2) + k_c / d;
}

// Whether a bond of length d can be evaluated: 0 < d < d_max and finite.
KOKKOS_INLINE_FUNCTION bool fene_pow_bond_ok(double d, double d_rest, double x_max) {
  return math::isfinite(d) && d > 0 && d < x_max * d_rest;
}

// d* of every bond from the current positions. prestretch: per cell (or one for all), the initial bond length
// over d*: d* = the given length / prestretch (1: the given shape is the network's rest state; > 1: a network
// under tension in it, e.g. a swollen cell; scene key cortex.bond_prestretch).
template <class ExecutionSpace, class MemorySpace>
BondRest<MemorySpace> make_bond_rest(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                                     const std::vector<double>& prestretch = {1.0}) {
  BondRest<MemorySpace> rest;
  rest.rest_length = decltype(rest.rest_length)(
      Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::bonds::rest_length"), mesh.n_bonds);
  Kokkos::View<double*, Kokkos::LayoutRight, MemorySpace> pre("dcm::bonds::prestretch", prestretch.size());
  const auto pre_host = Kokkos::create_mirror_view(pre);
  for (std::size_t c = 0; c < prestretch.size(); ++c) pre_host(c) = prestretch[c];
  Kokkos::deep_copy(pre, pre_host);
  const bool one = prestretch.size() == 1;
  const auto x = mesh.x;
  const auto bond = mesh.bond;
  const auto bond_cell = mesh.bond_cell;
  const auto length = rest.rest_length;
  Kokkos::parallel_for(
      "dcm::bonds::rest_length", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_bonds),
      KOKKOS_LAMBDA(const int b) {
        length(b) = norm(load3(x, bond(b, 0)) - load3(x, bond(b, 1))) / pre(one ? 0 : bond_cell(b));
      });
  return rest;
}

// force(i) += sum over the bonds of node i of F_i (a gather over the node's CSR bond list: no atomics).
// overstretched: set to -1 by the caller; receives the index of a bond that could not be evaluated.
// params: one FenePowParams or a CellTable of them (PerCell::table(), core/cell_params.hpp).
template <class ExecutionSpace, class MemorySpace, class Params>
void add_fene_pow_forces(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                         const BondRest<MemorySpace>& rest, const Params& params,
                         const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& force,
                         const Kokkos::View<int, MemorySpace>& overstretched) {
  const auto x = mesh.x;
  const auto bond = mesh.bond;
  const auto offsets = mesh.node_bond_offsets;
  const auto bonds = mesh.node_bonds;
  const auto rest_length = rest.rest_length;
  const auto node_cell = mesh.node_cell;
  Kokkos::parallel_for(
      "dcm::bonds::fene_pow", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
      KOKKOS_LAMBDA(const int i) {
        const FenePowParams pr = cell_value(params, node_cell(i));
        const double k_s = pr.k_s, x_max2 = pr.x_max * pr.x_max;
        const double k_c_factor = k_s / (1 - 1 / x_max2);  // k_c = k_c_factor d*^3, eq. 24
        const Real3 p = load3(x, i);
        Real3 f{0, 0, 0};
        for (int s = offsets(i); s < offsets(i + 1); ++s) {
          const int b = bonds(s);
          const int j = bond(b, 0) == i ? bond(b, 1) : bond(b, 0);
          const Real3 r = p - load3(x, j);
          const double d2 = norm2(r), d_rest = rest_length(b), d_max2 = x_max2 * d_rest * d_rest;
          if (!(math::isfinite(d2) && d2 > 0 && d2 < d_max2)) {
            Kokkos::atomic_compare_exchange(&overstretched(), -1, b);
            continue;
          }
          // U'(d) / d = k_s d_max^2 / (d_max^2 - d^2) - k_c / d^3 (two divisions, one square root)
          const double u_over_d =
              k_s * d_max2 / (d_max2 - d2) - k_c_factor * d_rest * d_rest * d_rest / (d2 * math::sqrt(d2));
          f += (-u_over_d) * r;
        }
        force(i, 0) += f.x;
        force(i, 1) += f.y;
        force(i, 2) += f.z;
      });
}

// Total FENE + POW energy of all cells (J); +infinity if a bond cannot be evaluated.
template <class ExecutionSpace, class MemorySpace, class Params>
double fene_pow_energy(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                       const BondRest<MemorySpace>& rest, const Params& params,
                       std::vector<double>* per_cell = nullptr) {
  const auto x = mesh.x;
  const auto bond = mesh.bond;
  const auto bond_cell = mesh.bond_cell;
  const auto rest_length = rest.rest_length;
  const double infinity = std::numeric_limits<double>::infinity();
  return fixed_order_sum(
      "dcm::bonds::fene_pow_energy", space, mesh.bond_sums,
      KOKKOS_LAMBDA(const int b) {
        const FenePowParams pr = cell_value(params, bond_cell(b));
        const double k_s = pr.k_s, x_max = pr.x_max;
        const double d = norm(load3(x, bond(b, 0)) - load3(x, bond(b, 1))), d_rest = rest_length(b);
        return fene_pow_bond_ok(d, d_rest, x_max) ? fene_pow_bond_energy(d, d_rest, k_s, x_max) : infinity;
      },
      per_cell);
}

}  // namespace dcm
