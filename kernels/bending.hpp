#pragma once
// Bending resistance of the cortex per hinge (paper eq. 26; MODEL.md section 3).
//
// Hinge h = (i, j, k, l): edge i-j, triangles (i, j, k) and (j, i, l), both outward oriented
// (core/buffers.hpp). With e = x_j - x_i and the area-weighted normals
//   n1 = (x_j - x_i) x (x_k - x_i),   n2 = (x_i - x_j) x (x_l - x_j),
// the signed hinge angle is the rotation from n1 to n2 about e:
//   theta = atan2((n1 x n2) . e, |e| n1 . n2)   in (-pi, pi],
// 0 for a flat hinge, > 0 where the surface is convex (a sphere: every theta > 0), < 0 where concave.
// Energy and moment (eq. 26):
//   U = k_b (1 - cos(theta - theta*)),   M = dU/dtheta = k_b sin(theta - theta*),
// theta* the hinge's angle in the rest shape, k_b in J. Forces F_a = -M dtheta/dx_a, with the exact
// gradient of theta (Bridson, Marino, Fedkiw 2003):
//   dtheta/dx_k = -|e| n1 / |n1|^2,        dtheta/dx_l = -|e| n2 / |n2|^2,
//   dtheta/dx_i = -(1 - a_k) dtheta/dx_k - (1 - a_l) dtheta/dx_l,
//   dtheta/dx_j = -a_k dtheta/dx_k - a_l dtheta/dx_l,
//   a_k = (x_k - x_i) . e / |e|^2,  a_l = (x_l - x_i) . e / |e|^2.
// The four forces sum to zero and have zero torque (theta is invariant under rigid motions). A
// degenerate hinge (a zero-area triangle or a zero-length edge) contributes no force.
//
// Two ways to gather: add_bending_forces() evaluates every hinge once into a scratch array owned by
// HingeRest (hinge_force[h][role][3]) and then gathers per node over the node -> (hinge, role) CSR list;
// add_bending_forces_per_node() recomputes each hinge at each of its four nodes (no scratch). Both are
// deterministic (no atomics). On the CPU the hinge pass is faster (docs/model/bonds_bending.md).
//
// Expectations (tests/test_bonds_bending.cpp): F = -grad U (central differences), F = 0 at the rest
// shape, zero net force and torque, theta = arccos(-1/3) on a regular tetrahedron, U = k_b (1 - cos dtheta)
// for a hinge bent by dtheta, theta > 0 on a sphere, the same result on Serial and OpenMP.
#include "core/buffers.hpp"
#include "core/vec3.hpp"

namespace dcm {

// Rest state of the hinges and the scratch space of the hinge pass (allocated once).
template <class MemorySpace>
struct HingeRest {
  Kokkos::View<double*, Kokkos::LayoutRight, MemorySpace> theta_rest;          // theta* (rad)
  Kokkos::View<double* [4][3], Kokkos::LayoutRight, MemorySpace> hinge_force;  // scratch (N)
};

// Signed hinge angle theta (rad).
KOKKOS_INLINE_FUNCTION double hinge_angle(Real3 xi, Real3 xj, Real3 xk, Real3 xl) {
  const Real3 e = xj - xi;
  const Real3 n1 = cross(e, xk - xi), n2 = cross(-e, xl - xj);
  return math::atan2(dot(cross(n1, n2), e), norm(e) * dot(n1, n2));
}

// theta and its gradient with respect to (x_i, x_j, x_k, x_l); false (and a zero gradient) for a
// degenerate hinge.
KOKKOS_INLINE_FUNCTION bool hinge_angle_gradient(Real3 xi, Real3 xj, Real3 xk, Real3 xl, double& theta,
                                                 Real3 grad[4]) {
  const Real3 e = xj - xi;
  const Real3 n1 = cross(e, xk - xi), n2 = cross(-e, xl - xj);
  const double e2 = norm2(e), n1_2 = norm2(n1), n2_2 = norm2(n2);
  const double e_len = math::sqrt(e2);
  theta = math::atan2(dot(cross(n1, n2), e), e_len * dot(n1, n2));
  if (!(e2 > 0 && n1_2 > 0 && n2_2 > 0)) {
    for (int a = 0; a < 4; ++a) grad[a] = Real3{0, 0, 0};
    return false;
  }
  const Real3 gk = (-e_len / n1_2) * n1, gl = (-e_len / n2_2) * n2;
  const double ak = dot(xk - xi, e) / e2, al = dot(xl - xi, e) / e2;
  grad[0] = (ak - 1) * gk + (al - 1) * gl;
  grad[1] = (-ak) * gk + (-al) * gl;
  grad[2] = gk;
  grad[3] = gl;
  return true;
}

// Forces of one hinge on (i, j, k, l) (N): F_a = -k_b sin(theta - theta*) dtheta/dx_a.
KOKKOS_INLINE_FUNCTION void hinge_bending_forces(Real3 xi, Real3 xj, Real3 xk, Real3 xl, double theta_rest,
                                                 double k_b, Real3 f[4]) {
  double theta;
  hinge_angle_gradient(xi, xj, xk, xl, theta, f);
  const double m = -k_b * math::sin(theta - theta_rest);  // -M, eq. 26
  for (int a = 0; a < 4; ++a) f[a] = m * f[a];
}

// theta* of every hinge from the current positions; allocates the scratch.
template <class ExecutionSpace, class MemorySpace>
HingeRest<MemorySpace> make_hinge_rest(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh) {
  HingeRest<MemorySpace> rest;
  rest.theta_rest = decltype(rest.theta_rest)(
      Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::bending::theta_rest"), mesh.n_hinges);
  rest.hinge_force = decltype(rest.hinge_force)(
      Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::bending::hinge_force"), mesh.n_hinges);
  const auto x = mesh.x;
  const auto hinge = mesh.hinge;
  const auto theta_rest = rest.theta_rest;
  Kokkos::parallel_for(
      "dcm::bending::theta_rest", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_hinges),
      KOKKOS_LAMBDA(const int h) {
        theta_rest(h) = hinge_angle(load3(x, hinge(h, 0)), load3(x, hinge(h, 1)), load3(x, hinge(h, 2)),
                                    load3(x, hinge(h, 3)));
      });
  return rest;
}

// force(i) += bending forces on node i: one pass over the hinges into rest.hinge_force, then a gather
// over the node's CSR (hinge, role) list (no atomics).
template <class ExecutionSpace, class MemorySpace>
void add_bending_forces(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                        const HingeRest<MemorySpace>& rest, double k_b,
                        const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& force) {
  const auto x = mesh.x;
  const auto hinge = mesh.hinge;
  const auto theta_rest = rest.theta_rest;
  const auto hinge_force = rest.hinge_force;
  Kokkos::parallel_for(
      "dcm::bending::hinges", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_hinges),
      KOKKOS_LAMBDA(const int h) {
        Real3 f[4];
        hinge_bending_forces(load3(x, hinge(h, 0)), load3(x, hinge(h, 1)), load3(x, hinge(h, 2)),
                             load3(x, hinge(h, 3)), theta_rest(h), k_b, f);
        for (int a = 0; a < 4; ++a) {
          hinge_force(h, a, 0) = f[a].x;
          hinge_force(h, a, 1) = f[a].y;
          hinge_force(h, a, 2) = f[a].z;
        }
      });
  const auto offsets = mesh.node_hinge_offsets;
  const auto roles = mesh.node_hinge_roles;
  Kokkos::parallel_for(
      "dcm::bending::gather", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
      KOKKOS_LAMBDA(const int i) {
        double f0 = 0, f1 = 0, f2 = 0;
        for (int s = offsets(i); s < offsets(i + 1); ++s) {
          const int h = roles(s) / 4, a = roles(s) % 4;
          f0 += hinge_force(h, a, 0);
          f1 += hinge_force(h, a, 1);
          f2 += hinge_force(h, a, 2);
        }
        force(i, 0) += f0;
        force(i, 1) += f1;
        force(i, 2) += f2;
      });
}

// The same forces, each hinge recomputed at each of its nodes (no scratch, one kernel).
template <class ExecutionSpace, class MemorySpace>
void add_bending_forces_per_node(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                                 const HingeRest<MemorySpace>& rest, double k_b,
                                 const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& force) {
  const auto x = mesh.x;
  const auto hinge = mesh.hinge;
  const auto theta_rest = rest.theta_rest;
  const auto offsets = mesh.node_hinge_offsets;
  const auto roles = mesh.node_hinge_roles;
  Kokkos::parallel_for(
      "dcm::bending::per_node", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
      KOKKOS_LAMBDA(const int i) {
        Real3 sum{0, 0, 0};
        for (int s = offsets(i); s < offsets(i + 1); ++s) {
          const int h = roles(s) / 4, a = roles(s) % 4;
          Real3 f[4];
          hinge_bending_forces(load3(x, hinge(h, 0)), load3(x, hinge(h, 1)), load3(x, hinge(h, 2)),
                               load3(x, hinge(h, 3)), theta_rest(h), k_b, f);
          sum += f[a];
        }
        force(i, 0) += sum.x;
        force(i, 1) += sum.y;
        force(i, 2) += sum.z;
      });
}

// Total bending energy of all cells (J).
template <class ExecutionSpace, class MemorySpace>
double bending_energy(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                      const HingeRest<MemorySpace>& rest, double k_b) {
  const auto x = mesh.x;
  const auto hinge = mesh.hinge;
  const auto theta_rest = rest.theta_rest;
  double energy = 0;
  Kokkos::parallel_reduce(
      "dcm::bending::energy", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_hinges),
      KOKKOS_LAMBDA(const int h, double& sum) {
        const double theta = hinge_angle(load3(x, hinge(h, 0)), load3(x, hinge(h, 1)), load3(x, hinge(h, 2)),
                                         load3(x, hinge(h, 3)));
        sum += k_b * (1 - math::cos(theta - theta_rest(h)));
      },
      energy);
  return energy;
}

}  // namespace dcm
