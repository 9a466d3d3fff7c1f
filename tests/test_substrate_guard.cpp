// The substrate guard (kernels/substrate_guard.hpp): its forces are the exact gradient of its energy
// (central differences on a sphere sunk past the guard depth), nothing acts on nodes above the guard depth,
// the stiffness it hands the solve is k_g A_i exactly where it acts, and each cell of a batch gets its own
// constants.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "core/host_copy.hpp"
#include "kernels/substrate_guard.hpp"

namespace dcm {
namespace {

using Exec = Kokkos::DefaultExecutionSpace;
using Mem = Exec::memory_space;
using Scalars = Kokkos::View<double*, Kokkos::LayoutRight, Mem>;
using Vector = Kokkos::View<double* [3], Kokkos::LayoutRight, Mem>;

constexpr double kR = 3.25e-6, kDepth = 100e-9, kStiff = 2.5e13;

SubstrateGuard guard(double depth = kDepth, double stiffness = kStiff) {
  SubstrateGuard g;
  g.depth = depth;
  g.stiffness = stiffness;
  g.plane.point = {0, 0, 0};
  g.plane.normal = {0, 0, 2};  // not unit: the kernel normalises it
  return g;
}

// A 162-node sphere whose bottom is `sink` below the plane z = 0; node areas from 0.5 to 1.5 µm² (any fixed
// values: the guard takes them as given).
struct Sunk {
  MeshBuffers<Mem> mesh;
  Scalars area;
  explicit Sunk(double sink, int cells = 1) {
    std::vector<HostCell> list;
    for (int c = 0; c < cells; ++c) {
      HostMesh m = make_icosphere(2, kR);
      for (auto& p : m.nodes) {
        p[2] += kR - sink;
        p[0] += 20e-6 * c;
      }
      list.emplace_back(std::move(m));
    }
    mesh = upload_cells<Mem>(list);
    area = Scalars("area", mesh.n_nodes);
    auto h = Kokkos::create_mirror_view(area);
    for (int i = 0; i < mesh.n_nodes; ++i) h(i) = (0.5 + (i % 11) / 10.0) * 1e-12;
    Kokkos::deep_copy(area, h);
  }
};

// On the plane z = 0 and on a tilted one (normal (0.3, −0.2, 2), not unit: the kernel normalises it): the
// force is k_g A_i e_i n̂ on the nodes past the guard depth, 0 elsewhere, and the energy's exact gradient.
TEST(SubstrateGuard, ForcesAreTheEnergyGradientAndActOnlyPastTheDepth) {
  for (const Real3 normal : {Real3{0, 0, 2}, Real3{0.3, -0.2, 2}}) {
    const Sunk s(0.6e-6);
    SubstrateGuard g = guard();
    g.plane.normal = normal;
    const Real3 nh = (1.0 / norm(normal)) * normal;
    Vector force("force", s.mesh.n_nodes);
    Scalars k("k", s.mesh.n_nodes);
    add_substrate_guard_forces(Exec(), s.mesh, g, s.area, force, k);
    const auto f = to_host_vector(force), kh = to_host_vector(k), a = to_host_vector(s.area);
    auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), s.mesh.x);
    int acting = 0;
    double worst = 0, fmax = 0;
    for (int i = 0; i < s.mesh.n_nodes; ++i) {
      const double excess = -dot(Real3{x(i, 0), x(i, 1), x(i, 2)}, nh) - kDepth;
      const double expected = excess > 0 ? kStiff * a[i] * excess : 0.0;
      if (excess > 0) {
        ++acting;
        EXPECT_DOUBLE_EQ(kh[i], kStiff * a[i]) << "node " << i;
      } else {
        EXPECT_EQ(kh[i], 0.0) << "node " << i;
      }
      const double along[3] = {nh.x, nh.y, nh.z};
      for (int d = 0; d < 3; ++d) {
        if (excess > 0)
          EXPECT_NEAR(f[3 * i + d], expected * along[d], 1e-12 * expected)
              << "node " << i << " component " << d;
        else
          EXPECT_EQ(f[3 * i + d], 0.0) << "node " << i << " above the guard depth";
        fmax = std::max(fmax, std::abs(f[3 * i + d]));
        const double step = 1e-3 * kDepth, x0 = x(i, d);
        x(i, d) = x0 + step;
        Kokkos::deep_copy(s.mesh.x, x);
        const double ep = substrate_guard_energy(Exec(), s.mesh, g, s.area);
        x(i, d) = x0 - step;
        Kokkos::deep_copy(s.mesh.x, x);
        const double em = substrate_guard_energy(Exec(), s.mesh, g, s.area);
        x(i, d) = x0;
        worst = std::max(worst, std::abs(-(ep - em) / (2 * step) - f[3 * i + d]));
      }
    }
    Kokkos::deep_copy(s.mesh.x, x);
    // The bottom 0.5 µm past the guard depth: the nodes of the lowest rings.
    EXPECT_GE(acting, 6);
    EXPECT_LT(acting, 40);
    EXPECT_GT(fmax, 0.0);
    EXPECT_LT(worst, 1e-6 * fmax);
    std::printf(
        "  normal (%g, %g, %g): %d of 162 nodes past the guard depth, largest force %.3g N, worst "
        "difference %.3g N\n",
        normal.x, normal.y, normal.z, acting, fmax, worst);
  }
}

TEST(SubstrateGuard, ABoundMembraneAboveTheDepthFeelsNothing) {
  const Sunk s(0.9 * kDepth);  // the lowest node 90 nm deep: within the guard depth
  Vector force("force", s.mesh.n_nodes);
  Scalars k("k", s.mesh.n_nodes);
  add_substrate_guard_forces(Exec(), s.mesh, guard(), s.area, force, k);
  for (const double v : to_host_vector(force)) EXPECT_EQ(v, 0.0);
  for (const double v : to_host_vector(k)) EXPECT_EQ(v, 0.0);
  EXPECT_EQ(substrate_guard_energy(Exec(), s.mesh, guard(), s.area), 0.0);
}

TEST(SubstrateGuard, EachCellOfABatchHasItsOwnConstants) {
  const Sunk both(0.6e-6, 2), one(0.6e-6);
  const SubstrateGuard g0 = guard(), g1 = guard(0.2e-6, 4e13);
  const PerCell<SubstrateGuard, Mem> guards(std::vector<SubstrateGuard>{g0, g1});
  Vector force("force", both.mesh.n_nodes);
  Scalars k("k", both.mesh.n_nodes);
  add_substrate_guard_forces(Exec(), both.mesh, guards.table(), both.area, force, k);
  const auto f = to_host_vector(force);
  std::vector<double> per_cell;
  const double e = substrate_guard_energy(Exec(), both.mesh, guards.table(), both.area, &per_cell);
  ASSERT_EQ(per_cell.size(), 2u);
  EXPECT_NEAR(e, per_cell[0] + per_cell[1], 1e-12 * e);
  // Each cell alone with its own constants and its own node areas: the same forces, bit for bit.
  const int n = one.mesh.n_nodes;
  for (int c = 0; c < 2; ++c) {
    Scalars area("area", n);
    Kokkos::deep_copy(area, Kokkos::subview(both.area, std::make_pair(c * n, (c + 1) * n)));
    Vector alone("alone", n);
    Scalars ka("ka", n);
    add_substrate_guard_forces(Exec(), one.mesh, c == 0 ? g0 : g1, area, alone, ka);
    const auto h = to_host_vector(alone);
    EXPECT_EQ(std::vector<double>(f.begin() + 3 * c * n, f.begin() + 3 * (c + 1) * n), h) << "cell " << c;
    EXPECT_NEAR(substrate_guard_energy(Exec(), one.mesh, c == 0 ? g0 : g1, area), per_cell[c],
                1e-12 * per_cell[c]);
  }
}

}  // namespace
}  // namespace dcm
