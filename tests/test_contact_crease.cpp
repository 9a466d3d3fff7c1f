// The crease at the contact line (kernels/contact_crease.hpp): its forces are the exact gradient of its
// energy (central differences on random rim hinges, both nodes bound or within the range), a hinge lying flat
// on the plane stores nothing, a wall rising from a bound edge stores W ρ |e| f(c) and is turned toward
// laying down outside, and nothing acts on an edge whose node is beyond the range.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "kernels/contact_crease.hpp"

namespace dcm {
namespace {

constexpr double kW = 1e-3, kH0 = 20e-9, kRho = 11e-9, kL = 245e-9;
CreaseLaw law() {
  CreaseLaw c;
  c.W = kW;
  c.h0 = kH0;
  c.rho = kRho;
  return c;  // the plane z = 0, normal +z
}

// A rim hinge: i, j on (or near) the plane along y (the rim at x = 0, the cell's inside at x < 0), k inside
// on the plane (the bound wing (i, j, k) faces the plane: outward normal −z), l up the wall leaning inward by
// `lean` over its height H (wing (j, i, l), outward normal +x and up).
void rim_hinge(double zi, double zj, double H, double lean, Real3 x[4]) {
  x[0] = {0, kL, zi};
  x[1] = {0, 0, zj};
  x[2] = {-0.8 * kL, 0.5 * kL, 0};
  x[3] = {-lean, 0.5 * kL, H};
}

TEST(ContactCrease, ForcesAreTheEnergyGradient) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> z(-0.3 * kH0, 1.2 * kH0), u(-1, 1);
  int checked = 0;
  for (int trial = 0; trial < 200; ++trial) {
    Real3 x[4];
    rim_hinge(z(rng), z(rng), kL * (0.3 + 0.7 * (u(rng) + 1)), 0.3 * kL * u(rng), x);
    for (auto& p : x) p += Real3{0.05 * kL * u(rng), 0.05 * kL * u(rng), 0.02 * kL * u(rng)};
    Real3 f[4];
    const double e0 = crease_hinge(x[0], x[1], x[2], x[3], law(), f);
    if (e0 == 0) continue;
    double worst = 0, fmax = 0;
    for (int a = 0; a < 4; ++a) fmax = std::max(fmax, norm(f[a]));
    for (int a = 0; a < 4; ++a)
      for (int d = 0; d < 3; ++d) {
        const double step = 1e-4 * kH0;
        Real3 p[4] = {x[0], x[1], x[2], x[3]}, m[4] = {x[0], x[1], x[2], x[3]};
        double* pp = d == 0 ? &p[a].x : d == 1 ? &p[a].y : &p[a].z;
        double* mm = d == 0 ? &m[a].x : d == 1 ? &m[a].y : &m[a].z;
        *pp += step;
        *mm -= step;
        Real3 g[4];
        const double fd = -(crease_hinge(p[0], p[1], p[2], p[3], law(), g) -
                            crease_hinge(m[0], m[1], m[2], m[3], law(), g)) /
                          (2 * step);
        const double fa = d == 0 ? f[a].x : d == 1 ? f[a].y : f[a].z;
        worst = std::max(worst, std::abs(fd - fa));
      }
    EXPECT_LT(worst, 1e-5 * fmax) << "trial " << trial;
    ++checked;
  }
  EXPECT_GT(checked, 100);
}

TEST(ContactCrease, FlatOnThePlaneStoresNothing) {
  Real3 x[4];
  rim_hinge(0, 0, 0, -0.8 * kL, x);  // l out on the plane: both wings face it
  Real3 f[4];
  EXPECT_EQ(crease_hinge(x[0], x[1], x[2], x[3], law(), f), 0.0);
  for (const Real3& fa : f) EXPECT_LT(norm(fa), 1e-30);
}

TEST(ContactCrease, AWallFromABoundEdgeIsTurnedOutward) {
  Real3 x[4];
  const double H = kL, lean = 0.25 * kL;  // the wall at ~76° to the plane, leaning inward
  rim_hinge(0, 0, H, lean, x);
  Real3 f[4];
  const double e = crease_hinge(x[0], x[1], x[2], x[3], law(), f);
  // the wall wing: n = (−H, 0, −lean)/|.| ... its turn from −z: c = −n_z
  const Real3 n2 = cross(x[0] - x[1], x[3] - x[1]);
  const double c = -n2.z / norm(n2), g = (1 - c) / (1 + c);
  EXPECT_NEAR(e, kW * kRho * kL * (std::sqrt(g + kCreaseEps * kCreaseEps) - kCreaseEps), 1e-12 * e);
  EXPECT_GT(e, 0.0);
  // The wall's far node is turned about the rim outward, toward laying the wall down outside (+x): along
  // (H, 0, lean), outward and, while the wall leans inward, up; mostly along that turn.
  const Real3 turn = (1 / std::hypot(H, lean)) * Real3{H, 0, lean};
  EXPECT_GT(dot(f[3], turn), 0.9 * norm(f[3]));
  // Far from the plane (i, j beyond h0) nothing acts.
  rim_hinge(1.01 * kH0, 0, H, lean, x);
  EXPECT_EQ(crease_hinge(x[0], x[1], x[2], x[3], law(), f), 0.0);
}

}  // namespace
}  // namespace dcm
