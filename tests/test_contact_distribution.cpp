// Distribution of a triangle's contact force and moment to its nodes (paper eq. 19,
// kernels/contact_distribution.hpp), and the pressure integration of eqs. 16-17 feeding it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "kernels/contact_distribution.hpp"

namespace dcm {
namespace {

constexpr double kL = 2e-7;     // triangle size (m)
constexpr double kF = 3e-10;    // force scale (N)
constexpr double kTol = 1e-12;  // relative reproduction of F and M

struct Rng {
  std::mt19937_64 gen{20130722};
  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(gen); }
  Real3 vec(double s) { return {uniform(-s, s), uniform(-s, s), uniform(-s, s)}; }
  Real3 unit() {
    for (;;) {
      const Real3 v = vec(1);
      const double l = norm(v);
      if (l > 0.1 && l < 1) return (1 / l) * v;
    }
  }
};

Real3 project_on_plane(Real3 v, Real3 n) { return v - dot(v, n) * n; }

// An in-plane unit vector perpendicular to the unit n.
Real3 in_plane(Real3 n, Rng& rng) {
  for (;;) {
    const Real3 v = project_on_plane(rng.vec(1), n);
    if (norm(v) > 0.1) return (1 / norm(v)) * v;
  }
}

struct Reproduction {
  double force = 0, moment = 0;  // relative errors
};

// Errors of sum f against Fn and of sum (x_i - C) x f_i n against M, relative to the size of the nodal
// loads (sum |f_i| + |Fn|) and that times the largest lever arm.
Reproduction reproduction(const NodeLoads& r, const Real3 x[3], Real3 C, Real3 n, double Fn, Real3 M) {
  double sum = 0, scale = std::fabs(Fn), arm = 0;
  Real3 m{0, 0, 0};
  for (int i = 0; i < 3; ++i) {
    sum += r.f[i];
    scale += std::fabs(r.f[i]);
    m += cross(x[i] - C, r.f[i] * n);
    arm = std::max(arm, norm(project_on_plane(x[i] - C, n)));
  }
  Reproduction e;
  e.force = std::fabs(sum - Fn) / scale;
  e.moment = norm(m - M) / (scale * arm);
  return e;
}

// Barycentric coordinates of the projection of p along n in the projected triangle x.
void projected_barycentric(const Real3 x[3], Real3 p, Real3 n, double lam[3]) {
  const double d = dot(cross(x[1] - x[0], x[2] - x[0]), n);
  for (int i = 0; i < 3; ++i) lam[i] = dot(cross(x[(i + 1) % 3] - p, x[(i + 2) % 3] - p), n) / d;
}

void expect_finite_weights(const NodeLoads& r) {
  double sum = 0;
  for (int i = 0; i < 3; ++i) {
    EXPECT_TRUE(std::isfinite(r.f[i]));
    EXPECT_TRUE(std::isfinite(r.beta[i]));
    EXPECT_GE(r.beta[i], 0);
    sum += r.beta[i];
  }
  EXPECT_NEAR(sum, 1, 1e-14);
}

// A triangle above the plane (through C, normal n): in-plane offsets within `spread` of C plus heights.
void random_triangle(Rng& rng, Real3 C, Real3 n, double spread, Real3 x[3]) {
  for (int i = 0; i < 3; ++i) x[i] = C + project_on_plane(rng.vec(spread), n) + rng.uniform(0, kL) * n;
}

// Shape quality of the projected triangle: 2 A_proj / (sum of squared projected edges), 0.29 equilateral.
double projected_quality(const Real3 x[3], Real3 n) {
  double s = 0;
  for (int i = 0; i < 3; ++i) s += norm2(project_on_plane(x[(i + 1) % 3] - x[i], n));
  return std::fabs(dot(cross(x[1] - x[0], x[2] - x[0]), n)) / s;
}

TEST(ContactDistribution, RandomLoadsReproduceForceAndMoment) {
  Rng rng;
  Reproduction worst;
  int degenerate = 0;
  const int trials = 2000;
  for (int t = 0; t < trials; ++t) {
    const Real3 n = rng.unit();
    const Real3 C = rng.vec(1e-5);
    Real3 x[3];
    random_triangle(rng, C, n, t % 2 ? kL : 4 * kL, x);  // odd trials: C far outside, often
    const double Fn = rng.uniform(-kF, kF);
    const Real3 M = (kF * kL) * project_on_plane(rng.vec(1), n);
    const NodeLoads r = distribute_normal_load(x[0], x[1], x[2], C, n, Fn, M);
    if (r.degenerate) {
      ++degenerate;
      continue;
    }
    const Reproduction e = reproduction(r, x, C, n, Fn, M);
    worst.force = std::max(worst.force, e.force);
    worst.moment = std::max(worst.moment, e.moment);
    expect_finite_weights(r);
  }
  std::printf("  %d random triangles (%d degenerate): max rel. error sum f %.2e, moment %.2e\n", trials,
              degenerate, worst.force, worst.moment);
  EXPECT_EQ(degenerate, 0);
  EXPECT_LE(worst.force, kTol);
  EXPECT_LE(worst.moment, kTol);
}

TEST(ContactDistribution, UnnormalisedNormalAndMomentAlongNormalAreHandled) {
  Rng rng;
  const Real3 n = rng.unit(), C = rng.vec(1e-5);
  Real3 x[3];
  random_triangle(rng, C, n, kL, x);
  const double Fn = 0.7 * kF;
  const Real3 M = (kF * kL) * project_on_plane(rng.vec(1), n);
  const NodeLoads a = distribute_normal_load(x[0], x[1], x[2], C, n, Fn, M);
  // a normal of another length, and a twisting moment (along n) that normal forces cannot carry
  const NodeLoads b = distribute_normal_load(x[0], x[1], x[2], C, 3.5 * n, Fn, M + (kF * kL) * n);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(a.f[i], b.f[i], 1e-13 * kF);
}

TEST(ContactDistribution, PureCoupleHasZeroNetForce) {
  Rng rng;
  Reproduction worst;
  for (int t = 0; t < 200; ++t) {
    const Real3 n = rng.unit(), C = rng.vec(1e-5);
    Real3 x[3];
    random_triangle(rng, C, n, kL, x);
    const Real3 M = (kF * kL) * in_plane(n, rng);
    const NodeLoads r = distribute_normal_load(x[0], x[1], x[2], C, n, 0.0, M);
    ASSERT_FALSE(r.degenerate);
    const Reproduction e = reproduction(r, x, C, n, 0.0, M);
    worst.force = std::max(worst.force, e.force);
    worst.moment = std::max(worst.moment, e.moment);
    double f_abs = 0;
    for (int i = 0; i < 3; ++i) f_abs += std::fabs(r.f[i]);
    EXPECT_GT(f_abs, 0);
    expect_finite_weights(r);
    // beta: C's barycentric coordinates, clamped into the triangle
    double lam[3];
    projected_barycentric(x, C, n, lam);
    if (lam[0] >= 0 && lam[1] >= 0 && lam[2] >= 0) {
      for (int i = 0; i < 3; ++i) EXPECT_NEAR(r.beta[i], lam[i], 1e-12);
    }
  }
  std::printf("  pure couple: max rel. error sum f %.2e, moment %.2e\n", worst.force, worst.moment);
  EXPECT_LE(worst.force, kTol);
  EXPECT_LE(worst.moment, kTol);
}

TEST(ContactDistribution, ForceAtInteriorCentreGivesItsBarycentricCoordinates) {
  Rng rng;
  double worst_f = 0, worst_beta = 0;
  for (int t = 0; t < 200; ++t) {
    const Real3 n = rng.unit();
    Real3 x[3];
    // barycentric coordinates are as well conditioned as the triangle is shaped: no slivers here
    do random_triangle(rng, rng.vec(1e-5), n, kL, x);
    while (projected_quality(x, n) < 0.05);
    double lam[3] = {rng.uniform(0.01, 1), rng.uniform(0.01, 1), rng.uniform(0.01, 1)};
    const double s = lam[0] + lam[1] + lam[2];
    for (double& l : lam) l /= s;
    const Real3 p = lam[0] * x[0] + lam[1] * x[1] + lam[2] * x[2];
    const Real3 C = p - rng.uniform(0.1, 1) * kL * n;  // below the triangle, on the plane
    const double Fn = rng.uniform(0.1, 1) * kF * (t % 2 ? 1 : -1);
    const NodeLoads r = distribute_normal_load(x[0], x[1], x[2], C, n, Fn, Real3{0, 0, 0});
    ASSERT_FALSE(r.degenerate);
    for (int i = 0; i < 3; ++i) {
      worst_f = std::max(worst_f, std::fabs(r.f[i] - lam[i] * Fn) / std::fabs(Fn));
      worst_beta = std::max(worst_beta, std::fabs(r.beta[i] - lam[i]));
    }
  }
  std::printf("  M = 0, C inside: max |f_i / F - lambda_i| %.2e, max |beta_i - lambda_i| %.2e\n", worst_f,
              worst_beta);
  EXPECT_LE(worst_f, kTol);
  EXPECT_LE(worst_beta, kTol);
}

TEST(ContactDistribution, BetaIsCentreOfPressureClampedIntoTriangle) {
  // Flat triangle in the plane z = 0, n = z: the centre of pressure C + (n x M) / F.
  const Real3 x[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const Real3 n{0, 0, 1}, C{0.25, 0.25, 0};
  // n x M = (0.1, 0.2, 0) with F = 1: M = (0.2, -0.1, 0); centre of pressure (0.35, 0.45), inside
  NodeLoads r = distribute_normal_load(x[0], x[1], x[2], C, n, 1.0, Real3{0.2, -0.1, 0});
  EXPECT_NEAR(r.beta[0], 0.2, 1e-15);
  EXPECT_NEAR(r.beta[1], 0.35, 1e-15);
  EXPECT_NEAR(r.beta[2], 0.45, 1e-15);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(r.f[i], r.beta[i], 1e-15);
  // centre of pressure (2.25, 0.25), outside beyond node 1: f has a negative entry, beta clamps to node 1
  r = distribute_normal_load(x[0], x[1], x[2], C, n, 1.0, Real3{0, -2, 0});
  EXPECT_LT(r.f[0], 0);
  EXPECT_NEAR(r.beta[0], 0, 1e-15);
  EXPECT_NEAR(r.beta[1], 1, 1e-15);
  EXPECT_NEAR(r.beta[2], 0, 1e-15);
  // pure couple with C outside the triangle: C's nearest point (0.5, 0) on edge 0-1
  r = distribute_normal_load(x[0], x[1], x[2], Real3{0.5, -1, 0}, n, 0.0, Real3{1, 0, 0});
  EXPECT_NEAR(r.beta[0], 0.5, 1e-15);
  EXPECT_NEAR(r.beta[1], 0.5, 1e-15);
  EXPECT_NEAR(r.beta[2], 0, 1e-15);
}

TEST(ContactDistribution, DegenerateProjectionIsFlaggedAndFinite) {
  Rng rng;
  for (int t = 0; t < 100; ++t) {
    const Real3 n = rng.unit(), C = rng.vec(1e-5), d = in_plane(n, rng), e = cross(n, d);
    const double Fn = rng.uniform(-kF, kF);
    const double mu = rng.uniform(-1, 1) * kF * kL, nu = rng.uniform(-1, 1) * kF * kL;
    const Real3 M = mu * cross(n, d) + nu * d;
    // (a) perpendicular to the plane: collinear projection, C off the line
    // (b) a needle: thickness 1e-12 of its length
    // (c) all three nodes on one normal line: projects to a point
    // (d) two coincident nodes
    const double off = rng.uniform(-1, 1) * kL;
    const Real3 a[3] = {C + off * e + 0.2 * kL * d + 0.1 * kL * n, C + off * e - 0.7 * kL * d + 0.9 * kL * n,
                        C + off * e + 0.5 * kL * d + 0.4 * kL * n};
    const Real3 b[3] = {C + 0.3 * kL * d, C + 1.3 * kL * d + 1e-12 * kL * e, C - 0.5 * kL * d};
    const Real3 c[3] = {C + off * d + 0.1 * kL * n, C + off * d + 0.5 * kL * n, C + off * d + kL * n};
    const Real3 dd[3] = {C + 0.2 * kL * d, C + 0.2 * kL * d, C + 0.3 * kL * d + 0.4 * kL * e};
    const Real3* cases[4] = {a, b, c, dd};
    for (int k = 0; k < 4; ++k) {
      const Real3* x = cases[k];
      const NodeLoads r = distribute_normal_load(x[0], x[1], x[2], C, n, Fn, M);
      EXPECT_TRUE(r.degenerate) << "case " << k;
      expect_finite_weights(r);
      EXPECT_NEAR(r.f[0] + r.f[1] + r.f[2], Fn, 1e-12 * kF) << "case " << k;
      if (k < 2) {
        // a segment carries the moment component along n x d
        Real3 m{0, 0, 0};
        for (int i = 0; i < 3; ++i) m += cross(x[i] - C, r.f[i] * n);
        EXPECT_NEAR(dot(m, cross(n, d)), mu, 1e-11 * kF * kL) << "case " << k;
      }
    }
  }
  // zero normal
  const NodeLoads r = distribute_normal_load(Real3{0, 0, 0}, Real3{1, 0, 0}, Real3{0, 1, 0}, Real3{0, 0, 0},
                                             Real3{0, 0, 0}, 1.0, Real3{0, 1, 0});
  EXPECT_TRUE(r.degenerate);
  expect_finite_weights(r);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(r.f[i], 1.0 / 3.0, 1e-15);
}

// Pressure fields integrated by the 16-point rule (eqs. 16-17) and distributed (eq. 19). The solution of
// eq. 19 is the consistent nodal load f_i = integral of p lambda_i over the projected triangle.
TEST(ContactDistribution, IntegratedPressureIsReproduced) {
  Rng rng;
  double worst_fm = 0, worst_exact = 0, worst_nodal = 0;
  for (int t = 0; t < 100; ++t) {
    const Real3 n = rng.unit(), C = rng.vec(1e-5);
    Real3 x[3];
    random_triangle(rng, C, n, kL, x);
    Real3 r3[3];  // projected nodes relative to C
    for (int i = 0; i < 3; ++i) r3[i] = project_on_plane(x[i] - C, n);
    const double area_p = 0.5 * std::fabs(dot(cross(r3[1] - r3[0], r3[2] - r3[0]), n));
    if (projected_quality(x, n) < 0.05) continue;  // nodal loads of slivers are conditioning-limited

    // (1) linear pressure p = p0 + g.r: exact F, M and nodal loads from  int l_i l_j dA = A (1 + d_ij) / 12
    const double p0 = rng.uniform(-1, 1) * 1e3;
    const Real3 grad = (1e3 / kL) * project_on_plane(rng.vec(1), n);
    auto linear = [=](Real3 rr) { return p0 + dot(grad, rr); };
    double Fn, pn[3];
    Real3 M;
    integrate_pressure(x[0], x[1], x[2], C, n, area_p, 16, linear, Fn, M);
    for (int i = 0; i < 3; ++i) pn[i] = linear(r3[i]);
    double F_exact = 0, nodal[3];
    Real3 M_exact{0, 0, 0};
    for (int i = 0; i < 3; ++i) {
      nodal[i] = area_p / 12 * (2 * pn[i] + pn[(i + 1) % 3] + pn[(i + 2) % 3]);
      F_exact += nodal[i];
      M_exact += cross(nodal[i] * r3[i], n);  // int p r x n dA = sum_i (int p l_i dA) r_i x n
    }
    const double f_scale = std::fabs(nodal[0]) + std::fabs(nodal[1]) + std::fabs(nodal[2]);
    worst_exact = std::max(worst_exact, std::fabs(Fn - F_exact) / f_scale);
    worst_exact = std::max(worst_exact, norm(M - M_exact) / (f_scale * kL));
    NodeLoads r = distribute_normal_load(x[0], x[1], x[2], C, n, Fn, M);
    for (int i = 0; i < 3; ++i) worst_nodal = std::max(worst_nodal, std::fabs(r.f[i] - nodal[i]) / f_scale);
    Reproduction e = reproduction(r, x, C, n, Fn, M);
    worst_fm = std::max({worst_fm, e.force, e.moment});

    // (2) a smooth non-polynomial pressure (repulsive core, adhesive rim): nodal loads equal the rule's own
    // consistent loads A sum_q w_q p_q lambda_q,i
    const double s2 = kL * kL * rng.uniform(0.3, 3);
    auto bump = [=](Real3 rr) { return 2e3 * std::exp(-dot(rr, rr) / s2) - 5e2; };
    integrate_pressure(x[0], x[1], x[2], C, n, area_p, 16, bump, Fn, M);
    double discrete[3] = {0, 0, 0};
    for (int q = 0; q < 16; ++q) {
      double l[3], w;
      quadrature_point(16, q, l[0], l[1], l[2], w);
      const double p = bump(l[0] * r3[0] + l[1] * r3[1] + l[2] * r3[2]);
      for (int i = 0; i < 3; ++i) discrete[i] += area_p * w * p * l[i];
    }
    r = distribute_normal_load(x[0], x[1], x[2], C, n, Fn, M);
    const double d_scale = std::fabs(discrete[0]) + std::fabs(discrete[1]) + std::fabs(discrete[2]);
    for (int i = 0; i < 3; ++i)
      worst_nodal = std::max(worst_nodal, std::fabs(r.f[i] - discrete[i]) / d_scale);
    e = reproduction(r, x, C, n, Fn, M);
    worst_fm = std::max({worst_fm, e.force, e.moment});
  }
  std::printf(
      "  16-point integration: linear p vs exact F, M %.2e; nodal loads vs consistent loads %.2e; "
      "F, M reproduced %.2e\n",
      worst_exact, worst_nodal, worst_fm);
  EXPECT_LE(worst_exact, 1e-13);
  EXPECT_LE(worst_nodal, kTol);
  EXPECT_LE(worst_fm, kTol);
}

// The kernels inside a Kokkos parallel region (a free function: CUDA lambdas cannot live in a test body).
Kokkos::View<double* [4]> device_results(int n) {
  Kokkos::View<double* [4]> out("contact_distribution_out", n);
  Kokkos::parallel_for(
      "test::contact_distribution", n, KOKKOS_LAMBDA(const int i) {
        const double s = 1 + 0.01 * i;
        const NodeLoads r =
            distribute_normal_load(Real3{0, 0, 0.1}, Real3{s, 0, 0.2}, Real3{0, s, 0.3}, Real3{0.2, 0.3, 0},
                                   Real3{0, 0, 1}, 1.0 + i, Real3{0.1, -0.2, 0});
        double l1, l2, l3, w;
        quadrature_point(16, i % 16, l1, l2, l3, w);
        out(i, 0) = r.f[0];
        out(i, 1) = r.f[1];
        out(i, 2) = r.beta[2];
        out(i, 3) = w * (l1 + l2 + l3);
      });
  return out;
}

TEST(ContactDistribution, DeviceCallableAndAgreesWithHost) {
  const int n = 64;
  const auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), device_results(n));
  for (int i = 0; i < n; ++i) {
    const double s = 1 + 0.01 * i;
    const NodeLoads r =
        distribute_normal_load(Real3{0, 0, 0.1}, Real3{s, 0, 0.2}, Real3{0, s, 0.3}, Real3{0.2, 0.3, 0},
                               Real3{0, 0, 1}, 1.0 + i, Real3{0.1, -0.2, 0});
    double l1, l2, l3, w;
    quadrature_point(16, i % 16, l1, l2, l3, w);
    // Equal up to rounding: the compiler may fuse multiply-adds (FMA) differently in the kernel and here.
    const double tol = 1e-13;
    EXPECT_NEAR(h(i, 0), r.f[0], tol * std::abs(r.f[0]));
    EXPECT_NEAR(h(i, 1), r.f[1], tol * std::abs(r.f[1]));
    EXPECT_NEAR(h(i, 2), r.beta[2], tol * std::abs(r.beta[2]));
    EXPECT_NEAR(h(i, 3), w * (l1 + l2 + l3), tol * std::abs(w * (l1 + l2 + l3)));
  }
}

}  // namespace
}  // namespace dcm
