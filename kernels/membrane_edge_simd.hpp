#pragma once
// The membrane edge pass (kernels/membrane_edge_pass.hpp, docs/model/membrane_pass.md "Session 21") on
// explicit 8-wide vectors (GCC / Clang vector extensions) for host execution spaces. The physics is
// EdgePass's own, edge_forces() instantiated for vectors of eight edges; what differs is how the lanes are
// built and emptied, all in registers:
//  - positions: one 4-vector load per hinge node from a padded copy of x ([node][4], made per call), then an
//    8 x 4 transpose per role (the auto-vectorised lanes went through stack arrays: scalar loads and stores,
//    then vector loads, and the indices back and forth between vector and scalar registers);
//  - the hinge gradients ([edge][12]) and the slots ([slot][4]: x, y, z, unused) stored as one 4-vector per
//    (edge, role) after a 4 x 8 transpose, instead of 24 scalar stores per edge;
//  - the node gather adds one 4-vector per slot.
// Selected by add_membrane_forces() where MembraneLanes is 8; MembraneEdgeKernel::lanes runs EdgePass<8>.
//
// Host compilers only: not under nvcc / hipcc / SYCL (there the host spaces run EdgePass<8>), nor with
// -DDCM_NO_MEMBRANE_SIMD (the ctests portable.MembraneForces.* build the membrane tests so).
#if defined(__GNUC__) && !defined(__CUDACC__) && !defined(__HIPCC__) && !defined(SYCL_LANGUAGE_VERSION) && \
    !defined(DCM_NO_MEMBRANE_SIMD)
#define DCM_MEMBRANE_EDGE_SIMD 1
#if defined(__AVX__)
#include <immintrin.h>
#endif

#include <Kokkos_Core.hpp>

#include "kernels/membrane_edge_pass.hpp"

namespace dcm {
namespace membrane_detail {

using vd8 = double __attribute__((vector_size(64)));
using vm8 = long long __attribute__((vector_size(64)));
using vd4 = double __attribute__((vector_size(32)));

// The lengths and reciprocals of edge_forces() (ScalarRoots) for eight edges. With AVX-512 from the
// hardware's 14-bit estimates of 1/sqrt(x) and 1/x and two Newton steps each (a few ulp;
// docs/model/membrane_pass.md, "Session 34"): the three square roots and the division of ScalarRoots wait on
// the divider, the estimates and Newton steps run on the multiply-add pipes. Otherwise square roots and one
// division.
struct VectorRoots {
  KOKKOS_FORCEINLINE_FUNCTION void operator()(const vd8& e2, const vd8& n1_2, const vd8& n2_2, const vd8& gap,
                                              vd8& len, vd8& r1, vd8& r2, vd8& inv_len, vd8& inv_gap,
                                              vd8& inv_r1, vd8& inv_r2) const {
#if defined(__AVX512F__)
    inv_len = rsqrt(e2);
    inv_r1 = rsqrt(n1_2);
    inv_r2 = rsqrt(n2_2);
    len = e2 * inv_len;
    r1 = n1_2 * inv_r1;
    r2 = n2_2 * inv_r2;
    inverse(gap, inv_gap);
#else
    sqrt8(e2, len);
    sqrt8(n1_2, r1);
    sqrt8(n2_2, r2);
    const vd8 q = 1.0 / (len * gap * r1 * r2);
    inv_len = q * gap * r1 * r2;
    inv_gap = q * len * r1 * r2;
    inv_r1 = q * len * gap * r2;
    inv_r2 = q * len * gap * r1;
#endif
  }
  KOKKOS_FORCEINLINE_FUNCTION static void inverse(const vd8& a, vd8& r) {  // 1/a, a > 0
#if defined(__AVX512F__)
    // the 14-bit estimate, then z (2 − a z) twice (14 → 28 → 53 bits)
    vd8 z = reinterpret_cast<vd8>(_mm512_maskz_rcp14_pd(0xFF, reinterpret_cast<__m512d>(a)));
    z = z * (2.0 - a * z);
    r = z * (2.0 - a * z);
#else
    r = 1.0 / a;
#endif
  }
#if defined(__AVX512F__)
  // 1/sqrt(x), x > 0: the 14-bit estimate, then y (3 − x y²)/2 twice (14 → 28 → 53 bits).
  KOKKOS_FORCEINLINE_FUNCTION static vd8 rsqrt(const vd8& x) {
    vd8 y = reinterpret_cast<vd8>(_mm512_maskz_rsqrt14_pd(0xFF, reinterpret_cast<__m512d>(x)));
    const vd8 h = 0.5 * x;
    y = y * (1.5 - h * y * y);
    return y * (1.5 - h * y * y);
  }
#else
  KOKKOS_FORCEINLINE_FUNCTION static void sqrt8(const vd8& a, vd8& r) {
#if defined(__AVX__)
    const __m256d lo = _mm256_sqrt_pd(_mm256_setr_pd(a[0], a[1], a[2], a[3]));
    const __m256d hi = _mm256_sqrt_pd(_mm256_setr_pd(a[4], a[5], a[6], a[7]));
    r = vd8{lo[0], lo[1], lo[2], lo[3], hi[0], hi[1], hi[2], hi[3]};
#else
    for (int l = 0; l < 8; ++l) r[l] = __builtin_sqrt(a[l]);
#endif
  }
#endif
};

// {p[idx[0]], p[idx[s]], ..., p[idx[7 s]]} and {p[0], p[s], ..., p[7 s]}.
KOKKOS_FORCEINLINE_FUNCTION void load8_indexed(const double* p, const int* idx, const int s, vd8& r) {
  r = vd8{p[idx[0]],     p[idx[s]],     p[idx[2 * s]], p[idx[3 * s]],
          p[idx[4 * s]], p[idx[5 * s]], p[idx[6 * s]], p[idx[7 * s]]};
}
KOKKOS_FORCEINLINE_FUNCTION void load8_strided(const double* p, const int s, vd8& r) {
  r = vd8{p[0], p[s], p[2 * s], p[3 * s], p[4 * s], p[5 * s], p[6 * s], p[7 * s]};
}

// r[l] = (a[l], b[l], c[l], d[l]) for the eight lanes l.
KOKKOS_FORCEINLINE_FUNCTION void transpose4x8(const vd8& a, const vd8& b, const vd8& c, const vd8& d,
                                              vd4* r) {
  const vd8 ab_lo = __builtin_shufflevector(a, b, 0, 8, 1, 9, 2, 10, 3, 11);  // a0 b0 a1 b1 a2 b2 a3 b3
  const vd8 ab_hi = __builtin_shufflevector(a, b, 4, 12, 5, 13, 6, 14, 7, 15);
  const vd8 cd_lo = __builtin_shufflevector(c, d, 0, 8, 1, 9, 2, 10, 3, 11);
  const vd8 cd_hi = __builtin_shufflevector(c, d, 4, 12, 5, 13, 6, 14, 7, 15);
  r[0] = __builtin_shufflevector(ab_lo, cd_lo, 0, 1, 8, 9);
  r[1] = __builtin_shufflevector(ab_lo, cd_lo, 2, 3, 10, 11);
  r[2] = __builtin_shufflevector(ab_lo, cd_lo, 4, 5, 12, 13);
  r[3] = __builtin_shufflevector(ab_lo, cd_lo, 6, 7, 14, 15);
  r[4] = __builtin_shufflevector(ab_hi, cd_hi, 0, 1, 8, 9);
  r[5] = __builtin_shufflevector(ab_hi, cd_hi, 2, 3, 10, 11);
  r[6] = __builtin_shufflevector(ab_hi, cd_hi, 4, 5, 12, 13);
  r[7] = __builtin_shufflevector(ab_hi, cd_hi, 6, 7, 14, 15);
}

struct EdgePassSimd8 : EdgePassArgs {
  static constexpr int W = 8;
  const double* x4;  // positions [node][4] (x, y, z, unused): a padded copy of x, one 4-vector per node

  // The three coordinates of the eight nodes idx[0], idx[4], ..., idx[28] (one role of a batch), from the
  // padded copy of the positions: one 4-vector load per node, then a transpose.
  KOKKOS_FORCEINLINE_FUNCTION void load_role(const int* idx, vd8 (&r)[3]) const {
    vd4 q[W];
    for (int l = 0; l < W; ++l) __builtin_memcpy(&q[l], x4 + 4 * static_cast<long>(idx[4 * l]), sizeof(vd4));
    const vd8 c01 = __builtin_shufflevector(q[0], q[1], 0, 1, 2, 3, 4, 5, 6, 7);  // x0 y0 z0 w0 x1 y1 z1 w1
    const vd8 c23 = __builtin_shufflevector(q[2], q[3], 0, 1, 2, 3, 4, 5, 6, 7);
    const vd8 c45 = __builtin_shufflevector(q[4], q[5], 0, 1, 2, 3, 4, 5, 6, 7);
    const vd8 c67 = __builtin_shufflevector(q[6], q[7], 0, 1, 2, 3, 4, 5, 6, 7);
    const vd8 xy03 = __builtin_shufflevector(c01, c23, 0, 4, 8, 12, 1, 5, 9, 13);  // x0..x3 y0..y3
    const vd8 xy47 = __builtin_shufflevector(c45, c67, 0, 4, 8, 12, 1, 5, 9, 13);
    const vd8 z03 = __builtin_shufflevector(c01, c23, 2, 6, 10, 14, 3, 7, 11, 15);  // z0..z3 w0..w3
    const vd8 z47 = __builtin_shufflevector(c45, c67, 2, 6, 10, 14, 3, 7, 11, 15);
    r[0] = __builtin_shufflevector(xy03, xy47, 0, 1, 2, 3, 8, 9, 10, 11);
    r[1] = __builtin_shufflevector(xy03, xy47, 4, 5, 6, 7, 12, 13, 14, 15);
    r[2] = __builtin_shufflevector(z03, z47, 0, 1, 2, 3, 8, 9, 10, 11);
  }

  KOKKOS_INLINE_FUNCTION void operator()(const int batch) const {
    const int start = batch * W;
    const int base = start + W <= n ? start : n - W, first = start - base;
    const int* h = hinge + 4 * base;
    vd8 p[4][3];  // role, coordinate; one role's eight nodes at a time
    load_role(h + 0, p[0]);
    load_role(h + 1, p[1]);
    load_role(h + 2, p[2]);
    load_role(h + 3, p[3]);
    EdgeRestValues<vd8> rest;
    __builtin_memcpy(&rest.d_rest, rest_length + base, sizeof(vd8));  // unaligned
    load8_strided(rest_trig + 2 * base, 2, rest.cos_rest);
    load8_strided(rest_trig + 2 * base + 1, 2, rest.sin_rest);
    load8_indexed(rest_area, tri2 + 2 * base, 2, rest.area1);
    load8_indexed(rest_area, tri2 + 2 * base + 1, 2, rest.area2);
    CellRowValues<vd8> row;
    auto& [kb, ks, xm2, kcf, ka, global, vol] = row;
    const int c_first = edge_cell[base], c_last = edge_cell[base + W - 1];
    if (c_first == c_last) {
      const double* k = cell_constants + K * c_first;
      kb = vd8{} + k[0];
      ks = vd8{} + k[1];
      xm2 = vd8{} + k[2];
      kcf = vd8{} + k[3];
      ka = vd8{} + k[4];
      global = vd8{} + k[5];
      vol = vd8{} + k[6];
    } else {
      for (int l = 0; l < W; ++l) {
        const double* k = cell_constants + K * edge_cell[base + l];
        kb[l] = k[0];
        ks[l] = k[1];
        xm2[l] = k[2];
        kcf[l] = k[3];
        ka[l] = k[4];
        global[l] = k[5];
        vol[l] = k[6];
      }
    }
    vd8 g[4][3], o[4][3], mm, cd;
    vm8 bond_ok;
    edge_forces(p, rest, row, VectorRoots{}, g, o, mm, cd, bond_ok);
    long long any_bad = 0;  // a bond at or past d_max, or NaN (the lanes' test above)
    for (int l = 0; l < W; ++l) any_bad |= ~bond_ok[l];
    if (any_bad)
      for (int l = first; l < W; ++l)
        if (!bond_ok[l]) Kokkos::atomic_compare_exchange(overstretched, -1, base + l);
    if (first == 0)  // a whole batch: constant lane bounds, unrolled
      store(base, 0, mm, cd, g, o);
    else
      store(base, first, mm, cd, g, o);
  }

  // moment and cos_delta as vectors; the hinge gradients ([edge][12]) and the slots ([slot][4]: x, y, z, 0)
  // through in-register transposes, one 4-vector per (edge, role). Lanes from `first` on.
  KOKKOS_FORCEINLINE_FUNCTION void store(const int base, const int first, const vd8& mm, const vd8& cd,
                                         const vd8 (&g)[4][3], const vd8 (&o)[4][3]) const {
    // Local copies: the stores below are byte copies, which may alias this functor's members.
    double* const grad_p = grad + 12 * base;
    double* const out_p = out;
    const int* const slot_p = slot + 4 * base;
    if (first == 0) {
      __builtin_memcpy(moment + base, &mm, sizeof mm);
      __builtin_memcpy(cos_delta + base, &cd, sizeof cd);
    } else {
      for (int l = first; l < W; ++l) {
        moment[base + l] = mm[l];
        cos_delta[base + l] = cd[l];
      }
    }
    vd4 t[W];
    transpose4x8(g[0][0], g[0][1], g[0][2], g[1][0], t);
    for (int l = first; l < W; ++l) __builtin_memcpy(grad_p + 12 * l, &t[l], sizeof(vd4));
    transpose4x8(g[1][1], g[1][2], g[2][0], g[2][1], t);
    for (int l = first; l < W; ++l) __builtin_memcpy(grad_p + 12 * l + 4, &t[l], sizeof(vd4));
    transpose4x8(g[2][2], g[3][0], g[3][1], g[3][2], t);
    for (int l = first; l < W; ++l) __builtin_memcpy(grad_p + 12 * l + 8, &t[l], sizeof(vd4));
    const vd8 pad = vd8{};
    for (int v = 0; v < 4; ++v) {
      transpose4x8(o[v][0], o[v][1], o[v][2], pad, t);
      for (int l = first; l < W; ++l) __builtin_memcpy(out_p + 4 * slot_p[4 * l + v], &t[l], sizeof(vd4));
    }
  }
};

// The node gather (kernels/membrane_forces.hpp, pass 2) on 4-vectors: force(i) += the sum of node i's
// slots, in the same order as the scalar gather (so the same bits).
struct GatherSimd {
  const int* offsets;  // [node + 1]
  const double* in;    // [slot][4]
  double* force;       // [node][3]
  KOKKOS_INLINE_FUNCTION void operator()(const int i) const {
    vd4 sum = vd4{};
    for (int s = offsets[i]; s < offsets[i + 1]; ++s) {
      vd4 v;
      __builtin_memcpy(&v, in + 4 * s, sizeof v);
      sum += v;
    }
    double* f = force + 3 * i;
    f[0] += sum[0];
    f[1] += sum[1];
    f[2] += sum[2];
  }
};

}  // namespace membrane_detail
}  // namespace dcm
#endif
