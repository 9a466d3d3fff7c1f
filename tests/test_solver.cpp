// The friction operator Γ and the preconditioned CG solve of Γ v = F.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>

#include "core/host_copy.hpp"
#include "core/update_geometry.hpp"
#include "solvers/global_woodbury.hpp"
#include "solvers/pcg.hpp"
#include "tests/dense_reference.hpp"
#include "tests/friction_setup.hpp"

namespace dcm {
namespace {

using namespace test_friction;

double dot_host(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

// PCG on Γ v = f (block-Jacobi) against Eigen's dense solve of the assembled Γ = a, f random (seed).
void expect_pcg_matches_eigen(const FrictionSetup& s, const Eigen::MatrixXd& a, unsigned seed) {
  const Vector f = s.random_vector(seed, 1e-12);
  const auto fh = to_host_vector(f);
  const Eigen::VectorXd ref = test_dense::cholesky_solve(a, fh);
  Vector x("x", s.mesh.n_nodes);
  CgWorkspace<Mem> ws(s.mesh.n_nodes);
  CgSettings cg;
  cg.abs_tol = 0;
  cg.rel_tol = 1e-12;
  const CgResult r = pcg_solve(
      Exec(), [&](const Vector& in, const Vector& out) { apply_friction(Exec(), s.mesh, s.op, in, out); },
      [&](const Vector& in, const Vector& out) { apply_block_jacobi(Exec(), s.op, in, out); }, f, x, ws, cg);
  EXPECT_TRUE(r.converged);
  const auto xh = to_host_vector(x);
  EXPECT_LT((Eigen::Map<const Eigen::VectorXd>(xh.data(), xh.size()) - ref).norm(), 1e-8 * ref.norm());
}

TEST(FrictionOperator, SymmetricAndPositiveOnRandomVectors) {
  const FrictionSetup s(3);
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const Vector u = s.random_vector(seed), w = s.random_vector(seed + 100);
    const auto gu = to_host_vector(s.apply(u)), gw = to_host_vector(s.apply(w));
    const auto hu = to_host_vector(u), hw = to_host_vector(w);
    const double uGw = dot_host(hu, gw), wGu = dot_host(hw, gu);
    EXPECT_NEAR(uGw, wGu, 1e-12 * std::fabs(uGw) + 1e-30);
    EXPECT_GT(dot_host(hu, gu), 0.0);
  }
}

TEST(FrictionOperator, RigidTranslationFeelsOnlyTheDrag) {
  const FrictionSetup s(3);
  Vector v("v", s.mesh.n_nodes);
  Kokkos::deep_copy(Kokkos::subview(v, Kokkos::ALL(), 0), 2.0);  // every node moves at 2 m/s along x
  const auto g = to_host_vector(s.apply(v));
  const double zeta = 6 * kPi * 0.8e-3 * 3.25e-6 / s.mesh.n_nodes;
  for (int i = 0; i < s.mesh.n_nodes; ++i) {
    EXPECT_NEAR(g[3 * i], 2 * zeta, 1e-9 * zeta);
    EXPECT_NEAR(g[3 * i + 1], 0, 1e-9 * zeta);
  }
}

TEST(FrictionOperator, MatchesTheAssembledMatrixWhichIsPositiveDefinite) {
  const FrictionSetup s(2);
  const Eigen::MatrixXd a = s.assemble();
  const Vector v = s.random_vector(21);
  const auto vh = to_host_vector(v), gv = to_host_vector(s.apply(v));
  const Eigen::VectorXd expected = a * Eigen::Map<const Eigen::VectorXd>(vh.data(), vh.size());
  EXPECT_LT((Eigen::Map<const Eigen::VectorXd>(gv.data(), gv.size()) - expected).norm(),
            1e-12 * expected.norm());
  const Eigen::VectorXd eigenvalues = test_dense::symmetric_eigenvalues(a);
  const double lo = eigenvalues.minCoeff(), hi = eigenvalues.maxCoeff();
  std::printf("  162 nodes, paper parameters: eigenvalues of Gamma in [%.3g, %.3g] N s/m, kappa = %.3g\n", lo,
              hi, hi / lo);
  EXPECT_GT(lo, 0.0);
}

// Substrate friction (MODEL.md section 5): blocks β_ti β_tj Γ_t, Γ_t = A^C_t [γ_n n̂n̂ᵀ + γ_t (I − n̂n̂ᵀ)], on
// random β and contact areas: Γ still matches its assembly, is symmetric, and the substrate part is positive
// semi-definite; the block-Jacobi diagonal includes it (PCG with it agrees with Eigen).
TEST(FrictionOperator, SubstrateBlocksMatchAssemblyAndKeepGammaSymmetricPositive) {
  FrictionSetup s(2);
  const Eigen::MatrixXd without = s.assemble();
  s.enable_random_substrate(5);
  const Eigen::MatrixXd a = s.assemble();
  // The substrate blocks from their definition, independently of assemble().
  {
    Eigen::MatrixXd b = Eigen::MatrixXd::Zero(a.rows(), a.cols());
    const auto tri = to_host_vector(s.mesh.tri);
    const auto beta = to_host_vector(s.op.tri_beta), area = to_host_vector(s.op.tri_contact_area);
    const Eigen::Vector3d nn = Eigen::Vector3d(0.2, -0.1, 1.0).normalized();
    const Eigen::Matrix3d gt =
        8e9 * nn * nn.transpose() + 6e9 * (Eigen::Matrix3d::Identity() - nn * nn.transpose());
    for (std::size_t t = 0; t < area.size(); ++t)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          b.block<3, 3>(3 * tri[3 * t + i], 3 * tri[3 * t + j]) +=
              beta[3 * t + i] * beta[3 * t + j] * area[t] * gt;
    EXPECT_LT((a - without - b).norm(), 1e-14 * a.norm());
    const Eigen::VectorXd eigenvalues = test_dense::symmetric_eigenvalues(b);
    EXPECT_GT(eigenvalues.minCoeff(), -1e-12 * eigenvalues.maxCoeff()) << "PSD";
    EXPECT_GT(eigenvalues.maxCoeff(), 0.0) << "the substrate blocks are switched on";
  }
  const Vector v = s.random_vector(31);
  const auto vh = to_host_vector(v), gv = to_host_vector(s.apply(v));
  const Eigen::VectorXd expected = a * Eigen::Map<const Eigen::VectorXd>(vh.data(), vh.size());
  EXPECT_LT((Eigen::Map<const Eigen::VectorXd>(gv.data(), gv.size()) - expected).norm(),
            1e-12 * expected.norm());
  EXPECT_LT((a - a.transpose()).norm(), 1e-14 * a.norm());
  // PCG (block-Jacobi with the substrate diagonal) against Eigen's dense solve.
  expect_pcg_matches_eigen(s, a, 41);
}

// The substrate guard taken implicit (FrictionOperator::node_guard, kernels/substrate_guard.hpp): g_i n̂n̂ᵀ on
// the diagonal block of the nodes where it acts, on top of the substrate blocks. Γ matches its assembly plus
// those blocks from their definition, stays symmetric positive definite, and PCG with the block-Jacobi
// diagonal (which carries the guard) agrees with Eigen's dense solve.
TEST(FrictionOperator, SubstrateGuardAddsNormalBlocksOnItsNodes) {
  FrictionSetup s(2);
  s.enable_random_substrate(9);
  const Eigen::MatrixXd without = s.assemble();
  const int n = s.mesh.n_nodes;
  Kokkos::View<double*, Kokkos::LayoutRight, Mem> guard("guard", n);
  auto gh = Kokkos::create_mirror_view(guard);
  for (int i = 0; i < n; ++i)
    gh(i) = i % 3 == 0 ? 1e-4 * (1 + i % 7) : 0.0;  // a third of the nodes, as strong as the substrate
  Kokkos::deep_copy(guard, gh);
  s.op.node_guard = guard;
  update_friction(Exec(), s.mesh, s.op);
  const Eigen::Vector3d nn = Eigen::Vector3d(0.2, -0.1, 1.0).normalized();  // the random substrate's normal
  Eigen::MatrixXd a = without;
  for (int i = 0; i < n; ++i) a.block<3, 3>(3 * i, 3 * i) += gh(i) * nn * nn.transpose();
  const Vector v = s.random_vector(33);
  const auto vh = to_host_vector(v), gv = to_host_vector(s.apply(v));
  const Eigen::VectorXd expected = a * Eigen::Map<const Eigen::VectorXd>(vh.data(), vh.size());
  const Eigen::VectorXd got = Eigen::Map<const Eigen::VectorXd>(gv.data(), gv.size());
  EXPECT_LT((got - expected).norm(), 1e-12 * expected.norm());
  const Eigen::VectorXd plain = without * Eigen::Map<const Eigen::VectorXd>(vh.data(), vh.size());
  EXPECT_GT((got - plain).norm(), 1e-3 * plain.norm()) << "the guard is switched on";
  // The block-Jacobi preconditioner inverts each node's diagonal block, guard included.
  const auto inv = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), s.op.block_inverse);
  double worst_inverse = 0;
  for (int i = 0; i < n; ++i) {
    const Eigen::Matrix3d blk = a.block<3, 3>(3 * i, 3 * i).inverse();
    const double got_inv[6] = {inv(i, 0), inv(i, 1), inv(i, 2), inv(i, 3), inv(i, 4), inv(i, 5)};
    const double want[6] = {blk(0, 0), blk(1, 1), blk(2, 2), blk(0, 1), blk(0, 2), blk(1, 2)};
    for (int k = 0; k < 6; ++k)
      worst_inverse = std::max(worst_inverse, std::abs(got_inv[k] - want[k]) / blk.norm());
  }
  EXPECT_LT(worst_inverse, 1e-10);
  const Eigen::VectorXd eigenvalues = test_dense::symmetric_eigenvalues(a);
  EXPECT_GT(eigenvalues.minCoeff(), 0.0);
  expect_pcg_matches_eigen(s, a, 43);
}

// Lumped substrate friction (contact.friction_weights = lumped): w_ti Γ_t on each node's own velocity. It
// matches its assembly, is diagonal in the nodes (block-Jacobi is exact for it), keeps Γ symmetric positive,
// and a rigid translation feels the same substrate force as with the consistent blocks (Σ w = Σ β = 1).
TEST(FrictionOperator, LumpedSubstrateFrictionIsBlockDiagonalAndKeepsRigidForces) {
  FrictionSetup consistent(2), lumped(2);
  const Eigen::MatrixXd without = lumped.assemble();
  consistent.enable_random_substrate(5, false);
  lumped.enable_random_substrate(5, true);
  const Eigen::MatrixXd a = lumped.assemble(), b = consistent.assemble();
  const Eigen::MatrixXd sub = a - without;
  ASSERT_GT(sub.norm(), 0.0);
  for (int i = 0; i < lumped.mesh.n_nodes; ++i)
    for (int j = 0; j < lumped.mesh.n_nodes; ++j)
      if (i != j) {
        ASSERT_EQ((sub.block<3, 3>(3 * i, 3 * j).norm()), 0.0) << i << " " << j;
      }
  const Eigen::VectorXd eigenvalues = test_dense::symmetric_eigenvalues(sub);
  EXPECT_GT(eigenvalues.minCoeff(), -1e-12 * eigenvalues.maxCoeff()) << "PSD despite β < 0";
  const Vector v = lumped.random_vector(31);
  const auto vh = to_host_vector(v), gv = to_host_vector(lumped.apply(v));
  const Eigen::VectorXd expected = a * Eigen::Map<const Eigen::VectorXd>(vh.data(), vh.size());
  EXPECT_LT((Eigen::Map<const Eigen::VectorXd>(gv.data(), gv.size()) - expected).norm(),
            1e-12 * expected.norm());
  // Net substrate force of a rigid translation u: Σ_i w_i Γ_t u = Γ_t u = (Σ_i β_i)(Σ_j β_j) Γ_t u.
  Eigen::VectorXd u(a.rows());
  for (int i = 0; i < lumped.mesh.n_nodes; ++i) u.segment<3>(3 * i) = Eigen::Vector3d(0.3, -0.5, 1.0);
  const Eigen::VectorXd fa = (a - without) * u, fb = (b - without) * u;
  Eigen::Vector3d ta = Eigen::Vector3d::Zero(), tb = Eigen::Vector3d::Zero();
  for (int i = 0; i < lumped.mesh.n_nodes; ++i) {
    ta += fa.segment<3>(3 * i);
    tb += fb.segment<3>(3 * i);
  }
  EXPECT_LT((ta - tb).norm(), 1e-12 * tb.norm()) << "Σ_i w_i Γ_t u = Σ_ij β_i β_j Γ_t u = Γ_t u";
}

// Block-Jacobi PCG of Γ v = f on s's cell (v: the start and the result).
CgResult block_jacobi_solve(const FrictionSetup& s, const Vector& f, const Vector& v, CgWorkspace<Mem>& w,
                            const CgSettings& settings) {
  const Exec space;
  return pcg_solve(
      space, [&](const Vector& in, const Vector& out) { apply_friction(space, s.mesh, s.op, in, out); },
      [&](const Vector& in, const Vector& out) { apply_block_jacobi(space, s.op, in, out); }, f, v, w,
      settings);
}

// out = −out (a free function: CUDA takes no extended lambda inside a test body).
void negate(const Exec& space, const Vector& out) {
  Kokkos::parallel_for(
      "dcm::test::negate", Kokkos::RangePolicy<Exec>(space, 0, static_cast<int>(out.extent(0))),
      KOKKOS_LAMBDA(const int i) {
        for (int d = 0; d < 3; ++d) out(i, d) = -out(i, d);
      });
}

// An operator that is not positive definite: CG stops at the first direction with p·Γp ≤ 0 and says so,
// instead of stepping by a negative or infinite α.
TEST(Pcg, ReportsBreakdownOnAnIndefiniteOperator) {
  const FrictionSetup s(2);
  const Vector f = s.random_vector(7, 1e-12);
  Vector v("v", s.mesh.n_nodes);
  CgWorkspace<Mem> w(s.mesh.n_nodes);
  CgSettings settings;
  settings.abs_tol = 0;
  settings.rel_tol = 1e-12;
  const Exec space;
  const CgResult r = pcg_solve(
      space,
      [&](const Vector& in, const Vector& out) {  // −Γ
        apply_friction(space, s.mesh, s.op, in, out);
        negate(space, out);
      },
      [&](const Vector& in, const Vector& out) { apply_block_jacobi(space, s.op, in, out); }, f, v, w,
      settings);
  EXPECT_FALSE(r.converged);
  EXPECT_TRUE(r.breakdown);
  EXPECT_EQ(r.iterations, 1);
  EXPECT_LT(r.curvature, 0.0);
  const auto vh = to_host_vector(v);
  for (const double x : vh) ASSERT_EQ(x, 0.0) << "no step taken along a direction of negative curvature";

  // The same solve with Γ itself converges and reports no breakdown.
  const CgResult ok = block_jacobi_solve(s, f, v, w, settings);
  EXPECT_TRUE(ok.converged);
  EXPECT_FALSE(ok.breakdown);
}

TEST(Pcg, AgreesWithEigenReferenceOn642Nodes) {
  const FrictionSetup s(3);  // 642 nodes, paper parameters
  const Eigen::MatrixXd a = s.assemble();
  const Vector f = s.random_vector(11, 1e-12);  // pN-scale forces
  const auto fh = to_host_vector(f);
  const Eigen::VectorXd reference = test_dense::cholesky_solve(a, fh);

  Vector v("v", s.mesh.n_nodes);  // cold start
  CgWorkspace<Mem> w(s.mesh.n_nodes);
  CgSettings settings;
  settings.abs_tol = 0;
  settings.rel_tol = 1e-12;
  const CgResult r = block_jacobi_solve(s, f, v, w, settings);
  std::printf("  642 nodes: block-Jacobi PCG, cold start, %d iterations to 1e-12 relative\n", r.iterations);
  ASSERT_TRUE(r.converged);
  const auto vh = to_host_vector(v);
  const Eigen::VectorXd diff = Eigen::Map<const Eigen::VectorXd>(vh.data(), vh.size()) - reference;
  EXPECT_LT(diff.norm(), 1e-8 * reference.norm());

  // Warm start from the solution: converged at once (round-off may ask for a few iterations: 2 with the
  // nodes in subdivision order, 3 in the locality order of session 22).
  const CgResult again = block_jacobi_solve(s, f, v, w, settings);
  EXPECT_LE(again.iterations, 3);
}

TEST(Pcg, ReportsNonConvergence) {
  const FrictionSetup s(3);
  const Vector f = s.random_vector(3, 1e-12);
  Vector v("v", s.mesh.n_nodes);
  CgWorkspace<Mem> w(s.mesh.n_nodes);
  CgSettings settings;
  settings.abs_tol = 0;
  settings.rel_tol = 1e-14;
  settings.max_iterations = 3;
  const CgResult r = block_jacobi_solve(s, f, v, w, settings);
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.iterations, 3);
}

TEST(Pcg, DiagonalSystemWithoutDashpotsIsOneStep) {
  const FrictionSetup s(3, /*c=*/0.0);
  const Vector f = s.random_vector(5, 1e-12);
  Vector v("v", s.mesh.n_nodes);
  CgWorkspace<Mem> w(s.mesh.n_nodes);
  CgSettings settings;
  settings.abs_tol = 0;
  settings.rel_tol = 1e-13;
  const CgResult r = block_jacobi_solve(s, f, v, w, settings);
  EXPECT_TRUE(r.converged);
  EXPECT_LE(r.iterations, 1);
}

// The transverse dashpot (eq. 32's c (v_i − v_j) when c_t = c): still the assembled matrix, still SPD,
// and it damps a rigid rotation, which the axial dashpot does not.
TEST(FrictionOperator, TransverseDashpotMatchesAssemblyAndDampsRotation) {
  FrictionSetup s(2);
  auto rotation = [&] {  // v = ω × x with ω = z
    const auto x = to_host_vector(s.mesh.x);
    Vector v("v", s.mesh.n_nodes);
    auto h = Kokkos::create_mirror_view(v);
    for (int i = 0; i < s.mesh.n_nodes; ++i) {
      h(i, 0) = -x[3 * i + 1];
      h(i, 1) = x[3 * i];
      h(i, 2) = 0;
    }
    Kokkos::deep_copy(v, h);
    return v;
  };
  const Vector w = rotation();
  const auto hw = to_host_vector(w);
  const double axial_power = dot_host(hw, to_host_vector(s.apply(w)));
  s.op.dashpot_transverse = s.op.dashpot;
  update_friction(Exec(), s.mesh, s.op);
  const Eigen::MatrixXd a = s.assemble();
  const Vector v = s.random_vector(5);
  const auto vh = to_host_vector(v), gv = to_host_vector(s.apply(v));
  const Eigen::VectorXd expected = a * Eigen::Map<const Eigen::VectorXd>(vh.data(), vh.size());
  EXPECT_LT((Eigen::Map<const Eigen::VectorXd>(gv.data(), gv.size()) - expected).norm(),
            1e-12 * expected.norm());
  const Eigen::VectorXd eigenvalues = test_dense::symmetric_eigenvalues(a);
  EXPECT_GT(eigenvalues.minCoeff(), 0.0);
  const double relative_power = dot_host(hw, to_host_vector(s.apply(w)));
  EXPECT_GT(relative_power, 10 * axial_power);  // axial: drag only (perturbed mesh: ~drag)
}

}  // namespace
}  // namespace dcm

namespace dcm {
namespace {

using namespace test_friction;

// solvers/global_woodbury.hpp: with P the block-Jacobi preconditioner of Γ and the implicit volume term
// s u uᵀ (u = ∇V, s = Δt k_v/V*) of a 10 ms step, z = M⁻¹ r satisfies (P⁻¹ + s u uᵀ) z = r, i.e.
// P (r − s u uᵀ z) = z, on two cells (each corrected with its own u); and PCG on Γ + s u uᵀ needs fewer
// iterations with the correction, to the same solution.
TEST(GlobalWoodbury, InvertsThePreconditionerPlusTheVolumeTermAndSavesIterations) {
  const FrictionSetup s(std::vector<int>{3, 3});
  const Exec space;
  GeometryBuffers<Mem> geo(s.mesh);
  update_geometry(space, s.mesh, geo, 1e4);
  // Rest volumes 5% above the current ones; k_v = 1e4 Pa, Δt = 10 ms.
  Kokkos::View<double*, Kokkos::LayoutRight, Mem> rest_volume("rest_volume", s.mesh.n_cells);
  {  // (on the host: a CUDA extended lambda may not sit in a gtest body, which is a private member)
    auto h = Kokkos::create_mirror_view(rest_volume);
    Kokkos::deep_copy(h, geo.cell_volume);
    for (int c = 0; c < s.mesh.n_cells; ++c) h(c) *= 1.05;
    Kokkos::deep_copy(rest_volume, h);
  }
  GlobalStiffness<Mem> g(s.mesh, false, true);
  update_global_stiffness(space, s.mesh, geo, rest_volume, rest_volume, 0.0, 1e4, 10e-3, g);
  GlobalWoodbury<Mem> wb(s.mesh);
  const auto precondition = [&](const Vector& in, const Vector& out) {
    apply_block_jacobi(space, s.op, in, out);
  };
  update_global_woodbury(space, s.mesh, g, wb, precondition);

  const Vector r = s.random_vector(5, 1e-12), z("z", s.mesh.n_nodes), y("y", s.mesh.n_nodes),
               back("back", s.mesh.n_nodes);
  precondition(r, z);
  apply_global_woodbury(space, s.mesh, wb, r, z);
  Kokkos::deep_copy(y, 0.0);
  apply_global_stiffness(space, s.mesh, g, z, y);  // s u uᵀ z
  {                                                // y = r − y
    auto yh = Kokkos::create_mirror_view(y);
    auto rh = Kokkos::create_mirror_view(r);
    Kokkos::deep_copy(yh, y);
    Kokkos::deep_copy(rh, r);
    for (int i = 0; i < s.mesh.n_nodes; ++i)
      for (int d = 0; d < 3; ++d) yh(i, d) = rh(i, d) - yh(i, d);
    Kokkos::deep_copy(y, yh);
  }
  precondition(y, back);
  const auto zh = to_host_vector(z), bh = to_host_vector(back), ph = to_host_vector(wb.w);
  double diff = 0, norm = 0, correction = 0;
  std::vector<double> pz(zh.size());
  {
    Vector plain("plain", s.mesh.n_nodes);
    precondition(r, plain);
    pz = to_host_vector(plain);
  }
  for (std::size_t k = 0; k < zh.size(); ++k) {
    diff = std::fmax(diff, std::fabs(bh[k] - zh[k]));
    norm = std::fmax(norm, std::fabs(zh[k]));
    correction = std::fmax(correction, std::fabs(zh[k] - pz[k]));
  }
  std::printf("  max |P(r - s u u^T z) - z| = %.2e of max |z| = %.2e; the correction moved z by %.2e\n", diff,
              norm, correction);
  EXPECT_LT(diff, 1e-12 * norm);
  EXPECT_GT(correction, 1e-3 * norm) << "the volume term must matter in this test";

  // PCG on Γ + s u uᵀ, cold start, with P and with M.
  const Vector f = s.random_vector(11, 1e-12);
  CgSettings settings;
  settings.abs_tol = 0;
  settings.rel_tol = 1e-8;
  settings.max_iterations = 20000;
  const auto op = [&](const Vector& in, const Vector& out) {
    apply_friction(space, s.mesh, s.op, in, out);
    apply_global_stiffness(space, s.mesh, g, in, out);
  };
  Vector v_plain("v_plain", s.mesh.n_nodes), v_wb("v_wb", s.mesh.n_nodes);
  CgWorkspace<Mem> w(s.mesh.n_nodes);
  const CgResult plain = pcg_solve(space, op, precondition, f, v_plain, w, settings);
  const CgResult corrected = pcg_solve(
      space, op,
      [&](const Vector& in, const Vector& out) {
        precondition(in, out);
        apply_global_woodbury(space, s.mesh, wb, in, out);
      },
      f, v_wb, w, settings);
  std::printf("  block-Jacobi PCG on friction + volume term: %d iterations, with the correction %d\n",
              plain.iterations, corrected.iterations);
  ASSERT_TRUE(plain.converged);
  ASSERT_TRUE(corrected.converged);
  EXPECT_LT(corrected.iterations, plain.iterations);
  const auto a = to_host_vector(v_plain), b = to_host_vector(v_wb);
  double d2 = 0, n2 = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    d2 += (a[k] - b[k]) * (a[k] - b[k]);
    n2 += a[k] * a[k];
  }
  EXPECT_LT(std::sqrt(d2), 1e-8 * std::sqrt(n2));
}

}  // namespace
}  // namespace dcm

namespace dcm {
namespace {

using namespace test_friction;

// Table 1's c read as the membrane's shear viscosity η (cortex.c_reading = surface_viscosity): the bond
// dashpots of bond_dashpot_of_surface_viscosity dissipate, for the homogeneous flow v = D x (D symmetric),
// what a continuum membrane of shear viscosity η dissipates. d = P D P is the surface rate of strain (P the
// tangent projector of a triangle, N its normal). Axial dashpots 4η/√3: ∫ (2η d:d + η (tr d)²) dA (their
// second, Lamé viscosity is η, as the triangular lattice's λ = μ). Relative dashpots 2η/√3: ∫ 2η (d:d + |P D
// N|²) dA (no second viscosity; the last term the tilt they also damp). On the icosphere (icosahedral
// symmetry: an isotropic network on average) each pair agrees to 1.1% on every level and for every D; with
// c_b = η (the per-bond reading) the axial network is √3/4 as viscous.
TEST(FrictionOperator, BondDashpotsOfASurfaceViscosityDissipateAsTheMembrane) {
  const double eta = 1.5e-6;
  const Eigen::Matrix3d rates[] = {
      (Eigen::Matrix3d() << 1, 0, 0, 0, -1, 0, 0, 0, 0).finished(),  // pure shear in x-y
      (Eigen::Matrix3d() << 0, 1, 0, 1, 0, 0, 0, 0, 0).finished(),   // simple shear's symmetric part
      (Eigen::Matrix3d() << 1, 0, 0, 0, 1, 0, 0, 0, -2).finished(),  // axisymmetric extension
      (Eigen::Matrix3d() << 0.3, -0.7, 0.2, -0.7, 1.1, 0.5, 0.2, 0.5, -0.4).finished()};
  for (const int level : {2, 3, 4}) {
    const std::vector<HostCell> cells{HostCell(make_icosphere(level, 3.25e-6))};
    const MeshBuffers<Mem> mesh = upload_cells<Mem>(cells);
    Kokkos::View<double*, Kokkos::LayoutRight, Mem> no_drag("drag", mesh.n_nodes);
    const auto x = to_host_vector(mesh.x);
    const auto tri = to_host_vector(mesh.tri);
    for (const bool relative : {false, true}) {
      const double c_b = bond_dashpot_of_surface_viscosity(eta, relative);
      FrictionOperator<Mem> op(mesh, no_drag, c_b, relative ? c_b : 0.0);
      update_friction(Exec(), mesh, op);
      for (const Eigen::Matrix3d& D : rates) {
        Vector v("v", mesh.n_nodes);
        auto vh = Kokkos::create_mirror_view(v);
        for (int i = 0; i < mesh.n_nodes; ++i) {
          const Eigen::Vector3d vi = D * Eigen::Vector3d(x[3 * i], x[3 * i + 1], x[3 * i + 2]);
          for (int d = 0; d < 3; ++d) vh(i, d) = vi[d];
        }
        Kokkos::deep_copy(v, vh);
        Vector gv("gv", mesh.n_nodes);
        apply_friction(Exec(), mesh, op, v, gv);
        const double network = dot_host(to_host_vector(v), to_host_vector(gv));
        double continuum = 0;
        for (int t = 0; t < mesh.n_tris; ++t) {
          Eigen::Vector3d p[3];
          for (int k = 0; k < 3; ++k) {
            const int i = tri[3 * t + k];
            p[k] = Eigen::Vector3d(x[3 * i], x[3 * i + 1], x[3 * i + 2]);
          }
          const Eigen::Vector3d cross = (p[1] - p[0]).cross(p[2] - p[0]);
          const Eigen::Vector3d n = cross.normalized();
          const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - n * n.transpose();
          const Eigen::Matrix3d d = P * D * P;
          const double dd = d.cwiseProduct(d).sum();
          continuum += 0.5 * cross.norm() * eta *
                       (relative ? 2 * (dd + (P * D * n).squaredNorm()) : 2 * dd + d.trace() * d.trace());
        }
        const double ratio = network / continuum;
        EXPECT_NEAR(ratio, 1.0, 0.02)
            << "level " << level << (relative ? ", relative" : ", axial") << ", D =\n"
            << D;
        if (!relative) {
          EXPECT_LT(ratio * eta / c_b, 0.5) << "c_b = η per bond would be as viscous";
        }
      }
    }
  }
}

}  // namespace
}  // namespace dcm
