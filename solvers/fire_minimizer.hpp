#pragma once
// Equilibrium of a CortexModel by FIRE (Bitzek et al. 2006, PRL 97:170201): damped dynamics with a
// velocity mixing towards the force and an adaptive step, restarted whenever the power F·u turns
// negative. Used where only the equilibrium matters (the optical-tweezers stretch): equilibria do not
// depend on the friction operator, and FIRE reaches them in far fewer force evaluations than the
// overdamped flow. A step that overstretches a FENE bond is undone and retried with half the step.
//
// Converged when max_i |F_i| ≤ force_tol (N). Masses are uniform; the step is in units where the
// "mass" is 1 kg·(mass_scale): only the product dt²/m matters, chosen automatically from the stiffness.
#include <cmath>
#include <cstdio>

#include "solvers/cortex_model.hpp"

namespace dcm {

struct FireSettings {
  double force_tol = 1e-15;  // N, largest node force at equilibrium
  int max_steps = 200000;
  double dt_start = 0;  // 0: chosen from the initial forces (a step moving the fastest node ~1e-3 edge)
  int n_min = 5;
  double f_inc = 1.1, f_dec = 0.5, alpha_start = 0.1, f_alpha = 0.99, dt_max_factor = 10;
  int trace_every = 0;  // > 0: print progress to stderr every so many steps
};

struct FireResult {
  int steps = 0, force_evaluations = 0;
  double max_force = 0;
  bool converged = false;
};

template <class ExecutionSpace>
FireResult fire_minimize(CortexModel<ExecutionSpace>& model, const FireSettings& s, double length_scale) {
  using Vector = typename CortexModel<ExecutionSpace>::Vector;
  using Policy = Kokkos::RangePolicy<ExecutionSpace>;
  const ExecutionSpace space = model.space();
  const int n = model.mesh().n_nodes;
  const Vector x = model.positions();
  const Vector f = model.force();
  Vector u("dcm::fire::u", n), x_saved("dcm::fire::x_saved", n);

  auto max_force = [&] {
    double m = 0;
    Kokkos::parallel_reduce(
        "dcm::fire::max_force", Policy(space, 0, n),
        KOKKOS_LAMBDA(const int i, double& v) {
          const double a = norm(load3(f, i));
          if (a > v) v = a;
        },
        Kokkos::Max<double>(m));
    return m;
  };

  FireResult r;
  model.compute_forces();
  r.force_evaluations = 1;
  r.max_force = max_force();
  // Semi-implicit Euler with unit mass: displacement per step ~ dt² F. Start where the largest node
  // moves 1e-3 of the length scale.
  double dt = s.dt_start > 0 ? s.dt_start : std::sqrt(1e-3 * length_scale / std::fmax(r.max_force, 1e-300));
  const double dt_max = s.dt_max_factor * dt;
  double alpha = s.alpha_start;
  int since_reset = 0;
  while (r.steps < s.max_steps) {
    if (r.max_force <= s.force_tol) {
      r.converged = true;
      break;
    }
    ++r.steps;
    // FIRE mixing: u <- (1 - alpha) u + alpha |u| F/|F|, using the power P = F·u.
    const auto& sums = model.mesh().node_sums;  // fixed-order dot products
    const double p = cg_detail::dot(space, sums, f, u, "dcm::fire::dot"),
                 uu = cg_detail::dot(space, sums, u, u, "dcm::fire::dot"),
                 ff = cg_detail::dot(space, sums, f, f, "dcm::fire::dot");
    if (p > 0) {
      const double mix = alpha * std::sqrt(uu / ff);
      const double keep = 1 - alpha;
      Kokkos::parallel_for(
          "dcm::fire::mix", Policy(space, 0, n), KOKKOS_LAMBDA(const int i) {
            for (int d = 0; d < 3; ++d) u(i, d) = keep * u(i, d) + mix * f(i, d);
          });
      if (++since_reset > s.n_min) {
        dt = std::fmin(dt * s.f_inc, dt_max);
        alpha *= s.f_alpha;
      }
    } else {
      // FIRE 2.0 (Guénolé et al. 2020): step half back before stopping, which damps the overshoot.
      const double back = 0.5 * dt;
      Kokkos::parallel_for(
          "dcm::fire::back", Policy(space, 0, n), KOKKOS_LAMBDA(const int i) {
            for (int d = 0; d < 3; ++d) x(i, d) -= back * u(i, d);
          });
      Kokkos::deep_copy(space, u, 0.0);
      dt *= s.f_dec;
      alpha = s.alpha_start;
      since_reset = 0;
    }
    // Semi-implicit Euler: u += dt F, x += dt u.
    Kokkos::deep_copy(space, x_saved, x);
    const double h = dt;
    Kokkos::parallel_for(
        "dcm::fire::move", Policy(space, 0, n), KOKKOS_LAMBDA(const int i) {
          for (int d = 0; d < 3; ++d) {
            u(i, d) += h * f(i, d);
            x(i, d) += h * u(i, d);
          }
        });
    try {
      model.compute_forces();
    } catch (const NumericalError&) {  // overstretched: undo, stop, and take a smaller step
      Kokkos::deep_copy(space, x, x_saved);
      Kokkos::deep_copy(space, u, 0.0);
      dt *= s.f_dec;
      alpha = s.alpha_start;
      since_reset = 0;
      if (dt < 1e-12 * dt_max) throw;
      model.compute_forces();
    }
    ++r.force_evaluations;
    r.max_force = max_force();
    if (s.trace_every > 0 && r.steps % s.trace_every == 0)
      std::fprintf(stderr, "  FIRE step %d: max |F| = %.3e N, dt = %.3e, alpha = %.3f\n", r.steps,
                   r.max_force, dt, alpha);
  }
  return r;
}

}  // namespace dcm
