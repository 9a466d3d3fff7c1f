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
// 2. Node gather. Pass 1 writes each hinge node's share (3 doubles) into a slot of that node's contiguous
//    range of the scratch (fill_membrane_slots()); the gather sums the range: no atomics, deterministic,
//    and no scattered reads (the scattered accesses are the pass's stores).
//
// Pass 1 works on MembraneLanes consecutive edges per work item, loaded into small local arrays and
// computed in straight-line loops over the lanes, which the host compiler turns into SIMD instructions (8
// doubles per AVX-512 instruction); on a GPU a work item is one edge (MembraneLanes = 1).
//
// Expectations (tests/test_membrane_forces.cpp): the same forces, hinge scratch and overstretch flag as the
// per-term kernels (to rounding), on meshes with several cells and per-cell constants.
#include <stdexcept>
#include <string>

#include "core/cell_params.hpp"
#include "core/geometry.hpp"
#include "core/vec3.hpp"
#include "kernels/area_constraints.hpp"
#include "kernels/bending.hpp"
#include "kernels/fene_pow_bonds.hpp"
#include "kernels/volume_constraint.hpp"

namespace dcm {

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
  Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace> slot_force;  // per (node, hinge entry) (N)
  Kokkos::View<int* [4], Kokkos::LayoutRight, MemorySpace> edge_slot;      // slot of (edge, hinge node)
  Kokkos::View<int* [2], Kokkos::LayoutRight, MemorySpace> edge_tri;       // triangles of the wings k, l
  // Per cell and call: k_d (A_c - A_c*)/A_c* (N/m) and -k_v (V_c - V_c*)/(3 V_c*) (Pa), eqs. 28 and 29.
  Kokkos::View<double* [2], Kokkos::LayoutRight, MemorySpace> cell_factor;
  MembraneScratch() = default;
  explicit MembraneScratch(const MeshBuffers<MemorySpace>& mesh)
      : slot_force("dcm::membrane::slot_force", 4 * mesh.n_hinges),
        edge_slot("dcm::membrane::edge_slot", mesh.n_hinges),
        edge_tri("dcm::membrane::edge_tri", mesh.n_hinges),
        cell_factor("dcm::membrane::cell_factor", mesh.n_cells) {
    fill_membrane_slots(mesh, edge_slot, edge_tri);
    const auto tris = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), edge_tri);
    for (int e = 0; e < mesh.n_hinges; ++e)
      if (tris(e, 0) < 0 || tris(e, 1) < 0)
        throw std::invalid_argument("membrane pass: edge " + std::to_string(e) +
                                    " lacks a triangle (i, j, k) or (j, i, l) with its hinge's wing");
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
                         const Kokkos::View<int, MemorySpace>& overstretched) {
  constexpr int W = MembraneLanes<ExecutionSpace>::value;
  const auto x = mesh.x;
  const int n = mesh.n_hinges;
  const auto hinge = mesh.hinge;
  const auto edge_cell = mesh.hinge_cell;
  const auto rest_length = bond_rest.rest_length;
  const auto rest_trig = hinge_rest.rest_trig;
  const auto grad = hinge_rest.hinge_grad;
  const auto moment = hinge_rest.hinge_moment;
  const auto cos_delta = hinge_rest.hinge_cos_delta;
  const auto slot = scratch.edge_slot;
  const auto edge_tri = scratch.edge_tri;
  const auto out = scratch.slot_force;
  const auto rest_area = area_rest.tri_area;
  const auto factor = scratch.cell_factor;
  {  // the cells' global area and volume factors, once per cell
    const auto cell_area = geo.cell_area;
    const auto cell_volume = geo.cell_volume;
    const auto rest_cell_area = area_rest.cell_area;
    const auto rest_volume = volume_rest.cell_volume;
    Kokkos::parallel_for(
        "dcm::membrane::cells", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_cells),
        KOKKOS_LAMBDA(const int c) {
          factor(c, 0) =
              cell_value(k_d, c) * (cell_area(c) - rest_cell_area(c)) / rest_cell_area(c);  // eq. 28
          factor(c, 1) =
              -cell_value(k_v, c) * (cell_volume(c) - rest_volume(c)) / rest_volume(c) / 3.0;  // eq. 29
        });
  }
  // 1. Edge pass.
  Kokkos::parallel_for(
      "dcm::membrane::edges", Kokkos::RangePolicy<ExecutionSpace>(space, 0, (n + W - 1) / W),
      KOKKOS_LAMBDA(const int batch) {
        double p[4][3][W], d_rest[W], cr[W], sr[W], kb[W], ks[W], xm2[W];
        double a0[2][W], ka[W], global[W], vol[W];  // the wings' triangles: eqs. 27-29
        for (int l = 0; l < W; ++l) {
          const int e = batch * W + l < n ? batch * W + l : n - 1;
          const int c = edge_cell(e);
          for (int v = 0; v < 4; ++v)
            for (int d = 0; d < 3; ++d) p[v][d][l] = x(hinge(e, v), d);
          d_rest[l] = rest_length(e);
          cr[l] = rest_trig(e, 0);
          sr[l] = rest_trig(e, 1);
          kb[l] = cell_value(k_b, c);
          const FenePowParams bp = cell_value(bond_params, c);
          ks[l] = bp.k_s;
          xm2[l] = bp.x_max * bp.x_max;
          a0[0][l] = rest_area(edge_tri(e, 0));
          a0[1][l] = rest_area(edge_tri(e, 1));
          ka[l] = cell_value(k_a, c);
          global[l] = factor(c, 0);
          vol[l] = factor(c, 1);
        }
        double g[4][3][W], m[W], cd[W], fb[3][W], fw[2][3][W];
        int bond_bad[W];
        for (int l = 0; l < W; ++l) {
          const double ex = p[1][0][l] - p[0][0][l], ey = p[1][1][l] - p[0][1][l],
                       ez = p[1][2][l] - p[0][2][l];  // e = x_j - x_i
          const double ax = p[2][0][l] - p[0][0][l], ay = p[2][1][l] - p[0][1][l],
                       az = p[2][2][l] - p[0][2][l];  // x_k - x_i
          const double bx = p[3][0][l] - p[1][0][l], by = p[3][1][l] - p[1][1][l],
                       bz = p[3][2][l] - p[1][2][l];  // x_l - x_j
          // n1 = e x a = 2 A_1 n_1 of triangle (i, j, k); n2 = b x e = 2 A_2 n_2 of triangle (j, i, l)
          const double n1x = ey * az - ez * ay, n1y = ez * ax - ex * az, n1z = ex * ay - ey * ax;
          const double n2x = by * ez - bz * ey, n2y = bz * ex - bx * ez, n2z = bx * ey - by * ex;
          const double e2 = ex * ex + ey * ey + ez * ez;
          const double n1_2 = n1x * n1x + n1y * n1y + n1z * n1z, n2_2 = n2x * n2x + n2y * n2y + n2z * n2z;
          const double dr = d_rest[l], d_max2 = xm2[l] * dr * dr;
          // Bond (eqs. 21-24): usable for 0 < d < d_max; hinge: for non-degenerate triangles.
          const bool bond_ok = (e2 > 0) & (e2 < d_max2);  // false for NaN too (& keeps the lanes branch-free)
          const bool hinge_ok = (e2 > 0) & (n1_2 > 0) & (n2_2 > 0);
          const double e2s = e2 > 0 ? e2 : 1.0, gap = bond_ok ? d_max2 - e2 : 1.0;
          const double n1s = n1_2 > 0 ? n1_2 : 1.0, n2s = n2_2 > 0 ? n2_2 : 1.0;
          const double len = math::sqrt(e2s), r1 = math::sqrt(n1s), r2 = math::sqrt(n2s);  // |e|, |n1|, |n2|
          // One division for the four reciprocals 1/|e|, 1/gap, 1/|n1|, 1/|n2|.
          const double q = 1.0 / (len * gap * r1 * r2);
          const double inv_len = q * gap * r1 * r2, inv_gap = q * len * r1 * r2;
          const double inv_r1 = q * len * gap * r2, inv_r2 = q * len * gap * r1;
          const double inv_n1 = inv_r1 * inv_r1, inv_n2 = inv_r2 * inv_r2;  // 1/|n1|^2, 1/|n2|^2
          // U'(d)/d = k_s d_max^2 / (d_max^2 - d^2) - k_c / d^3, k_c = k_s d*^3 / (1 - 1/x_max^2) (eq. 24)
          const double k_c = ks[l] * dr * dr * dr / (1 - 1 / xm2[l]);
          const double u = bond_ok ? ks[l] * d_max2 * inv_gap - k_c * inv_len * inv_len * inv_len : 0.0;
          fb[0][l] = u * ex;  // the bond's force on i: U'(d)/d (x_j - x_i); on j the opposite
          fb[1][l] = u * ey;
          fb[2][l] = u * ez;
          bond_bad[l] = bond_ok ? 0 : 1;
          // Hinge (eq. 26), kernels/bending.hpp's hinge_trig_gradient() with these reciprocals.
          const double inv = inv_r1 * inv_r2 * inv_len;  // 1 / (|e| |n1| |n2|)
          const double c = hinge_ok ? len * (n1x * n2x + n1y * n2y + n1z * n2z) * inv : 1.0;
          const double s = hinge_ok ? ((n1y * n2z - n1z * n2y) * ex + (n1z * n2x - n1x * n2z) * ey +
                                       (n1x * n2y - n1y * n2x) * ez) *
                                          inv
                                    : 0.0;
          const double gk = hinge_ok ? -len * inv_n1 : 0.0, gl = hinge_ok ? -len * inv_n2 : 0.0;
          const double inv_e2 = inv_len * inv_len;
          const double ak = (ax * ex + ay * ey + az * ez) * inv_e2;
          const double al = (bx * ex + by * ey + bz * ez) * inv_e2 + 1.0;  // (x_l - x_i) . e / |e|^2
          g[2][0][l] = gk * n1x;
          g[2][1][l] = gk * n1y;
          g[2][2][l] = gk * n1z;
          g[3][0][l] = gl * n2x;
          g[3][1][l] = gl * n2y;
          g[3][2][l] = gl * n2z;
          for (int d = 0; d < 3; ++d) {
            g[0][d][l] = (ak - 1) * g[2][d][l] + (al - 1) * g[3][d][l];
            g[1][d][l] = -ak * g[2][d][l] - al * g[3][d][l];
          }
          m[l] = -kb[l] * (s * cr[l] - c * sr[l]);  // -M = -k_b sin(theta - theta*), eq. 26
          cd[l] = c * cr[l] + s * sr[l];
          // The wings' area and volume forces (each triangle's corner opposite this edge; the triangle's
          // other corners get theirs from its other two edges), kernels/area_constraints.hpp and
          // volume_constraint.hpp with A = |n|/2 and unit normal n/|n|:
          //   F = -(1/2) [k_a (A - A*)/A* + k_d (A_c - A_c*)/A_c*] n/|n| x (x_c - x_b)   (eqs. 27, 28)
          //       - k_v (V_c - V_c*)/V_c* (A/3) n/|n|                                      (eq. 29)
          // with x_c - x_b = e for the wing k of (i, j, k) and -e for the wing l of (j, i, l). A degenerate
          // triangle (n = 0) gets no force, as in the per-term kernels.
          const double h1 = -0.5 * (ka[l] * (0.5 * r1 - a0[0][l]) / a0[0][l] + global[l]) * inv_r1;
          const double h2 = 0.5 * (ka[l] * (0.5 * r2 - a0[1][l]) / a0[1][l] + global[l]) * inv_r2;
          const double v2 = 0.5 * vol[l];
          fw[0][0][l] = h1 * (n1y * ez - n1z * ey) + v2 * n1x;
          fw[0][1][l] = h1 * (n1z * ex - n1x * ez) + v2 * n1y;
          fw[0][2][l] = h1 * (n1x * ey - n1y * ex) + v2 * n1z;
          fw[1][0][l] = h2 * (n2y * ez - n2z * ey) + v2 * n2x;
          fw[1][1][l] = h2 * (n2z * ex - n2x * ez) + v2 * n2y;
          fw[1][2][l] = h2 * (n2x * ey - n2y * ex) + v2 * n2z;
        }
        for (int l = 0; l < W; ++l) {
          const int e = batch * W + l;
          if (e >= n) continue;
          if (bond_bad[l]) Kokkos::atomic_compare_exchange(&overstretched(), -1, e);
          moment(e) = m[l];
          cos_delta(e) = cd[l];
          for (int v = 0; v < 4; ++v)
            for (int d = 0; d < 3; ++d) grad(e, v, d) = g[v][d][l];
          const int s0 = slot(e, 0), s1 = slot(e, 1), s2 = slot(e, 2), s3 = slot(e, 3);
          for (int d = 0; d < 3; ++d) {
            out(s0, d) = m[l] * g[0][d][l] + fb[d][l];
            out(s1, d) = m[l] * g[1][d][l] - fb[d][l];
            out(s2, d) = m[l] * g[2][d][l] + fw[0][d][l];
            out(s3, d) = m[l] * g[3][d][l] + fw[1][d][l];
          }
        }
      });
  // 2. Node gather: the node's slots, contiguous.
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
