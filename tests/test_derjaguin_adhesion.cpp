// Derjaguin adhesion of flat triangles (kernels/derjaguin_adhesion.hpp): the forces are the exact gradient
// of the stored energy (central differences, also for triangles straddling 0, h_c and h0), the energy of a
// bound flat triangle is −W per projected area, a triangle that faces away has none, the in-plane forces
// add up to zero force and zero torque about the normal, and the exact means agree with a fine Monte Carlo
// free brute-force sum over a subdivided triangle.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "kernels/derjaguin_adhesion.hpp"

namespace dcm {
namespace {

constexpr double kW = 1e-3, kH0 = 20e-9, kK = 4.0 / 3.0 * 800e3 / (1 - 0.16);
const DerjaguinLaw kLaw{kW, kH0, kK};
const Real3 kP{0, 0, 0}, kN{0, 0, 1};

double energy(const Real3 x[3]) { return derjaguin_triangle(kLaw, x[0], x[1], x[2], kP, kN).energy; }

// A facing triangle (clockwise seen from above, so its outward normal points down) of size ~L whose corner
// heights are z[0..2].
void facing_triangle(std::mt19937& rng, double L, const double z[3], Real3 x[3]) {
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  x[0] = {L * u(rng), L * u(rng), z[0]};
  x[1] = {L * (-0.5 + u(rng)), L * (1 + u(rng)), z[1]};
  x[2] = {L * (1 + u(rng)), L * u(rng), z[2]};
  if (dot(cross(x[1] - x[0], x[2] - x[0]), kN) > 0) {
    const Real3 t = x[1];
    x[1] = x[2];
    x[2] = t;
  }
}

TEST(DerjaguinAdhesion, ForcesAreTheEnergyGradient) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> height(-0.3 * kH0, 1.6 * kH0);
  int checked = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const double L = trial % 2 ? 250e-9 : 40e-9;
    const double z[3] = {height(rng), height(rng), height(rng)};
    Real3 x[3];
    facing_triangle(rng, L, z, x);
    const DerjaguinTriangle t = derjaguin_triangle(kLaw, x[0], x[1], x[2], kP, kN);
    if (t.energy == 0) continue;
    double scale = 0;
    for (int k = 0; k < 3; ++k) scale = std::max(scale, std::fabs(t.normal_force[k]) + norm(t.shear[k]));
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d) {
        const double e = 1e-13;  // m: far below h0 and the triangle, far above rounding
        Real3 xp[3] = {x[0], x[1], x[2]}, xm[3] = {x[0], x[1], x[2]};
        (d == 0 ? xp[k].x : d == 1 ? xp[k].y : xp[k].z) += e;
        (d == 0 ? xm[k].x : d == 1 ? xm[k].y : xm[k].z) -= e;
        const double fd = -(energy(xp) - energy(xm)) / (2 * e);
        const Real3 f = t.shear[k] + t.normal_force[k] * kN;
        const double an = d == 0 ? f.x : d == 1 ? f.y : f.z;
        EXPECT_NEAR(an, fd, 1e-6 * scale) << "trial " << trial << " corner " << k << " axis " << d;
      }
    ++checked;
  }
  EXPECT_GT(checked, 100);
}

TEST(DerjaguinAdhesion, BoundFlatTriangleStoresMinusWPerArea) {
  std::mt19937 rng(3);
  Real3 x[3];
  const double z[3] = {0, 0, 0};
  facing_triangle(rng, 200e-9, z, x);
  const DerjaguinTriangle t = derjaguin_triangle(kLaw, x[0], x[1], x[2], kP, kN);
  const double a_p = 0.5 * norm(cross(x[1] - x[0], x[2] - x[0]));
  EXPECT_NEAR(t.energy, -kW * a_p, 1e-12 * kW * a_p);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(t.normal_force[k], 0.0, 1e-20);  // h = 0: no traction
  EXPECT_NEAR(t.contact_area, a_p, 1e-12 * a_p);
  // Lifted by h: E = A φ(h) with φ = −W (1 − u²)².
  for (Real3& p : x) p.z = 0.5 * kH0;
  const DerjaguinTriangle up = derjaguin_triangle(kLaw, x[0], x[1], x[2], kP, kN);
  EXPECT_NEAR(up.energy, -kW * 0.5625 * a_p, 1e-9 * kW * a_p);
  EXPECT_NEAR(up.contact_area, a_p, 1e-12 * a_p);  // 0.5 h0 < h_c = 0.577 h0
  // Pressed in by h: E = A (−W + ½ K/h0 h²), pushed out with K/h0 h per area.
  for (Real3& p : x) p.z = -0.1 * kH0;
  const DerjaguinTriangle in = derjaguin_triangle(kLaw, x[0], x[1], x[2], kP, kN);
  double push = 0;
  for (int k = 0; k < 3; ++k) push += in.normal_force[k];
  EXPECT_NEAR(push, kK * 0.1 * a_p, 1e-9 * kK * 0.1 * a_p);
}

TEST(DerjaguinAdhesion, FacingAwayOrOutOfRangeHasNothing) {
  std::mt19937 rng(5);
  Real3 x[3];
  const double z[3] = {0, 0.2 * kH0, 0.1 * kH0};
  facing_triangle(rng, 100e-9, z, x);
  EXPECT_LT(derjaguin_triangle(kLaw, x[0], x[1], x[2], kP, kN).energy, 0);
  EXPECT_EQ(derjaguin_triangle(kLaw, x[0], x[2], x[1], kP, kN).energy, 0);  // reversed: faces away
  for (Real3& p : x) p.z += 1.01 * kH0;
  EXPECT_EQ(derjaguin_triangle(kLaw, x[0], x[1], x[2], kP, kN).energy, 0);
}

TEST(DerjaguinAdhesion, InPlaneForcesHaveNoNetForceOrTorque) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> height(-0.2 * kH0, 1.2 * kH0);
  for (int trial = 0; trial < 50; ++trial) {
    const double z[3] = {height(rng), height(rng), height(rng)};
    Real3 x[3];
    facing_triangle(rng, 150e-9, z, x);
    const DerjaguinTriangle t = derjaguin_triangle(kLaw, x[0], x[1], x[2], kP, kN);
    Real3 f{0, 0, 0};
    double torque = 0, scale = 0;
    for (int k = 0; k < 3; ++k) {
      f = f + t.shear[k];
      torque += dot(cross(x[k], t.shear[k]), kN);
      scale += norm(t.shear[k]);
      EXPECT_NEAR(dot(t.shear[k], kN), 0.0, 1e-30);
    }
    EXPECT_LE(norm(f), 1e-12 * scale + 1e-30);
    EXPECT_LE(std::fabs(torque), 1e-12 * scale * 150e-9 + 1e-40);
  }
}

// The exact means against a brute-force sum over a 400²-cell subdivision of the triangle.
TEST(DerjaguinAdhesion, ExactMeansMatchAFineSum) {
  std::mt19937 rng(13);
  for (int trial = 0; trial < 6; ++trial) {
    std::uniform_real_distribution<double> height(-0.5 * kH0, 2 * kH0);
    const double h[3] = {height(rng), height(rng), height(rng)};
    const DerjaguinIntegrands m = derjaguin_means(kLaw, h);
    const int n = 400;
    double phi = 0, zone = 0;
    int count = 0;
    for (int i = 0; i < n; ++i)
      for (int j = 0; i + j < n; ++j)
        for (int up = 0; up < (i + j + 1 < n ? 2 : 1); ++up) {  // the two small triangles of each cell
          const double l1 = (i + (up ? 2.0 : 1.0) / 3.0) / n, l2 = (j + (up ? 2.0 : 1.0) / 3.0) / n;
          const double hh = (1 - l1 - l2) * h[0] + l1 * h[1] + l2 * h[2];
          const double u = hh / kH0;
          phi += hh < 0 ? -kW + 0.5 * kK / kH0 * hh * hh : hh < kH0 ? -kW * (1 - u * u) * (1 - u * u) : 0.0;
          zone += hh < kH0 ? 1 : 0;
          ++count;
        }
    EXPECT_NEAR(m.phi.v, phi / count, 2e-3 * kW) << "trial " << trial;
    EXPECT_NEAR(m.zone.v, zone / count, 5e-3) << "trial " << trial;
  }
}

}  // namespace
}  // namespace dcm
