// The assembled cortex model: energy balance of the overdamped flow, equilibrium by FIRE, and the
// numerical-trouble reports.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <utility>

#include "core/host_copy.hpp"
#include "solvers/fire_minimizer.hpp"
#include "solvers/newton_equilibrium.hpp"

namespace dcm {
namespace {

using Exec = Kokkos::DefaultExecutionSpace;

MechanicsParams table1(double k_local = 6e-4, double k_global = 6e-3, double k_volume = 1e4) {
  MechanicsParams p;
  p.bonds = {3.2e-6, 2.05};
  p.k_b = 240e-21;
  p.k_area_local = k_local;
  p.k_area_global = k_global;
  p.k_volume = k_volume;
  p.dashpot = 1.5e-6;
  p.viscosity = 0.8e-3;
  return p;
}

// m with every coordinate moved by a uniform random amount in [−amplitude, amplitude].
HostMesh perturbed(HostMesh m, double amplitude, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  for (auto& x : m.nodes)
    for (double& v : x) v += u(rng);
  return m;
}

HostMesh perturbed_sphere(int k, double amplitude, unsigned seed) {
  return perturbed(make_icosphere(k, 3.25e-6), amplitude, seed);
}

// Relaxation of a perturbed cell (rest state: the unperturbed sphere) under Γ v = F, x += dt v:
// E never increases, and (E(t+dt) − E(t))/dt = −vᵀΓv up to the O(dt) error of forward Euler.
TEST(CortexModel, UnforcedRelaxationDissipatesEnergyAtTheRateVGammaV) {
  const HostMesh rest = make_icosphere(2, 3.25e-6);
  CortexModel<Exec> model(Exec(), {HostCell(rest)}, table1());
  {  // displace the nodes from the rest shape
    const HostMesh moved = perturbed_sphere(2, 0.04e-6, 3);
    auto x = Kokkos::create_mirror_view(model.positions());
    for (std::size_t i = 0; i < moved.nodes.size(); ++i)
      for (int d = 0; d < 3; ++d) x(i, d) = moved.nodes[i][d];
    Kokkos::deep_copy(model.positions(), x);
  }
  const double dt = 6e-6;
  CgSettings cg;
  cg.abs_tol = 0;
  cg.rel_tol = 1e-10;
  double e_prev = model.energy();
  const double e_start = e_prev;
  double worst = 0;
  for (int step = 0; step < 300; ++step) {
    model.compute_forces();
    model.solve_velocity(cg);
    const double power = model.dissipation();
    model.advance(dt);
    const double e = model.energy();
    EXPECT_LE(e, e_prev) << "step " << step;
    worst = std::fmax(worst, std::fabs((e - e_prev) / dt + power) / power);
    e_prev = e;
  }
  std::printf("  energy %.4g J -> %.4g J in 300 steps; max |dE/dt + v'Gv| / v'Gv = %.3g\n", e_start, e_prev,
              worst);
  EXPECT_LT(e_prev, e_start);
  EXPECT_LT(worst, 0.2);

  // The residual is forward Euler's O(dt) error: from one state, halving dt halves it.
  const auto x0 = to_host_vector(model.positions());
  auto residual = [&](double h) {
    auto x = Kokkos::create_mirror_view(model.positions());
    for (std::size_t i = 0; i < x0.size() / 3; ++i)
      for (int d = 0; d < 3; ++d) x(i, d) = x0[3 * i + d];
    Kokkos::deep_copy(model.positions(), x);
    const double e0 = model.energy();
    model.compute_forces();
    model.solve_velocity(cg);
    const double power = model.dissipation();
    model.advance(h);
    return std::fabs((model.energy() - e0) / h + power) / power;
  };
  const double r1 = residual(dt), r2 = residual(dt / 2), r4 = residual(dt / 4);
  std::printf("  one-step residual at dt, dt/2, dt/4: %.3g, %.3g, %.3g\n", r1, r2, r4);
  EXPECT_NEAR(r1 / r2, 2.0, 0.3);
  EXPECT_NEAR(r2 / r4, 2.0, 0.3);
}

TEST(CortexModel, FireFindsTheEquilibriumOfAStretchedCell) {
  const HostMesh rest = make_icosphere(2, 3.25e-6);
  CortexModel<Exec> model(Exec(), {HostCell(rest)}, table1(0, 6e-3, 1e4));
  auto ext = Kokkos::create_mirror_view(model.external_force());
  Kokkos::deep_copy(ext, 0.0);
  int pulled = 0;
  for (std::size_t i = 0; i < rest.nodes.size(); ++i) {
    if (std::fabs(rest.nodes[i][0]) > 0.9 * 3.25e-6) {
      ext(i, 0) = rest.nodes[i][0] > 0 ? 5e-12 : -5e-12;
      ++pulled;
    }
  }
  Kokkos::deep_copy(model.external_force(), ext);
  FireSettings s;
  s.force_tol = 1e-17;
  const FireResult r = fire_minimize(model, s, 0.5e-6);
  std::printf("  %d pulled nodes: FIRE converged in %d steps, max |F| = %.3g N\n", pulled, r.steps,
              r.max_force);
  ASSERT_TRUE(r.converged);
  // At equilibrium the internal forces balance the pull: the model's total force is the residual.
  EXPECT_LE(r.max_force, 1e-17);
  const auto x = to_host_vector(model.positions());
  double xmax = 0;
  for (std::size_t i = 0; i < x.size(); i += 3) xmax = std::fmax(xmax, x[i]);
  EXPECT_GT(xmax, 3.25e-6 * 1.01);  // stretched along the pull
}

TEST(CortexModel, NewtonFindsTheSameEquilibriumAsFireInFewSteps) {
  const HostMesh rest = make_icosphere(2, 3.25e-6);
  auto pulled = [&](CortexModel<Exec>& model) {
    auto ext = Kokkos::create_mirror_view(model.external_force());
    Kokkos::deep_copy(ext, 0.0);
    for (std::size_t i = 0; i < rest.nodes.size(); ++i)
      if (std::fabs(rest.nodes[i][0]) > 0.9 * 3.25e-6) ext(i, 0) = rest.nodes[i][0] > 0 ? 5e-12 : -5e-12;
    Kokkos::deep_copy(model.external_force(), ext);
  };
  CortexModel<Exec> a(Exec(), {HostCell(rest)}, table1(6e-4, 6e-3, 1e4)),
      b(Exec(), {HostCell(rest)}, table1(6e-4, 6e-3, 1e4));
  pulled(a);
  pulled(b);
  FireSettings fs;
  fs.force_tol = 1e-18;
  const FireResult rf = fire_minimize(a, fs, 0.5e-6);
  NewtonSettings ns;
  ns.force_tol = 1e-18;
  const NewtonResult rn = newton_equilibrium(b, ns, 0.5e-6);
  std::printf("  FIRE %d steps, Newton %d steps (%d force evaluations), residual %.3g N\n", rf.steps,
              rn.newton_steps, rn.force_evaluations, rn.max_force);
  ASSERT_TRUE(rf.converged);
  ASSERT_TRUE(rn.converged);
  EXPECT_LT(rn.newton_steps, 30);
  const auto xa = to_host_vector(a.positions()), xb = to_host_vector(b.positions());
  double diff = 0;
  for (std::size_t i = 0; i < xa.size(); ++i) diff = std::fmax(diff, std::fabs(xa[i] - xb[i]));
  EXPECT_LT(diff, 1e-4 * 3.25e-6);  // the same equilibrium
}

// Runs `steps` forward-Euler steps of size dt from the model's current positions; returns how many steps
// were taken before a NumericalError (or all of them) and whether the energy never increased.
std::pair<int, bool> run_steps(CortexModel<Exec>& model, double dt, int steps, double solve_dt) {
  double e_prev = model.energy();
  bool monotonic = true;
  int done = 0;
  try {
    for (; done < steps; ++done) {
      model.compute_forces();
      model.solve_velocity(CgSettings{}, solve_dt);
      model.advance(dt);
      const double e = model.energy();
      monotonic = monotonic && e <= e_prev;
      e_prev = e;
    }
  } catch (const NumericalError&) {
    return {done, false};
  }
  return {done, monotonic};
}

void set_positions(CortexModel<Exec>& model, const HostMesh& m) {
  auto x = Kokkos::create_mirror_view(model.positions());
  for (std::size_t i = 0; i < m.nodes.size(); ++i)
    for (int d = 0; d < 3; ++d) x(i, d) = m.nodes[i][d];
  Kokkos::deep_copy(model.positions(), x);
}

// Stiff global constraints (k_v = 1e4 Pa, k_d = 6e-3 N/m) on the 642-node Evans–Fung cell: forward Euler
// with explicit forces blows up within a few steps at the paper's Δt; with the global terms linearly
// implicit the energy decreases monotonically.
TEST(CortexModel, ImplicitGlobalConstraintsAreStableWhereExplicitOnesAreNot) {
  const HostMesh rest = make_evans_fung(3);
  HostMesh inflated = rest;  // inflated by 1%: area and volume both off their rest values
  for (auto& x : inflated.nodes)
    for (double& v : x) v *= 1.01;
  auto run = [&](bool implicit) {
    CortexModel<Exec> model(Exec(), {HostCell(rest)}, table1(0, 6e-3, 1e4));
    set_positions(model, inflated);
    return run_steps(model, 6e-6, 40, implicit ? 6e-6 : 0.0);
  };
  const auto [explicit_steps, explicit_ok] = run(false);
  const auto [implicit_steps, implicit_ok] = run(true);
  std::printf("  explicit: %d steps, energy monotonic %d; implicit: %d steps, energy monotonic %d\n",
              explicit_steps, explicit_ok, implicit_steps, implicit_ok);
  EXPECT_FALSE(explicit_ok);
  EXPECT_EQ(implicit_steps, 40);
  EXPECT_TRUE(implicit_ok);
}

// Bending modes feel only the drag; at Δt = 40 µs on the 642-node cell forward Euler is unstable in them,
// and with the bending stiffness in the solve (Γ + Δt K_bend) it is not.
TEST(CortexModel, ImplicitBendingIsStableWhereExplicitBendingIsNot) {
  const HostMesh rest = make_evans_fung(3);
  const HostMesh moved = perturbed(rest, 0.01e-6, 9);
  auto run = [&](bool implicit_bending) {
    MechanicsParams p = table1(6e-3, 6e-3, 1e4);
    p.implicit_bending = implicit_bending;
    CortexModel<Exec> model(Exec(), {HostCell(rest)}, p);
    set_positions(model, moved);
    return run_steps(model, 4e-5, 60, 4e-5);
  };
  const auto [explicit_steps, explicit_ok] = run(false);
  const auto [implicit_steps, implicit_ok] = run(true);
  std::printf(
      "  dt = 40 us, 642 nodes: explicit bending %d steps (energy monotonic %d), implicit %d steps (%d)\n",
      explicit_steps, explicit_ok, implicit_steps, implicit_ok);
  EXPECT_FALSE(explicit_ok);
  EXPECT_EQ(implicit_steps, 60);
  EXPECT_TRUE(implicit_ok);
}

// What only the preconditioner needs (the multigrid's hierarchy with level 0's bending, the volume's Woodbury
// correction) is built on its first application in a solve: a solve that iterates builds it once; one whose
// warm start already meets the tolerance builds nothing and keeps the velocity bit for bit; and after the
// nodes move, the next solve that iterates rebuilds it, so its velocity equals a fresh model's from the same
// warm start, bit for bit (a hierarchy left stale would differ). (spread's outputs are the same bits as with
// the eager build of sessions 8-36: docs/PERFORMANCE.md, "Session 37".)
TEST(CortexModel, ThePreconditionerIsBuiltOnlyForASolveThatIterates) {
  const HostMesh rest = make_evans_fung(3);
  const HostMesh moved = perturbed(rest, 0.02e-6, 4);
  MechanicsParams p = table1(6e-3, 6e-3, 1e4);
  p.multigrid = true;
  p.precondition_volume = true;
  p.implicit_bending = true;
  p.mg.bending = MultigridSettings::Bending::on;  // level 0's bending too, built lazily
  CortexModel<Exec> model(Exec(), {HostCell(rest)}, p);
  set_positions(model, moved);
  model.compute_forces();
  CgSettings cg;
  cg.abs_tol = 1e-16;
  const double dt = 6e-6;
  const CgResult first = model.solve_velocity(cg, dt);
  const long long built = model.preconditioner_builds();
  const std::vector<double> v = to_host_vector(model.velocity());
  cg.abs_tol =
      1e-15;  // ten times the first solve's: its recursive residual met 1e-16, the true one meets this
  const CgResult again = model.solve_velocity(cg, dt);
  std::printf("  first solve: %d iterations, %lld build(s); again from its velocity: %d iterations, %lld\n",
              first.iterations, built, again.iterations, model.preconditioner_builds());
  EXPECT_TRUE(model.last_bending_preconditioned());
  EXPECT_GT(first.iterations, 0);
  EXPECT_EQ(built, 1);
  EXPECT_EQ(again.iterations, 0);
  EXPECT_EQ(model.preconditioner_builds(), 1);
  EXPECT_EQ(to_host_vector(model.velocity()), v);
  // Move the nodes by one step along v and solve again: the hierarchy must be rebuilt for the new positions.
  const std::vector<double> x = to_host_vector(model.positions());
  HostMesh stepped = moved;
  for (std::size_t i = 0; i < stepped.nodes.size(); ++i)
    for (int d = 0; d < 3; ++d) stepped.nodes[i][d] = x[3 * i + d] + dt * v[3 * i + d];
  set_positions(model, stepped);
  model.compute_forces();
  cg.abs_tol = 1e-16;
  const CgResult moved_solve = model.solve_velocity(cg, dt);
  CortexModel<Exec> fresh(Exec(), {HostCell(rest)}, p);
  set_positions(fresh, stepped);
  fresh.compute_forces();
  auto start = Kokkos::create_mirror_view(fresh.velocity());
  for (std::size_t i = 0; i < start.extent(0); ++i)
    for (int d = 0; d < 3; ++d) start(i, d) = v[3 * i + d];  // the model's warm start for its solve
  Kokkos::deep_copy(fresh.velocity(), start);
  const CgResult fresh_solve = fresh.solve_velocity(cg, dt);
  std::printf("  after the nodes moved: %d iterations (%lld builds); a fresh model from the same start: %d\n",
              moved_solve.iterations, model.preconditioner_builds(), fresh_solve.iterations);
  EXPECT_GT(moved_solve.iterations, 0);
  EXPECT_EQ(model.preconditioner_builds(), 2);
  EXPECT_EQ(moved_solve.iterations, fresh_solve.iterations);
  EXPECT_EQ(to_host_vector(model.velocity()), to_host_vector(fresh.velocity()));
}

// MultigridSettings::Bending::automatic: the bending's Gauss–Newton stiffness enters the multigrid's level 0
// in the steps where bending_ratio() = Δt k_b R² / (c h⁴) reaches 0.15 (solvers/multigrid.hpp), and there it
// saves iterations; on the paper's Δt on 642 nodes it stays out.
TEST(CortexModel, BendingEntersThePreconditionerWhereItIsStrongAgainstTheDashpots) {
  const HostMesh rest = make_icosphere(3, 3.25e-6);
  const Topology topo = build_topology(rest);
  auto point = [&](int i) { return Real3{rest.nodes[i][0], rest.nodes[i][1], rest.nodes[i][2]}; };
  double h = 0, area = 0;
  for (const auto& e : topo.edges) h += norm(point(e[1]) - point(e[0]));
  h /= static_cast<double>(topo.edges.size());
  for (const auto& t : rest.triangles)
    area += 0.5 * norm(cross(point(t[1]) - point(t[0]), point(t[2]) - point(t[0])));
  const double r = std::sqrt(area / (4 * M_PI));
  const double ratio_per_s = 240e-21 * r * r / (1.5e-6 * h * h * h * h);  // β / Δt, Table 1
  HostMesh moved = perturbed_sphere(3, 0.02e-6, 5);
  struct Solve {
    double ratio;
    bool preconditioned;
    int iterations;
  };
  auto solve = [&](MultigridSettings::Bending mode, double dt, double c_t = 0) {
    MechanicsParams p = table1(6e-3, 6e-3, 1e4);
    p.multigrid = true;
    p.implicit_bending = true;
    p.mg.bending = mode;
    p.dashpot_transverse = c_t;
    CortexModel<Exec> model(Exec(), {HostCell(rest)}, p);
    set_positions(model, moved);
    model.compute_forces();
    CgSettings cg;
    cg.abs_tol = 0;
    cg.rel_tol = 1e-10;
    const CgResult res = model.solve_velocity(cg, dt);
    EXPECT_TRUE(res.converged);
    return Solve{model.last_bending_ratio(), model.last_bending_preconditioned(), res.iterations};
  };
  using B = MultigridSettings::Bending;
  const double paper_dt = 6e-6, strong_dt = 4.0 / ratio_per_s;  // β = 4
  const Solve paper = solve(B::automatic, paper_dt), strong = solve(B::automatic, strong_dt),
              strong_off = solve(B::off, strong_dt), paper_on = solve(B::on, paper_dt);
  // A transverse dashpot (cortex.dashpot = "relative": c_t = c) resists the normal modes directly.
  const double c = 1.5e-6, relative_dt = 1e-3;
  const double relative_ratio = relative_dt * 240e-21 / (h * h * (c * h * h / (r * r) + c));
  EXPECT_NEAR(solve(B::automatic, relative_dt, c).ratio, relative_ratio, 1e-9 * relative_ratio);
  // The threshold, MultigridSettings::kAutoRatio = 0.15, from both sides.
  EXPECT_FALSE(solve(B::automatic, 0.14 / ratio_per_s).preconditioned);
  EXPECT_TRUE(solve(B::automatic, 0.16 / ratio_per_s).preconditioned);
  std::printf(
      "  642 nodes, h = %.3f um: beta = %.2e at dt = 6 us (%d iterations), beta = %.2f at dt = %.3g s: "
      "%d iterations with the bending in the preconditioner, %d without\n",
      h * 1e6, paper.ratio, paper.iterations, strong.ratio, strong_dt, strong.iterations,
      strong_off.iterations);
  EXPECT_NEAR(paper.ratio, paper_dt * ratio_per_s, 1e-9 * paper.ratio);
  EXPECT_NEAR(strong.ratio, 4.0, 1e-9);
  EXPECT_FALSE(paper.preconditioned);
  EXPECT_TRUE(strong.preconditioned);
  EXPECT_FALSE(strong_off.preconditioned);
  EXPECT_TRUE(paper_on.preconditioned);
  EXPECT_LT(strong.iterations, strong_off.iterations);
}

// A tense, nearly flat cortex: the Evans–Fung cell stretched 12% in its plane (area terms under tension
// ≈ 1.5e-3 N/m) with small random displacements. Out-of-plane motion of a node of the flat faces is damped by
// the drag alone (the axial dashpots are nearly perpendicular to it), so the tension's out-of-plane stiffness
// makes forward Euler at the paper's Δt unstable there; with the tension stiffness in the solve
// (solvers/tension_stiffness.hpp) the same steps are stable. Bending, bonds and global terms implicit in
// both; the multigrid preconditioner only makes the solves (to CgSettings{}'s 1e-14 N) cheaper: 3.5x less
// time than block-Jacobi, which matters under the sanitizers.
TEST(CortexModel, ImplicitTensionIsStableWhereExplicitTensionIsNot) {
  const HostMesh rest = make_evans_fung(3);
  HostMesh moved = rest;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.005e-6, 0.005e-6);
  for (auto& x : moved.nodes) {
    x[0] *= 1.12;
    x[1] *= 1.12;
    for (double& v : x) v += u(rng);
  }
  auto run = [&](bool implicit_tension) {
    MechanicsParams p = table1(6e-3, 6e-3, 1e4);
    p.implicit_bending = true;
    p.implicit_bonds = true;
    p.implicit_tension = implicit_tension;
    p.multigrid = true;
    CortexModel<Exec> model(Exec(), {HostCell(rest)}, p);
    set_positions(model, moved);
    return run_steps(model, 6e-6, 200, 6e-6);
  };
  const auto [explicit_steps, explicit_ok] = run(false);
  const auto [implicit_steps, implicit_ok] = run(true);
  std::printf(
      "  dt = 6 us, 642 nodes, stretched 12%%: explicit tension %d steps (energy monotonic %d), implicit "
      "%d steps (%d)\n",
      explicit_steps, explicit_ok, implicit_steps, implicit_ok);
  EXPECT_FALSE(explicit_ok);
  EXPECT_EQ(implicit_steps, 200);
  EXPECT_TRUE(implicit_ok);
}

TEST(CortexModel, OverstretchedBondIsReportedNotNaN) {
  const HostMesh rest = make_icosphere(1, 3.25e-6);
  CortexModel<Exec> model(Exec(), {HostCell(rest)}, table1());
  auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), model.positions());
  for (int d = 0; d < 3; ++d) x(0, d) *= 3.0;  // node 0 pulled far out: its bonds pass x_max = 2.05
  Kokkos::deep_copy(model.positions(), x);
  try {
    model.compute_forces();
    FAIL() << "no NumericalError";
  } catch (const NumericalError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("FENE bond"), std::string::npos) << what;
    EXPECT_NE(what.find("nodes 0-"), std::string::npos) << what;
  }
}

TEST(CortexModel, NonFiniteForceNamesTheNodeAndTerm) {
  const HostMesh rest = make_icosphere(1, 3.25e-6);
  MechanicsParams p = table1();
  p.bonds.k_s = 0;  // so that the NaN reaches the other terms
  CortexModel<Exec> model(Exec(), {HostCell(rest)}, p);
  auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), model.positions());
  x(5, 1) = NAN;
  Kokkos::deep_copy(model.positions(), x);
  try {
    model.compute_forces();
    FAIL() << "no NumericalError";
  } catch (const NumericalError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("non-finite force at node"), std::string::npos) << what;
    EXPECT_NE(what.find("term:"), std::string::npos) << what;
  }
}

// A conjugate-gradient breakdown names the operator term that is not positive along its search direction and
// a node, and lists the others: here a negative dashpot coefficient (no scene allows one; the message is what
// is tested) makes the friction term indefinite, while the implicit bending and tension stay positive.
TEST(CortexModel, BreakdownNamesTheTermAndNode) {
  const HostMesh rest = make_icosphere(2, 3.25e-6);
  MechanicsParams p = table1();
  p.implicit_bending = true;
  p.dashpot = -1e-3;
  CortexModel<Exec> model(Exec(), {HostCell(rest)}, p);
  set_positions(model, perturbed(rest, 0.05e-6, 7));
  model.compute_forces();
  CgSettings cg;
  cg.abs_tol = 1e-30;
  try {
    model.solve_velocity(cg, 1e-4);
    FAIL() << "no NumericalError";
  } catch (const NumericalError& e) {
    const std::string what = e.what();
    std::printf("  %s\n", what.c_str());
    EXPECT_NE(what.find("broke down"), std::string::npos) << what;
    EXPECT_NE(what.find("friction (drag, dashpots, substrate) -"), std::string::npos) << what;
    EXPECT_NE(what.find("(the term at fault: lowest at node "), std::string::npos) << what;
    const auto bending = what.find("implicit bending ");
    ASSERT_NE(bending, std::string::npos) << what;
    EXPECT_NE(what[bending + 17], '-') << what;  // positive: named only once, the first term at fault
    EXPECT_EQ(what.find("term at fault"), what.rfind("term at fault")) << what;
  }
}

// The message of an equilibrium not reached names the node with the largest force, its |F| and the term that
// contributes most there: a node pulled 20% out of the sphere is that node; with Table 1's area constants the
// area terms hold it back most, without them (and without the volume term) its bonds.
TEST(CortexModel, LargestForceIsNamedWithItsTerm) {
  const HostMesh rest = make_icosphere(2, 3.25e-6);
  const auto named = [&](const MechanicsParams& p) {
    CortexModel<Exec> model(Exec(), {HostCell(rest)}, p);
    auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), model.positions());
    for (int d = 0; d < 3; ++d) x(7, d) *= 1.2;
    Kokkos::deep_copy(model.positions(), x);
    model.compute_forces();
    const std::string what = model.describe_largest_force();
    std::printf("  %s\n", what.c_str());
    const auto f = to_host_vector(model.force());
    char norm[32];
    std::snprintf(norm, sizeof norm, "|F| = %.3g N",
                  std::sqrt(f[21] * f[21] + f[22] * f[22] + f[23] * f[23]));
    EXPECT_EQ(what.rfind("node 7 (", 0), 0u) << what;
    EXPECT_NE(what.find(norm), std::string::npos) << what << " vs " << norm;
    return what;
  };
  EXPECT_NE(named(table1()).find("largest term there: area constraints"), std::string::npos);
  EXPECT_NE(named(table1(0, 0, 0)).find("largest term there: FENE+POW bonds"), std::string::npos);
}

TEST(CortexModel, WithoutDashpotsTheSolveIsDiagonal) {
  MechanicsParams p = table1();
  p.dashpot = 0;
  CortexModel<Exec> model(Exec(), {HostCell(perturbed_sphere(2, 0.02e-6, 1))}, p);
  model.compute_forces();
  const CgResult r = model.solve_velocity(CgSettings{});
  EXPECT_EQ(r.iterations, 0);
  // v = F / ζ exactly.
  const auto f = to_host_vector(model.force()), v = to_host_vector(model.velocity());
  const double zeta = to_host_vector(model.friction().node_drag)[0];
  for (std::size_t i = 0; i < f.size(); ++i)
    EXPECT_NEAR(v[i], f[i] / zeta, 1e-12 * std::fabs(f[i] / zeta) + 1e-30);
}

// Gravity on a cell at rest: the nodes carry the buoyant weight Δρ V g in total, and the cell sinks
// rigidly at Stokes' velocity Δρ V g / (6πηr) (the dashpots see no relative motion).
TEST(CortexModel, GravityGivesTheStokesSedimentationVelocity) {
  MechanicsParams p = table1();
  p.gravity = 9.81;
  p.density_excess = 75;
  const double r = 3.25e-6, pi = 3.14159265358979323846;
  CortexModel<Exec> model(Exec(), {HostCell(make_icosphere(3, r))}, p);
  model.compute_forces();
  const auto f = to_host_vector(model.force());
  const double volume = to_host_vector(model.geometry().cell_volume)[0];
  const double area = to_host_vector(model.geometry().cell_area)[0];
  double fz = 0;
  for (std::size_t i = 2; i < f.size(); i += 3) fz += f[i];
  const double weight = 75 * volume * 9.81;
  EXPECT_NEAR(fz, -weight, 1e-9 * weight);
  CgSettings cg;
  cg.abs_tol = 0;
  cg.rel_tol = 1e-12;
  model.solve_velocity(cg);
  const auto v = to_host_vector(model.velocity());
  const double stokes = weight / (6 * pi * p.viscosity * std::sqrt(area / (4 * pi)));
  for (std::size_t i = 0; i < v.size(); i += 3) {
    EXPECT_NEAR(v[i + 2], -stokes, 1e-8 * stokes);
    EXPECT_NEAR(v[i], 0, 1e-8 * stokes);
  }
  // Energy: the weight's potential −Σ F·x changes by weight × the sinking distance.
  const double e0 = model.energy();
  model.advance(1e-3);
  EXPECT_NEAR(model.energy() - e0, -weight * stokes * 1e-3, 1e-6 * weight * stokes * 1e-3);
}

// A cell on an adhesive plane: at rest shape, the only force is the contact, its node sum equals the
// triangles' total load and that of the perfect sphere (attractive at a small overlap); the contact area is
// the perfect sphere's; the solve with substrate friction converges and the cell moves towards the plane.
// Pressed deeper, nodes fully in contact are pinned: Γ's diagonal carries the pin friction there.
MechanicsParams on_plane(double r, double a) {
  MechanicsParams p = table1();
  p.has_plane = true;
  p.plane.point = {0, 0, -r + (r - std::sqrt(r * r - a * a))};  // the sphere's bottom overlaps the plane
  p.contact.material = md_material(800e3, 0.4, 1e-3, 20e-9);
  p.gamma_n = 8e9;
  p.gamma_t = 6e9;
  p.pin_friction = 1e-3;
  return p;
}

// The substrate guard (kernels/substrate_guard.hpp) in the model: a cell at rest shape sunk 0.25 µm into a
// plane whose contact law does nothing (W = 0, a 1-Pa modulus), so that the guard alone acts. Its energy is
// part of energy() (½ k_g A_i e_i², A_i the start shape's node areas); the solve takes it implicit, so steps
// of 10 µs, about 20 times the explicit limit 2c/(k_g A_i) of a node held by its dashpots, push the sunk
// nodes back towards the guard depth monotonically without overshooting above it; without the guard they
// stay.
// With block-Jacobi and with the multigrid preconditioner (whose fine level is the operator CG multiplies
// by).
class SubstrateGuardModel : public ::testing::TestWithParam<bool> {};
INSTANTIATE_TEST_SUITE_P(Preconditioner, SubstrateGuardModel, ::testing::Values(false, true),
                         [](const ::testing::TestParamInfo<bool>& i) {
                           return std::string(i.param ? "Multigrid" : "BlockJacobi");
                         });

TEST_P(SubstrateGuardModel, PushesSunkNodesBackImplicitly) {
  const double r = 3.25e-6, depth = 100e-9, stiffness = 2.5e13, sink = 0.25e-6;
  HostMesh m = make_icosphere(2, r);
  double zmin = 0;
  for (const auto& x : m.nodes) zmin = std::min(zmin, x[2]);
  MechanicsParams p = table1();
  p.has_plane = true;
  p.plane.point = {0, 0, zmin + sink};
  p.contact.material = md_material(1.0, 0.4, 0.0, 20e-9);
  p.guard_depth = depth;
  p.guard_stiffness = stiffness;
  p.multigrid = GetParam();
  MechanicsParams off = p;
  off.guard_stiffness = 0;
  CortexModel<Exec> model(Exec(), {HostCell(m)}, p), unguarded(Exec(), {HostCell(m)}, off);
  const auto area = to_host_vector(model.geometry().node_area);
  const auto largest_excess = [&](const CortexModel<Exec>& c, double* energy) {
    const auto x = to_host_vector(c.mesh().x);
    double worst = -1, e = 0;
    for (std::size_t i = 0; i < area.size(); ++i) {
      const double excess = p.plane.point.z - x[3 * i + 2] - depth;
      worst = std::max(worst, excess);
      if (excess > 0) e += 0.5 * stiffness * area[i] * excess * excess;
    }
    if (energy) *energy = e;
    return worst;
  };
  double guard_energy = 0;
  const double start = largest_excess(model, &guard_energy);
  EXPECT_NEAR(start, sink - depth, 1e-12);
  EXPECT_NEAR(model.energy() - unguarded.energy(), guard_energy, 1e-9 * guard_energy);
  CgSettings cg;
  cg.abs_tol = 0;
  cg.rel_tol = 1e-10;
  const double dt = 1e-5;
  double previous = start;
  for (int step = 0; step < 20; ++step) {
    for (CortexModel<Exec>* c : {&model, &unguarded}) {
      c->compute_forces();
      c->solve_velocity(cg, dt);
      c->advance(dt);
    }
    const double now = largest_excess(model, nullptr);
    if (previous > 1e-3 * start) {  // (below that, the cortex's own drift)
      EXPECT_LE(now, previous) << "step " << step;
    }
    EXPECT_GT(now, -depth) << "step " << step << ": a node overshot above the plane";
    previous = now;
  }
  const double after = largest_excess(unguarded, nullptr);
  std::printf(
      "  largest depth past the guard: %.3g m at the start, %.3g m after 20 steps of 10 us (%.3g m "
      "without the guard)\n",
      start, previous, after);
  EXPECT_LT(previous, 0.05 * start);
  EXPECT_GT(after, 0.9 * start);
  // The guard's energy takes the start shape's node areas, not the current shape's: both cells blown up by
  // 10% (areas +21%, the bottom 0.28 µm deeper) differ in energy by ½ k_g A_i e_i² with the start areas.
  auto blown = Kokkos::create_mirror_view(model.mesh().x);
  for (std::size_t i = 0; i < m.nodes.size(); ++i)
    for (int d = 0; d < 3; ++d) blown(i, d) = 1.1 * m.nodes[i][d];
  Kokkos::deep_copy(model.mesh().x, blown);
  Kokkos::deep_copy(unguarded.mesh().x, blown);
  largest_excess(model, &guard_energy);
  EXPECT_GT(guard_energy, 0.0);
  EXPECT_NEAR(model.energy() - unguarded.energy(), guard_energy, 1e-9 * guard_energy);
  // The same step with the guard explicit (a solve without Δt leaves it out of the operator) throws the sunk
  // nodes far past the plane, or the bonds past their limit: why the solve takes it implicit.
  CortexModel<Exec> explicit_guard(Exec(), {HostCell(m)}, p);
  bool overshot = false;
  try {
    explicit_guard.compute_forces();
    explicit_guard.solve_velocity(cg);
    explicit_guard.advance(dt);
    const auto x = to_host_vector(explicit_guard.mesh().x);
    for (std::size_t i = 0; i < area.size(); ++i) overshot |= x[3 * i + 2] > p.plane.point.z + 1e-6;
  } catch (const NumericalError&) {
    overshot = true;
  }
  EXPECT_TRUE(overshot) << "an explicit guard step of 10 us should overshoot";
}

// contact.law = "derjaguin" (kernels/derjaguin_adhesion.hpp): the adhesion is an energy, so in the overdamped
// flow the total energy (cortex + adhesion) never increases and falls at the rate vᵀΓv up to forward Euler's
// O(Δt); the contact power the spread app balances (in-plane forces included) is −dE_adhesion/dt; the
// contact grows.
TEST(CortexModel, DerjaguinAdhesionIsConservative) {
  const double r = 3.25e-6;
  MechanicsParams p = on_plane(r, 0.3e-6);
  p.pin_friction = 0;
  p.contact.derjaguin = true;
  p.contact.material.h0 = 100e-9;  // resolves the 162-node mesh's contact line (docs/model/contact_line.md)
  CortexModel<Exec> model(Exec(), {HostCell(make_icosphere(2, r))}, p);
  CgSettings cg;
  cg.abs_tol = 0;
  cg.rel_tol = 1e-12;
  const double dt = 6e-6;
  double e_prev = model.energy() + model.adhesion_energy();
  const double e_start = e_prev, adh_start = model.adhesion_energy();
  model.compute_forces();
  const double area_start = model.contact_area();
  EXPECT_LT(adh_start, 0.0);
  double worst = 0, worst_power = 0;
  for (int step = 0; step < 300; ++step) {
    model.compute_forces();
    model.solve_velocity(cg);
    const double dissipation = model.dissipation(), power = model.contact_power();
    const double adh0 = model.adhesion_energy();
    model.advance(dt);
    const double adh = model.adhesion_energy(), e = model.energy() + adh;
    EXPECT_LE(e, e_prev) << "step " << step;
    worst = std::fmax(worst, std::fabs((e - e_prev) / dt + dissipation) / dissipation);
    worst_power = std::fmax(worst_power, std::fabs((adh - adh0) / dt + power) / dissipation);
    e_prev = e;
  }
  model.compute_forces();
  std::printf(
      "  total energy %.4g J -> %.4g J; max |dE/dt + v'Gv| / v'Gv = %.3g; max |dE_adh/dt + P_c| / v'Gv"
      " = %.3g; contact area %.3g -> %.3g um^2\n",
      e_start, e_prev, worst, worst_power, area_start * 1e12, model.contact_area() * 1e12);
  EXPECT_LT(e_prev, e_start);
  EXPECT_LT(worst, 0.05);
  EXPECT_LT(worst_power, 0.05);
  EXPECT_GT(model.contact_area(), 1.03 * area_start);  // (1.06 × in these 1.8 ms)
}

TEST(CortexModel, CellOnAnAdhesivePlane) {
  const double r = 3.25e-6, a = 0.2e-6, pi = 3.14159265358979323846;
  const MechanicsParams p = on_plane(r, a);
  CortexModel<Exec> model(Exec(), {HostCell(make_icosphere(4, r))}, p);
  model.compute_forces();
  const auto f = to_host_vector(model.force());
  double fz = 0;
  for (std::size_t i = 2; i < f.size(); i += 3) fz += f[i];
  EXPECT_NEAR(fz, model.contact_load(), 1e-9 * std::fabs(model.contact_load()));
  const MdState exact = md_state_from_radius(a, r, p.contact.material);
  EXPECT_LT(exact.P, 0.0) << "adhesive at this overlap";
  EXPECT_NEAR(model.contact_load(), exact.P, 1e-3 * std::fabs(exact.P));
  EXPECT_NEAR(std::sqrt(model.contact_area() / pi), a, 1e-3 * a);
  CgSettings cg;
  cg.abs_tol = 0;
  cg.rel_tol = 1e-10;
  EXPECT_TRUE(model.solve_velocity(cg, 6e-6).converged);
  const auto v = to_host_vector(model.velocity());
  double vz = 0;
  for (std::size_t i = 2; i < v.size(); i += 3) vz += v[i];
  EXPECT_LT(vz, 0.0) << "pulled towards the plane";

  CortexModel<Exec> pressed(Exec(), {HostCell(make_icosphere(4, r))}, on_plane(r, 1.0e-6));
  pressed.compute_forces();
  EXPECT_TRUE(pressed.solve_velocity(cg, 6e-6).converged);
  const auto regime = to_host_vector(pressed.contact()->tri_regime);
  const MeshBuffers<Exec::memory_space>& mesh = pressed.mesh();
  const auto offsets = to_host_vector(mesh.node_tri_offsets), corners = to_host_vector(mesh.node_tri_corners);
  int pinned = 0;
  for (int i = 0; i < mesh.n_nodes; ++i) {
    bool all = true;
    for (int k = offsets[i]; k < offsets[i + 1]; ++k) all = all && regime[corners[k] / 3] == kFullContact;
    if (!all) continue;
    ++pinned;
    FrictionOperator<Exec::memory_space>::Vector e("e", mesh.n_nodes), out("out", mesh.n_nodes);
    Kokkos::deep_copy(Kokkos::subview(e, i, 0), 1.0);
    apply_friction(Exec(), mesh, pressed.friction(), e, out);
    EXPECT_GE(to_host_vector(out)[3 * i], 1e-3) << "node " << i;
  }
  EXPECT_GT(pinned, 0);
}

}  // namespace
}  // namespace dcm
