#pragma once
// Structure-of-arrays buffers (Kokkos Views) for every cell of a simulation.
//
// Several cells share one set of buffers: each node, triangle, bond and hinge carries its cell index,
// and cell c owns the contiguous ranges [cell_node_begin(c), cell_node_begin(c+1)) and likewise for
// triangles, bonds and hinges. Indices in tri/bond/hinge/CSR arrays are global node indices.
// Allocated once by upload_cells(); nothing here is resized during a run.
#include <Kokkos_Core.hpp>
#include <vector>

#include "core/host_mesh.hpp"
#include "core/segmented_sum.hpp"

namespace dcm {

template <class MemorySpace>
struct MeshBuffers {
  using memory_space = MemorySpace;
  template <class T>
  using View = Kokkos::View<T, Kokkos::LayoutRight, MemorySpace>;

  int n_nodes = 0, n_tris = 0, n_bonds = 0, n_hinges = 0, n_cells = 0;

  View<double* [3]> x;  // node positions (m)
  View<int*> node_cell;
  View<int* [3]> tri;  // outward oriented
  View<int*> tri_cell;
  View<int* [2]> bond;  // i < j
  View<int*> bond_cell;
  View<int* [4]> hinge;  // (i, j, k, l): triangles (i, j, k) and (j, i, l)
  View<int*> hinge_cell;
  View<int*> cell_node_begin, cell_tri_begin, cell_bond_begin, cell_hinge_begin;  // n_cells + 1
  std::vector<int> host_cell_node_begin, host_cell_tri_begin;  // the same ranges, for host-side launches

  // CSR node adjacency (gather kernels need no atomics).
  View<int*> node_tri_offsets, node_tri_corners;  // corner entries packed as 3 * triangle + corner
  View<int*> node_bond_offsets, node_bonds;
  View<int*> node_hinge_offsets, node_hinge_roles;  // hinge entries packed as 4 * hinge + role (0..3)
  View<int*> ring_offsets, ring;                    // one-ring neighbours, counter-clockwise from outside

  // Per-cell sums in a fixed order over the nodes, triangles, bonds, hinges and cells
  // (core/segmented_sum.hpp).
  SumPlan<MemorySpace> node_sums, tri_sums, bond_sums, hinge_sums, cell_sums;
};

// One cell before upload: its surface and the topology derived from it.
struct HostCell {
  HostMesh mesh;
  Topology topology;
  explicit HostCell(HostMesh m) : mesh(std::move(m)), topology(build_topology(mesh)) {}
};

// Concatenates the cells into one set of buffers (node indices offset per cell).
template <class MemorySpace>
MeshBuffers<MemorySpace> upload_cells(const std::vector<HostCell>& cells);

}  // namespace dcm

#include "core/buffers_impl.hpp"
