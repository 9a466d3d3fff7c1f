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
// theta* the hinge's angle in the rest shape, k_b in J. The kernels never form theta itself: with
//   cos theta = n1 . n2 / (|n1| |n2|),   sin theta = (n1 x n2) . e / (|e| |n1| |n2|)
// (one square root for both) and the rest state kept as (cos theta*, sin theta*),
//   sin(theta - theta*) = sin theta cos theta* - cos theta sin theta*,  cos(theta - theta*) likewise,
// so a hinge costs two square roots and no atan2 or sin (docs/PERFORMANCE.md, "Force terms"). Forces F_a = -M
// dtheta/dx_a, with the exact gradient of theta (Bridson, Marino, Fedkiw 2003):
//   dtheta/dx_k = -|e| n1 / |n1|^2,        dtheta/dx_l = -|e| n2 / |n2|^2,
//   dtheta/dx_i = -(1 - a_k) dtheta/dx_k - (1 - a_l) dtheta/dx_l,
//   dtheta/dx_j = -a_k dtheta/dx_k - a_l dtheta/dx_l,
//   a_k = (x_k - x_i) . e / |e|^2,  a_l = (x_l - x_i) . e / |e|^2.
// The four forces sum to zero and have zero torque (theta is invariant under rigid motions). A
// degenerate hinge (a zero-area triangle or a zero-length edge) contributes no force.
//
// Two ways to gather: add_bending_forces() evaluates every hinge once into arrays owned by HingeRest (the
// gradient of theta per role, the factor -M and cos(theta - theta*); solvers/bending_stiffness.hpp reuses
// them for the implicit step) and then gathers per node over the node -> (hinge, role) CSR list;
// add_bending_forces_per_node() recomputes each hinge at each of its four nodes (no scratch). Both are
// deterministic (no atomics). On the CPU the hinge pass is faster (docs/model/bonds_bending.md).
//
// Expectations (tests/test_bonds_bending.cpp): F = -grad U (central differences), F = 0 at the rest
// shape, zero net force and torque, theta = arccos(-1/3) on a regular tetrahedron, U = k_b (1 - cos dtheta)
// for a hinge bent by dtheta, theta > 0 on a sphere, the same result on Serial and OpenMP.
#include <cmath>
#include <vector>

#include "core/buffers.hpp"
#include "core/cell_params.hpp"
#include "core/vec3.hpp"

namespace dcm {

// Rest state of the hinges and what the hinge pass of add_bending_forces() leaves (allocated once).
template <class MemorySpace>
struct HingeRest {
  Kokkos::View<double* [2], Kokkos::LayoutRight, MemorySpace> rest_trig;      // (cos theta*, sin theta*)
  Kokkos::View<double* [4][3], Kokkos::LayoutRight, MemorySpace> hinge_grad;  // dtheta/dx per role (1/m)
  Kokkos::View<double*, Kokkos::LayoutRight, MemorySpace> hinge_moment;       // -k_b sin(theta - theta*) (J)
  Kokkos::View<double*, Kokkos::LayoutRight, MemorySpace> hinge_cos_delta;    // cos(theta - theta*)
};

// Signed hinge angle theta (rad).
KOKKOS_INLINE_FUNCTION double hinge_angle(Real3 xi, Real3 xj, Real3 xk, Real3 xl) {
  const Real3 e = xj - xi;
  const Real3 n1 = cross(e, xk - xi), n2 = cross(-e, xl - xj);
  return math::atan2(dot(cross(n1, n2), e), norm(e) * dot(n1, n2));
}

// cos theta, sin theta and the gradient of theta with respect to (x_i, x_j, x_k, x_l); false (theta = 0
// and a zero gradient) for a degenerate hinge.
KOKKOS_INLINE_FUNCTION bool hinge_trig_gradient(Real3 xi, Real3 xj, Real3 xk, Real3 xl, double& cos_theta,
                                                double& sin_theta, Real3 grad[4]) {
  const Real3 e = xj - xi;
  const Real3 n1 = cross(e, xk - xi), n2 = cross(-e, xl - xj);
  const double e2 = norm2(e), n1_2 = norm2(n1), n2_2 = norm2(n2);
  if (!(e2 > 0 && n1_2 > 0 && n2_2 > 0)) {
    cos_theta = 1;
    sin_theta = 0;
    for (int a = 0; a < 4; ++a) grad[a] = Real3{0, 0, 0};
    return false;
  }
  const double e_len = math::sqrt(e2);
  const double inv = 1.0 / (e_len * math::sqrt(n1_2 * n2_2));  // 1 / (|e| |n1| |n2|)
  cos_theta = e_len * dot(n1, n2) * inv;
  sin_theta = dot(cross(n1, n2), e) * inv;
  const Real3 gk = (-e_len / n1_2) * n1, gl = (-e_len / n2_2) * n2;
  const double ak = dot(xk - xi, e) / e2, al = dot(xl - xi, e) / e2;
  grad[0] = (ak - 1) * gk + (al - 1) * gl;
  grad[1] = (-ak) * gk + (-al) * gl;
  grad[2] = gk;
  grad[3] = gl;
  return true;
}

// Forces of one hinge on (i, j, k, l) (N): F_a = -k_b sin(theta - theta*) dtheta/dx_a.
KOKKOS_INLINE_FUNCTION void hinge_bending_forces(Real3 xi, Real3 xj, Real3 xk, Real3 xl, double cos_rest,
                                                 double sin_rest, double k_b, Real3 f[4]) {
  double c, s;
  hinge_trig_gradient(xi, xj, xk, xl, c, s, f);
  const double m = -k_b * (s * cos_rest - c * sin_rest);  // -M = -k_b sin(theta - theta*), eq. 26
  for (int a = 0; a < 4; ++a) f[a] = m * f[a];
}

// theta* of every hinge from the current positions; allocates the scratch.
template <class ExecutionSpace, class MemorySpace>
HingeRest<MemorySpace> make_hinge_rest(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh) {
  HingeRest<MemorySpace> rest;
  rest.rest_trig = decltype(rest.rest_trig)(
      Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::bending::rest_trig"), mesh.n_hinges);
  rest.hinge_grad = decltype(rest.hinge_grad)("dcm::bending::hinge_grad", mesh.n_hinges);
  rest.hinge_moment = decltype(rest.hinge_moment)("dcm::bending::hinge_moment", mesh.n_hinges);
  rest.hinge_cos_delta = decltype(rest.hinge_cos_delta)("dcm::bending::hinge_cos_delta", mesh.n_hinges);
  const auto x = mesh.x;
  const auto hinge = mesh.hinge;
  const auto rest_trig = rest.rest_trig;
  Kokkos::parallel_for(
      "dcm::bending::rest", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_hinges),
      KOKKOS_LAMBDA(const int h) {
        double c, s;
        Real3 grad[4];
        hinge_trig_gradient(load3(x, hinge(h, 0)), load3(x, hinge(h, 1)), load3(x, hinge(h, 2)),
                            load3(x, hinge(h, 3)), c, s, grad);
        rest_trig(h, 0) = c;
        rest_trig(h, 1) = s;
      });
  return rest;
}

// theta* of every hinge (rad, host copy; for tests and diagnostics).
template <class MemorySpace>
std::vector<double> hinge_rest_angles(const HingeRest<MemorySpace>& rest) {
  const auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), rest.rest_trig);
  std::vector<double> theta(h.extent(0));
  for (std::size_t k = 0; k < theta.size(); ++k) theta[k] = std::atan2(h(k, 1), h(k, 0));
  return theta;
}

// Sets theta* of every hinge (rad; one value for all, or one per hinge).
template <class MemorySpace>
void set_hinge_rest_angles(const HingeRest<MemorySpace>& rest, const std::vector<double>& theta) {
  const auto h = Kokkos::create_mirror_view(rest.rest_trig);
  for (std::size_t k = 0; k < h.extent(0); ++k) {
    const double t = theta.size() == 1 ? theta[0] : theta.at(k);
    h(k, 0) = std::cos(t);
    h(k, 1) = std::sin(t);
  }
  Kokkos::deep_copy(rest.rest_trig, h);
}

// force(i) += bending forces on node i: one pass over the hinges (gradient, -M and cos(theta - theta*) into
// rest), then a gather over the node's CSR (hinge, role) list of F_a = -M dtheta/dx_a (no atomics).
// k_b: one value (J) or a CellTable (PerCell::table(), core/cell_params.hpp).
template <class ExecutionSpace, class MemorySpace, class KB>
void add_bending_forces(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                        const HingeRest<MemorySpace>& rest, const KB& k_b,
                        const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& force) {
  const auto x = mesh.x;
  const auto hinge = mesh.hinge;
  const auto rest_trig = rest.rest_trig;
  const auto grad = rest.hinge_grad;
  const auto moment = rest.hinge_moment;
  const auto cos_delta = rest.hinge_cos_delta;
  const auto hinge_cell = mesh.hinge_cell;
  Kokkos::parallel_for(
      "dcm::bending::hinges", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_hinges),
      KOKKOS_LAMBDA(const int h) {
        double c, s;
        Real3 g[4];
        hinge_trig_gradient(load3(x, hinge(h, 0)), load3(x, hinge(h, 1)), load3(x, hinge(h, 2)),
                            load3(x, hinge(h, 3)), c, s, g);
        const double cr = rest_trig(h, 0), sr = rest_trig(h, 1);
        moment(h) =
            -cell_value(k_b, hinge_cell(h)) * (s * cr - c * sr);  // -M = -k_b sin(theta - theta*), eq. 26
        cos_delta(h) = c * cr + s * sr;
        for (int a = 0; a < 4; ++a) {
          grad(h, a, 0) = g[a].x;
          grad(h, a, 1) = g[a].y;
          grad(h, a, 2) = g[a].z;
        }
      });
  const auto offsets = mesh.node_hinge_offsets;
  const auto roles = mesh.node_hinge_roles;
  Kokkos::parallel_for(
      "dcm::bending::gather", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
      KOKKOS_LAMBDA(const int i) {
        double f0 = 0, f1 = 0, f2 = 0;
        for (int s = offsets(i); s < offsets(i + 1); ++s) {
          const int h = roles(s) >> 2, a = roles(s) & 3;  // 4 h + role, non-negative
          const double m = moment(h);
          f0 += m * grad(h, a, 0);
          f1 += m * grad(h, a, 1);
          f2 += m * grad(h, a, 2);
        }
        force(i, 0) += f0;
        force(i, 1) += f1;
        force(i, 2) += f2;
      });
}

// The same forces, each hinge recomputed at each of its nodes (no scratch, one kernel).
template <class ExecutionSpace, class MemorySpace, class KB>
void add_bending_forces_per_node(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                                 const HingeRest<MemorySpace>& rest, const KB& k_b,
                                 const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& force) {
  const auto x = mesh.x;
  const auto hinge = mesh.hinge;
  const auto rest_trig = rest.rest_trig;
  const auto offsets = mesh.node_hinge_offsets;
  const auto roles = mesh.node_hinge_roles;
  const auto node_cell = mesh.node_cell;
  Kokkos::parallel_for(
      "dcm::bending::per_node", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
      KOKKOS_LAMBDA(const int i) {
        const double kb = cell_value(k_b, node_cell(i));
        Real3 sum{0, 0, 0};
        for (int s = offsets(i); s < offsets(i + 1); ++s) {
          const int h = roles(s) >> 2, a = roles(s) & 3;  // 4 h + role, non-negative
          Real3 f[4];
          hinge_bending_forces(load3(x, hinge(h, 0)), load3(x, hinge(h, 1)), load3(x, hinge(h, 2)),
                               load3(x, hinge(h, 3)), rest_trig(h, 0), rest_trig(h, 1), kb, f);
          sum += f[a];
        }
        force(i, 0) += sum.x;
        force(i, 1) += sum.y;
        force(i, 2) += sum.z;
      });
}

// Total bending energy of all cells (J).
template <class ExecutionSpace, class MemorySpace, class KB>
double bending_energy(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                      const HingeRest<MemorySpace>& rest, const KB& k_b,
                      std::vector<double>* per_cell = nullptr) {
  const auto x = mesh.x;
  const auto hinge_cell = mesh.hinge_cell;
  const auto hinge = mesh.hinge;
  const auto rest_trig = rest.rest_trig;
  return fixed_order_sum(
      "dcm::bending::energy", space, mesh.hinge_sums,
      KOKKOS_LAMBDA(const int h) {
        double c, s;
        Real3 grad[4];
        hinge_trig_gradient(load3(x, hinge(h, 0)), load3(x, hinge(h, 1)), load3(x, hinge(h, 2)),
                            load3(x, hinge(h, 3)), c, s, grad);
        return cell_value(k_b, hinge_cell(h)) *
               (1 - (c * rest_trig(h, 0) + s * rest_trig(h, 1)));  // 1 - cos(theta - theta*)
      },
      per_cell);
}

}  // namespace dcm
