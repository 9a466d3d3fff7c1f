#pragma once
// The membrane forces (FENE + POW bonds, bending, local and global area, volume) in two passes instead of
// one per term (docs/model/membrane_pass.md). The physics is that of the term files, which keep the
// per-term kernels and the energies:
//   kernels/fene_pow_bonds.hpp      eqs. 21-24     kernels/bending.hpp         eq. 26
//   kernels/area_constraints.hpp    eqs. 27-28     kernels/volume_constraint.hpp  eq. 29
//
// 1. Edge pass: an edge is a bond, a hinge and, through its wings, a corner of each of its two triangles
//    (core/host_mesh.cpp numbers bonds and hinges alike). Per edge: the bond force, the hinge's four bending
//    forces, and the area and volume forces of the two triangles on their corners opposite the edge (wing k
//    of (i, j, k), wing l of (j, i, l); each triangle corner is opposite exactly one edge),
//      F_a = -(1/2) [k_a (A_t - A_t*)/A_t* + k_d (A_c - A_c*)/A_c*] n_t x (x_c - x_b)   (eqs. 27, 28)
//            - k_v (V_c - V_c*)/V_c* (A_t/3) n_t                                        (eq. 29)
//    all from one evaluation that shares |x_j - x_i|, the triangles' normals (e x a, b x e: twice the
//    areas) and the reciprocals (one division per edge). The hinge's gradient, -M and cos(theta - theta*)
//    go into HingeRest as add_bending_forces() leaves them (the implicit bending stiffness reads them).
// 2. Node gather. Pass 1 writes each hinge node's share (x, y, z and an unused fourth double) into a slot of
//    that node's contiguous range of the scratch (fill_membrane_slots()); the gather sums the range: no
//    atomics, deterministic, and no scattered reads (the scattered accesses are the pass's stores).
//
// Pass 1 works on MembraneLanes consecutive edges per work item: on the host 8, with explicit vectors where
// the compiler is GCC or Clang (kernels/membrane_edge_simd.hpp) and otherwise in straight-line loops over
// the lanes that the compiler vectorises (kernels/membrane_edge_pass.hpp); on a GPU a work item is one edge
// (MembraneLanes = 1). MembraneEdgeKernel picks another form (the tests run all three). The constants of each
// cell (k_b, k_s, x_max, k_a and the global area and volume factors) are gathered into one row per cell
// before the pass; a batch whose edges share a cell reads one row. Where the edge count is not a multiple of
// the lanes, the last batch overlaps the one before it and stores only its own edges.
//
// Expectations (tests/test_membrane_forces.cpp): the same forces, hinge scratch and overstretch flag as the
// per-term kernels (to rounding), on meshes with several cells and per-cell constants.
#include <stdexcept>
#include <string>
#include <type_traits>

#include "core/cell_params.hpp"
#include "core/geometry.hpp"
#include "core/vec3.hpp"
#include "kernels/area_constraints.hpp"
#include "kernels/bending.hpp"
#include "kernels/fene_pow_bonds.hpp"
#include "kernels/membrane_edge_pass.hpp"
#include "kernels/membrane_edge_simd.hpp"
#include "kernels/volume_constraint.hpp"

namespace dcm {

// Which form of the edge pass runs: the fastest this build has for the execution space (the default), the
// portable lanes (EdgePass<8> on the host), or one edge per work item (the device form). Tests run all three.
enum class MembraneEdgeKernel { fastest, lanes, one_edge };

// Items per work item of the triangle and edge passes: 8 where the execution space runs on the host (SIMD
// lanes), 1 on a device (CUDA, HIP, SYCL: one thread per item). Asked of the execution space, not of its
// memory: a device space with host-accessible (managed) memory still runs one item per thread.
template <class ExecutionSpace>
struct MembraneLanes {
  static constexpr int value =
      Kokkos::SpaceAccessibility<ExecutionSpace, Kokkos::HostSpace>::accessible ? 8 : 1;
};

// The slot of each (edge, hinge node) in its node's contiguous range of the scratch: the node's (hinge,
// role) entries in the order of the mesh's node -> hinge lists (slot = the entry's index there). And the two
// triangles of each edge: (i, j, k) and (j, i, l) as the mesh orients them (the hinge's wings k and l are
// their corners opposite the edge).
template <class MemorySpace>
void fill_membrane_slots(const MeshBuffers<MemorySpace>& mesh,
                         const Kokkos::View<int* [4], Kokkos::LayoutRight, MemorySpace>& edge_slot,
                         const Kokkos::View<int* [2], Kokkos::LayoutRight, MemorySpace>& edge_tri) {
  using Exec = typename MemorySpace::execution_space;
  const auto hinge_offsets = mesh.node_hinge_offsets;
  const auto roles = mesh.node_hinge_roles;
  Kokkos::parallel_for(
      "dcm::membrane::slots", Kokkos::RangePolicy<Exec>(0, mesh.n_nodes), KOKKOS_LAMBDA(const int i) {
        for (int s = hinge_offsets(i); s < hinge_offsets(i + 1); ++s)
          edge_slot(roles(s) / 4, roles(s) % 4) = s;
      });
  const auto hinge = mesh.hinge;
  const auto tri = mesh.tri;
  const auto tri_offsets = mesh.node_tri_offsets;
  const auto corners = mesh.node_tri_corners;
  Kokkos::parallel_for(
      "dcm::membrane::edge_triangles", Kokkos::RangePolicy<Exec>(0, mesh.n_hinges),
      KOKKOS_LAMBDA(const int e) {
        for (int side = 0; side < 2; ++side) {  // wing k: triangle (i, j, k); wing l: triangle (j, i, l)
          const int wing = hinge(e, 2 + side), a = hinge(e, side), b = hinge(e, 1 - side);
          edge_tri(e, side) = -1;
          for (int q = tri_offsets(wing); q < tri_offsets(wing + 1); ++q) {
            const int t = corners(q) / 3, c = corners(q) % 3;
            if (tri(t, (c + 1) % 3) == a && tri(t, (c + 2) % 3) == b) edge_tri(e, side) = t;
          }
        }
      });
}

// Scratch of the passes (allocated once per mesh). The edge pass writes each hinge node's share into a slot
// of that node's own contiguous range (fill_membrane_slots()), so that the gather reads one contiguous range
// per node and no pass needs atomics.
template <class MemorySpace>
struct MembraneScratch {
  // Per cell and call, the constants of the edge pass: k_b, k_s, x_max^2, k_s / (1 - 1/x_max^2), k_a,
  // k_d (A_c - A_c*)/A_c* (N/m) and -k_v (V_c - V_c*)/(3 V_c*) (Pa), eqs. 24, 26-29; one row per cell.
  static constexpr int kCellConstants = 8;
  Kokkos::View<double* [4], Kokkos::LayoutRight, MemorySpace>
      slot_force;  // per (node, hinge entry): x, y, z, 0 (N)
  Kokkos::View<int* [4], Kokkos::LayoutRight, MemorySpace> edge_slot;  // slot of (edge, hinge node)
  Kokkos::View<int* [2], Kokkos::LayoutRight, MemorySpace> edge_tri;   // triangles of the wings k, l
  Kokkos::View<double* [kCellConstants], Kokkos::LayoutRight, MemorySpace> cell_constants;
  // The vector pass of host builds (kernels/membrane_edge_simd.hpp) loads the positions from a padded copy.
#if defined(DCM_MEMBRANE_EDGE_SIMD)
  static constexpr bool kHostSimd = Kokkos::SpaceAccessibility<Kokkos::HostSpace, MemorySpace>::accessible;
#else
  static constexpr bool kHostSimd = false;
#endif
  Kokkos::View<double* [4], Kokkos::LayoutRight, MemorySpace> x4;  // [node]: x, y, z, 0 (empty without it)
  MembraneScratch() = default;
  explicit MembraneScratch(const MeshBuffers<MemorySpace>& mesh)
      : slot_force("dcm::membrane::slot_force", 4 * mesh.n_hinges),
        edge_slot("dcm::membrane::edge_slot", mesh.n_hinges),
        edge_tri("dcm::membrane::edge_tri", mesh.n_hinges),
        cell_constants("dcm::membrane::cell_constants", mesh.n_cells),
        x4("dcm::membrane::x4", kHostSimd ? mesh.n_nodes : 0) {
    fill_membrane_slots(mesh, edge_slot, edge_tri);
    const auto tris = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), edge_tri);
    for (int e = 0; e < mesh.n_hinges; ++e)
      if (tris(e, 0) < 0 || tris(e, 1) < 0)
        throw std::invalid_argument("membrane pass: edge " + std::to_string(e) +
                                    " lacks a triangle (i, j, k) or (j, i, l) with its hinge's wing");
    // The edge pass reads one row of constants for a batch whose first and last edges share a cell: each
    // cell's edges must be one contiguous range (upload_cells() numbers them so).
    const auto cell = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.hinge_cell);
    for (int e = 1; e < mesh.n_hinges; ++e)
      if (cell(e) < cell(e - 1))
        throw std::invalid_argument("membrane pass: the edges of a cell are not one contiguous range (edge " +
                                    std::to_string(e) + ")");
  }
};

// Whether the mesh numbers bonds and hinges alike (bond e = (hinge(e, 0), hinge(e, 1))): the edge pass
// needs it. Host check, once per mesh.
template <class MemorySpace>
bool bonds_match_hinges(const MeshBuffers<MemorySpace>& mesh) {
  if (mesh.n_bonds != mesh.n_hinges) return false;
  const auto b = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.bond);
  const auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.hinge);
  for (int e = 0; e < mesh.n_bonds; ++e)
    if (b(e, 0) != h(e, 0) || b(e, 1) != h(e, 1)) return false;
  return true;
}

// force += bonds + bending + area + volume forces. Needs update_geometry() on the current mesh.x (the cells'
// area and volume; the triangles' areas and normals are recomputed from the positions). Requires
// bonds_match_hinges(mesh). A zero constant costs its arithmetic but no extra pass. overstretched: set to -1
// by the caller; receives a bond that could not be evaluated (as add_fene_pow_forces()).
template <class ExecutionSpace, class MemorySpace, class BondP, class KB, class KA, class KD, class KV>
void add_membrane_forces(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                         const GeometryBuffers<MemorySpace>& geo, const BondRest<MemorySpace>& bond_rest,
                         const BondP& bond_params, const HingeRest<MemorySpace>& hinge_rest, const KB& k_b,
                         const AreaRest<MemorySpace>& area_rest, const KA& k_a, const KD& k_d,
                         const VolumeRest<MemorySpace>& volume_rest, const KV& k_v,
                         const MembraneScratch<MemorySpace>& scratch,
                         const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& force,
                         const Kokkos::View<int, MemorySpace>& overstretched,
                         const MembraneEdgeKernel kernel = MembraneEdgeKernel::fastest) {
  static_assert(MembraneScratch<MemorySpace>::kCellConstants == membrane_detail::EdgePassArgs::K,
                "one row layout");
  const int n = mesh.n_hinges;
  {  // Per cell, once per call: the edge pass's constants, the global area and volume factors included.
    const auto cell_area = geo.cell_area;
    const auto cell_volume = geo.cell_volume;
    const auto rest_cell_area = area_rest.cell_area;
    const auto rest_volume = volume_rest.cell_volume;
    const auto row = scratch.cell_constants;
    Kokkos::parallel_for(
        "dcm::membrane::cells", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_cells),
        KOKKOS_LAMBDA(const int c) {
          const FenePowParams bp = cell_value(bond_params, c);
          const double xm2 = bp.x_max * bp.x_max;
          row(c, 0) = cell_value(k_b, c);
          row(c, 1) = bp.k_s;
          row(c, 2) = xm2;
          row(c, 3) = bp.k_s / (1 - 1 / xm2);  // k_c / d*^3 (eq. 24)
          row(c, 4) = cell_value(k_a, c);
          row(c, 5) = cell_value(k_d, c) * (cell_area(c) - rest_cell_area(c)) / rest_cell_area(c);  // eq. 28
          row(c, 6) =
              -cell_value(k_v, c) * (cell_volume(c) - rest_volume(c)) / rest_volume(c) / 3.0;  // eq. 29
          row(c, 7) = 0;
        });
  }
  // 1. Edge pass. It indexes the Views' data with their unpadded LayoutRight strides.
  const auto grad = hinge_rest.hinge_grad;
  if (mesh.x.stride_0() != 3 || mesh.hinge.stride_0() != 4 || scratch.edge_slot.stride_0() != 4 ||
      scratch.edge_tri.stride_0() != 2 || hinge_rest.rest_trig.stride_0() != 2 || grad.stride_0() != 12 ||
      scratch.slot_force.stride_0() != 4)
    throw std::logic_error("add_membrane_forces: a View is padded");
  membrane_detail::EdgePassArgs args;
  args.n = n;
  args.x = mesh.x.data();
  args.hinge = mesh.hinge.data();
  args.slot = scratch.edge_slot.data();
  args.tri2 = scratch.edge_tri.data();
  args.edge_cell = mesh.hinge_cell.data();
  args.rest_length = bond_rest.rest_length.data();
  args.rest_trig = hinge_rest.rest_trig.data();
  args.rest_area = area_rest.tri_area.data();
  args.cell_constants = scratch.cell_constants.data();
  args.out = scratch.slot_force.data();
  args.grad = grad.data();
  args.moment = hinge_rest.hinge_moment.data();
  args.cos_delta = hinge_rest.hinge_cos_delta.data();
  args.overstretched = overstretched.data();
  auto run = [&](auto pass) {
    constexpr int W = decltype(pass)::W;
    Kokkos::parallel_for("dcm::membrane::edges",
                         Kokkos::RangePolicy<ExecutionSpace>(space, 0, (n + W - 1) / W), pass);
  };
  constexpr int W = MembraneLanes<ExecutionSpace>::value;
  const bool lanes = n >= W && kernel != MembraneEdgeKernel::one_edge;
  bool done = false;
#if defined(DCM_MEMBRANE_EDGE_SIMD)
  if constexpr (W == 8 && MembraneScratch<MemorySpace>::kHostSimd) {
    if (lanes && kernel == MembraneEdgeKernel::fastest) {
      // The padded copy of the positions that the vector pass loads one 4-vector per node from.
      const auto x = mesh.x;
      const auto x4 = scratch.x4;
      Kokkos::parallel_for(
          "dcm::membrane::x4", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
          KOKKOS_LAMBDA(const int i) {
            x4(i, 0) = x(i, 0);
            x4(i, 1) = x(i, 1);
            x4(i, 2) = x(i, 2);
          });
      membrane_detail::EdgePassSimd8 pass;
      static_cast<membrane_detail::EdgePassArgs&>(pass) = args;
      pass.x4 = x4.data();
      run(pass);
      done = true;
    }
  }
#endif
  if (!done && lanes)
    run(membrane_detail::EdgePass<W>{args});
  else if (!done)
    run(membrane_detail::EdgePass<1>{args});
    // 2. Node gather: the node's slots, contiguous.
#if defined(DCM_MEMBRANE_EDGE_SIMD)
  if constexpr (W == 8 && MembraneScratch<MemorySpace>::kHostSimd) {
    if (force.stride_0() != 3) throw std::logic_error("add_membrane_forces: the force View is padded");
    const membrane_detail::GatherSimd gather{mesh.node_hinge_offsets.data(), scratch.slot_force.data(),
                                             force.data()};
    Kokkos::parallel_for("dcm::membrane::gather", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
                         gather);
    return;
  }
#endif
  {
    const auto hinge_offsets = mesh.node_hinge_offsets;
    const auto in = scratch.slot_force;
    Kokkos::parallel_for(
        "dcm::membrane::gather", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
        KOKKOS_LAMBDA(const int i) {
          double f0 = 0, f1 = 0, f2 = 0;
          for (int s = hinge_offsets(i); s < hinge_offsets(i + 1); ++s) {
            f0 += in(s, 0);
            f1 += in(s, 1);
            f2 += in(s, 2);
          }
          force(i, 0) += f0;
          force(i, 1) += f1;
          force(i, 2) += f2;
        });
  }
}

}  // namespace dcm
