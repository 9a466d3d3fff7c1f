#pragma once
// Triangle areas and unit normals, the cotangent of each corner angle and each corner's mixed area, and
// per-cell surface area and enclosed volume (paper: the global area constraint eq. 28 and the volume
// constraint eq. 29 act on these).
//   A_t = |(x1 - x0) x (x2 - x0)| / 2,  n_t = (x1 - x0) x (x2 - x0) / (2 A_t)  (outward for CCW triangles)
//   cot(angle at c) = (e_c,next . e_c,prev) / (2 A_t)                       (one square root per triangle)
//   mixed area of corner c (Meyer et al. 2002): Voronoi area (1/8)(|x_c x_prev|^2 cot_next +
//   |x_c x_next|^2 cot_prev) in a non-obtuse triangle, A_t / 2 if c is obtuse, A_t / 4 if another is.
//   A = sum_t A_t,  V = sum_t x0 . (x1 x x2) / 6   (divergence theorem; exact for the polyhedron)
// Expectations (tests/test_geometry.cpp): a sphere of radius R converges to 4 pi R^2 and 4 pi R^3 / 3
// at second order in the edge length; V does not depend on where the cell is.
#include "core/geometry.hpp"
#include "core/vec3.hpp"

namespace dcm {

template <class ExecutionSpace, class MemorySpace>
void compute_triangle_geometry(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                               const GeometryBuffers<MemorySpace>& geo) {
  const auto x = mesh.x;
  const auto tri = mesh.tri;
  const auto area = geo.tri_area;
  const auto normal = geo.tri_normal;
  const auto cot = geo.tri_cot;
  const auto corner_area = geo.tri_corner_area;
  Kokkos::parallel_for(
      "dcm::geometry::triangles", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_tris),
      KOKKOS_LAMBDA(const int t) {
        const Real3 p[3] = {load3(x, tri(t, 0)), load3(x, tri(t, 1)), load3(x, tri(t, 2))};
        const Real3 e[3] = {p[2] - p[1], p[0] - p[2], p[1] - p[0]};  // e[c]: the edge facing corner c
        const Real3 c = cross(e[2], -e[1]);
        const double twice_area = norm(c);
        area(t) = 0.5 * twice_area;
        if (!(twice_area > 0)) {  // degenerate: contributes nothing to curvature
          store3(normal, t, Real3{0, 0, 0});
          for (int k = 0; k < 3; ++k) cot(t, k) = corner_area(t, k) = 0;
          return;
        }
        store3(normal, t, (1.0 / twice_area) * c);
        // dot of the two edges leaving corner k: -e[k+1] . e[k+2]
        double d[3];
        for (int k = 0; k < 3; ++k) d[k] = -dot(e[(k + 1) % 3], e[(k + 2) % 3]);
        const double inv = 1.0 / twice_area;
        for (int k = 0; k < 3; ++k) cot(t, k) = d[k] * inv;
        const bool obtuse = d[0] < 0 || d[1] < 0 || d[2] < 0;
        for (int k = 0; k < 3; ++k) {
          const int n = (k + 1) % 3, v = (k + 2) % 3;  // next and previous corner
          corner_area(t, k) = !obtuse    ? 0.125 * (norm2(e[n]) * d[n] * inv + norm2(e[v]) * d[v] * inv)
                              : d[k] < 0 ? 0.25 * twice_area
                                         : 0.125 * twice_area;
        }
      });
}

// Per-cell A and V. Needs no other geometry. One launch for all cells, summed in an order fixed by the cell
// alone (core/segmented_sum.hpp): the same bits on any thread count.
template <class ExecutionSpace, class MemorySpace>
void compute_cell_measures(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                           const GeometryBuffers<MemorySpace>& geo) {
  const auto x = mesh.x;
  const auto tri = mesh.tri;
  segmented_sum<2>(
      "dcm::geometry::cell_measures", space, mesh.tri_sums,
      KOKKOS_LAMBDA(const int t, double(&sum)[2]) {
        const Real3 p0 = load3(x, tri(t, 0)), p1 = load3(x, tri(t, 1)), p2 = load3(x, tri(t, 2));
        sum[0] += 0.5 * norm(cross(p1 - p0, p2 - p0));  // A = sum_t A_t
        sum[1] += dot(p0, cross(p1, p2)) / 6.0;         // V = sum_t x0 . (x1 x x2) / 6
      },
      PairOut<MemorySpace>{geo.cell_area, geo.cell_volume});
}

}  // namespace dcm
