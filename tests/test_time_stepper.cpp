// The time stepper (solvers/time_stepper.hpp): fixed steps are the paper's forward Euler, adaptive steps
// follow their error tolerance, and a solve that cannot converge ends in a clear error after the halvings.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <tuple>

#include "core/host_copy.hpp"
#include "solvers/time_stepper.hpp"
#include "tests/model_params.hpp"

namespace dcm {
namespace {

using Exec = Kokkos::DefaultExecutionSpace;

MechanicsParams table1() { return test_params::table1_cortex(); }

// A 162-node cell whose rest state is the sphere, displaced by up to `amplitude` per coordinate.
void perturb(CortexModel<Exec>& model, double amplitude, unsigned seed) {
  auto x = Kokkos::create_mirror_view(model.positions());
  Kokkos::deep_copy(x, model.positions());
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  for (std::size_t i = 0; i < x.extent(0); ++i)
    for (int d = 0; d < 3; ++d) x(i, d) += u(rng);
  Kokkos::deep_copy(model.positions(), x);
}

CgSettings tight() {
  CgSettings cg;
  cg.abs_tol = 0;
  cg.rel_tol = 1e-12;
  return cg;
}

double max_distance(const std::vector<double>& a, const std::vector<double>& b) {
  double m = 0;
  for (std::size_t i = 0; i < a.size(); i += 3)
    m = std::fmax(m, std::hypot(a[i] - b[i], a[i + 1] - b[i + 1], a[i + 2] - b[i + 2]));
  return m;
}

// Fixed steps: exactly compute_forces, start the solve from 2 v(t_n) − v(t_{n−1}) (from v(t_n) on the first
// two steps), solve with the step's implicit terms, x += Δt v. The extrapolated start is the same solution to
// the CG tolerance in fewer iterations than the plain warm start from v(t_n).
TEST(TimeStepper, FixedStepsAreTheForwardEulerLoop) {
  const HostMesh sphere = make_icosphere(2, 3.25e-6);
  CortexModel<Exec> a(Exec(), {HostCell(sphere)}, table1()), b(Exec(), {HostCell(sphere)}, table1()),
      plain(Exec(), {HostCell(sphere)}, table1());
  for (CortexModel<Exec>* m : {&a, &b, &plain}) perturb(*m, 0.04e-6, 7);
  TimeStepSettings s;
  s.dt = 6e-6;
  TimeStepper<Exec> stepper(a, s);
  int observed = 0, iterations_a = 0, iterations_plain = 0;
  std::vector<double> v1, v2;  // b's velocities of the last two steps
  for (int k = 0; k < 50; ++k) {
    const StepReport rep = stepper.step(a, tight(), INFINITY, [&](double h) {
      EXPECT_EQ(h, s.dt);
      ++observed;
    });
    iterations_a += rep.iterations;
    EXPECT_EQ(rep.h, s.dt);
    EXPECT_EQ(rep.halvings, 0);
    if (k >= 2) {
      auto v = Kokkos::create_mirror_view(b.velocity());
      for (std::size_t i = 0; i < v.extent(0); ++i)
        for (int d = 0; d < 3; ++d) v(i, d) = v1[3 * i + d] + (v1[3 * i + d] - v2[3 * i + d]);
      Kokkos::deep_copy(b.velocity(), v);
    }
    b.compute_forces();
    b.solve_velocity(tight(), s.dt);
    v2 = v1;
    v1 = to_host_vector(b.velocity());
    b.advance(s.dt);
    plain.compute_forces();
    iterations_plain += plain.solve_velocity(tight(), s.dt).iterations;
    plain.advance(s.dt);
  }
  EXPECT_EQ(observed, 50);
  EXPECT_NEAR(stepper.time(), 50 * s.dt, 1e-15);
  const auto xa = to_host_vector(a.positions()), xb = to_host_vector(b.positions()),
             xp = to_host_vector(plain.positions());
  for (std::size_t i = 0; i < xa.size(); ++i) ASSERT_EQ(xa[i], xb[i]) << i;
  std::printf(
      "  50 fixed steps: %d CG iterations from the extrapolated start, %d from v(t_n); positions "
      "differ by %.2e m\n",
      iterations_a, iterations_plain, max_distance(xa, xp));
  EXPECT_LT(iterations_a, iterations_plain);
  EXPECT_LT(max_distance(xa, xp), 1e-12);  // the CG tolerance's trace, ~1e-6 of the 40 nm perturbation
}

// Fixed steps end on t_end: the rest of the run under 1.5 Δt is one step (10.3 Δt: ten steps, the last
// 1.3 Δt), and 200 steps of 6 µs end at 1.2 ms without an extra sliver of a step for the rounding of their
// sum.
TEST(TimeStepper, FixedStepsLandOnTheEndTime) {
  const HostMesh sphere = make_icosphere(1, 3.25e-6);
  for (const auto& [t_end, want_steps, want_last] :
       {std::tuple{10.3 * 6e-6, 10, 1.3 * 6e-6}, std::tuple{1.2e-3, 200, 6e-6}}) {
    CortexModel<Exec> m(Exec(), {HostCell(sphere)}, table1());
    perturb(m, 0.04e-6, 3);
    TimeStepSettings s;
    s.dt = 6e-6;
    TimeStepper<Exec> stepper(m, s);
    int steps = 0;
    double last = 0;
    while (stepper.time() < t_end * (1 - 1e-12) && steps < 1000) {
      const double remaining = t_end - stepper.time();
      last = stepper.step(m, CgSettings{}, remaining < 1.5 * s.dt ? remaining : INFINITY, [](double) {}).h;
      ++steps;
    }
    EXPECT_EQ(steps, want_steps) << "t_end " << t_end;
    EXPECT_NEAR(last, want_last, 1e-9 * want_last);
    EXPECT_NEAR(stepper.time(), t_end, 1e-12 * t_end);
  }
}

// Adaptive steps: relaxing the perturbed cell over 1.5 ms, the error against a reference (fixed steps of 1
// and 0.5 µs, Richardson-extrapolated: forward Euler is first order) falls as the tolerance is tightened,
// stays within ten times the tolerance times the number of steps, and costs fewer steps than the paper's
// fixed Δt. The last step lands on t_end.
TEST(TimeStepper, AdaptiveErrorFollowsTheTolerance) {
  const HostMesh sphere = make_icosphere(2, 3.25e-6);
  const double t_end = 0.0015;
  MechanicsParams p = table1();
  p.multigrid = true;  // the solves are to 1e-12 relative; the V-cycle only makes them cheaper
  auto run = [&](TimeStepSettings s, int& steps) {
    CortexModel<Exec> m(Exec(), {HostCell(sphere)}, p);
    perturb(m, 0.04e-6, 11);
    TimeStepper<Exec> stepper(m, s);
    steps = 0;
    while (stepper.time() < t_end * (1 - 1e-12)) {
      stepper.step(m, tight(), t_end - stepper.time(), [](double) {});
      ++steps;
    }
    EXPECT_NEAR(stepper.time(), t_end, 1e-12 * t_end);
    return to_host_vector(m.positions());
  };
  TimeStepSettings fine;
  fine.dt = 1e-6;
  int n_ref = 0;
  const auto coarse_ref = run(fine, n_ref);
  fine.dt = 0.5e-6;
  auto ref = run(fine, n_ref);
  for (std::size_t i = 0; i < ref.size(); ++i) ref[i] = 2 * ref[i] - coarse_ref[i];
  double previous_error = INFINITY;
  for (double tol : {1e-10, 1e-11, 1e-12}) {
    TimeStepSettings s;
    s.adaptive = true;
    s.dt = 1e-6;
    s.error_tol_m = tol;
    int steps = 0;
    const double error = max_distance(run(s, steps), ref);
    std::printf(
        "  tol %.0e m: %d steps, max node error %.3g m (reference: %d steps of 0.5 us, extrapolated)\n", tol,
        steps, error, n_ref);
    EXPECT_LT(error, previous_error) << "tol " << tol;
    EXPECT_LT(error, 10 * tol * steps) << "tol " << tol;
    if (tol >= 1e-10) {
      EXPECT_LT(steps, static_cast<int>(t_end / 6e-6)) << "fewer steps than the paper's fixed dt";
    }
    previous_error = error;
  }
}

// Adaptive steps with time.contact_change = q on a cell spreading on an adhesive plane: between two accepted
// steps the contact area changes by at most q relative, |ΔA| / max(A, Ā_t) ≤ q; without the criterion the
// same run changes it by far more per step (so the bound is the criterion's doing). Table 1 cortex, the
// spreading scene's solver options, 642 nodes, 4 ms.
TEST(TimeStepper, ContactChangeBoundsTheContactAreaPerStep) {
  const double r = 3.25e-6, a = 0.3e-6, t_end = 0.004;
  const MechanicsParams p = test_params::spreading_on_plane(r, a);
  const HostMesh sphere = make_icosphere(3, r);
  auto largest_change = [&](double q, int& steps) {
    CortexModel<Exec> m(Exec(), {HostCell(sphere)}, p);
    const double floor = to_host_vector(m.geometry().cell_area)[0] / m.mesh().n_tris;
    TimeStepSettings s;
    s.adaptive = true;
    s.error_tol_m = 1e-8;
    s.contact_change = q;
    TimeStepper<Exec> stepper(m, s);
    // The contact area at the start of every step, once its rejections are settled: a step is checked (and
    // taken again, shorter) at the start of the next one, so observe() sees the accepted positions.
    std::vector<double> area;
    while (stepper.time() < t_end * (1 - 1e-12))
      stepper.step(m, CgSettings{}, t_end - stepper.time(),
                   [&](double) { area.push_back(m.contact_area()); });
    steps = static_cast<int>(area.size());
    double worst = 0;
    for (std::size_t k = 1; k < area.size(); ++k)
      worst = std::max(worst, std::fabs(area[k] - area[k - 1]) / std::max(area[k], floor));
    EXPECT_GT(area.back(), area.front()) << "the cell spreads";
    return worst;
  };
  int steps_on = 0, steps_off = 0;
  const double q = 0.05;
  const double on = largest_change(q, steps_on), off = largest_change(0, steps_off);
  std::printf("  contact change per step: %.3g with q = %.2g (%d steps), %.3g without (%d steps)\n", on, q,
              steps_on, off, steps_off);
  EXPECT_LE(on, q * (1 + 1e-9));
  EXPECT_GT(off, 2 * q);
  EXPECT_GT(steps_on, steps_off);
}

// observe() sees the model's contact of the current positions, the same as update_contact() computes there,
// with fixed steps and with adaptive ones that take steps again (spread's onset reads it without evaluating
// the contact again).
TEST(TimeStepper, ObserveSeesTheContactOfTheCurrentPositions) {
  const double r = 3.25e-6, a = 0.3e-6, t_end = 0.002;
  const MechanicsParams p = test_params::spreading_on_plane(r, a);
  const HostMesh sphere = make_icosphere(3, r);
  for (const bool adaptive : {false, true}) {
    CortexModel<Exec> m(Exec(), {HostCell(sphere)}, p);
    TimeStepSettings s;
    s.adaptive = adaptive;
    s.dt = 2e-5;
    s.error_tol_m = 1e-9;
    s.contact_change = adaptive ? 0.02 : 0;
    TimeStepper<Exec> stepper(m, s);
    int steps = 0, rejected = 0, differ = 0, in_contact = 0;
    while (stepper.time() < t_end * (1 - 1e-12)) {
      const StepReport rep = stepper.step(m, CgSettings{}, t_end - stepper.time(), [&](double) {
        const double seen = m.contact_area(), load_seen = m.contact_load();
        m.update_contact();
        differ += seen != m.contact_area() || load_seen != m.contact_load();
        in_contact += seen > 0;
      });
      rejected += rep.rejections;
      ++steps;
    }
    std::printf("  %s: %d steps, %d taken again, %d with contact, %d where observe saw another contact\n",
                adaptive ? "adaptive" : "fixed", steps, rejected, in_contact, differ);
    EXPECT_EQ(differ, 0);
    EXPECT_GT(in_contact, steps / 2);
    if (adaptive) {
      EXPECT_GT(rejected, 0) << "the case must take steps again to check that path";
    }
  }
}

// A solve that cannot converge (one CG iteration allowed) is retried with half the step, and after the
// allowed halvings the run ends with a message that says so, never with garbage.
TEST(TimeStepper, UnconvergedSolveEndsInAClearErrorAfterTheHalvings) {
  const HostMesh sphere = make_icosphere(2, 3.25e-6);
  CortexModel<Exec> m(Exec(), {HostCell(sphere)}, table1());
  perturb(m, 0.04e-6, 3);
  TimeStepSettings s;
  s.max_halvings = 4;
  TimeStepper<Exec> stepper(m, s);
  CgSettings cg = tight();
  cg.max_iterations = 1;
  try {
    stepper.step(m, cg, INFINITY, [](double) {});
    FAIL() << "expected a NumericalError";
  } catch (const NumericalError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("did not converge"), std::string::npos) << what;
    EXPECT_NE(what.find("halved 4 times"), std::string::npos) << what;
  }
  EXPECT_EQ(stepper.time(), 0.0) << "no step was taken";
}

}  // namespace
}  // namespace dcm
