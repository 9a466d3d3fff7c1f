// Triangle areas and normals, cell area and volume: convergence on spheres, the Evans-Fung cell,
// several cells in one set of buffers, and independence of the execution space and thread count.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "tests/geometry_helpers.hpp"

namespace dcm {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kHMin = 1e4;

TEST(SphereMeasures, ConvergeAtSecondOrder) {
  const double r = 3.25e-6;
  const double area_exact = 4 * kPi * r * r, volume_exact = 4 * kPi * r * r * r / 3;
  double prev_area_err = 0, prev_volume_err = 0;
  std::printf("   k   nodes   area rel. error   order   volume rel. error   order\n");
  for (int k = 1; k <= 6; ++k) {
    const auto g = test::compute_geometry(make_icosphere(k, r), kHMin);
    const double ea = (area_exact - g.cell_area[0]) / area_exact;
    const double ev = (volume_exact - g.cell_volume[0]) / volume_exact;
    EXPECT_GT(ea, 0);  // inscribed polyhedron: always smaller
    EXPECT_GT(ev, 0);
    // Halving the edge length (one subdivision) divides the error by ~4: second order.
    const double oa = k > 1 ? std::log2(prev_area_err / ea) : 0,
                 ov = k > 1 ? std::log2(prev_volume_err / ev) : 0;
    std::printf("  %2d  %6lld   %.3e        %5.2f   %.3e          %5.2f\n", k, icosphere_node_count(k), ea,
                oa, ev, ov);
    if (k >= 3) {
      EXPECT_NEAR(oa, 2.0, 0.1) << "k = " << k;
      EXPECT_NEAR(ov, 2.0, 0.1) << "k = " << k;
    }
    prev_area_err = ea;
    prev_volume_err = ev;
  }
  EXPECT_LT(prev_area_err, 2e-4);  // 40962 nodes
}

TEST(SphereMeasures, TrianglesSumToCellAreaAndNormalsAreUnitOutward) {
  const auto g = test::compute_geometry(make_icosphere(3, 2.0), kHMin);
  double sum = 0;
  for (std::size_t t = 0; t < g.tri_area.size(); ++t) {
    sum += g.tri_area[t];
    const double* n = &g.tri_normal[3 * t];
    EXPECT_NEAR(n[0] * n[0] + n[1] * n[1] + n[2] * n[2], 1.0, 1e-14);
    const double* x0 = &g.x[3 * g.tri[3 * t]];
    EXPECT_GT(n[0] * x0[0] + n[1] * x0[1] + n[2] * x0[2], 0.0);
  }
  EXPECT_NEAR(sum, g.cell_area[0], 1e-13 * sum);
}

TEST(SphereMeasures, VolumeDoesNotDependOnPosition) {
  HostMesh m = make_icosphere(3, 1e-6);
  const double v0 = test::compute_geometry(m, kHMin).cell_volume[0];
  translate(m, {5e-6, -2e-6, 7e-6});
  const double v1 = test::compute_geometry(m, kHMin).cell_volume[0];
  EXPECT_NEAR(v1, v0, 1e-11 * v0);
}

TEST(EvansFungMeasures, AreaAndVolumeAt2562Nodes) {
  const auto g = test::compute_geometry(make_evans_fung(4), kHMin);
  const double area_um2 = g.cell_area[0] * 1e12, volume_um3 = g.cell_volume[0] * 1e18;
  std::printf("  Evans-Fung, 2562 nodes: A = %.3f um^2 (134.09), V = %.3f um^3 (94.10), v = %.4f (0.644)\n",
              area_um2, volume_um3, 6 * std::sqrt(kPi) * volume_um3 / std::pow(area_um2, 1.5));
  EXPECT_NEAR(area_um2, 134.09, 0.005 * 134.09);
  EXPECT_NEAR(volume_um3, 94.10, 0.005 * 94.10);
  EXPECT_NEAR(6 * std::sqrt(kPi) * volume_um3 / std::pow(area_um2, 1.5), 0.644, 0.005);
}

TEST(SeveralCells, EachCellMeasuredAsIfAlone) {
  HostMesh sphere = make_icosphere(3, 3.25e-6);
  HostMesh rbc = make_evans_fung(3);
  translate(rbc, {20e-6, 0, 0});
  const auto alone_sphere = test::compute_geometry(sphere, kHMin);
  const auto alone_rbc = test::compute_geometry(rbc, kHMin);
  const auto both = test::compute_geometry(std::vector<HostCell>{HostCell(sphere), HostCell(rbc)}, kHMin);
  ASSERT_EQ(both.cell_area.size(), 2u);
  EXPECT_NEAR(both.cell_area[0], alone_sphere.cell_area[0], 1e-13 * alone_sphere.cell_area[0]);
  EXPECT_NEAR(both.cell_volume[0], alone_sphere.cell_volume[0], 1e-13 * alone_sphere.cell_volume[0]);
  EXPECT_NEAR(both.cell_area[1], alone_rbc.cell_area[0], 1e-13 * alone_rbc.cell_area[0]);
  EXPECT_NEAR(both.cell_volume[1], alone_rbc.cell_volume[0], 1e-12 * alone_rbc.cell_volume[0]);
  // Node curvature of the second cell is unchanged by sharing the buffers.
  const std::size_t n0 = 3 * sphere.nodes.size();
  for (std::size_t i = 0; i < alone_rbc.node_curvature.size(); ++i)
    EXPECT_NEAR(both.node_curvature[n0 + i], alone_rbc.node_curvature[i], 1e-9 * 1e6);
}

// The same results from every host execution space the build has (Serial, OpenMP with its threads).
#if defined(KOKKOS_ENABLE_SERIAL) && defined(KOKKOS_ENABLE_OPENMP)
TEST(Backends, SerialAndOpenMPAgree) {
  const std::vector<HostCell> cells{HostCell(make_evans_fung(4))};
  const auto s = test::compute_geometry<Kokkos::Serial>(cells, kHMin);
  const auto o = test::compute_geometry<Kokkos::OpenMP>(cells, kHMin);
  auto same = [](const std::vector<double>& a, const std::vector<double>& b, const char* what) {
    ASSERT_EQ(a.size(), b.size()) << what;
    for (std::size_t i = 0; i < a.size(); ++i)
      EXPECT_LE(std::fabs(a[i] - b[i]), 1e-12 * std::fabs(a[i]) + 1e-300) << what << "[" << i << "]";
  };
  same(s.cell_area, o.cell_area, "cell_area");
  same(s.cell_volume, o.cell_volume, "cell_volume");
  same(s.node_curvature, o.node_curvature, "node_curvature");
  same(s.tri_sphere_center, o.tri_sphere_center, "tri_sphere_center");
  same(s.tri_sphere_radius, o.tri_sphere_radius, "tri_sphere_radius");
}
#endif

}  // namespace
}  // namespace dcm
