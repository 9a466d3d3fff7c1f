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

// The physics of one edge, shared by every form of the pass: V is double (one edge) or an 8-wide vector of
// doubles (eight edges, kernels/membrane_edge_simd.hpp), M the matching truth value (bool, or a vector mask).
template <class V>
struct EdgeRestValues {
  V d_rest, cos_rest, sin_rest;  // d*, cos theta*, sin theta*
  V area1, area2;                // A_t* of the wings' triangles (i, j, k) and (j, i, l)
};
template <class V>
struct CellRowValues {  // MembraneScratch::cell_constants
  V kb, ks, xm2, kcf, ka, global, vol;
};
// The edge's lengths and their reciprocals from the squares (all positive): |e|, |n1|, |n2| and 1/|e|, 1/gap,
// 1/|n1|, 1/|n2|; three square roots and one division for the four reciprocals. The vector pass brings its
// own (kernels/membrane_edge_simd.hpp). By reference: a vector argument by value would change the calling
// convention with the ISA (-Wpsabi).
struct ScalarRoots {
  template <class V>
  KOKKOS_FORCEINLINE_FUNCTION void operator()(const V& e2, const V& n1_2, const V& n2_2, const V& gap, V& len,
                                              V& r1, V& r2, V& inv_len, V& inv_gap, V& inv_r1,
                                              V& inv_r2) const {
    len = math::sqrt(e2);
    r1 = math::sqrt(n1_2);
    r2 = math::sqrt(n2_2);
    const V q = 1.0 / (len * gap * r1 * r2);
    inv_len = q * gap * r1 * r2;
    inv_gap = q * len * r1 * r2;
    inv_r1 = q * len * gap * r2;
    inv_r2 = q * len * gap * r1;
  }
};

// p: the positions of i, j, k, l. Writes g (dtheta/dx of i, j, k, l), o (the force on each of them), -M =
// -k_b sin(theta - theta*), cos(theta - theta*) and bond_ok (0 < d < d_max; false: the bond adds nothing and
// is reported). Separate outputs, not one struct: GCC keeps arrays of this size in vector registers, and did
// not the 1.7 KB struct of all of them.
template <class V, class M, class Roots>
KOKKOS_FORCEINLINE_FUNCTION void edge_forces(const V (&p)[4][3], const EdgeRestValues<V>& rest,
                                             const CellRowValues<V>& k, const Roots& roots, V (&g)[4][3],
                                             V (&o)[4][3], V& moment, V& cos_delta, M& bond_ok) {
  const V zero = V{}, one = V{} + 1.0;
  const V cos_rest = rest.cos_rest, sin_rest = rest.sin_rest, area1 = rest.area1, area2 = rest.area2;
  const V kb = k.kb, ks = k.ks, kcf = k.kcf, ka = k.ka, global = k.global, vol = k.vol;
  const V ex = p[1][0] - p[0][0], ey = p[1][1] - p[0][1], ez = p[1][2] - p[0][2];  // e = x_j - x_i
  const V ax = p[2][0] - p[0][0], ay = p[2][1] - p[0][1], az = p[2][2] - p[0][2];  // x_k - x_i
  const V bx = p[3][0] - p[1][0], by = p[3][1] - p[1][1], bz = p[3][2] - p[1][2];  // x_l - x_j
  // n1 = e x a = 2 A_1 n_1 of triangle (i, j, k); n2 = b x e = 2 A_2 n_2 of triangle (j, i, l)
  const V n1x = ey * az - ez * ay, n1y = ez * ax - ex * az, n1z = ex * ay - ey * ax;
  const V n2x = by * ez - bz * ey, n2y = bz * ex - bx * ez, n2z = bx * ey - by * ex;
  const V e2 = ex * ex + ey * ey + ez * ez;
  const V n1_2 = n1x * n1x + n1y * n1y + n1z * n1z, n2_2 = n2x * n2x + n2y * n2y + n2z * n2z;
  const V d_rest = rest.d_rest, d_max2 = k.xm2 * d_rest * d_rest;
  // Bond (eqs. 21-24): usable for 0 < d < d_max; hinge: for non-degenerate triangles. False for NaN too;
  // & (not &&) keeps the lanes branch-free.
  bond_ok = (e2 > zero) & (e2 < d_max2);
  const auto hinge_ok = (e2 > zero) & (n1_2 > zero) & (n2_2 > zero);
  const V e2s = e2 > zero ? e2 : one, gap = bond_ok ? d_max2 - e2 : one;
  const V n1s = n1_2 > zero ? n1_2 : one, n2s = n2_2 > zero ? n2_2 : one;
  // |e|, |n1|, |n2| and the reciprocals of |e|, gap, |n1|, |n2|
  V len, r1, r2, inv_len, inv_gap, inv_r1, inv_r2;
  roots(e2s, n1s, n2s, gap, len, r1, r2, inv_len, inv_gap, inv_r1, inv_r2);
  const V inv_n1 = inv_r1 * inv_r1, inv_n2 = inv_r2 * inv_r2;  // 1/|n1|^2, 1/|n2|^2
  // U'(d)/d = k_s d_max^2 / (d_max^2 - d^2) - k_c / d^3, k_c = k_s d*^3 / (1 - 1/x_max^2) (eq. 24)
  const V k_c = kcf * d_rest * d_rest * d_rest;
  const V u = bond_ok ? ks * d_max2 * inv_gap - k_c * inv_len * inv_len * inv_len : zero;
  // Hinge (eq. 26), kernels/bending.hpp's hinge_trig_gradient() with these reciprocals.
  const V inv = inv_r1 * inv_r2 * inv_len;  // 1 / (|e| |n1| |n2|)
  const V c = hinge_ok ? len * (n1x * n2x + n1y * n2y + n1z * n2z) * inv : one;
  const V s =
      hinge_ok
          ? ((n1y * n2z - n1z * n2y) * ex + (n1z * n2x - n1x * n2z) * ey + (n1x * n2y - n1y * n2x) * ez) * inv
          : zero;
  const V gk = hinge_ok ? -len * inv_n1 : zero, gl = hinge_ok ? -len * inv_n2 : zero;
  const V inv_e2 = inv_len * inv_len;
  const V ak = (ax * ex + ay * ey + az * ez) * inv_e2;
  const V al = (bx * ex + by * ey + bz * ez) * inv_e2 + 1.0;  // (x_l - x_i) . e / |e|^2
  const V mm = -kb * (s * cos_rest - c * sin_rest);           // -M = -k_b sin(theta - theta*), eq. 26
  moment = mm;
  cos_delta = c * cos_rest + s * sin_rest;
  // The wings' area and volume forces (each triangle's corner opposite this edge; the triangle's other
  // corners get theirs from its other two edges), kernels/area_constraints.hpp and volume_constraint.hpp
  // with A = |n|/2 and unit normal n/|n|:
  //   F = -(1/2) [k_a (A - A*)/A* + k_d (A_c - A_c*)/A_c*] n/|n| x (x_c - x_b)   (eqs. 27, 28)
  //       - k_v (V_c - V_c*)/V_c* (A/3) n/|n|                                      (eq. 29)
  // with x_c - x_b = e for the wing k of (i, j, k) and -e for the wing l of (j, i, l). A degenerate
  // triangle (n = 0) gets no force, as in the per-term kernels.
  const V h1 = -0.5 * (ka * (0.5 * r1 - area1) / area1 + global) * inv_r1;
  const V h2 = 0.5 * (ka * (0.5 * r2 - area2) / area2 + global) * inv_r2;
  const V v2 = 0.5 * vol;
  const V n1v[3] = {n1x, n1y, n1z}, n2v[3] = {n2x, n2y, n2z}, ev[3] = {ex, ey, ez};
  const V w1[3] = {n1y * ez - n1z * ey, n1z * ex - n1x * ez, n1x * ey - n1y * ex};  // n1 x e
  const V w2[3] = {n2y * ez - n2z * ey, n2z * ex - n2x * ez, n2x * ey - n2y * ex};  // n2 x e
  for (int d = 0; d < 3; ++d) {
    const V g2 = gk * n1v[d], g3 = gl * n2v[d];
    const V g0 = (ak - 1.0) * g2 + (al - 1.0) * g3, g1 = -ak * g2 - al * g3;
    g[0][d] = g0;
    g[1][d] = g1;
    g[2][d] = g2;
    g[3][d] = g3;
    o[0][d] = mm * g0 + u * ev[d];  // the bond's force on i: U'(d)/d (x_j - x_i); on j the opposite
    o[1][d] = mm * g1 - u * ev[d];
    o[2][d] = mm * g2 + (h1 * w1[d] + v2 * n1v[d]);
    o[3][d] = mm * g3 + (h2 * w2[d] + v2 * n2v[d]);
  }
}

// The edge pass on W consecutive edges per work item, edge_forces() in a loop over the lanes that the host
// compiler vectorises (W = 8), or one edge per work item (W = 1: devices). Host builds with GCC or Clang
// run EdgePassSimd8 (kernels/membrane_edge_simd.hpp) instead of W = 8: the same edge_forces() on vectors.
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
      double pl[4][3];
      for (int v = 0; v < 4; ++v)
        for (int d = 0; d < 3; ++d) pl[v][d] = p[v][d][l];
      const EdgeRestValues<double> rest{dr[l], cr[l], sr[l], a0[0][l], a0[1][l]};
      const CellRowValues<double> row{kb[l], ks[l], xm2[l], kcf[l], ka[l], global[l], vol[l]};
      double gl[4][3], ol[4][3];
      bool ok;
      edge_forces(pl, rest, row, ScalarRoots{}, gl, ol, m[l], cd[l], ok);
      bond_bad[l] = ok ? 0 : 1;
      for (int v = 0; v < 4; ++v)
        for (int d = 0; d < 3; ++d) {
          g[v][d][l] = gl[v][d];
          o[v][d][l] = ol[v][d];
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
