#pragma once
// Geometric state derived from node positions, recomputed every step before the forces.
// The kernels live in kernels/ (one term per file); update_geometry() runs them in order.
#include "core/buffers.hpp"

namespace dcm {

template <class MemorySpace>
struct GeometryBuffers {
  template <class T>
  using View = Kokkos::View<T, Kokkos::LayoutRight, MemorySpace>;

  View<double*> tri_area;               // A_t (m^2)
  View<double* [3]> tri_normal;         // unit outward normal n_t
  View<double* [3]> tri_cot;            // cotangent of the angle at each corner
  View<double*> cell_area;              // A per cell (m^2)
  View<double*> cell_volume;            // V per cell (m^3)
  View<double* [3]> node_curvature;     // K_i, cotangent Laplace-Beltrami mean-curvature vector (1/m)
  View<double*> node_area;              // mixed Voronoi area A_mixed,i (m^2)
  View<double* [3]> tri_corner_area;    // each corner's share of A_mixed of its node (m^2)
  View<double* [3]> node_normal;        // unit area-weighted normal
  View<double*> node_mean_curvature;    // H_i = sign(K_i . n_i) |K_i| / 2 (1/m)
  View<double*> tri_mean_curvature;     // H_t, Voronoi-weighted mean of its nodes' H, clamped >= H_min
  View<double* [3]> tri_sphere_center;  // encompassing ("rounded triangle") sphere centre (m)
  View<double*> tri_sphere_radius;      // its radius R_t = max(1/H_t, circumradius) (m)

  GeometryBuffers() = default;
  explicit GeometryBuffers(const MeshBuffers<MemorySpace>& m) {
    auto a = [](const char* label, auto& v, int n) {
      using V = std::decay_t<decltype(v)>;
      v = V(Kokkos::view_alloc(Kokkos::WithoutInitializing, std::string("dcm::geometry::") + label), n);
    };
    a("tri_area", tri_area, m.n_tris);
    a("tri_normal", tri_normal, m.n_tris);
    a("tri_cot", tri_cot, m.n_tris);
    a("cell_area", cell_area, m.n_cells);
    a("cell_volume", cell_volume, m.n_cells);
    a("node_curvature", node_curvature, m.n_nodes);
    a("node_area", node_area, m.n_nodes);
    a("tri_corner_area", tri_corner_area, m.n_tris);
    a("node_normal", node_normal, m.n_nodes);
    a("node_mean_curvature", node_mean_curvature, m.n_nodes);
    a("tri_mean_curvature", tri_mean_curvature, m.n_tris);
    a("tri_sphere_center", tri_sphere_center, m.n_tris);
    a("tri_sphere_radius", tri_sphere_radius, m.n_tris);
  }
};

// Everything above from mesh.x, in dependency order. h_min: lower clamp of H_t (1/m), > 0. rounded = false:
// without the curvature and the spheres (core/update_geometry.hpp).
template <class ExecutionSpace, class MemorySpace>
void update_geometry(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                     const GeometryBuffers<MemorySpace>& geo, double h_min, bool rounded = true);

}  // namespace dcm
