#pragma once
// The membrane forces (FENE + POW bonds, bending, local and global area, volume) in three passes instead of
// one per term (docs/model/membrane_pass.md). The physics is that of the term files, which keep the
// per-term kernels and the energies:
//   kernels/fene_pow_bonds.hpp      eqs. 21-24     kernels/bending.hpp         eq. 26
//   kernels/area_constraints.hpp    eqs. 27-28     kernels/volume_constraint.hpp  eq. 29
//
// 1. Triangle pass: each corner's area and volume force,
//      F_a = -(1/2) [k_a (A_t - A_t*)/A_t* + k_d (A_c - A_c*)/A_c*] n_t x (x_c - x_b)   (eqs. 27, 28)
//            - k_v (V_c - V_c*)/V_c* (A_t/3) n_t                                        (eq. 29)
// 2. Edge pass: an edge is both a bond and a hinge (core/host_mesh.cpp numbers them alike); its bond force
//    and its hinge's four bending forces in one evaluation that shares |x_j - x_i| and the reciprocals
//    (one division per edge). The hinge's gradient, -M and cos(theta - theta*) go into HingeRest as
//    add_bending_forces() leaves them (the implicit bending stiffness reads them).
// 3. Node gather. Passes 1 and 2 write each node's share (3 doubles) into a slot of that node's contiguous
//    range of the scratch (fill_membrane_slots()); the gather sums the range: no atomics, deterministic,
//    and no scattered reads (the scattered accesses are the passes' stores).
//
// Passes 1 and 2 work on MembraneLanes consecutive items per work item, loaded into small local arrays and
// computed in straight-line loops over the lanes, which the host compiler turns into SIMD instructions (8
// doubles per AVX-512 instruction); on a GPU a work item is one item (MembraneLanes = 1).
//
// Expectations (tests/test_membrane_forces.cpp): the same forces, hinge scratch and overstretch flag as the
// per-term kernels (to rounding), on meshes with several cells and per-cell constants.
#include "core/cell_params.hpp"
#include "core/geometry.hpp"
#include "core/vec3.hpp"
#include "kernels/area_constraints.hpp"
#include "kernels/bending.hpp"
#include "kernels/fene_pow_bonds.hpp"
#include "kernels/volume_constraint.hpp"

namespace dcm {

// Items per work item of the triangle and edge passes: 8 where the execution space runs on the host (SIMD
// lanes), 1 on a device (CUDA, HIP, SYCL: one thread per item).
template <class ExecutionSpace>
struct MembraneLanes {
  static constexpr int value =
      Kokkos::SpaceAccessibility<Kokkos::HostSpace, typename ExecutionSpace::memory_space>::accessible ? 8
                                                                                                       : 1;
};

// The slot of each (edge, hinge node) and (triangle, corner) in its node's contiguous range of the scratch:
// the node's (hinge, role) entries of the mesh's lists first, then its (triangle, corner) entries.
template <class MemorySpace>
void fill_membrane_slots(const MeshBuffers<MemorySpace>& mesh,
                         const Kokkos::View<int* [4], Kokkos::LayoutRight, MemorySpace>& edge_slot,
                         const Kokkos::View<int* [3], Kokkos::LayoutRight, MemorySpace>& tri_slot) {
  const auto hinge_offsets = mesh.node_hinge_offsets;
  const auto roles = mesh.node_hinge_roles;
  const auto tri_offsets = mesh.node_tri_offsets;
  const auto corners = mesh.node_tri_corners;
  Kokkos::parallel_for(
      "dcm::membrane::slots", Kokkos::RangePolicy<typename MemorySpace::execution_space>(0, mesh.n_nodes),
      KOKKOS_LAMBDA(const int i) {
        for (int s = hinge_offsets(i); s < hinge_offsets(i + 1); ++s)
          edge_slot(roles(s) / 4, roles(s) % 4) = s + tri_offsets(i);
        for (int s = tri_offsets(i); s < tri_offsets(i + 1); ++s)
          tri_slot(corners(s) / 3, corners(s) % 3) = s + hinge_offsets(i + 1);
      });
}

// Scratch of the passes (allocated once per mesh). The passes write each node's share of a triangle or edge
// into a slot of the node's own contiguous range (fill_membrane_slots()), so that the gather reads one
// contiguous range per node and no pass needs atomics.
template <class MemorySpace>
struct MembraneScratch {
  Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace> slot_force;  // per (node, entry) (N)
  Kokkos::View<int* [4], Kokkos::LayoutRight, MemorySpace> edge_slot;      // slot of (edge, hinge node)
  Kokkos::View<int* [3], Kokkos::LayoutRight, MemorySpace> tri_slot;       // slot of (triangle, corner)
  MembraneScratch() = default;
  explicit MembraneScratch(const MeshBuffers<MemorySpace>& mesh)
      : slot_force("dcm::membrane::slot_force", 4 * mesh.n_hinges + 3 * mesh.n_tris),
        edge_slot("dcm::membrane::edge_slot", mesh.n_hinges),
        tri_slot("dcm::membrane::tri_slot", mesh.n_tris) {
    fill_membrane_slots(mesh, edge_slot, tri_slot);
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

// force += bonds + bending + area + volume forces. Needs update_geometry() on the current mesh.x (tri_area,
// tri_normal, cell_area, cell_volume). Requires bonds_match_hinges(mesh). A zero constant costs its
// arithmetic but no extra pass. overstretched: set to -1 by the caller; receives a bond that could not be
// evaluated (as add_fene_pow_forces()).
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
  // 1. Triangle pass.
  {
    const int n = mesh.n_tris;
    const auto tri = mesh.tri;
    const auto tri_cell = mesh.tri_cell;
    const auto area = geo.tri_area;
    const auto normal = geo.tri_normal;
    const auto cell_area = geo.cell_area;
    const auto cell_volume = geo.cell_volume;
    const auto rest_area = area_rest.tri_area;
    const auto rest_cell_area = area_rest.cell_area;
    const auto rest_volume = volume_rest.cell_volume;
    const auto slot = scratch.tri_slot;
    const auto out = scratch.slot_force;
    Kokkos::parallel_for(
        "dcm::membrane::triangles", Kokkos::RangePolicy<ExecutionSpace>(space, 0, (n + W - 1) / W),
        KOKKOS_LAMBDA(const int batch) {
          double p[3][3][W], nrm[3][W], a[W], a0[W], ka[W], global[W], vol[W];
          for (int l = 0; l < W; ++l) {
            const int t = batch * W + l < n ? batch * W + l : n - 1;
            const int c = tri_cell(t);
            for (int v = 0; v < 3; ++v)
              for (int d = 0; d < 3; ++d) p[v][d][l] = x(tri(t, v), d);
            for (int d = 0; d < 3; ++d) nrm[d][l] = normal(t, d);
            a[l] = area(t);
            a0[l] = rest_area(t);
            ka[l] = cell_value(k_a, c);
            global[l] =
                cell_value(k_d, c) * (cell_area(c) - rest_cell_area(c)) / rest_cell_area(c);  // eq. 28
            vol[l] =
                -cell_value(k_v, c) * (cell_volume(c) - rest_volume(c)) / rest_volume(c) / 3.0;  // eq. 29
          }
          double f[3][3][W];
          for (int l = 0; l < W; ++l) {
            const double half = -0.5 * (ka[l] * (a[l] - a0[l]) / a0[l] + global[l]);  // eq. 27 + eq. 28
            const double nx = nrm[0][l], ny = nrm[1][l], nz = nrm[2][l];
            const double va = vol[l] * a[l];
            for (int v = 0; v < 3; ++v) {
              const int b = v == 2 ? 0 : v + 1, c = v == 0 ? 2 : v - 1;
              const double ex = p[c][0][l] - p[b][0][l], ey = p[c][1][l] - p[b][1][l],
                           ez = p[c][2][l] - p[b][2][l];  // x_c - x_b, opposite the corner
              f[v][0][l] = half * (ny * ez - nz * ey) + va * nx;
              f[v][1][l] = half * (nz * ex - nx * ez) + va * ny;
              f[v][2][l] = half * (nx * ey - ny * ex) + va * nz;
            }
          }
          for (int l = 0; l < W; ++l)
            if (batch * W + l < n)
              for (int v = 0; v < 3; ++v)
                for (int d = 0; d < 3; ++d) out(slot(batch * W + l, v), d) = f[v][d][l];
        });
  }
  // 2. Edge pass.
  {
    const int n = mesh.n_hinges;
    const auto hinge = mesh.hinge;
    const auto edge_cell = mesh.hinge_cell;
    const auto rest_length = bond_rest.rest_length;
    const auto rest_trig = hinge_rest.rest_trig;
    const auto grad = hinge_rest.hinge_grad;
    const auto moment = hinge_rest.hinge_moment;
    const auto cos_delta = hinge_rest.hinge_cos_delta;
    const auto slot = scratch.edge_slot;
    const auto out = scratch.slot_force;
    Kokkos::parallel_for(
        "dcm::membrane::edges", Kokkos::RangePolicy<ExecutionSpace>(space, 0, (n + W - 1) / W),
        KOKKOS_LAMBDA(const int batch) {
          double p[4][3][W], d_rest[W], cr[W], sr[W], kb[W], ks[W], xm2[W];
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
          }
          double g[4][3][W], m[W], cd[W], fb[3][W];
          int bond_bad[W];
          for (int l = 0; l < W; ++l) {
            const double ex = p[1][0][l] - p[0][0][l], ey = p[1][1][l] - p[0][1][l],
                         ez = p[1][2][l] - p[0][2][l];  // e = x_j - x_i
            const double ax = p[2][0][l] - p[0][0][l], ay = p[2][1][l] - p[0][1][l],
                         az = p[2][2][l] - p[0][2][l];  // x_k - x_i
            const double bx = p[3][0][l] - p[1][0][l], by = p[3][1][l] - p[1][1][l],
                         bz = p[3][2][l] - p[1][2][l];  // x_l - x_j
            const double n1x = ey * az - ez * ay, n1y = ez * ax - ex * az, n1z = ex * ay - ey * ax;  // e x a
            const double n2x = by * ez - bz * ey, n2y = bz * ex - bx * ez, n2z = bx * ey - by * ex;  // b x e
            const double e2 = ex * ex + ey * ey + ez * ez;
            const double n1_2 = n1x * n1x + n1y * n1y + n1z * n1z, n2_2 = n2x * n2x + n2y * n2y + n2z * n2z;
            const double dr = d_rest[l], d_max2 = xm2[l] * dr * dr;
            // Bond (eqs. 21-24): usable for 0 < d < d_max; hinge: for non-degenerate triangles.
            const bool bond_ok =
                (e2 > 0) & (e2 < d_max2);  // false for NaN too (& keeps the lanes branch-free)
            const bool hinge_ok = (e2 > 0) & (n1_2 > 0) & (n2_2 > 0);
            const double e2s = e2 > 0 ? e2 : 1.0, gap = bond_ok ? d_max2 - e2 : 1.0;
            const double n1s = hinge_ok ? n1_2 : 1.0, n2s = hinge_ok ? n2_2 : 1.0;
            const double len = math::sqrt(e2s), root = math::sqrt(n1s * n2s);  // |e|, |n1| |n2|
            // One division for the four reciprocals 1/|e|, 1/gap, 1/|n1|^2, 1/|n2|^2.
            const double q = 1.0 / (len * gap * n1s * n2s);
            const double inv_len = q * gap * n1s * n2s, inv_gap = q * len * n1s * n2s;
            const double inv_n1 = q * len * gap * n2s, inv_n2 = q * len * gap * n1s;
            // U'(d)/d = k_s d_max^2 / (d_max^2 - d^2) - k_c / d^3, k_c = k_s d*^3 / (1 - 1/x_max^2) (eq. 24)
            const double k_c = ks[l] * dr * dr * dr / (1 - 1 / xm2[l]);
            const double u = bond_ok ? ks[l] * d_max2 * inv_gap - k_c * inv_len * inv_len * inv_len : 0.0;
            fb[0][l] = u * ex;  // the bond's force on i: U'(d)/d (x_j - x_i); on j the opposite
            fb[1][l] = u * ey;
            fb[2][l] = u * ez;
            bond_bad[l] = bond_ok ? 0 : 1;
            // Hinge (eq. 26), kernels/bending.hpp's hinge_trig_gradient() with these reciprocals.
            const double inv = root * inv_n1 * inv_n2 * inv_len;  // 1 / (|e| |n1| |n2|)
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
              out(s2, d) = m[l] * g[2][d][l];
              out(s3, d) = m[l] * g[3][d][l];
            }
          }
        });
  }
  // 3. Node gather: the node's slots, contiguous.
  {
    const auto hinge_offsets = mesh.node_hinge_offsets;
    const auto tri_offsets = mesh.node_tri_offsets;
    const auto in = scratch.slot_force;
    Kokkos::parallel_for(
        "dcm::membrane::gather", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
        KOKKOS_LAMBDA(const int i) {
          double f0 = 0, f1 = 0, f2 = 0;
          for (int s = hinge_offsets(i) + tri_offsets(i); s < hinge_offsets(i + 1) + tri_offsets(i + 1);
               ++s) {
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
