#pragma once
// update_geometry(): the geometry stage of a step, kernels in dependency order.
#include "kernels/curvature.hpp"
#include "kernels/rounded_triangle.hpp"
#include "kernels/triangle_geometry.hpp"

namespace dcm {

// rounded = false leaves out the curvature and the rounded triangles' spheres (node_curvature, node_area,
// node_normal, node_mean_curvature, tri_mean_curvature, tri_sphere_*), which only the paper's contact law
// needs: a scene without a plane, or with contact.law = "derjaguin", does not pay for them.
template <class ExecutionSpace, class MemorySpace>
void update_geometry(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                     const GeometryBuffers<MemorySpace>& geo, double h_min, bool rounded) {
  compute_triangle_geometry(space, mesh, geo);
  compute_cell_measures(space, mesh, geo);
  if (!rounded) return;
  compute_node_curvature(space, mesh, geo);
  compute_triangle_curvature(space, mesh, geo, h_min);
  compute_rounded_triangles(space, mesh, geo);
}

}  // namespace dcm
