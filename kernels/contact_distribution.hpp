#pragma once
// A contacting triangle's pressure integrated to a force and a moment (paper eqs. 16-17) and that load
// distributed to the triangle's three nodes (paper eq. 19, MODEL.md section 4).
// docs/model/contact_quadrature.md has the equations written out.
//
// The pressure acts along the contact-plane normal n, so the triangle carries a normal force Fn n and a
// moment M about the contact centre C with M perpendicular to n. Its nodes get f_i n with (eq. 19)
//   f_0 + f_1 + f_2                              = Fn
//   sum_i (x_i - C) x (f_i n)                    = M
// In a right-handed in-plane frame (e1, e2, n) with rho_i = (x_i - C).e1, sigma_i = (x_i - C).e2 the
// moment equations read  sum_i sigma_i f_i = M.e1  and  -sum_i rho_i f_i = M.e2: a 3x3 system whose
// determinant is twice the triangle's area projected on the plane. It is solved as it stands (a pure
// couple, Fn = 0 and M != 0, is a real case). Its solution is the consistent nodal load
// f_i = integral of p lambda_i dA for any pressure p, and for Fn != 0 f_i / Fn are the barycentric
// coordinates of the centre of pressure.
//
// beta_i, the weights the substrate friction spreads with (MODEL.md section 5): the barycentric
// coordinates of the centre of pressure P = C + (n x M) / Fn, or of C itself when Fn = 0, clamped to
// the nearest point of the (projected) triangle; so beta_i >= 0, sum beta_i = 1, and beta_i = f_i / Fn
// whenever the centre of pressure lies in the triangle.
//
// Degenerate triangles: when the projected triangle is (near) a segment, |2 A_proj| <= 1e-8 * (sum of
// squared projected edge lengths), the load goes to the two ends of its longest projected edge. That
// reproduces Fn and the moment component along n x d (d the edge direction); the component along d,
// which no set of normal forces on a segment can change, is dropped. A triangle that projects to a
// point (or a zero n) gets Fn / 3 per node and beta = 1/3. Both set `degenerate`; the output is finite.
//
// Expectations (tests/test_contact_distribution.cpp): random triangles, normals, centres, forces and
// moments: sum f = Fn and the moment about C = M to 1e-12 relative; the pure couple; Fn with M = 0 at
// C inside the triangle gives C's barycentric coordinates; degenerate triangles give finite output and
// the flag; a pressure integrated by the 16-point rule and distributed gives back F, M and the
// consistent nodal loads.
#include "core/vec3.hpp"
#include "kernels/quadrature_rules.hpp"

namespace dcm {

// Projected triangles with |2 A_proj| below this times the sum of their squared edge lengths are
// degenerate (an equilateral triangle has 0.29).
constexpr double kProjectedTriangleDegenerateRatio = 1e-8;

struct NodeLoads {
  double f[3];      // normal force on node i, along n (N)
  double beta[3];   // friction weights: >= 0, sum 1
  bool degenerate;  // the projected triangle is (near) degenerate; see the fallback above
};

namespace contact_detail {

// In-plane unit vectors e1, e2 with (e1, e2, n) right-handed, for a unit n.
KOKKOS_INLINE_FUNCTION void plane_frame(Real3 n, Real3& e1, Real3& e2) {
  const double ax = math::fabs(n.x), ay = math::fabs(n.y), az = math::fabs(n.z);
  // cross with the coordinate axis least aligned with n
  const Real3 a = (ax <= ay && ax <= az) ? Real3{1, 0, 0} : (ay <= az ? Real3{0, 1, 0} : Real3{0, 0, 1});
  const Real3 c = cross(n, a);
  e1 = (1.0 / norm(c)) * c;
  e2 = cross(n, e1);
}

// Barycentric coordinates of the nearest point to (pu, pv) in the 2D triangle (u_i, v_i) whose doubled
// signed area d is nonzero.
KOKKOS_INLINE_FUNCTION void clamped_barycentric(const double u[3], const double v[3], double d, double pu,
                                                double pv, double lam[3]) {
  bool inside = true;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    lam[i] = ((u[j] - pu) * (v[k] - pv) - (u[k] - pu) * (v[j] - pv)) / d;
    inside = inside && lam[i] >= 0;
  }
  if (inside) return;
  // nearest point on the three edges
  double best = -1;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;  // edge j -> k, opposite node i
    const double eu = u[k] - u[j], ev = v[k] - v[j];
    const double len2 = eu * eu + ev * ev;
    const double t = len2 > 0 ? math::clamp(((pu - u[j]) * eu + (pv - v[j]) * ev) / len2, 0.0, 1.0) : 0.0;
    const double du = u[j] + t * eu - pu, dv = v[j] + t * ev - pv;
    const double dist2 = du * du + dv * dv;
    if (best < 0 || dist2 < best) {
      best = dist2;
      lam[i] = 0;
      lam[j] = 1 - t;
      lam[k] = t;
    }
  }
}

}  // namespace contact_detail

// Barycentric coordinates in the triangle (x0, x1, x2), projected along n, of the point P (or of the nearest
// point of the projected triangle): >= 0, sum 1. A degenerate projection gives 1/3 each.
KOKKOS_INLINE_FUNCTION void projected_barycentric(Real3 x0, Real3 x1, Real3 x2, Real3 P, Real3 n,
                                                  double lam[3]) {
  Real3 e1, e2;
  contact_detail::plane_frame((1.0 / norm(n)) * n, e1, e2);
  const Real3 xs[3] = {x0, x1, x2};
  double u[3], v[3];
  for (int k = 0; k < 3; ++k) {
    u[k] = dot(xs[k] - x0, e1);
    v[k] = dot(xs[k] - x0, e2);
  }
  const double d = (u[1] - u[0]) * (v[2] - v[0]) - (u[2] - u[0]) * (v[1] - v[0]);
  const double scale = (u[1] - u[0]) * (u[1] - u[0]) + (v[1] - v[0]) * (v[1] - v[0]) +
                       (u[2] - u[0]) * (u[2] - u[0]) + (v[2] - v[0]) * (v[2] - v[0]);
  if (!(math::fabs(d) > kProjectedTriangleDegenerateRatio * scale)) {
    lam[0] = lam[1] = lam[2] = 1.0 / 3.0;
    return;
  }
  contact_detail::clamped_barycentric(u, v, d, dot(P - x0, e1), dot(P - x0, e2), lam);
}

// Eq. 19: the normal load Fn n and the moment M about C (M perpendicular to n; a component along n is
// ignored) of a triangle (x0, x1, x2), distributed to its nodes as f_i n; n need not be normalised.
KOKKOS_INLINE_FUNCTION NodeLoads distribute_normal_load(Real3 x0, Real3 x1, Real3 x2, Real3 C, Real3 n,
                                                        double Fn, Real3 M) {
  NodeLoads out{{Fn / 3, Fn / 3, Fn / 3}, {1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0}, true};
  const double n_len = norm(n);
  if (!(n_len > 0)) return out;
  const Real3 nh = (1.0 / n_len) * n;
  Real3 e1, e2;
  contact_detail::plane_frame(nh, e1, e2);

  // In-plane coordinates relative to the centroid G (better conditioned than relative to C).
  const Real3 g = (1.0 / 3.0) * (x0 + x1 + x2);
  const Real3 xs[3] = {x0, x1, x2};
  double u[3], v[3];
  for (int i = 0; i < 3; ++i) {
    u[i] = dot(xs[i] - g, e1);
    v[i] = dot(xs[i] - g, e2);
  }
  // First moments sum_i f_i (rho_i, sigma_i) about C that M demands (eq. 19's first two rows), moved to G.
  const double gu = dot(g - C, e1), gv = dot(g - C, e2);
  const double m_rho = -dot(M, e2), m_sigma = dot(M, e1);
  const double a = m_rho - Fn * gu, b = m_sigma - Fn * gv;
  // The point whose barycentric coordinates are beta: the centre of pressure, or C for a pure couple.
  double pu = -gu, pv = -gv;
  if (Fn != 0) {
    const double cu = a / Fn, cv = b / Fn;
    if (math::isfinite(cu) && math::isfinite(cv)) {
      pu = cu;
      pv = cv;
    }
  }

  const double d = (u[1] - u[0]) * (v[2] - v[0]) - (u[2] - u[0]) * (v[1] - v[0]);  // 2 A_proj
  double len2[3], sum_len2 = 0;  // len2[i]: projected edge opposite node i
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    len2[i] = (u[k] - u[j]) * (u[k] - u[j]) + (v[k] - v[j]) * (v[k] - v[j]);
    sum_len2 += len2[i];
  }

  // 3D size of the triangle, to tell a projection that is merely small from one lost in round-off
  const double size2 = norm2(x1 - x0) + norm2(x2 - x1) + norm2(x0 - x2);
  constexpr double ratio2 = kProjectedTriangleDegenerateRatio * kProjectedTriangleDegenerateRatio;
  if (math::fabs(d) > kProjectedTriangleDegenerateRatio * sum_len2 && sum_len2 > ratio2 * size2) {
    // Eq. 19 by Cramer's rule: rows (1, 1, 1 | Fn), (u_i | a), (v_i | b).
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3, k = (i + 2) % 3;
      out.f[i] = ((u[j] * v[k] - u[k] * v[j]) * Fn + (v[j] - v[k]) * a + (u[k] - u[j]) * b) / d;
    }
    contact_detail::clamped_barycentric(u, v, d, pu, pv, out.beta);
    out.degenerate = false;
    return out;
  }

  // Degenerate: the longest projected edge j -> k carries the load.
  int i = 0;
  if (len2[1] > len2[i]) i = 1;
  if (len2[2] > len2[i]) i = 2;
  const int j = (i + 1) % 3, k = (i + 2) % 3;
  if (!(len2[i] > ratio2 * size2)) return out;  // projects to a point
  const double len = math::sqrt(len2[i]);
  const double du = (u[k] - u[j]) / len, dv = (v[k] - v[j]) / len;
  const double sj = u[j] * du + v[j] * dv, sk = u[k] * du + v[k] * dv;
  const double m_d = a * du + b * dv;  // the first moment along d that the segment can carry
  out.f[i] = 0;
  out.f[k] = (m_d - sj * Fn) / (sk - sj);
  out.f[j] = Fn - out.f[k];
  const double t = math::clamp((pu * du + pv * dv - sj) / (sk - sj), 0.0, 1.0);
  out.beta[i] = 0;
  out.beta[j] = 1 - t;
  out.beta[k] = t;
  return out;
}

// Eqs. 16-17: force Fn (along n) and moment M about C of the pressure p over the triangle (x0, x1, x2)
// by the n_points quadrature rule. The quadrature points are projected on the contact plane (through C,
// normal n, n normalised here) and `pressure(r)` is called with r, the in-plane vector from C to the
// point (|r|^2 is what the Maugis-Dugdale pressure needs). `area` is the area the weights multiply: the
// triangle's own or its projection, the caller's choice. An unknown rule gives Fn = 0, M = 0.
template <class Pressure>
KOKKOS_INLINE_FUNCTION void integrate_pressure(Real3 x0, Real3 x1, Real3 x2, Real3 C, Real3 n, double area,
                                               int n_points, const Pressure& pressure, double& Fn, Real3& M) {
  Fn = 0;
  M = {0, 0, 0};
  const double n_len = norm(n);
  if (!quadrature_rule_valid(n_points) || !(n_len > 0)) return;
  const Real3 nh = (1.0 / n_len) * n;
  Real3 moment_arm_sum{0, 0, 0};  // sum_q w_q p_q r_q
  for (int q = 0; q < n_points; ++q) {
    double l1, l2, l3, w;
    quadrature_point(n_points, q, l1, l2, l3, w);
    const Real3 rel = l1 * x0 + l2 * x1 + l3 * x2 - C;
    const Real3 r = rel - dot(rel, nh) * nh;  // projected on the plane
    const double wp = w * pressure(r);
    Fn += wp;
    moment_arm_sum += wp * r;
  }
  Fn *= area;                            // eq. 16
  M = area * cross(moment_arm_sum, nh);  // eq. 17: sum w p r x n
}

}  // namespace dcm
