#pragma once
// Test helper: run update_geometry on a set of cells with a given execution space and bring every
// result back to the host as flat vectors.
#include <vector>

#include "core/host_copy.hpp"
#include "core/update_geometry.hpp"

namespace dcm::test {

struct HostGeometry {
  std::vector<double> x, tri_area, tri_normal, cell_area, cell_volume, node_curvature, node_area, node_normal,
      node_mean_curvature, tri_mean_curvature, tri_sphere_center, tri_sphere_radius;
  std::vector<int> tri;
};

template <class ExecutionSpace = Kokkos::DefaultExecutionSpace>
HostGeometry compute_geometry(const std::vector<HostCell>& cells, double h_min) {
  using Mem = typename ExecutionSpace::memory_space;
  const ExecutionSpace space;
  const MeshBuffers<Mem> mesh = upload_cells<Mem>(cells);
  const GeometryBuffers<Mem> geo(mesh);
  update_geometry(space, mesh, geo, h_min);
  space.fence();
  HostGeometry g;
  g.x = to_host_vector(mesh.x);
  g.tri_area = to_host_vector(geo.tri_area);
  g.tri_normal = to_host_vector(geo.tri_normal);
  g.cell_area = to_host_vector(geo.cell_area);
  g.cell_volume = to_host_vector(geo.cell_volume);
  g.node_curvature = to_host_vector(geo.node_curvature);
  g.node_area = to_host_vector(geo.node_area);
  g.node_normal = to_host_vector(geo.node_normal);
  g.node_mean_curvature = to_host_vector(geo.node_mean_curvature);
  g.tri_mean_curvature = to_host_vector(geo.tri_mean_curvature);
  g.tri_sphere_center = to_host_vector(geo.tri_sphere_center);
  g.tri_sphere_radius = to_host_vector(geo.tri_sphere_radius);
  g.tri = to_host_vector(mesh.tri);
  return g;
}

inline HostGeometry compute_geometry(const HostMesh& mesh, double h_min) {
  return compute_geometry(std::vector<HostCell>{HostCell(mesh)}, h_min);
}

}  // namespace dcm::test
