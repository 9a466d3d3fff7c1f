#pragma once
// Maugis–Dugdale (MD) adhesive contact of a sphere (reduced radius R) with a rigid plane, paper eqs. 3–10
// in the Maugis (1992) / Johnson–Greenwood (1997) form of MODEL.md section 4 (the paper's eqs. 11–12 are
// garbled). Device-callable: no std::, no exceptions, no allocation. Units SI. Sign: a positive force or
// pressure is repulsive (pushes the sphere away from the plane), adhesion is negative.
//
//   K = 4 Ê / 3, Ê = E / (1 - nu^2) (rigid substrate), sigma0 = W / h0                        (eqs. 4, 8)
//   length unit L = (pi W R^2 / K)^(1/3), force unit pi W R, approach unit L^2 / R
//   lambda = 2 sigma0 / (pi W K^2 / R)^(1/3)                                                 (eq. 3)
//   Abar = a / L, cbar = c / L, m = c / a, mu = sqrt(m^2 - 1), theta = atan mu = acos(a / c)
//   (lambda Abar^2 / 2) [mu + (m^2 - 2) theta] + (4 lambda^2 Abar / 3) [mu theta - m + 1] = 1  (m >= 1)
//   P = K a^3 / R - 2 sigma0 [c^2 theta + a sqrt(c^2 - a^2)]                                 (eqs. 6, 10)
//   p(r) = (3 K / (2 pi R)) sqrt(a^2 - r^2) - (2 sigma0 / pi) atan(sqrt((c^2 - a^2) / (a^2 - r^2)))  r < a
//        = -sigma0 (a <= r < c),  0 (r >= c)                                                 (eqs. 5, 7)
// The m-equation is solved for d = cbar - Abar >= 0 (finite also at a = 0, where m is infinite) by a
// Newton iteration kept inside a bracket with bisection as the fallback.
//
// Contact branch (overlap delta >= 0): a is geometric, a^2 = 2 R delta - delta^2 (as the paper applies it).
// Gap branch (gap g = -delta in (0, h0)): no contact (a = 0); the adhesive stress -sigma0 acts on a disc
// of radius c(g) where the deformed surfaces are h0 apart. With the central gap g, the elastic pull-up of a
// uniform stress sigma0 on a disc (centre minus edge: 8 (pi - 2) sigma0 c / (3 pi K)) and the sphere's shape:
//   c^2 / (2 R) + beta c = h0 - g,   beta = 8 (pi - 2) sigma0 / (3 pi K),   P = -pi sigma0 c^2.
// At g = 0 this is exactly the MD equation at Abar = 0 (continuous with the contact branch), c = 0 at g = h0,
// and beta -> 0 (DMT) gives the rigid c^2 = 2 R (h0 - g). docs/model/contact.md has the details and checks.
#include "core/kokkos_compat.hpp"

namespace dcm {

constexpr double kMdPi = 3.14159265358979323846;

struct MdMaterial {
  double K;   // 4/3 Ê (Pa)
  double W;   // work of adhesion (J/m^2)
  double h0;  // range of the Dugdale stress (m); sigma0 = W / h0
};

KOKKOS_INLINE_FUNCTION MdMaterial md_material(double E, double nu, double W, double h0) {
  return {4.0 / 3.0 * E / (1.0 - nu * nu), W, h0};
}

KOKKOS_INLINE_FUNCTION double md_sigma0(const MdMaterial& mat) { return mat.W > 0 ? mat.W / mat.h0 : 0.0; }

// Length unit (pi W R^2 / K)^(1/3) of Abar, cbar (m).
KOKKOS_INLINE_FUNCTION double md_length_unit(const MdMaterial& mat, double R) {
  return math::cbrt(kMdPi * mat.W * R * R / mat.K);
}

// Maugis' transition parameter (eq. 3); 0 without adhesion.
KOKKOS_INLINE_FUNCTION double md_lambda(const MdMaterial& mat, double R) {
  if (!(mat.W > 0)) return 0.0;
  return 2.0 * md_sigma0(mat) / math::cbrt(kMdPi * mat.W * mat.K * mat.K / R);
}

// The adhesive radius at a = 0: (pi lambda / 4) cbar^2 + (2 lambda^2 (pi - 2) / 3) cbar = 1.
KOKKOS_INLINE_FUNCTION double md_cbar0(double lambda) {
  if (!(lambda > 0)) return 0.0;
  const double A = 0.25 * kMdPi * lambda, B = 2.0 / 3.0 * lambda * lambda * (kMdPi - 2.0);
  return 2.0 / (B + math::sqrt(B * B + 4.0 * A));
}

namespace md_detail {

// The MD equation's left side minus 1, and its derivative in cbar, at cbar = Abar + d.
struct Residual {
  double f, dfdc;
};

KOKKOS_INLINE_FUNCTION Residual residual(double Abar, double d, double lambda) {
  const double x = Abar + d;  // cbar
  if (!(x > 0)) return {-1.0, 0.0};
  const double sin_x = math::sqrt(d * (2.0 * Abar + d));  // x sin(theta)
  // Both arguments >= 0: the polynomial first-quadrant atan2 (the library's was 18% of the contact call,
  // perf on bench_contact, session 26).
  const double theta = math::atan2_first_quadrant(sin_x, Abar);
  const double s = sin_x / x, cos_t = Abar / x;
  double t1;  // Abar x sin(theta) + (x^2 - 2 Abar^2) theta = Abar^2 [(tan - theta) + theta tan^2]
  if (theta < 1e-2) {
    const double th2 = theta * theta, tan_t = s / cos_t;
    const double tan_minus =
        theta * th2 * (1.0 / 3.0 + th2 * (2.0 / 15.0 + th2 * (17.0 / 315.0 + th2 * 62.0 / 2835.0)));
    t1 = Abar * Abar * (tan_minus + theta * tan_t * tan_t);
  } else {
    t1 = Abar * sin_x + (x * x - 2.0 * Abar * Abar) * theta;
  }
  const double t2 = sin_x * theta - d;  // Abar [mu theta - m + 1]
  const double f = 0.5 * lambda * t1 + 4.0 / 3.0 * lambda * lambda * t2 - 1.0;
  const double theta_over_sin = s > 0 ? theta / s : 1.0;
  const double dfdc =
      lambda * (Abar * s + x * theta) + 4.0 / 3.0 * lambda * lambda * (theta_over_sin + cos_t - 1.0);
  return {f, dfdc};
}

}  // namespace md_detail

// The adhesive zone's width d = cbar - Abar = (c - a) / L >= 0 solving the MD equation, to full relative
// precision also where c ~ a (JKR). Finite at Abar = 0 (d = md_cbar0). lambda <= 0 (no adhesion): 0.
KOKKOS_INLINE_FUNCTION double md_solve_zone(double Abar, double lambda) {
  if (!(lambda > 0)) return 0.0;
  if (!(Abar > 0)) Abar = 0.0;
  // Bracket [lo, hi] of d = cbar - Abar with f(lo) < 0 < f(hi); f increases with d and f(0) = -1.
  double lo = 0.0, hi = md_cbar0(lambda);
  md_detail::Residual r_hi = md_detail::residual(Abar, hi, lambda);
  for (int k = 0; k < 200 && r_hi.f <= 0; ++k) {
    lo = hi;
    hi = 2.0 * hi + 1e-300;
    r_hi = md_detail::residual(Abar, hi, lambda);
  }
  if (r_hi.f == 0) return hi;
  // Safeguarded Newton from the upper end.
  double d = hi;
  md_detail::Residual r = r_hi;
  double step_old = hi - lo, step = step_old;
  for (int it = 0; it < 200; ++it) {
    const double newton = r.dfdc > 0 ? d - r.f / r.dfdc : lo - 1.0;
    if (newton <= lo || newton >= hi || math::fabs(2.0 * r.f) > math::fabs(step_old * r.dfdc)) {
      step_old = step;
      step = 0.5 * (hi - lo);
      d = lo + step;
    } else {
      step_old = step;
      step = newton - d;
      d = newton;
    }
    r = md_detail::residual(Abar, d, lambda);
    if (r.f == 0) break;
    if (r.f < 0) {
      lo = d;
    } else {
      hi = d;
    }
    if (math::fabs(r.f) < 1e-15 || hi - lo <= 4e-16 * d) break;
  }
  return d;
}

// cbar = c / L >= Abar solving the MD equation (Abar = 0: md_cbar0(lambda)). lambda <= 0: Abar.
KOKKOS_INLINE_FUNCTION double md_solve_cbar(double Abar, double lambda) {
  return (Abar > 0 ? Abar : 0.0) + md_solve_zone(Abar, lambda);
}

// m = c / a >= 1 solving the MD equation. Abar = 0 (m infinite) returns 1e300; use md_solve_cbar there.
KOKKOS_INLINE_FUNCTION double md_solve_m(double Abar, double lambda) {
  if (!(Abar > 0)) return 1e300;
  return math::max(1.0, md_solve_cbar(Abar, lambda) / Abar);
}

// The state of one sphere–plane contact. In the gap branch a = 0, p0 = 0 and delta < 0.
struct MdState {
  double a;       // contact radius (m)
  double c;       // adhesive radius (m), >= a; 0 when there is no interaction
  double delta;   // geometric overlap (m); negative: gap
  double P;       // net normal load (N), repulsive positive
  double p0;      // Hertz peak pressure 3 K a / (2 pi R) (Pa)
  double sigma0;  // Dugdale stress W / h0 (Pa)
};

// The MD state for a given contact radius a >= 0 (delta: the geometric overlap R - sqrt(R^2 - a^2)).
KOKKOS_INLINE_FUNCTION MdState md_state_from_radius(double a, double R, const MdMaterial& mat) {
  MdState st{};
  st.a = a > 0 ? a : 0.0;
  st.delta = st.a * st.a / (R + math::sqrt(math::max(R * R - st.a * st.a, 0.0)));
  st.p0 = 1.5 * mat.K * st.a / (kMdPi * R);
  st.sigma0 = md_sigma0(mat);
  const double hertz = mat.K * st.a * st.a * st.a / R;
  if (!(st.sigma0 > 0)) {
    st.c = st.a;
    st.P = hertz;
    return st;
  }
  const double L = md_length_unit(mat, R);
  const double zone = L * md_solve_zone(st.a / L, md_lambda(mat, R));  // c - a
  st.c = st.a + zone;
  const double w = math::sqrt(zone * (st.c + st.a));         // sqrt(c^2 - a^2)
  const double theta = math::atan2_first_quadrant(w, st.a);  // acos(a / c)
  st.P = hertz - 2.0 * st.sigma0 * (st.c * st.c * theta + st.a * w);
  return st;
}

// The elastic approach of MD theory, delta_MD = a^2 / R - (8 sigma0 / (3 K)) sqrt(c^2 - a^2) (m), i.e.
// MODEL.md's delta_bar = Abar^2 - (4/3) Abar lambda mu in SI. Not what the paper's geometric overlap is:
// for W -> 0 it is the Hertz a^2 / R, twice the geometric R - sqrt(R^2 - a^2) ~ a^2 / (2 R).
KOKKOS_INLINE_FUNCTION double md_approach(const MdState& st, double R, const MdMaterial& mat) {
  const double w = math::sqrt(math::max(st.c * st.c - st.a * st.a, 0.0));
  return st.a * st.a / R - 8.0 * st.sigma0 / (3.0 * mat.K) * w;
}

// The gap branch: adhesive disc radius at central gap g in [0, h0] (0 beyond h0).
KOKKOS_INLINE_FUNCTION double md_gap_radius(double g, double R, const MdMaterial& mat) {
  const double sigma0 = md_sigma0(mat);
  if (!(sigma0 > 0) || !(g < mat.h0)) return 0.0;
  const double rhs = mat.h0 - math::max(g, 0.0);
  const double Rb = R * 8.0 * (kMdPi - 2.0) * sigma0 / (3.0 * kMdPi * mat.K);
  return 2.0 * R * rhs / (Rb + math::sqrt(Rb * Rb + 2.0 * R * rhs));
}

// The MD state for a geometric overlap delta (m): delta >= 0 contact with a^2 = 2 R delta - delta^2,
// delta < 0 the gap branch (no force beyond a gap of h0).
KOKKOS_INLINE_FUNCTION MdState md_state_from_overlap(double delta, double R, const MdMaterial& mat) {
  if (delta >= 0) {
    const double dd = math::min(delta, R);
    MdState st = md_state_from_radius(math::sqrt(math::max(2.0 * R * dd - dd * dd, 0.0)), R, mat);
    st.delta = delta;
    return st;
  }
  MdState st{};
  st.delta = delta;
  st.sigma0 = md_sigma0(mat);
  st.c = md_gap_radius(-delta, R, mat);
  st.P = -kMdPi * st.sigma0 * st.c * st.c;
  return st;
}

// Normal pressure (Pa, repulsive positive) at distance r from the contact centre: Hertz (eq. 5) plus the
// Dugdale stress (eq. 7); -sigma0 on the adhesive disc of the gap branch. Integrates to st.P over the plane.
KOKKOS_INLINE_FUNCTION double md_pressure(const MdState& st, double r) {
  if (!(r < st.c) && !(r < st.a)) return 0.0;
  if (!(r < st.a)) return -st.sigma0;
  const double in = math::sqrt(math::max(st.a * st.a - r * r, 0.0));
  const double hertz = st.p0 * in / st.a;
  const double w = math::sqrt(math::max(st.c * st.c - st.a * st.a, 0.0));
  return hertz - 2.0 / kMdPi * st.sigma0 * math::atan2_first_quadrant(w, in);
}

}  // namespace dcm
