#pragma once
// The crease at the contact line (`contact.crease_radius_m`, dcm's experiment of session 34; off by default;
// docs/model/contact_line.md, "The crease at the rim"). Not in the paper.
//
// A continuum membrane leaves the plane through a fillet of radius ρ (the contact-curvature condition gives
// ρ = √(κ/2W), ≈ 11 nm for Table 1's k_b and W = 1 mJ/m²). Where it turns from the bound plane into a wall at
// angle θ_w (turn π − θ_w) the fillet leaves a strip ρ tan((π − θ_w)/2) wide unbound along the line; a sharp
// discrete fold at the rim has no such loss. Per hinge (i, j, k, l), wings (i, j, k) and (j, i, l):
//
//   E_h = W ρ |x_j − x_i| w(h_i) w(h_j) [f(c_1) + f(c_2)],
//   w(h) = −φ(h)/W of the Derjaguin law (1 at h ≤ 0, (1 − (h/h₀)²)² below h₀, 0 beyond): how bound a node is;
//   c = −n̂·n_t, the cosine of the wing's turn from the bound membrane (outward normal −n̂) to its own outward
//   normal n_t; f(c) = √(tan²(turn/2) + ε²) − ε, tan²(turn/2) = (1 − c)/(1 + c), ε = 0.05 (smooth where a
//   wing lies flat on the plane, f = 0 there), c clamped at −0.95 (a wing folded back over the plane).
//
// The forces are the exact negative gradient of E_h (tests/test_contact_crease.cpp: central differences),
// gathered per node over the node's hinges (each hinge recomputed at its four nodes: no atomics, a fixed
// order). The energy is counted with the cortex energy (CortexModel::energy()), so spread's energy balance
// holds. W, h0 and ρ are each hinge's cell's (`laws`: one CreaseLaw for every cell, or a CellTable of them
// for a batch of cells with different constants, core/cell_params.hpp).
#include "core/buffers.hpp"
#include "core/cell_params.hpp"
#include "core/segmented_sum.hpp"
#include "core/vec3.hpp"
#include "kernels/plane_contact_triangle.hpp"

namespace dcm {

struct CreaseLaw {
  double W = 0;    // J/m²
  double h0 = 0;   // m, the Derjaguin range
  double rho = 0;  // m, the fillet radius; 0: off
  Plane plane;
};

constexpr double kCreaseEps = 0.05;
constexpr double kCreaseMinCos = -0.95;

// w(h) and dw/dh.
KOKKOS_INLINE_FUNCTION double crease_bound(double h, double h0, double& dw) {
  dw = 0;
  if (!(h < h0)) return 0;
  if (h <= 0) return 1;
  const double u = h / h0, s = 1 - u * u;
  dw = -4 * u * s / h0;
  return s * s;
}

// f(c) of a wing with (unnormalised) outward normal N, and df/dN.
KOKKOS_INLINE_FUNCTION double crease_fold(Real3 N, Real3 nh, Real3& dfdN) {
  dfdN = Real3{0, 0, 0};
  const double len = norm(N);
  if (!(len > 0)) return 0;
  const Real3 n = (1 / len) * N;
  const double c = -dot(nh, n);
  const bool clamped = c < kCreaseMinCos;
  const double cc = clamped ? kCreaseMinCos : c;
  const double g = (1 - cc) / (1 + cc), r = math::sqrt(g + kCreaseEps * kCreaseEps);
  if (!clamped) {
    const double df_dc = -1 / ((1 + cc) * (1 + cc) * r);  // (dg/dc) / (2 r), dg/dc = −2/(1 + c)²
    dfdN = (-df_dc / len) * (nh - dot(nh, n) * n);        // dc/dN = −(n̂ − (n̂·n) n)/|N|
  }
  return r - kCreaseEps;
}

// E_h of one hinge and the forces f[0..3] = −dE_h/dx on i, j, k, l.
KOKKOS_INLINE_FUNCTION double crease_hinge(Real3 xi, Real3 xj, Real3 xk, Real3 xl, const CreaseLaw& law,
                                           Real3 f[4]) {
  for (int a = 0; a < 4; ++a) f[a] = Real3{0, 0, 0};
  const Real3 nh = law.plane.normal;
  double dwi, dwj;
  const double wi = crease_bound(dot(xi - law.plane.point, nh), law.h0, dwi);
  const double wj = crease_bound(dot(xj - law.plane.point, nh), law.h0, dwj);
  if (wi == 0 || wj == 0) return 0;
  const Real3 e = xj - xi;
  const double len = norm(e);
  if (!(len > 0)) return 0;
  const Real3 u1 = e, v1 = xk - xi, u2 = xi - xj, v2 = xl - xj;  // wings (i, j, k) and (j, i, l)
  Real3 a1, a2;
  const double fold = crease_fold(cross(u1, v1), nh, a1) + crease_fold(cross(u2, v2), nh, a2);
  const double pre = law.W * law.rho, s = pre * wi * wj;
  // dE/dx: the length, the two nodes' weights, the wings' normals (d(a·(u × v)) = du·(v × a) + dv·(a × u))
  const Real3 de = (s * fold / len) * e;
  Real3 g[4] = {-1.0 * de, de, Real3{0, 0, 0}, Real3{0, 0, 0}};
  g[0] += (pre * len * dwi * wj * fold) * nh;
  g[1] += (pre * len * wi * dwj * fold) * nh;
  const Real3 t1 = (s * len) * a1, t2 = (s * len) * a2;
  const Real3 gu1 = cross(v1, t1), gv1 = cross(t1, u1), gu2 = cross(v2, t2), gv2 = cross(t2, u2);
  g[1] += gu1;
  g[2] += gv1;
  g[0] += -1.0 * (gu1 + gv1);
  g[0] += gu2;
  g[3] += gv2;
  g[1] += -1.0 * (gu2 + gv2);
  for (int a = 0; a < 4; ++a) f[a] = -1.0 * g[a];
  return s * len * fold;
}

// force += the crease forces (a gather per node over its hinges).
template <class ExecutionSpace, class MemorySpace, class Laws>
void add_crease_forces(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh, const Laws& laws,
                       const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& force) {
  const auto x = mesh.x;
  const auto hinge = mesh.hinge;
  const auto hinge_cell = mesh.hinge_cell;
  const auto offsets = mesh.node_hinge_offsets;
  const auto roles = mesh.node_hinge_roles;
  Kokkos::parallel_for(
      "dcm::contact::crease", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
      KOKKOS_LAMBDA(const int i) {
        Real3 sum{0, 0, 0};
        for (int s = offsets(i); s < offsets(i + 1); ++s) {
          const int h = roles(s) >> 2, a = roles(s) & 3;  // 4 h + role
          Real3 f[4];
          crease_hinge(load3(x, hinge(h, 0)), load3(x, hinge(h, 1)), load3(x, hinge(h, 2)),
                       load3(x, hinge(h, 3)), cell_value(laws, hinge_cell(h)), f);
          sum += f[a];
        }
        force(i, 0) += sum.x;
        force(i, 1) += sum.y;
        force(i, 2) += sum.z;
      });
}

// Σ_h E_h (J).
template <class ExecutionSpace, class MemorySpace, class Laws>
double crease_energy(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh, const Laws& laws,
                     std::vector<double>* per_cell = nullptr) {
  const auto x = mesh.x;
  const auto hinge = mesh.hinge;
  const auto hinge_cell = mesh.hinge_cell;
  return fixed_order_sum(
      "dcm::contact::crease_energy", space, mesh.hinge_sums,
      KOKKOS_LAMBDA(const int h) {
        Real3 f[4];
        return crease_hinge(load3(x, hinge(h, 0)), load3(x, hinge(h, 1)), load3(x, hinge(h, 2)),
                            load3(x, hinge(h, 3)), cell_value(laws, hinge_cell(h)), f);
      },
      per_cell);
}

}  // namespace dcm
