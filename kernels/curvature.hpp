#pragma once
// Local curvature of the triangulated surface (paper eq. 14; Meyer, Desbrun, Schroeder, Barr 2002).
//
// Node i, summed over its incident triangles (i, j, k) (a gather over the node's CSR triangle list):
//   K_i = 1 / (2 A_mixed,i) * sum_triangles [ cot(gamma_k) (x_i - x_j) + cot(gamma_j) (x_i - x_k) ]
// which is the usual sum over edges (cot alpha_ij + cot beta_ij)(x_i - x_j). A_mixed is Meyer's mixed
// area: the Voronoi area of the corner in a non-obtuse triangle, A_t/2 when the corner itself is obtuse,
// A_t/4 when another corner is. |K_i| = 2 H_i, and K_i points along the outward normal where the
// surface is convex: H_i = sign(K_i . n_i) |K_i| / 2 with n_i the area-weighted node normal.
//
// Triangle t: H_t = sum_c w_c H_c / sum_c w_c, w_c the mixed-area share of corner c in t, then
// clamped H_t >= H_min so that flat and concave regions keep a finite "rounded triangle" radius.
//
// Expectations (tests/test_curvature.cpp): on an icosphere of radius R with k >= 3, every H_i is within
// 1% of 1/R and K_i . x_i > 0; at the Evans-Fung dimple H matches the analytic -2 (a1 - 2 a0) / D.
#include "core/geometry.hpp"
#include "core/vec3.hpp"

namespace dcm {

// Needs compute_triangle_geometry() first (corner cotangents, corner mixed areas, areas, normals).
template <class ExecutionSpace, class MemorySpace>
void compute_node_curvature(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                            const GeometryBuffers<MemorySpace>& geo) {
  const auto x = mesh.x;
  const auto tri = mesh.tri;
  const auto offsets = mesh.node_tri_offsets;
  const auto corners = mesh.node_tri_corners;
  const auto cot = geo.tri_cot;
  const auto corner_area = geo.tri_corner_area;
  const auto tri_area = geo.tri_area;
  const auto tri_normal = geo.tri_normal;
  const auto curvature = geo.node_curvature;
  const auto node_area = geo.node_area;
  const auto node_normal = geo.node_normal;
  const auto mean_curvature = geo.node_mean_curvature;
  Kokkos::parallel_for(
      "dcm::curvature::nodes", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
      KOKKOS_LAMBDA(const int i) {
        const Real3 p = load3(x, i);
        Real3 sum{0, 0, 0}, area_normal{0, 0, 0};
        double a_mixed = 0;
        for (int s = offsets(i); s < offsets(i + 1); ++s) {
          const int t = corners(s) / 3, c = corners(s) % 3, n = (c + 1) % 3, v = (c + 2) % 3;
          // eq. 14: edge p-q (q the next corner) faces the previous corner, edge p-r faces the next one
          sum += cot(t, v) * (p - load3(x, tri(t, n))) + cot(t, n) * (p - load3(x, tri(t, v)));
          a_mixed += corner_area(t, c);
          area_normal += tri_area(t) * load3(tri_normal, t);
        }
        const Real3 k = a_mixed > 0 ? (0.5 / a_mixed) * sum : Real3{0, 0, 0};
        const double an = norm(area_normal);
        const Real3 nn = an > 0 ? (1.0 / an) * area_normal : Real3{0, 0, 0};
        store3(curvature, i, k);
        store3(node_normal, i, nn);
        node_area(i) = a_mixed;
        mean_curvature(i) = (dot(k, nn) < 0 ? -0.5 : 0.5) * norm(k);
      });
}

// Needs compute_node_curvature() first (node H and the corners' mixed areas).
template <class ExecutionSpace, class MemorySpace>
void compute_triangle_curvature(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                                const GeometryBuffers<MemorySpace>& geo, double h_min) {
  const auto tri = mesh.tri;
  const auto node_h = geo.node_mean_curvature;
  const auto corner_area = geo.tri_corner_area;
  const auto tri_h = geo.tri_mean_curvature;
  Kokkos::parallel_for(
      "dcm::curvature::triangles", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_tris),
      KOKKOS_LAMBDA(const int t) {
        double weighted = 0, weight = 0;
        for (int c = 0; c < 3; ++c) {
          weighted += corner_area(t, c) * node_h(tri(t, c));
          weight += corner_area(t, c);
        }
        const double h = weight > 0 ? weighted / weight : 0.0;
        tri_h(t) = math::max(h, h_min);  // clamp: H_t >= H_min
      });
}

}  // namespace dcm
