#pragma once
// Test helper: run update_geometry on a set of cells with a given execution space and bring every
// result back to the host as flat vectors.
#include <vector>

#include "core/update_geometry.hpp"

namespace dcm::test {

struct HostGeometry {
  std::vector<double> x, tri_area, tri_normal, cell_area, cell_volume, node_curvature, node_area,
      node_normal, node_mean_curvature, tri_mean_curvature, tri_sphere_center, tri_sphere_radius;
  std::vector<int> tri;
};

template <class View>
std::vector<double> to_vector(const View& v) {
  auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), v);
  std::vector<double> out;
  const std::size_t n0 = h.extent(0), n1 = View::rank == 2 ? h.extent(1) : 1;
  out.reserve(n0 * n1);
  for (std::size_t i = 0; i < n0; ++i)
    for (std::size_t j = 0; j < n1; ++j) {
      if constexpr (View::rank == 2)
        out.push_back(h(i, j));
      else
        out.push_back(h(i));
    }
  return out;
}

template <class ExecutionSpace = Kokkos::DefaultExecutionSpace>
HostGeometry compute_geometry(const std::vector<HostCell>& cells, double h_min) {
  using Mem = typename ExecutionSpace::memory_space;
  const ExecutionSpace space;
  const MeshBuffers<Mem> mesh = upload_cells<Mem>(cells);
  const GeometryBuffers<Mem> geo(mesh);
  update_geometry(space, mesh, geo, h_min);
  space.fence();
  HostGeometry g;
  g.x = to_vector(mesh.x);
  g.tri_area = to_vector(geo.tri_area);
  g.tri_normal = to_vector(geo.tri_normal);
  g.cell_area = to_vector(geo.cell_area);
  g.cell_volume = to_vector(geo.cell_volume);
  g.node_curvature = to_vector(geo.node_curvature);
  g.node_area = to_vector(geo.node_area);
  g.node_normal = to_vector(geo.node_normal);
  g.node_mean_curvature = to_vector(geo.node_mean_curvature);
  g.tri_mean_curvature = to_vector(geo.tri_mean_curvature);
  g.tri_sphere_center = to_vector(geo.tri_sphere_center);
  g.tri_sphere_radius = to_vector(geo.tri_sphere_radius);
  auto tri = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.tri);
  for (int t = 0; t < mesh.n_tris; ++t)
    for (int c = 0; c < 3; ++c) g.tri.push_back(tri(t, c));
  return g;
}

inline HostGeometry compute_geometry(const HostMesh& mesh, double h_min) {
  return compute_geometry(std::vector<HostCell>{HostCell(mesh)}, h_min);
}

}  // namespace dcm::test
