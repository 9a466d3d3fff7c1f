#pragma once
// Triangle areas and unit normals, and per-cell surface area and enclosed volume (paper: the global area
// constraint eq. 28 and the volume constraint eq. 29 act on these).
//   A_t = |(x1 - x0) x (x2 - x0)| / 2,  n_t = (x1 - x0) x (x2 - x0) / (2 A_t)  (outward for CCW triangles)
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
  Kokkos::parallel_for(
      "dcm::geometry::triangles", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_tris),
      KOKKOS_LAMBDA(const int t) {
        const Real3 p0 = load3(x, tri(t, 0)), p1 = load3(x, tri(t, 1)), p2 = load3(x, tri(t, 2));
        const Real3 c = cross(p1 - p0, p2 - p0);
        const double twice_area = norm(c);
        area(t) = 0.5 * twice_area;
        store3(normal, t, twice_area > 0 ? (1.0 / twice_area) * c : Real3{0, 0, 0});
      });
}

// Per-cell A and V. Needs no other geometry. One reduction per cell over its triangle range
// (a batched many-cell variant belongs with the batched engine).
template <class ExecutionSpace, class MemorySpace>
void compute_cell_measures(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                           const GeometryBuffers<MemorySpace>& geo) {
  const auto x = mesh.x;
  const auto tri = mesh.tri;
  auto begin = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.cell_tri_begin);
  auto area_h = Kokkos::create_mirror_view(geo.cell_area);
  auto volume_h = Kokkos::create_mirror_view(geo.cell_volume);
  for (int c = 0; c < mesh.n_cells; ++c) {
    const Kokkos::RangePolicy<ExecutionSpace> range(space, begin(c), begin(c + 1));
    double a = 0, v = 0;
    Kokkos::parallel_reduce(
        "dcm::geometry::cell_area", range,
        KOKKOS_LAMBDA(const int t, double& sum) {
          const Real3 p0 = load3(x, tri(t, 0)), p1 = load3(x, tri(t, 1)), p2 = load3(x, tri(t, 2));
          sum += 0.5 * norm(cross(p1 - p0, p2 - p0));
        },
        a);
    Kokkos::parallel_reduce(
        "dcm::geometry::cell_volume", range,
        KOKKOS_LAMBDA(const int t, double& sum) {
          const Real3 p0 = load3(x, tri(t, 0)), p1 = load3(x, tri(t, 1)), p2 = load3(x, tri(t, 2));
          sum += dot(p0, cross(p1, p2)) / 6.0;
        },
        v);
    area_h(c) = a;
    volume_h(c) = v;
  }
  Kokkos::deep_copy(geo.cell_area, area_h);
  Kokkos::deep_copy(geo.cell_volume, volume_h);
}

}  // namespace dcm
