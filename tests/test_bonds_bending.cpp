// FENE + POW bonds and hinge bending: forces against central-difference gradients of the energies,
// zero at the rest shape, zero net force and torque, closed-form cases, the overstretch flag, several
// cells in one set of buffers, and independence of the execution space.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "core/host_copy.hpp"
#include "kernels/bending.hpp"
#include "kernels/fene_pow_bonds.hpp"
#include "solvers/bending_stiffness.hpp"

namespace dcm {
namespace {

constexpr double kRadius = 3.25e-6;  // m
constexpr double kKb = 2.4e-19;      // J (Table 1)
const FenePowParams kFene{3.2e-6, 2.05};

using Exec = Kokkos::DefaultExecutionSpace;
using Mem = Exec::memory_space;
template <class M>
using ForceView = Kokkos::View<double* [3], Kokkos::LayoutRight, M>;

double mean_edge_length(const HostMesh& m) {
  const Topology t = build_topology(m);
  double sum = 0;
  for (const auto& e : t.edges) {
    double d2 = 0;
    for (int c = 0; c < 3; ++c) d2 += std::pow(m.nodes[e[0]][c] - m.nodes[e[1]][c], 2);
    sum += std::sqrt(d2);
  }
  return sum / t.edges.size();
}

// Every coordinate moved by a uniform random amount in [-amount, amount] (fixed seed).
HostMesh perturbed(HostMesh m, double amount, unsigned seed = 20130101u) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amount, amount);
  for (auto& p : m.nodes)
    for (double& v : p) v += u(rng);
  return m;
}

template <class M>
void set_positions(const MeshBuffers<M>& mesh, const HostMesh& m) {
  auto h = Kokkos::create_mirror_view(mesh.x);
  for (std::size_t i = 0; i < m.nodes.size(); ++i)
    for (int c = 0; c < 3; ++c) h(i, c) = m.nodes[i][c];
  Kokkos::deep_copy(mesh.x, h);
}

// Test rig: mesh and rest states from `rest_shape`, positions from `shape`.
template <class E = Exec>
struct Rig {
  using M = typename E::memory_space;
  MeshBuffers<M> mesh;
  BondRest<M> bonds;
  HingeRest<M> hinges;
  Rig(const std::vector<HostCell>& rest_cells, const HostMesh* shape = nullptr)
      : mesh(upload_cells<M>(rest_cells)),
        bonds(make_bond_rest(E(), mesh)),
        hinges(make_hinge_rest(E(), mesh)) {
    if (shape) set_positions(mesh, *shape);
  }
  Rig(const HostMesh& rest_shape, const HostMesh& shape) : Rig({HostCell(rest_shape)}, &shape) {}
  explicit Rig(const HostMesh& rest_shape) : Rig({HostCell(rest_shape)}) {}

  std::vector<double> fene_forces(int* flag = nullptr) const {
    ForceView<M> f("f", mesh.n_nodes);
    Kokkos::View<int, M> over("over");
    Kokkos::deep_copy(over, -1);
    add_fene_pow_forces(E(), mesh, bonds, kFene, f, over);
    E().fence();
    if (flag) Kokkos::deep_copy(*flag, over);
    return to_host_vector(f);
  }
  std::vector<double> bending_forces(bool per_node = false) const {
    ForceView<M> f("f", mesh.n_nodes);
    if (per_node)
      add_bending_forces_per_node(E(), mesh, hinges, kKb, f);
    else
      add_bending_forces(E(), mesh, hinges, kKb, f);
    E().fence();
    return to_host_vector(f);
  }
  double fene_energy() const { return fene_pow_energy(E(), mesh, bonds, kFene); }
  double bend_energy() const { return bending_energy(E(), mesh, hinges, kKb); }
};

double node_norm(const std::vector<double>& f, std::size_t i) {
  return std::sqrt(f[3 * i] * f[3 * i] + f[3 * i + 1] * f[3 * i + 1] + f[3 * i + 2] * f[3 * i + 2]);
}
double max_norm(const std::vector<double>& f) {
  double m = 0;
  for (std::size_t i = 0; i < f.size() / 3; ++i) m = std::max(m, node_norm(f, i));
  return m;
}

// Central differences of the energy, node by node, component by component: F_fd = -dU/dx.
// FD step as a fraction of the mean edge length (DCM_FD_STEP overrides, for a step study).
double fd_step() {
  const char* s = std::getenv("DCM_FD_STEP");
  return s ? std::atof(s) : 3e-5;
}

template <class EnergyOf>
std::vector<double> fd_forces(const MeshBuffers<Mem>& mesh, double h, EnergyOf&& energy) {
  std::vector<double> f(3 * mesh.n_nodes);
  auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.x);
  for (int i = 0; i < mesh.n_nodes; ++i)
    for (int c = 0; c < 3; ++c) {
      const double x0 = x(i, c);
      Kokkos::deep_copy(Kokkos::subview(mesh.x, i, c), x0 + h);
      const double up = energy();
      Kokkos::deep_copy(Kokkos::subview(mesh.x, i, c), x0 - h);
      const double down = energy();
      Kokkos::deep_copy(Kokkos::subview(mesh.x, i, c), x0);
      f[3 * i + c] = -(up - down) / (2 * h);
    }
  return f;
}

// Relative error of the whole force vector, and the worst per-node relative error among nodes whose
// force is at least a tenth of the rms (where a relative error means something).
struct FdError {
  double global = 0, worst_node = 0;
};
FdError compare(const std::vector<double>& f, const std::vector<double>& fd) {
  double diff2 = 0, norm2 = 0;
  for (std::size_t a = 0; a < f.size(); ++a) {
    diff2 += (f[a] - fd[a]) * (f[a] - fd[a]);
    norm2 += f[a] * f[a];
  }
  FdError e;
  e.global = std::sqrt(diff2 / norm2);
  const double rms = std::sqrt(norm2 / static_cast<double>(f.size() / 3));
  for (std::size_t i = 0; i < f.size() / 3; ++i) {
    const double fi = node_norm(f, i);
    if (fi < 0.1 * rms) continue;
    double d2 = 0;
    for (int c = 0; c < 3; ++c) d2 += std::pow(f[3 * i + c] - fd[3 * i + c], 2);
    e.worst_node = std::max(e.worst_node, std::sqrt(d2) / fi);
  }
  return e;
}

// Net force and torque relative to sum |F| and sum |x| |F|.
void expect_no_net_force_or_torque(const std::vector<double>& f, const HostMesh& shape, const char* what) {
  double net[3] = {0, 0, 0}, torque[3] = {0, 0, 0}, sum = 0, sum_moment = 0;
  for (std::size_t i = 0; i < shape.nodes.size(); ++i) {
    const double* fi = &f[3 * i];
    const Vec3& x = shape.nodes[i];
    for (int c = 0; c < 3; ++c) net[c] += fi[c];
    torque[0] += x[1] * fi[2] - x[2] * fi[1];
    torque[1] += x[2] * fi[0] - x[0] * fi[2];
    torque[2] += x[0] * fi[1] - x[1] * fi[0];
    sum += node_norm(f, i);
    sum_moment += std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) * node_norm(f, i);
  }
  const double net_norm = std::sqrt(net[0] * net[0] + net[1] * net[1] + net[2] * net[2]);
  const double torque_norm = std::sqrt(torque[0] * torque[0] + torque[1] * torque[1] + torque[2] * torque[2]);
  std::printf("  %s: |sum F| / sum |F| = %.1e, |sum x x F| / sum |x||F| = %.1e\n", what, net_norm / sum,
              torque_norm / sum_moment);
  EXPECT_LT(net_norm, 1e-13 * sum) << what;
  EXPECT_LT(torque_norm, 1e-13 * sum_moment) << what;
}

struct BondsBendingPerturbed : ::testing::Test {
  HostMesh rest = make_icosphere(2, kRadius);
  double edge = mean_edge_length(rest);
  HostMesh shape = perturbed(rest, 0.05 * edge);
};

TEST_F(BondsBendingPerturbed, FenePowForceIsMinusEnergyGradient) {
  const Rig<> s(rest, shape);
  const auto f = s.fene_forces();
  const auto fd = fd_forces(s.mesh, fd_step() * edge, [&] { return s.fene_energy(); });
  const FdError e = compare(f, fd);
  std::printf("  FENE+POW, %d nodes, h = %.0e edge: |F - F_fd| / |F| = %.2e, worst node %.2e\n",
              s.mesh.n_nodes, fd_step(), e.global, e.worst_node);
  EXPECT_LT(e.global, 1e-6);
  EXPECT_LT(e.worst_node, 1e-6);
}

TEST_F(BondsBendingPerturbed, BendingForceIsMinusEnergyGradient) {
  const Rig<> s(rest, shape);
  const auto f = s.bending_forces();
  const auto fd = fd_forces(s.mesh, fd_step() * edge, [&] { return s.bend_energy(); });
  const FdError e = compare(f, fd);
  std::printf("  bending, %d nodes, h = %.0e edge: |F - F_fd| / |F| = %.2e, worst node %.2e\n",
              s.mesh.n_nodes, fd_step(), e.global, e.worst_node);
  EXPECT_LT(e.global, 1e-6);
  EXPECT_LT(e.worst_node, 1e-6);
}

TEST_F(BondsBendingPerturbed, NoNetForceOrTorque) {
  const Rig<> s(rest, shape);
  expect_no_net_force_or_torque(s.fene_forces(), shape, "FENE+POW");
  expect_no_net_force_or_torque(s.bending_forces(), shape, "bending");
}

TEST_F(BondsBendingPerturbed, BendingGatherVariantsAgree) {
  const Rig<> s(rest, shape);
  const auto a = s.bending_forces(false), b = s.bending_forces(true);
  const double scale = max_norm(a);
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_NEAR(a[i], b[i], 1e-13 * scale) << i;
}

// The implicit bending operator Δt K_bend v (solvers/bending_stiffness.hpp, built from what the force pass
// left in HingeRest) against Σ_h Δt k_b max(cos(θ_h − θ*_h), 0) (g_h · v) g_h with g_h = ∇θ_h by central
// differences of the hinge angle, for a random v.
TEST_F(BondsBendingPerturbed, BendingStiffnessIsTheGaussNewtonHessianOfTheForcePass) {
  const Rig<> s(rest, shape);
  s.bending_forces();  // the hinge pass the stiffness reuses
  const double dt = 6e-6;
  BendingStiffness<Mem> bs(s.mesh);
  update_bending_stiffness(kKb, dt, bs);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<double> v(3 * s.mesh.n_nodes);
  for (double& c : v) c = u(rng);
  ForceView<Mem> vin("v", s.mesh.n_nodes), out("out", s.mesh.n_nodes);
  from_host_vector(vin, v);
  apply_bending_stiffness(Exec(), s.mesh, s.hinges, bs, vin, out);
  Exec().fence();
  const auto got = to_host_vector(out);
  const auto hinge = to_host_vector(s.mesh.hinge);
  const auto theta_rest = hinge_rest_angles(s.hinges);
  std::vector<double> x = to_host_vector(s.mesh.x), ref(v.size(), 0.0);
  const double h = 1e-6 * edge;
  auto angle = [&](int k) {
    auto p = [&](int a) {
      return Real3{x[3 * hinge[4 * k + a]], x[3 * hinge[4 * k + a] + 1], x[3 * hinge[4 * k + a] + 2]};
    };
    return hinge_angle(p(0), p(1), p(2), p(3));
  };
  for (std::size_t k = 0; k < theta_rest.size(); ++k) {
    double g[12];
    for (int a = 0; a < 4; ++a)
      for (int c = 0; c < 3; ++c) {
        double& xc = x[3 * hinge[4 * k + a] + c];
        const double x0 = xc;
        xc = x0 + h;
        const double tp = angle(static_cast<int>(k));
        xc = x0 - h;
        const double tm = angle(static_cast<int>(k));
        xc = x0;
        g[3 * a + c] = (tp - tm) / (2 * h);
      }
    const double w2 = dt * kKb * std::max(std::cos(angle(static_cast<int>(k)) - theta_rest[k]), 0.0);
    double gv = 0;
    for (int a = 0; a < 4; ++a)
      for (int c = 0; c < 3; ++c) gv += g[3 * a + c] * v[3 * hinge[4 * k + a] + c];
    for (int a = 0; a < 4; ++a)
      for (int c = 0; c < 3; ++c) ref[3 * hinge[4 * k + a] + c] += w2 * gv * g[3 * a + c];
  }
  double d2 = 0, r2 = 0;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    d2 += (got[i] - ref[i]) * (got[i] - ref[i]);
    r2 += ref[i] * ref[i];
  }
  std::printf("  dt K_bend v against the finite-difference Gauss-Newton operator: relative error %.2e\n",
              std::sqrt(d2 / r2));
  EXPECT_GT(r2, 0);
  EXPECT_LT(std::sqrt(d2 / r2), 1e-6);
}

TEST(BondsBendingRestShape, ForcesVanish) {
  for (const HostMesh& m : {make_icosphere(3, kRadius), make_evans_fung(3)}) {
    const Rig<> s(m);
    const double edge = mean_edge_length(m);
    const double fene = max_norm(s.fene_forces()), bend = max_norm(s.bending_forces());
    std::printf("  %zu nodes at rest: max |F_fene| / (k_s d*) = %.1e, max |F_bend| / (k_b / d*) = %.1e\n",
                m.nodes.size(), fene / (kFene.k_s * edge), bend / (kKb / edge));
    EXPECT_LT(fene, 1e-12 * kFene.k_s * edge);
    EXPECT_LT(bend, 1e-12 * kKb / edge);
    EXPECT_NEAR(s.bend_energy(), 0.0, 1e-12 * kKb);
  }
}

// One bond away from its rest length, all others at rest: the force on its ends is eq. 22 + eq. 23.
TEST(FenePowSingleBond, ForceMatchesEquations22And23) {
  const HostMesh m = make_icosphere(1, kRadius);
  const Rig<> s(m);
  auto rest_h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), s.bonds.rest_length);
  auto bond_h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), s.mesh.bond);
  const int b = 7, i = bond_h(b, 0), j = bond_h(b, 1);
  const double d = rest_h(b);
  double u[3];
  for (int c = 0; c < 3; ++c) u[c] = (m.nodes[i][c] - m.nodes[j][c]) / d;  // from j to i
  std::printf("     d/d*   F (radial, N)   eq. 22 + 23\n");
  for (double stretch : {0.3, 0.6, 0.9, 1.0, 1.1, 1.5, 2.0, 2.04}) {
    const double d_rest = d / stretch, d_max = kFene.x_max * d_rest;
    Kokkos::deep_copy(Kokkos::subview(s.bonds.rest_length, b), d_rest);
    const auto f = s.fene_forces();
    const double radial = f[3 * i] * u[0] + f[3 * i + 1] * u[1] + f[3 * i + 2] * u[2];
    const double k_c = kFene.k_s * std::pow(d_rest, 3) / (1 - std::pow(d_rest / d_max, 2));  // eq. 24
    const double expected = -kFene.k_s * d / (1 - std::pow(d / d_max, 2))                    // eq. 22
                            + k_c / (d * d);                                                 // eq. 23
    std::printf("    %5.2f   %+.6e   %+.6e\n", stretch, radial, expected);
    EXPECT_NEAR(radial, expected, 1e-12 * std::fabs(expected) + 1e-13 * kFene.k_s * d);
    if (stretch > 1) {
      EXPECT_LT(radial, 0) << "attractive above d*";
    } else if (stretch < 1) {
      EXPECT_GT(radial, 0) << "repulsive below d*";
    } else {
      EXPECT_LT(std::fabs(radial), 1e-13 * kFene.k_s * d);
    }
    // Newton's third law on the bond, nothing elsewhere.
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(f[3 * j + c], -f[3 * i + c], 1e-13 * kFene.k_s * d);
    for (std::size_t n = 0; n < m.nodes.size(); ++n) {
      if (static_cast<int>(n) != i && static_cast<int>(n) != j) {
        EXPECT_LT(node_norm(f, n), 1e-13 * kFene.k_s * d);
      }
    }
  }
}

TEST(FenePowSingleBond, OverstretchIsFlaggedWithoutNaN) {
  const HostMesh m = make_icosphere(1, kRadius);
  const Rig<> s(m);
  int flag = 0;
  s.fene_forces(&flag);
  EXPECT_EQ(flag, -1);
  auto rest_h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), s.bonds.rest_length);
  const int b = 11;
  Kokkos::deep_copy(Kokkos::subview(s.bonds.rest_length, b), rest_h(b) / (1.0001 * kFene.x_max));
  const auto f = s.fene_forces(&flag);
  EXPECT_EQ(flag, b);
  for (double v : f) EXPECT_TRUE(std::isfinite(v));
  EXPECT_LT(max_norm(f), 1e-13 * kFene.k_s * rest_h(b));  // the bad bond contributes nothing
  EXPECT_TRUE(std::isinf(s.fene_energy()));
}

// Two triangles sharing the edge (0,0,0)-(1,0,0); l rotated about the edge by phi: theta = phi.
TEST(BendingSingleHinge, AngleAndEnergyOfAKnownBend) {
  const Real3 xi{0, 0, 0}, xj{1, 0, 0}, xk{0.3, 1, 0};
  for (double phi : {-2.5, -1.0, -0.2, 0.0, 0.4, 1.3, 3.0}) {
    const Real3 xl{0.6, -0.8 * std::cos(phi), -0.8 * std::sin(phi)};
    const double theta = hinge_angle(xi, xj, xk, xl);
    EXPECT_NEAR(theta, phi, 1e-14) << "convex (l folded below the outward normal) is positive";
    double c = 0, s = 0;
    Real3 grad[4];
    EXPECT_TRUE(hinge_trig_gradient(xi, xj, xk, xl, c, s, grad));
    EXPECT_NEAR(c, std::cos(phi), 1e-15) << "the kernels' cos theta without atan2";
    EXPECT_NEAR(s, std::sin(phi), 1e-15) << "the kernels' sin theta without atan2";
    for (double theta_rest : {0.0, 0.25}) {
      Real3 f[4];
      hinge_bending_forces(xi, xj, xk, xl, std::cos(theta_rest), std::sin(theta_rest), kKb, f);
      const Real3 net = f[0] + f[1] + f[2] + f[3];
      EXPECT_LT(norm(net), 1e-14 * kKb);
    }
  }
}

// Regular tetrahedron: every theta = arccos(-1/3); against a flat rest shape U = 6 k_b (1 + 1/3).
TEST(BendingTetrahedron, HingeAnglesAndEnergyAgainstFlatRest) {
  HostMesh m;
  m.nodes = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  for (Vec3& p : m.nodes)
    for (double& v : p) v *= 1e-6;
  m.triangles = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
  const Rig<> s(m);
  for (double theta : hinge_rest_angles(s.hinges)) EXPECT_NEAR(theta, std::acos(-1.0 / 3), 1e-14);
  set_hinge_rest_angles(s.hinges, {0.0});
  EXPECT_NEAR(s.bend_energy(), 8 * kKb, 1e-14 * kKb);
}

TEST(BendingSphere, AllHingeAnglesPositiveEvansFungDimpleNegative) {
  const Rig<> sphere(make_icosphere(4, kRadius));
  const auto ts = hinge_rest_angles(sphere.hinges);
  EXPECT_GT(*std::min_element(ts.begin(), ts.end()), 0.0);
  const Rig<> rbc(make_evans_fung(4));
  const auto tr = hinge_rest_angles(rbc.hinges);
  std::printf("  sphere theta in [%.4f, %.4f]; Evans-Fung theta in [%.4f, %.4f]\n",
              *std::min_element(ts.begin(), ts.end()), *std::max_element(ts.begin(), ts.end()),
              *std::min_element(tr.begin(), tr.end()), *std::max_element(tr.begin(), tr.end()));
  EXPECT_LT(*std::min_element(tr.begin(), tr.end()), 0.0);  // the concave dimple
}

// A hinge bent by dtheta away from its rest angle: U = k_b (1 - cos dtheta).
TEST(BendingSphere, EnergyOfOneHingeBentByKnownAngle) {
  const Rig<> s(make_icosphere(2, kRadius));
  const double dtheta = 0.37;
  auto theta = hinge_rest_angles(s.hinges);
  theta[5] -= dtheta;
  set_hinge_rest_angles(s.hinges, theta);
  EXPECT_NEAR(s.bend_energy(), kKb * (1 - std::cos(dtheta)), 1e-13 * kKb);
}

TEST(BondsBendingSeveralCells, EachCellAsIfAlone) {
  const HostMesh a_rest = make_icosphere(2, kRadius);
  HostMesh b_rest = make_evans_fung(2);
  translate(b_rest, {20e-6, 0, 0});
  const HostMesh a = perturbed(a_rest, 0.05 * mean_edge_length(a_rest), 1);
  const HostMesh b = perturbed(b_rest, 0.05 * mean_edge_length(b_rest), 2);
  HostMesh both = a;
  both.nodes.insert(both.nodes.end(), b.nodes.begin(), b.nodes.end());
  const Rig<> sa(a_rest, a), sb(b_rest, b), sab({HostCell(a_rest), HostCell(b_rest)}, &both);
  const auto fa = sa.fene_forces(), fb = sb.fene_forces(), fab = sab.fene_forces();
  const auto ga = sa.bending_forces(), gb = sb.bending_forces(), gab = sab.bending_forces();
  ASSERT_EQ(fab.size(), fa.size() + fb.size());
  for (std::size_t n = 0; n < fa.size(); ++n) {
    EXPECT_EQ(fab[n], fa[n]);
    EXPECT_EQ(gab[n], ga[n]);
  }
  for (std::size_t n = 0; n < fb.size(); ++n) {
    EXPECT_EQ(fab[fa.size() + n], fb[n]);
    EXPECT_EQ(gab[fa.size() + n], gb[n]);
  }
}

#if defined(KOKKOS_ENABLE_SERIAL) && defined(KOKKOS_ENABLE_OPENMP)
TEST(BondsBendingBackends, SerialAndOpenMPAgree) {
  const HostMesh rest = make_evans_fung(4);
  const HostMesh shape = perturbed(rest, 0.05 * mean_edge_length(rest));
  const Rig<Kokkos::Serial> s(rest, shape);
  const Rig<Kokkos::OpenMP> o(rest, shape);
  auto same = [](const std::vector<double>& a, const std::vector<double>& b, const char* what) {
    ASSERT_EQ(a.size(), b.size()) << what;
    for (std::size_t i = 0; i < a.size(); ++i)
      EXPECT_LE(std::fabs(a[i] - b[i]), 1e-12 * std::fabs(a[i]) + 1e-300) << what << "[" << i << "]";
  };
  same(s.fene_forces(), o.fene_forces(), "fene_pow");
  same(s.bending_forces(), o.bending_forces(), "bending");
  same(s.bending_forces(true), o.bending_forces(true), "bending per node");
  EXPECT_NEAR(s.fene_energy(), o.fene_energy(), 1e-12 * s.fene_energy());
  EXPECT_NEAR(s.bend_energy(), o.bend_energy(), 1e-12 * s.bend_energy());
}
#endif

}  // namespace
}  // namespace dcm

namespace dcm {
namespace {
// The axial stiffness used by the linearly implicit bonds is dF/dd of the FENE+POW force (central
// differences, relative 1e-7), positive everywhere, and grows without bound towards d_max.
TEST(FenePow, AxialStiffnessIsTheDerivativeOfTheForce) {
  const double k_s = 3.2e-6, x_max = 2.05, d0 = 0.5e-6;
  double previous = 0;
  for (double s : {0.5, 0.8, 1.0, 1.3, 1.7, 2.0, 2.04, 2.049}) {
    const double d = s * d0, h = 1e-6 * d * (x_max - s);
    const double fd =
        (fene_pow_force_magnitude(d + h, d0, k_s, x_max) - fene_pow_force_magnitude(d - h, d0, k_s, x_max)) /
        (2 * h);
    const double k = fene_pow_axial_stiffness(d, d0, k_s, x_max);
    EXPECT_NEAR(k, fd, 1e-6 * k) << "stretch " << s;
    EXPECT_GT(k, 0.0);
    if (s > 1.0) {
      EXPECT_GT(k, previous) << "stiffer towards d_max";
    }
    previous = k;
  }
}
}  // namespace
}  // namespace dcm

namespace dcm {
namespace {
// The implicit step's stiffness is at least the tangent and at least the secant to half-way to d_max: a
// 1D bond pulled by a constant force F_pull from a length where F(d) < F_pull, stepped with (c/Δt + k) Δd =
// F_pull − F(d), never passes the half-way point as long as F_pull ≤ F(d_h), and so never reaches d_max.
TEST(FenePow, ImplicitStiffnessBoundsTheStepToHalfWay) {
  const double k_s = 3.2e-6, x_max = 2.05, d0 = 0.25e-6, d_max = x_max * d0;
  for (double s : {1.0, 1.5, 1.9, 2.0, 2.04}) {
    const double d = s * d0, d_half = d + 0.5 * (d_max - d);
    const double k = fene_pow_implicit_stiffness(d, d0, k_s, x_max);
    EXPECT_GE(k, fene_pow_axial_stiffness(d, d0, k_s, x_max));
    const double pull = fene_pow_force_magnitude(d_half, d0, k_s, x_max);  // the largest pull covered
    const double step = (pull - fene_pow_force_magnitude(d, d0, k_s, x_max)) / k;
    EXPECT_LE(d + step, d_half * (1 + 1e-12)) << "stretch " << s;
    // With the tangent alone the same pull overshoots d_max near the singularity.
    if (s >= 1.9) {
      const double tangent_step =
          (pull - fene_pow_force_magnitude(d, d0, k_s, x_max)) / fene_pow_axial_stiffness(d, d0, k_s, x_max);
      EXPECT_GT(d + tangent_step, d_half) << "stretch " << s;
    }
  }
}
}  // namespace
}  // namespace dcm

namespace dcm {
namespace {

// cortex.bond_prestretch: d* = the given length / prestretch, per cell. A prestretched sphere's bonds pull
// every node toward the centre (the tension a swollen cell carries), and its FENE energy is that of bonds at
// stretch s; the cell given with prestretch 1 has zero bond force in its given shape.
TEST(BondPrestretch, RestLengthsPerCellAndTheTensionOfASwollenSphere) {
  const HostMesh sphere = make_icosphere(2, kRadius);
  HostMesh shifted = sphere;
  for (auto& p : shifted.nodes) p[0] += 10 * kRadius;
  const auto mesh = upload_cells<Mem>({HostCell(sphere), HostCell(shifted)});
  const double s = 1.5;
  const auto plain = to_host_vector(make_bond_rest(Exec(), mesh).rest_length);
  const auto pre = to_host_vector(make_bond_rest(Exec(), mesh, {1.0, s}).rest_length);
  const auto cell = to_host_vector(mesh.bond_cell);
  ASSERT_EQ(pre.size(), plain.size());
  for (std::size_t b = 0; b < pre.size(); ++b)
    EXPECT_NEAR(pre[b], cell[b] == 0 ? plain[b] : plain[b] / s, 1e-15 * plain[b]) << "bond " << b;
  ForceView<Mem> f("f", mesh.n_nodes);
  Kokkos::View<int, Mem> over("over");
  Kokkos::deep_copy(over, -1);
  add_fene_pow_forces(Exec(), mesh, make_bond_rest(Exec(), mesh, {1.0, s}), kFene, f, over);
  const auto force = to_host_vector(f);
  const int n = static_cast<int>(sphere.nodes.size());
  double largest_rest = 0;
  for (int i = 0; i < n; ++i) largest_rest = std::max(largest_rest, node_norm(force, i));
  EXPECT_LT(largest_rest, 1e-20);  // cell 0: the given shape is the rest state
  for (int i = n; i < 2 * n; ++i) {
    double radial = 0;
    for (int c = 0; c < 3; ++c)
      radial += force[3 * i + c] * (shifted.nodes[i - n][c] - (c == 0 ? 10 * kRadius : 0));
    EXPECT_LT(radial, -0.5 * node_norm(force, i) * kRadius)
        << "node " << i - n << " of the prestretched cell";
  }
}

}  // namespace
}  // namespace dcm
