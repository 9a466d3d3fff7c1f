// The crease at the contact line (kernels/contact_crease.hpp): its forces are the exact gradient of its
// energy (central differences on random rim hinges, both nodes bound or within the range), a hinge lying flat
// on the plane stores nothing, a wall rising from a bound edge stores W ρ |e| f(c) and is turned toward
// laying down outside, and nothing acts on an edge whose node is beyond the range; a wing folded back past
// the clamp still gets the exact gradient; the per-node gather of a whole mesh is the gradient of
// crease_energy, with each cell's own constants in a batch.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/host_copy.hpp"
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

// The largest difference between the hinge's forces and central differences of its energy, and the largest
// force (0, 0 when the hinge stores nothing).
void gradient_error(const Real3 x[4], double& worst, double& fmax) {
  Real3 f[4];
  worst = fmax = 0;
  if (crease_hinge(x[0], x[1], x[2], x[3], law(), f) == 0) return;
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
      const double fd =
          -(crease_hinge(p[0], p[1], p[2], p[3], law(), g) - crease_hinge(m[0], m[1], m[2], m[3], law(), g)) /
          (2 * step);
      const double fa = d == 0 ? f[a].x : d == 1 ? f[a].y : f[a].z;
      worst = std::max(worst, std::abs(fd - fa));
    }
}

TEST(ContactCrease, ForcesAreTheEnergyGradient) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> z(-0.3 * kH0, 1.2 * kH0), u(-1, 1);
  int checked = 0;
  for (int trial = 0; trial < 200; ++trial) {
    Real3 x[4];
    rim_hinge(z(rng), z(rng), kL * (0.3 + 0.7 * (u(rng) + 1)), 0.3 * kL * u(rng), x);
    for (auto& p : x) p += Real3{0.05 * kL * u(rng), 0.05 * kL * u(rng), 0.02 * kL * u(rng)};
    double worst, fmax;
    gradient_error(x, worst, fmax);
    if (fmax == 0) continue;
    EXPECT_LT(worst, 1e-5 * fmax) << "trial " << trial;
    ++checked;
  }
  EXPECT_GT(checked, 100);
}

// A wall folded back over the bound membrane (its wing turned by more than acos(−0.95) = 162° from the bound
// plane): f is clamped there, so that wing adds no moment, and the forces are still the exact gradient.
TEST(ContactCrease, AWingFoldedBackPastTheClampIsStillTheGradient) {
  Real3 x[4];
  rim_hinge(0.1 * kH0, 0.2 * kH0, 0.15 * kL, 0.8 * kL, x);  // l far inside and low: the wall wing lies back
  const Real3 n2 = cross(x[0] - x[1], x[3] - x[1]);
  ASSERT_LT(-n2.z / norm(n2), kCreaseMinCos) << "the wing is past the clamp";
  double worst, fmax;
  gradient_error(x, worst, fmax);
  ASSERT_GT(fmax, 0.0);
  EXPECT_LT(worst, 1e-5 * fmax);
  // The clamped wing's far node gets nothing from its fold (only the other wing's and the length's terms,
  // which do not involve l).
  Real3 f[4];
  crease_hinge(x[0], x[1], x[2], x[3], law(), f);
  EXPECT_EQ(norm(f[3]), 0.0);
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
  // the wall wing (j, i, l): n ∝ (x_i − x_j) × (x_l − x_j) = (H, 0, lean) L; its turn from −z: c = −n_z
  const Real3 n2 = cross(x[0] - x[1], x[3] - x[1]);
  const double c = -n2.z / norm(n2), g = (1 - c) / (1 + c);
  EXPECT_NEAR(e, kW * kRho * kL * (std::sqrt(g + kCreaseEps * kCreaseEps) - kCreaseEps), 1e-12 * e);
  EXPECT_GT(e, 0.0);
  // The wall's far node is turned about the rim outward, toward laying the wall down outside (+x): along
  // (H, 0, lean), outward and, while the wall leans inward, up; mostly along that turn.
  const Real3 turn = (1 / std::hypot(H, lean)) * Real3{H, 0, lean};
  EXPECT_GT(dot(f[3], turn), 0.9 * norm(f[3]));
  // Node i beyond h0 (j still on the plane): nothing acts.
  rim_hinge(1.01 * kH0, 0, H, lean, x);
  EXPECT_EQ(crease_hinge(x[0], x[1], x[2], x[3], law(), f), 0.0);
}

// The per-node gather (add_crease_forces) against central differences of crease_energy on a whole mesh: a
// 162-node sphere whose lower part is pressed onto the plane (nodes below it put at random heights within the
// range), and a second cell, the same sphere shifted, with other constants in one batch: each cell's forces
// are those of its own law alone.
TEST(ContactCrease, TheNodeGatherIsTheGradientOfTheEnergyPerCell) {
  using Exec = Kokkos::DefaultExecutionSpace;
  using Mem = Exec::memory_space;
  HostMesh sphere = make_icosphere(2, 3.25e-6);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> z(-0.3 * kH0, 0.9 * kH0);
  for (auto& p : sphere.nodes) {
    p[2] += 0.7 * 3.25e-6;
    if (p[2] < 0) p[2] = z(rng);
  }
  HostMesh shifted = sphere;
  for (auto& p : shifted.nodes) p[0] += 20e-6;
  const int n = static_cast<int>(sphere.nodes.size());
  const auto mesh = upload_cells<Mem>({HostCell(sphere), HostCell(shifted)});
  CreaseLaw other = law();
  other.W = 3e-3;
  other.h0 = 30e-9;
  other.rho = 2e-8;
  const PerCell<CreaseLaw, Mem> laws(std::vector<CreaseLaw>{law(), other});
  Kokkos::View<double* [3], Kokkos::LayoutRight, Mem> force("force", mesh.n_nodes);
  add_crease_forces(Exec(), mesh, laws.table(), force);
  const auto f = to_host_vector(force);
  std::vector<double> per_cell;
  const double e0 = crease_energy(Exec(), mesh, laws.table(), &per_cell);
  ASSERT_EQ(per_cell.size(), 2u);
  EXPECT_GT(per_cell[0], 0.0);
  EXPECT_GT(per_cell[1], per_cell[0]) << "the second cell's larger W rho";
  EXPECT_NEAR(e0, per_cell[0] + per_cell[1], 1e-12 * e0);
  // Central differences of the batch's energy, every component of every node (a hinge the gather missed
  // would leave a zero force where the energy still moves).
  auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.x);
  double worst = 0, fmax = 0;
  int checked = 0;
  for (int i = 0; i < mesh.n_nodes; ++i)
    for (int d = 0; d < 3; ++d) {
      if (f[3 * i + d] != 0) ++checked;
      fmax = std::max(fmax, std::abs(f[3 * i + d]));
      const double step = 1e-4 * kH0, x0 = x(i, d);
      x(i, d) = x0 + step;
      Kokkos::deep_copy(mesh.x, x);
      const double ep = crease_energy(Exec(), mesh, laws.table());
      x(i, d) = x0 - step;
      Kokkos::deep_copy(mesh.x, x);
      const double em = crease_energy(Exec(), mesh, laws.table());
      x(i, d) = x0;
      worst = std::max(worst, std::abs(-(ep - em) / (2 * step) - f[3 * i + d]));
    }
  Kokkos::deep_copy(mesh.x, x);
  EXPECT_GT(checked, 30);
  EXPECT_LT(worst, 1e-5 * fmax);
  // Each cell alone with its own law: the same forces, bit for bit.
  const auto alone0 = upload_cells<Mem>({HostCell(sphere)}), alone1 = upload_cells<Mem>({HostCell(shifted)});
  Kokkos::View<double*[3], Kokkos::LayoutRight, Mem> f0("f0", n), f1("f1", n);
  add_crease_forces(Exec(), alone0, law(), f0);
  add_crease_forces(Exec(), alone1, other, f1);
  const auto h0 = to_host_vector(f0), h1 = to_host_vector(f1);
  EXPECT_EQ(std::vector<double>(f.begin(), f.begin() + 3 * n), h0);
  EXPECT_EQ(std::vector<double>(f.begin() + 3 * n, f.end()), h1);
  std::printf("  %d non-zero force components of 972 checked, largest %.3g N, worst difference %.3g N\n",
              checked, fmax, worst);
}

}  // namespace
}  // namespace dcm
