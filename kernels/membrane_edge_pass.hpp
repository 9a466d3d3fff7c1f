#pragma once
// The edge pass of the fused membrane forces (kernels/membrane_forces.hpp, docs/model/membrane_pass.md) in
// its portable form: per edge, the bond force, the hinge's four bending forces and the wings' area and
// volume forces, into the hinge nodes' slots, and the hinge's gradient, -M and cos(theta - theta*) into
// HingeRest. Physics: kernels/fene_pow_bonds.hpp (eqs. 21-24), bending.hpp (eq. 26),
// area_constraints.hpp (eqs. 27-28), volume_constraint.hpp (eq. 29).
#include <Kokkos_Core.hpp>

#include "core/kokkos_compat.hpp"

namespace dcm {
namespace membrane_detail {

// What every form of the edge pass reads and writes: raw pointers with compile-time strides (the lanes' loads
// and stores are most of the pass, and a View's runtime strides cost an integer multiply per access).
struct EdgePassArgs {
  static constexpr int K = 8;    // constants per cell (MembraneScratch::kCellConstants)
  int n;                         // edges (n >= the lanes)
  const double* x;               // positions [node][3]
  const int* hinge;              // [edge][4] (i, j, k, l)
  const int* slot;               // [edge][4] the slots of (i, j, k, l)
  const int* tri2;               // [edge][2] the wings' triangles
  const int* edge_cell;          // [edge]
  const double* rest_length;     // [edge] d*
  const double* rest_trig;       // [edge][2] (cos theta*, sin theta*)
  const double* rest_area;       // [triangle] A_t*
  const double* cell_constants;  // [cell][K]
  double* out;                   // [slot][4] (x, y, z, unused)
  double* grad;                  // [edge][4][3] dtheta/dx per role
  double* moment;                // [edge]
  double* cos_delta;             // [edge]
  int* overstretched;
};

// The edge pass on W consecutive edges per work item, in straight-line loops over the lanes that the host
// compiler vectorises (W = 8), or one edge per work item (W = 1: devices). Host builds with GCC or Clang
// use EdgePassSimd8 (kernels/membrane_edge_simd.hpp) instead of W = 8; the same physics.
template <int Lanes>
struct EdgePass : EdgePassArgs {
  static constexpr int W = Lanes;

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
        double* o_v = out + 4 * slot[4 * (base + l) + v];
        o_v[0] = o[v][0][l];
        o_v[1] = o[v][1][l];
        o_v[2] = o[v][2][l];
      }
  }
};

}  // namespace membrane_detail
}  // namespace dcm
