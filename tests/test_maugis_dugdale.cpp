// The Maugis–Dugdale contact law (kernels/maugis_dugdale.hpp): the m-solve, its JKR / DMT / Hertz limits,
// the adhesive load of paper eq. 10, the approach, the gap branch's continuity and the pressure's integral.
// The inline functions are host-callable, so the tests call them directly. Numbers are printed for
// docs/model/contact.md.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <utility>
#include <vector>

#include "kernels/maugis_dugdale.hpp"

namespace dcm {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kR = 3.25e-6;  // paper Table 1: sphered cell radius (m)

// Paper Table 1, Hategan set: E = 800 kPa, nu = 0.4, W = 1 mJ/m^2, h0 = 20 nm.
MdMaterial paper_material() { return md_material(800e3, 0.4, 1e-3, 20e-9); }

// The paper's E, nu, W with h0 chosen so that md_lambda(., kR) = lambda.
MdMaterial material_with_lambda(double lambda) {
  MdMaterial mat = paper_material();
  mat.h0 = 2.0 * mat.W / (lambda * std::cbrt(kPi * mat.W * mat.K * mat.K / kR));
  return mat;
}

// MODEL.md's MD equation (left side minus 1) in m, written with m - 1 given exactly (m - 1 = zone / Abar),
// independently of the kernel's own form.
double md_equation_residual(double Abar, double m_minus_1, double lambda) {
  const double m = 1.0 + m_minus_1;
  const double mu = std::sqrt(m_minus_1 * (m + 1.0));
  const double at = std::atan(mu);
  return lambda * Abar * Abar / 2.0 * (mu + (m_minus_1 * (m + 1.0) - 1.0) * at) +
         4.0 * lambda * lambda * Abar / 3.0 * (mu * at - m_minus_1) - 1.0;
}

// Minimum of f over [lo, hi]: a scan, then golden sections around the best sample.
double minimise(const std::function<double(double)>& f, double lo, double hi, double* at = nullptr) {
  const int n = 2000;
  int best = 0;
  double fbest = f(lo);
  for (int i = 1; i <= n; ++i) {
    const double v = f(lo + (hi - lo) * i / n);
    if (v < fbest) fbest = v, best = i;
  }
  double a = lo + (hi - lo) * std::max(best - 1, 0) / n, b = lo + (hi - lo) * std::min(best + 1, n) / n;
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = b - g * (b - a), x2 = a + g * (b - a), f1 = f(x1), f2 = f(x2);
  for (int it = 0; it < 200 && b - a > 1e-14 * (std::fabs(a) + std::fabs(b)); ++it) {
    if (f1 < f2) {
      b = x2, x2 = x1, f2 = f1, x1 = b - g * (b - a), f1 = f(x1);
    } else {
      a = x1, x1 = x2, f1 = f2, x2 = a + g * (b - a), f2 = f(x2);
    }
  }
  const double xm = f1 < f2 ? x1 : x2;
  if (at) *at = xm;
  return std::min({fbest, f1, f2});
}

// Pull-off (the minimum over a of the net load, load control) in units of pi W R.
double pull_off_bar(const MdMaterial& mat, double* a_at = nullptr) {
  const double L = md_length_unit(mat, kR);
  return minimise([&](double a) { return md_state_from_radius(a, kR, mat).P; }, 0.0, 3.0 * L, a_at) /
         (kPi * mat.W * kR);
}

// 2 pi int_0^inf p(r) r dr, split at a and c; on [0, a] with r = a sin(phi) (removes the sqrt edges).
double integrate_pressure(const MdState& st) {
  static const double x[8] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                              -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                              0.7966664774136267,  0.9602898564975363};
  static const double w[8] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873, 0.3626837833783620,
                              0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};
  const auto gauss = [&](const std::function<double(double)>& f, double lo, double hi, int panels) {
    double sum = 0;
    for (int p = 0; p < panels; ++p) {
      const double a = lo + (hi - lo) * p / panels, b = lo + (hi - lo) * (p + 1) / panels;
      for (int i = 0; i < 8; ++i) sum += 0.5 * (b - a) * w[i] * f(0.5 * (a + b) + 0.5 * (b - a) * x[i]);
    }
    return sum;
  };
  double total = 0;
  if (st.a > 0)
    total += gauss(
        [&](double phi) {
          const double r = st.a * std::sin(phi);
          return md_pressure(st, r) * r * st.a * std::cos(phi);
        },
        0.0, 0.5 * kPi, 400);
  if (st.c > st.a) total += gauss([&](double r) { return md_pressure(st, r) * r; }, st.a, st.c, 50);
  // Beyond c the pressure must vanish.
  EXPECT_EQ(md_pressure(st, st.c * (1 + 1e-12) + 1e-30), 0.0);
  EXPECT_EQ(md_pressure(st, 10 * st.c + 1e-9), 0.0);
  return 2.0 * kPi * total;
}

std::vector<double> log_grid(double lo, double hi, int n) {
  std::vector<double> v;
  for (int i = 0; i < n; ++i) v.push_back(lo * std::pow(hi / lo, double(i) / (n - 1)));
  return v;
}

// math::atan2_first_quadrant (core/kokkos_compat.hpp), used by the contact integrals, against std::atan2:
// y/x over 32 decades, both orderings, the reduction's seams (t = 0.66, t = 1), and the edges x = 0, y = 0.
TEST(FastAtan2, MatchesTheLibraryToTwoUlpsInTheFirstQuadrant) {
  double worst = 0;
  std::vector<double> ratios;
  for (int e = -160; e <= 160; ++e) ratios.push_back(std::pow(10.0, e / 10.0));
  for (double t : {0.66, std::nextafter(0.66, 1.0), std::nextafter(0.66, 0.0), 1.0, std::nextafter(1.0, 0.0)})
    ratios.push_back(t);
  for (int i = 0; i < 20000; ++i) ratios.push_back((i + 0.5) / 20000.0);
  for (double t : ratios)
    for (double scale : {1e-9, 1.0, 3e7}) {
      const double y = t * scale, x = scale;
      for (const auto& [a, b] : {std::pair<double, double>{y, x}, std::pair<double, double>{x, y}}) {
        const double ref = std::atan2(a, b);
        worst = std::max(worst, std::fabs(math::atan2_first_quadrant(a, b) - ref) / ref);
      }
    }
  std::printf("largest relative error %.2e\n", worst);
  EXPECT_LT(worst, 4.5e-16);
  EXPECT_EQ(math::atan2_first_quadrant(0.0, 0.0), 0.0);
  EXPECT_EQ(math::atan2_first_quadrant(0.0, 2.0), 0.0);
  EXPECT_NEAR(math::atan2_first_quadrant(2.0, 0.0), std::atan2(2.0, 0.0), 2e-16);
  EXPECT_TRUE(std::isnan(math::atan2_first_quadrant(std::nan(""), 1.0)));
}

TEST(MaugisDugdaleSolve, ResidualBelow1e10OnTheGrid) {
  double worst = 0, worst_A = 0, worst_l = 0;
  int via_ulps = 0;
  for (const double A : log_grid(1e-6, 10.0, 61)) {
    for (const double l : log_grid(1e-3, 1e3, 61)) {
      const double zone = md_solve_zone(A, l);
      ASSERT_TRUE(std::isfinite(zone) && zone >= 0) << "Abar " << A << " lambda " << l;
      const double res = std::fabs(md_equation_residual(A, zone / A, l));
      if (res > worst) worst = res, worst_A = A, worst_l = l;
      EXPECT_LT(res, 1e-10) << "Abar " << A << " lambda " << l;
      // m itself: >= 1, finite, c / a; where m is too close to 1 for a double to satisfy the equation to
      // 1e-10, it must be the root to within 8 ulps (the residual changes sign across it).
      const double m = md_solve_m(A, l);
      ASSERT_TRUE(std::isfinite(m) && m >= 1.0) << "Abar " << A << " lambda " << l;
      EXPECT_NEAR(m, md_solve_cbar(A, l) / A, 1e-15 * m);
      if (std::fabs(md_equation_residual(A, m - 1.0, l)) >= 1e-10) {
        ++via_ulps;
        const double eps = std::numeric_limits<double>::epsilon();
        EXPECT_LT(md_equation_residual(A, m * (1 - 8 * eps) - 1.0, l), 0.0) << A << ' ' << l;
        EXPECT_GT(md_equation_residual(A, m * (1 + 8 * eps) - 1.0, l), 0.0) << A << ' ' << l;
      }
    }
  }
  std::printf(
      "  max |MD residual| over 61 x 61 (Abar 1e-6..10, lambda 1e-3..1e3) = %.2e (at Abar %.3g, "
      "lambda %.3g); %d points where m is checked by ulps\n",
      worst, worst_A, worst_l, via_ulps);
}

TEST(MaugisDugdaleSolve, ZeroRadiusGivesTheFiniteLimit) {
  for (const double l : log_grid(1e-3, 1e3, 13)) {
    const double c0 = md_solve_cbar(0.0, l);
    ASSERT_TRUE(std::isfinite(c0) && c0 > 0);
    EXPECT_DOUBLE_EQ(c0, md_cbar0(l));
    // the a -> 0 limit of the MD equation: (pi l / 4) c^2 + (2 l^2 (pi - 2) / 3) c = 1
    EXPECT_NEAR(kPi * l / 4 * c0 * c0 + 2 * l * l * (kPi - 2) / 3 * c0, 1.0, 1e-14);
    EXPECT_NEAR(md_solve_cbar(1e-9, l), c0, 1e-6 * c0) << "lambda " << l;
    const double m0 = md_solve_m(0.0, l);
    EXPECT_TRUE(std::isfinite(m0) && m0 >= 1.0);
  }
  // DMT (rigid) geometry at small lambda: c0^2 = 2 R h0.
  const MdMaterial mat = material_with_lambda(1e-4);
  const MdState st = md_state_from_radius(0.0, kR, mat);
  EXPECT_NEAR(st.c * st.c / (2 * kR * mat.h0), 1.0, 2e-2);
  // No adhesion: m = 1.
  EXPECT_EQ(md_solve_m(0.5, 0.0), 1.0);
}

TEST(MaugisDugdaleLimits, JkrPullOffAtLargeLambda) {
  for (const double l : {100.0, 1000.0}) {
    double a_at = 0;
    const double P = pull_off_bar(material_with_lambda(l), &a_at);
    const double err = P / -1.5 - 1;
    std::printf("  lambda %g: pull-off %.6f pi W R (JKR -1.5): error %.2e, at Abar %.4f\n", l, P, err,
                a_at / md_length_unit(material_with_lambda(l), kR));
    EXPECT_LT(std::fabs(err), 5e-3);
  }
}

TEST(MaugisDugdaleLimits, DmtPullOffAtSmallLambda) {
  for (const double l : {0.01, 0.001}) {
    const double P = pull_off_bar(material_with_lambda(l));
    const double err = P / -2.0 - 1;
    std::printf("  lambda %g: pull-off %.6f pi W R (DMT -2): error %.2e\n", l, P, err);
    EXPECT_LT(std::fabs(err), 5e-3);
  }
  // In between (the paper's Hategan set, lambda ~ 0.86) the pull-off lies between the two.
  const MdMaterial mat = paper_material();
  const double P = pull_off_bar(mat);
  std::printf("  paper Table 1 (lambda %.4f): pull-off %.6f pi W R\n", md_lambda(mat, kR), P);
  EXPECT_LT(P, -1.5);
  EXPECT_GT(P, -2.0);
}

TEST(MaugisDugdaleLimits, HertzWithoutAdhesion) {
  MdMaterial mat = paper_material();
  mat.W = 1e-12;  // sigma0 = 5e-5 Pa; the adhesive disc stays ~ sqrt(2 R h0) = 0.36 um wide, so a >= 0.1 um
  double worst_P = 0, worst_p = 0;
  for (const double a : {1e-7, 5e-7, 1e-6}) {
    const MdState st = md_state_from_radius(a, kR, mat);
    const double hertz = mat.K * a * a * a / kR;  // eq. 6, K = 4 E_hat / 3
    worst_P = std::max(worst_P, std::fabs(st.P / hertz - 1));
    EXPECT_NEAR(st.p0, 3 * hertz / (2 * kPi * a * a), 1e-12 * st.p0);
    for (int i = 0; i <= 20; ++i) {
      const double r = a * i / 20.0;
      const double pH = 2 * (0.75 * mat.K) / (kPi * kR) * std::sqrt(a * a - r * r);  // eq. 5
      worst_p = std::max(worst_p, std::fabs(md_pressure(st, r) - pH) / st.p0);
    }
    EXPECT_EQ(md_pressure(st, 1.01 * st.c), 0.0);
  }
  std::printf("  W = 1e-12: max |P / P_Hertz - 1| = %.2e, max |p - p_Hertz| / p0 = %.2e\n", worst_P, worst_p);
  EXPECT_LT(worst_P, 1e-6);
  EXPECT_LT(worst_p, 1e-6);
  // W = 0 exactly: Hertz, c = a.
  mat.W = 0;
  const MdState st = md_state_from_radius(2e-7, kR, mat);
  EXPECT_DOUBLE_EQ(st.P, mat.K * 8e-21 / kR);
  EXPECT_EQ(st.c, st.a);
  EXPECT_EQ(md_state_from_overlap(-1e-9, kR, mat).P, 0.0);
}

TEST(MaugisDugdaleLoad, AdhesivePartIsEq10AndMatchesTheDimensionlessForm) {
  double worst10 = 0, worst_bar = 0;
  for (const double l : {0.01, 0.3, 1.0, 10.0, 300.0}) {
    const MdMaterial mat = material_with_lambda(l);
    const double L = md_length_unit(mat, kR), s0 = md_sigma0(mat);
    for (const double Abar : {0.05, 0.3, 1.0, 2.0, 5.0}) {
      const double a = Abar * L;
      const MdState st = md_state_from_radius(a, kR, mat);
      const double adh = st.P - mat.K * a * a * a / kR;
      const double eq10 = -2 * s0 * (st.c * st.c * std::acos(a / st.c) + a * std::sqrt(st.c * st.c - a * a));
      worst10 = std::max(worst10, std::fabs(adh / eq10 - 1));
      EXPECT_NEAR(adh, eq10, 1e-9 * std::fabs(eq10)) << "lambda " << l << " Abar " << Abar;
      // MODEL.md: Pbar = Abar^3 - lambda Abar^2 [mu + m^2 atan mu]
      const double m = md_solve_m(Abar, l), mu = std::sqrt(m * m - 1);
      const double Pbar = Abar * Abar * Abar - l * Abar * Abar * (mu + m * m * std::atan(mu));
      const double scale = std::max(std::fabs(st.P), kPi * mat.W * kR);
      worst_bar = std::max(worst_bar, std::fabs(st.P - kPi * mat.W * kR * Pbar) / scale);
      EXPECT_NEAR(st.P, kPi * mat.W * kR * Pbar, 1e-9 * scale);
      EXPECT_NEAR(st.c / st.a, m, 1e-12 * m);
    }
  }
  std::printf("  max |adhesive P / eq. 10 - 1| = %.2e; max |P - pi W R Pbar| / max(|P|, pi W R) = %.2e\n",
              worst10, worst_bar);
}

TEST(MaugisDugdaleApproach, ElasticApproachAndGeometricOverlap) {
  // MODEL.md's delta_bar = Abar^2 - (4/3) Abar lambda mu, in units L^2 / R, equals md_approach.
  for (const double l : {0.01, 1.0, 100.0}) {
    const MdMaterial mat = material_with_lambda(l);
    const double L = md_length_unit(mat, kR);
    for (const double Abar : {0.1, 1.0, 3.0}) {
      const MdState st = md_state_from_radius(Abar * L, kR, mat);
      const double m = md_solve_m(Abar, l), mu = std::sqrt(m * m - 1);
      const double dbar = Abar * Abar - 4.0 / 3.0 * Abar * l * mu;
      EXPECT_NEAR(md_approach(st, kR, mat), dbar * L * L / kR, 1e-9 * L * L / kR);
    }
  }
  // JKR limit (lambda = 1000): delta = a^2 / R - sqrt(2 pi W a / E_hat).
  {
    const MdMaterial mat = material_with_lambda(1000.0);
    const double Ehat = 0.75 * mat.K, L = md_length_unit(mat, kR);
    for (const double Abar : {0.5, 1.0, 2.0}) {
      const double a = Abar * L;
      const double jkr = a * a / kR - std::sqrt(2 * kPi * mat.W * a / Ehat);
      const double md = md_approach(md_state_from_radius(a, kR, mat), kR, mat);
      EXPECT_NEAR(md / jkr, 1.0, 2e-2) << "Abar " << Abar;
    }
  }
  // At a = 0 the MD approach is minus the centre deflection of a uniform stress sigma0 on a disc c0:
  // 2 sigma0 c0 / E_hat (Timoshenko & Goodier).
  {
    const MdMaterial mat = paper_material();
    const MdState st = md_state_from_radius(0.0, kR, mat);
    EXPECT_NEAR(md_approach(st, kR, mat), -2 * st.sigma0 * st.c / (0.75 * mat.K), 1e-12 * st.c);
  }
  // The geometric overlap the paper uses: a^2 = 2 R delta - delta^2, both ways; for W -> 0 it is half the
  // Hertz approach a^2 / R.
  {
    MdMaterial mat = paper_material();
    for (const double delta : {1e-10, 1e-9, 3e-8, 1e-7}) {
      const MdState st = md_state_from_overlap(delta, kR, mat);
      EXPECT_NEAR(st.a * st.a, 2 * kR * delta - delta * delta, 1e-12 * st.a * st.a);
      EXPECT_NEAR(md_state_from_radius(st.a, kR, mat).delta, delta, 1e-9 * delta);
    }
    mat.W = 0;
    const MdState st = md_state_from_overlap(1e-9, kR, mat);
    EXPECT_NEAR(md_approach(st, kR, mat) / st.delta, 2.0, 1e-3);
  }
}

TEST(MaugisDugdaleGap, ContinuousAtContactOnsetAndVanishingAtH0) {
  for (const double l : {0.01, 0.1, 0.8619, 3.0, 30.0}) {
    const MdMaterial mat = material_with_lambda(l);
    const double unit = 2 * kPi * mat.W * kR;
    const MdState touch = md_state_from_overlap(0.0, kR, mat);
    const MdState gap = md_state_from_overlap(-1e-30, kR, mat);
    const double jump = std::fabs(touch.P - gap.P) / unit;
    std::printf("  lambda %-7g P(0) = %.6f pi W R, |P(0+) - P(0-)| = %.2e x 2 pi W R; |dP| at +-eps:", l,
                touch.P / (kPi * mat.W * kR), jump);
    EXPECT_LT(jump, 1e-9);
    EXPECT_NEAR(touch.c, gap.c, 1e-9 * touch.c);
    EXPECT_LT(touch.P, 0.0);
    // The contact branch tends to it as the overlap -> 0 (measured: |dP| ~ delta, since Pbar(Abar) - Pbar(0)
    // ~ Abar^2 ~ delta).
    double prev = 1e300;
    for (const double e : {1e-16, 1e-18, 1e-20, 1e-22}) {
      const double d =
          std::fabs(md_state_from_overlap(e, kR, mat).P - md_state_from_overlap(-e, kR, mat).P) / unit;
      std::printf(" %.1e", d);
      EXPECT_LT(d, prev);
      prev = d;
    }
    std::printf("\n");
    EXPECT_LT(prev, 1e-4);
    // Gap: the attraction decreases monotonically to exactly 0 at h0 and stays 0 beyond.
    double last = touch.P;
    for (int i = 1; i <= 100; ++i) {
      const MdState st = md_state_from_overlap(i == 100 ? -mat.h0 : -mat.h0 * i / 100.0, kR, mat);
      EXPECT_GE(st.P, last) << "gap " << i << "% h0";
      EXPECT_LE(st.P, 0.0);
      last = st.P;
    }
    EXPECT_EQ(last, 0.0);
    EXPECT_EQ(md_state_from_overlap(-2 * mat.h0, kR, mat).P, 0.0);
    EXPECT_LT(std::fabs(md_state_from_overlap(-mat.h0 * (1 - 1e-9), kR, mat).P) / unit, 1e-8);
  }
}

TEST(MaugisDugdalePressure, IntegratesToTheNetLoad) {
  double worst = 0;
  for (const double l : {0.01, 0.8619, 10.0, 300.0}) {
    const MdMaterial mat = material_with_lambda(l);
    const double L = md_length_unit(mat, kR);
    std::vector<MdState> states;
    for (const double Abar : {0.0, 0.02, 0.5, 1.2, 4.0})
      states.push_back(md_state_from_radius(Abar * L, kR, mat));
    for (const double g : {0.0, 0.3, 0.9}) states.push_back(md_state_from_overlap(-g * mat.h0, kR, mat));
    for (const MdState& st : states) {
      const double P = integrate_pressure(st);
      const double scale = std::max(std::fabs(st.P), 1e-3 * kPi * mat.W * kR);
      worst = std::max(worst, std::fabs(P - st.P) / scale);
      EXPECT_NEAR(P, st.P, 1e-6 * scale) << "lambda " << l << " a " << st.a << " delta " << st.delta;
    }
  }
  std::printf("  max |2 pi int p r dr - P| / |P| = %.2e\n", worst);
  // The Dugdale term is continuous at r = a with value -sigma0.
  const MdState st = md_state_from_radius(1e-7, kR, paper_material());
  const double p0 = st.p0 * std::sqrt(1 - std::pow(1 - 1e-10, 2));
  EXPECT_NEAR(md_pressure(st, st.a * (1 - 1e-10)) - p0, -st.sigma0, 1e-4 * st.sigma0);
  EXPECT_EQ(md_pressure(st, st.a), -st.sigma0);
  EXPECT_EQ(md_pressure(st, 0.5 * (st.a + st.c)), -st.sigma0);
}

}  // namespace
}  // namespace dcm
