#pragma once
// Per-node fields for output (the paper's Figure 6 and Figure S2), computed on demand, not every step:
//   cortex tension τ_i = (1/N_c^i) Σ_j √3 F_FENE(d_ij) / d_ij   (paper eq. 1; J/m², tensile positive)
//   stretch s_i = (1/N_c^i) Σ_j d_ij / d*_ij                    (mean bond stretch, x_max is the limit)
//   normal force f_i = F_i · n_i                                 (N; the paper's "normal pressure": the sum
//   of
//                                                                 the conservative forces on the node along
//                                                                 its outward normal; adhesion positive)
//   normal pressure f_i / A_mixed,i                              (Pa)
// and the power of the contact forces Σ_t Σ_c f_tc n̂ · v_tc (W) for the energy balance.
#include "core/geometry.hpp"
#include "core/vec3.hpp"
#include "kernels/fene_pow_bonds.hpp"
#include "kernels/plane_contact.hpp"

namespace dcm {

template <class MemorySpace>
struct NodeFields {
  template <class T>
  using View = Kokkos::View<T, Kokkos::LayoutRight, MemorySpace>;
  View<double*> tension, stretch, normal_force, normal_pressure;
  NodeFields() = default;
  explicit NodeFields(int n)
      : tension("dcm::fields::tension", n),
        stretch("dcm::fields::stretch", n),
        normal_force("dcm::fields::normal_force", n),
        normal_pressure("dcm::fields::normal_pressure", n) {}
};

// Needs update_geometry() for the node normals and areas; force = the total conservative force per node.
template <class ExecutionSpace, class MemorySpace, class Params>
void compute_node_fields(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                         const GeometryBuffers<MemorySpace>& geo, const BondRest<MemorySpace>& rest,
                         const Params& params,
                         const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& force,
                         const NodeFields<MemorySpace>& out) {
  const auto x = mesh.x;
  const auto bond = mesh.bond;
  const auto offsets = mesh.node_bond_offsets;
  const auto bonds = mesh.node_bonds;
  const auto rest_length = rest.rest_length;
  const auto normal = geo.node_normal;
  const auto area = geo.node_area;
  const auto node_cell = mesh.node_cell;
  const auto tension = out.tension, stretch = out.stretch, fn = out.normal_force, pn = out.normal_pressure;
  Kokkos::parallel_for(
      "dcm::fields::node", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
      KOKKOS_LAMBDA(const int i) {
        const FenePowParams pr = cell_value(params, node_cell(i));
        const double k_s = pr.k_s, x_max = pr.x_max;
        double tau = 0, s = 0;
        const int nb = offsets(i + 1) - offsets(i);
        for (int k = offsets(i); k < offsets(i + 1); ++k) {
          const int b = bonds(k);
          const double d = norm(load3(x, bond(b, 1)) - load3(x, bond(b, 0))), d0 = rest_length(b);
          tau += 1.7320508075688772 * fene_pow_force_magnitude(d, d0, k_s, x_max) / d;  // eq. 1
          s += d / d0;
        }
        tension(i) = nb > 0 ? tau / nb : 0.0;
        stretch(i) = nb > 0 ? s / nb : 0.0;
        const double f = dot(load3(force, i), load3(normal, i));
        fn(i) = f;
        pn(i) = area(i) > 0 ? f / area(i) : 0.0;
      });
}

// Σ_t Σ_c f_tc (n̂ · v_node(t,c)) (+ the in-plane forces' Σ s_tc · v_node(t,c)): the power of the contact
// forces (W).
template <class ExecutionSpace, class MemorySpace>
double contact_power(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh, const Plane& plane,
                     const ContactBuffers<MemorySpace>& contact,
                     const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& velocity,
                     std::vector<double>* per_cell = nullptr) {
  const auto tri = mesh.tri;
  const auto load = contact.tri_node_load;
  const auto shear = contact.tri_node_shear;
  const bool has_shear = shear.extent(0) > 0;
  const Real3 n = (1.0 / norm(plane.normal)) * plane.normal;
  return fixed_order_sum(
      "dcm::fields::contact_power", space, mesh.tri_sums,
      KOKKOS_LAMBDA(const int t) {
        double s = 0;
        for (int c = 0; c < 3; ++c) {
          const Real3 v = load3(velocity, tri(t, c));
          s += load(t, c) * dot(n, v);
          if (has_shear) s += shear(t, c, 0) * v.x + shear(t, c, 1) * v.y + shear(t, c, 2) * v.z;
        }
        return s;
      },
      per_cell);
}

}  // namespace dcm
