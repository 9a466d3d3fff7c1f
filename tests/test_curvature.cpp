// Cotangent mean curvature, triangle curvature with its clamp, and the rounded triangles' spheres.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "tests/geometry_helpers.hpp"

namespace dcm {
namespace {

constexpr double kHMin = 1e4;

double dot_at(const std::vector<double>& a, const std::vector<double>& b, std::size_t i) {
  return a[3 * i] * b[3 * i] + a[3 * i + 1] * b[3 * i + 1] + a[3 * i + 2] * b[3 * i + 2];
}

class SphereCurvature : public ::testing::TestWithParam<int> {};

TEST_P(SphereCurvature, NodeMeanCurvatureIsInverseRadiusAndPointsOutward) {
  const int k = GetParam();
  const double r = 3.25e-6;
  const auto g = test::compute_geometry(make_icosphere(k, r), kHMin);
  double worst = 0, area = 0;
  for (std::size_t i = 0; i < g.node_mean_curvature.size(); ++i) {
    worst = std::max(worst, std::fabs(g.node_mean_curvature[i] * r - 1));
    EXPECT_GT(dot_at(g.node_curvature, g.x, i), 0.0) << "K points outward at node " << i;
    // |K| = 2H
    EXPECT_NEAR(std::sqrt(dot_at(g.node_curvature, g.node_curvature, i)), 2 * g.node_mean_curvature[i],
                1e-12 / r);
    area += g.node_area[i];
  }
  std::printf("  k = %d (%lld nodes): max |H R - 1| = %.2e\n", k, icosphere_node_count(k), worst);
  EXPECT_LT(worst, 0.01);
  EXPECT_NEAR(area, g.cell_area[0], 1e-12 * area);  // mixed areas tile the surface
}

INSTANTIATE_TEST_SUITE_P(Levels3to6, SphereCurvature, ::testing::Range(3, 7));

TEST(TriangleCurvature, SphereTrianglesAndTheirEncompassingSpheres) {
  const double r = 3.25e-6;
  const auto g = test::compute_geometry(make_icosphere(4, r), kHMin);
  for (std::size_t t = 0; t < g.tri_area.size(); ++t) {
    EXPECT_NEAR(g.tri_mean_curvature[t] * r, 1.0, 0.01);
    EXPECT_NEAR(g.tri_sphere_radius[t] / r, 1.0, 0.01);
    const double* c = &g.tri_sphere_center[3 * t];
    EXPECT_LT(std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]), 0.02 * r) << "centre near the origin";
    for (int corner = 0; corner < 3; ++corner) {  // the sphere passes through the triangle's nodes
      const double* x = &g.x[3 * g.tri[3 * t + corner]];
      const double d = std::sqrt((x[0] - c[0]) * (x[0] - c[0]) + (x[1] - c[1]) * (x[1] - c[1]) +
                                 (x[2] - c[2]) * (x[2] - c[2]));
      EXPECT_NEAR(d, g.tri_sphere_radius[t], 1e-9 * r);
    }
  }
}

TEST(TriangleCurvature, ClampKeepsFlatRegionsFinite) {
  // A sphere of 1 m radius has H = 1/m, far below H_min: every triangle is clamped to H_min and its
  // rounded sphere has radius 1/H_min, still through the nodes, centre on the inner side.
  const double h_min = 10.0;
  const auto g = test::compute_geometry(make_icosphere(3, 1.0), h_min);
  for (std::size_t t = 0; t < g.tri_area.size(); ++t) {
    EXPECT_DOUBLE_EQ(g.tri_mean_curvature[t], h_min);
    EXPECT_NEAR(g.tri_sphere_radius[t], 1.0 / h_min, 1e-12);
  }
}

TEST(TriangleCurvature, RadiusNeverBelowCircumradius) {
  // H_min above every node's curvature: R_t would be smaller than the triangle; raised to rho_c.
  const auto g = test::compute_geometry(make_icosphere(1, 1.0), 1e3);
  for (std::size_t t = 0; t < g.tri_area.size(); ++t) {
    const double* x0 = &g.x[3 * g.tri[3 * t]];
    const double* c = &g.tri_sphere_center[3 * t];
    const double d = std::sqrt((x0[0] - c[0]) * (x0[0] - c[0]) + (x0[1] - c[1]) * (x0[1] - c[1]) +
                               (x0[2] - c[2]) * (x0[2] - c[2]));
    EXPECT_NEAR(d, g.tri_sphere_radius[t], 1e-12);
    EXPECT_GT(g.tri_sphere_radius[t], 0.3);  // circumradius of an 80-face icosphere triangle (~0.36)
  }
}

TEST(EvansFungCurvature, DimpleIsConcave) {
  // At the poles z = D a0 + (a1 - 2 a0) rho^2 / D + O(rho^4): both principal curvatures are
  // -2 (a1 - 2 a0) / D seen from outside, so H = -2 (a1 - 2 a0) / D = -0.4857 / um.
  const EvansFungShape s{};
  const HostMesh m = make_evans_fung(5, s);
  const auto g = test::compute_geometry(m, kHMin);
  const double expected = -2 * (s.a1 - 2 * s.a0) / s.diameter;
  int poles = 0;
  for (std::size_t i = 0; i < m.nodes.size(); ++i) {
    if (std::hypot(m.nodes[i][0], m.nodes[i][1]) > 1e-15) continue;
    ++poles;
    std::printf("  Evans-Fung pole node %zu: H = %.4f /um (analytic %.4f)\n", i,
                g.node_mean_curvature[i] * 1e-6, expected * 1e-6);
    EXPECT_NEAR(g.node_mean_curvature[i], expected, 0.03 * std::fabs(expected));
  }
  EXPECT_EQ(poles, 2);
  // Triangles in the dimple are concave: clamped to H_min.
  int clamped = 0;
  for (double h : g.tri_mean_curvature) clamped += h == kHMin;
  EXPECT_GT(clamped, 0);
}

}  // namespace
}  // namespace dcm
