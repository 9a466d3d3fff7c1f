#pragma once
// The "rounded triangle" (paper section "Local curvature of the 3D shape", MODEL.md section 2): each
// triangle is replaced for contact by the cap of its encompassing sphere, the sphere of radius
// R_t = 1/H_t through the triangle's three nodes with its centre on the inner side:
//   centre = circumcentre - sqrt(R_t^2 - rho_c^2) n_t,   rho_c the circumradius;
// where R_t < rho_c no such sphere exists and R_t is raised to rho_c (centre = circumcentre).
// Expectations (tests/test_curvature.cpp): on an icosphere of radius R the spheres have radius ~R and
// centres ~ the sphere's centre; every node of the triangle lies on its sphere.
#include "core/geometry.hpp"
#include "core/vec3.hpp"

namespace dcm {

// Circumcentre of (a, b, c) and its circumradius; a degenerate triangle gives the centroid and 0.
KOKKOS_INLINE_FUNCTION Real3 circumcenter(Real3 a, Real3 b, Real3 c, double& radius) {
  const Real3 u = a - c, v = b - c;
  const Real3 w = cross(u, v);
  const double w2 = norm2(w);
  if (!(w2 > 0)) {
    radius = 0;
    return (1.0 / 3.0) * (a + b + c);
  }
  const Real3 rel = (0.5 / w2) * cross(norm2(u) * v - norm2(v) * u, w);
  radius = norm(rel);
  return c + rel;
}

template <class ExecutionSpace, class MemorySpace>
void compute_rounded_triangles(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                               const GeometryBuffers<MemorySpace>& geo) {
  const auto x = mesh.x;
  const auto tri = mesh.tri;
  const auto normal = geo.tri_normal;
  const auto tri_h = geo.tri_mean_curvature;
  const auto center = geo.tri_sphere_center;
  const auto radius = geo.tri_sphere_radius;
  Kokkos::parallel_for(
      "dcm::rounded_triangle::spheres", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_tris),
      KOKKOS_LAMBDA(const int t) {
        double rho_c = 0;
        const Real3 cc = circumcenter(load3(x, tri(t, 0)), load3(x, tri(t, 1)), load3(x, tri(t, 2)), rho_c);
        const double r = math::max(1.0 / tri_h(t), rho_c);
        const double depth = math::sqrt(math::max(r * r - rho_c * rho_c, 0.0));
        store3(center, t, cc - depth * load3(normal, t));
        radius(t) = r;
      });
}

}  // namespace dcm
