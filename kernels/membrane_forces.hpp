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
// computed in straight-line loops over the lanes, which the host compiler turns into SIMD instructions;
// on a GPU a work item is one edge (MembraneLanes = 1). The constants of each cell (k_b, k_s, x_max,
// k_a and the global area and volume factors) are gathered into one row per cell before the pass; a
// batch whose edges share a cell reads one row. Where the edge count is not a multiple of the lanes, the
// last batch overlaps the one before it and stores only its own edges.
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
  // Per cell and call, the constants of the edge pass: k_b, k_s, x_max^2, k_s / (1 - 1/x_max^2), k_a,
  // k_d (A_c - A_c*)/A_c* (N/m) and -k_v (V_c - V_c*)/(3 V_c*) (Pa), eqs. 24, 26-29; one row per cell.
  static constexpr int kCellConstants = 8;
  Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace> slot_force;  // per (node, hinge entry) (N)
  Kokkos::View<int* [4], Kokkos::LayoutRight, MemorySpace> edge_slot;      // slot of (edge, hinge node)
  Kokkos::View<int* [2], Kokkos::LayoutRight, MemorySpace> edge_tri;       // triangles of the wings k, l
  Kokkos::View<double* [kCellConstants], Kokkos::LayoutRight, MemorySpace> cell_constants;
  MembraneScratch() = default;
  explicit MembraneScratch(const MeshBuffers<MemorySpace>& mesh)
      : slot_force("dcm::membrane::slot_force", 4 * mesh.n_hinges),
        edge_slot("dcm::membrane::edge_slot", mesh.n_hinges),
        edge_tri("dcm::membrane::edge_tri", mesh.n_hinges),
        cell_constants("dcm::membrane::cell_constants", mesh.n_cells) {
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

namespace membrane_detail {

// The edge pass on W consecutive edges per work item (docs/model/membrane_pass.md). Raw pointers with
// compile-time strides: the lanes' loads and stores are most of the pass, and a View's runtime strides
// cost an integer multiply per access.
template <int W>
struct EdgePass {
  int n;                         // edges (n >= W)
  const double* x;               // positions [node][3]
  const int* hinge;              // [edge][4] (i, j, k, l)
  const int* slot;               // [edge][4] the slots of (i, j, k, l)
  const int* tri2;               // [edge][2] the wings' triangles
  const int* edge_cell;          // [edge]
  const double* rest_length;     // [edge] d*
  const double* rest_trig;       // [edge][2] (cos theta*, sin theta*)
  const double* rest_area;       // [triangle] A_t*
  const double* cell_constants;  // [cell][K]
  double* out;                   // [slot][3]
  double* grad;                  // [edge][4][3] dtheta/dx per role
  double* moment;                // [edge]
  double* cos_delta;             // [edge]
  int* overstretched;
  static constexpr int K = 8;

  KOKKOS_INLINE_FUNCTION void operator()(const int batch) const {
    const int start = batch * W;
    // The last batch overlaps the one before it (same lanes, same bits) and stores only its new edges.
    const int base = start + W <= n ? start : n - W, first = start - base;
    double p[4][3][W];
    for (int l = 0; l < W; ++l)
      for (int v = 0; v < 4; ++v) {
        const double* xv = x + 3 * hinge[4 * (base + l) + v];
        for (int d = 0; d < 3; ++d) p[v][d][l] = xv[d];
      }
    double dr[W], cr[W], sr[W], a0[2][W];
    for (int l = 0; l < W; ++l) {
      dr[l] = rest_length[base + l];
      cr[l] = rest_trig[2 * (base + l)];
      sr[l] = rest_trig[2 * (base + l) + 1];
    }
    for (int l = 0; l < W; ++l)
      for (int side = 0; side < 2; ++side) a0[side][l] = rest_area[tri2[2 * (base + l) + side]];
    // The cells' constants (MembraneScratch::cell_constants): one row for the batch where its edges share a
    // cell (each cell's edges are one contiguous range, checked when the scratch is made, so the first and
    // the last lane's cells decide).
    double kb[W], ks[W], xm2[W], kcf[W], ka[W], global[W], vol[W];
    const int c_first = edge_cell[base], c_last = edge_cell[base + W - 1];
    for (int l = 0; l < W; ++l) {
      const double* k = cell_constants + K * (c_first == c_last ? c_first : edge_cell[base + l]);
      kb[l] = k[0];
      ks[l] = k[1];
      xm2[l] = k[2];
      kcf[l] = k[3];
      ka[l] = k[4];
      global[l] = k[5];
      vol[l] = k[6];
    }
    double g[4][3][W], m[W], cd[W], o[4][3][W];
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
      const double d_rest = dr[l], d_max2 = xm2[l] * d_rest * d_rest;
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
      const double k_c = kcf[l] * d_rest * d_rest * d_rest;
      const double u = bond_ok ? ks[l] * d_max2 * inv_gap - k_c * inv_len * inv_len * inv_len : 0.0;
      bond_bad[l] = bond_ok ? 0 : 1;
      // Hinge (eq. 26), kernels/bending.hpp's hinge_trig_gradient() with these reciprocals.
      const double inv = inv_r1 * inv_r2 * inv_len;  // 1 / (|e| |n1| |n2|)
      const double c = hinge_ok ? len * (n1x * n2x + n1y * n2y + n1z * n2z) * inv : 1.0;
      const double s =
          hinge_ok
              ? ((n1y * n2z - n1z * n2y) * ex + (n1z * n2x - n1x * n2z) * ey + (n1x * n2y - n1y * n2x) * ez) *
                    inv
              : 0.0;
      const double gk = hinge_ok ? -len * inv_n1 : 0.0, gl = hinge_ok ? -len * inv_n2 : 0.0;
      const double inv_e2 = inv_len * inv_len;
      const double ak = (ax * ex + ay * ey + az * ez) * inv_e2;
      const double al = (bx * ex + by * ey + bz * ez) * inv_e2 + 1.0;  // (x_l - x_i) . e / |e|^2
      const double n1v[3] = {n1x, n1y, n1z}, n2v[3] = {n2x, n2y, n2z}, ev[3] = {ex, ey, ez};
      const double mm = -kb[l] * (s * cr[l] - c * sr[l]);  // -M = -k_b sin(theta - theta*), eq. 26
      m[l] = mm;
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
      const double w1[3] = {n1y * ez - n1z * ey, n1z * ex - n1x * ez, n1x * ey - n1y * ex};  // n1 x e
      const double w2[3] = {n2y * ez - n2z * ey, n2z * ex - n2x * ez, n2x * ey - n2y * ex};  // n2 x e
      for (int d = 0; d < 3; ++d) {
        const double g2 = gk * n1v[d], g3 = gl * n2v[d];
        const double g0 = (ak - 1) * g2 + (al - 1) * g3, g1 = -ak * g2 - al * g3;
        g[0][d][l] = g0;
        g[1][d][l] = g1;
        g[2][d][l] = g2;
        g[3][d][l] = g3;
        o[0][d][l] = mm * g0 + u * ev[d];  // the bond's force on i: U'(d)/d (x_j - x_i); on j the opposite
        o[1][d][l] = mm * g1 - u * ev[d];
        o[2][d][l] = mm * g2 + (h1 * w1[d] + v2 * n1v[d]);
        o[3][d][l] = mm * g3 + (h2 * w2[d] + v2 * n2v[d]);
      }
    }
    int any_bad = 0;
    for (int l = 0; l < W; ++l) any_bad |= bond_bad[l];
    if (any_bad)
      for (int l = first; l < W; ++l)
        if (bond_bad[l]) Kokkos::atomic_compare_exchange(overstretched, -1, base + l);
    // Whole batches: fixed-length runs (moment and cos_delta as vectors, grad at stride 12).
    if (first == 0) {
      for (int l = 0; l < W; ++l) {
        moment[base + l] = m[l];
        cos_delta[base + l] = cd[l];
      }
      for (int v = 0; v < 4; ++v)
        for (int d = 0; d < 3; ++d)
          for (int l = 0; l < W; ++l) grad[12 * (base + l) + 3 * v + d] = g[v][d][l];
    } else if (W > 1) {
      for (int l = first; l < W; ++l) {
        moment[base + l] = m[l];
        cos_delta[base + l] = cd[l];
        for (int v = 0; v < 4; ++v)
          for (int d = 0; d < 3; ++d) grad[12 * (base + l) + 3 * v + d] = g[v][d][l];
      }
    }
    for (int l = first; l < W; ++l)
      for (int v = 0; v < 4; ++v) {
        double* o_v = out + 3 * slot[4 * (base + l) + v];
        o_v[0] = o[v][0][l];
        o_v[1] = o[v][1][l];
        o_v[2] = o[v][2][l];
      }
  }
};

}  // namespace membrane_detail

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
  constexpr int K = MembraneScratch<MemorySpace>::kCellConstants;
  static_assert(K == membrane_detail::EdgePass<1>::K, "one row layout");
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
      scratch.slot_force.stride_0() != 3)
    throw std::logic_error("add_membrane_forces: a View is padded");
  auto run = [&](auto pass) {
    constexpr int W = decltype(pass)::value;
    membrane_detail::EdgePass<W> f;
    f.n = n;
    f.x = mesh.x.data();
    f.hinge = mesh.hinge.data();
    f.slot = scratch.edge_slot.data();
    f.tri2 = scratch.edge_tri.data();
    f.edge_cell = mesh.hinge_cell.data();
    f.rest_length = bond_rest.rest_length.data();
    f.rest_trig = hinge_rest.rest_trig.data();
    f.rest_area = area_rest.tri_area.data();
    f.cell_constants = scratch.cell_constants.data();
    f.out = scratch.slot_force.data();
    f.grad = grad.data();
    f.moment = hinge_rest.hinge_moment.data();
    f.cos_delta = hinge_rest.hinge_cos_delta.data();
    f.overstretched = overstretched.data();
    Kokkos::parallel_for("dcm::membrane::edges",
                         Kokkos::RangePolicy<ExecutionSpace>(space, 0, (n + W - 1) / W), f);
  };
  constexpr int W = MembraneLanes<ExecutionSpace>::value;
  if (n >= W)
    run(std::integral_constant<int, W>{});
  else
    run(std::integral_constant<int, 1>{});
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
