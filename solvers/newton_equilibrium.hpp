#pragma once
// Equilibrium of a CortexModel (F(x) = 0) by an inexact Levenberg–Marquardt Newton method: each step
// solves (H + μ I) δ = F with conjugate gradients, where H = −∂F/∂x is applied matrix-free by a finite
// difference of the forces (one force evaluation per product), and stops the inner CG at negative
// curvature (Steihaug). A step is accepted when it lowers the total energy (a FENE bond pushed past d_max
// counts as a rise); then μ shrinks, else μ grows and the step is retried. Quadratic convergence near the
// equilibrium makes it far better than FIRE where the cell is stiff (strained FENE bonds under a load).
//
// Converged when max_i |F_i| ≤ force_tol (N).
#include <chrono>
#include <cmath>
#include <cstdio>

#include "solvers/cortex_model.hpp"

namespace dcm {

struct NewtonSettings {
  double force_tol = 1e-16;  // N
  int max_newton_steps = 200;
  int max_cg_iterations = 3000;
  double cg_rel_tol = 1e-3;  // inner solve: relative to |F| (inexact Newton)
  double mu_start = 0;       // N/m; 0: 1e-3 k_s
  int trace = 0;             // > 0: print every Newton step to stderr
  double progress_s = 0;     // > 0: a progress line on stdout at most this often (wall seconds)
};

struct NewtonResult {
  int newton_steps = 0, force_evaluations = 0;
  double max_force = 0;
  bool converged = false;
};

template <class ExecutionSpace>
NewtonResult newton_equilibrium(CortexModel<ExecutionSpace>& model, const NewtonSettings& s,
                                double length_scale) {
  using Vector = typename CortexModel<ExecutionSpace>::Vector;
  using Policy = Kokkos::RangePolicy<ExecutionSpace>;
  const ExecutionSpace space = model.space();
  const int n = model.mesh().n_nodes;
  const auto& sums = model.mesh().node_sums;  // fixed-order dot products (core/segmented_sum.hpp)
  const Vector x = model.positions(), f = model.force();
  Vector f0("dcm::newton::f0", n), x0("dcm::newton::x0", n), delta("dcm::newton::delta", n),
      r("dcm::newton::r", n), p("dcm::newton::p", n), hp("dcm::newton::hp", n);
  NewtonResult result;

  auto max_norm = [&](const Vector& v) {
    double m = 0;
    Kokkos::parallel_reduce(
        "dcm::newton::max_norm", Policy(space, 0, n),
        KOKKOS_LAMBDA(const int i, double& a) {
          const double b = norm(load3(v, i));
          if (b > a) a = b;
        },
        Kokkos::Max<double>(m));
    return m;
  };
  auto axpy = [&](const char* label, const Vector& y, double a, const Vector& v) {  // y += a v
    Kokkos::parallel_for(
        label, Policy(space, 0, n), KOKKOS_LAMBDA(const int i) {
          for (int d = 0; d < 3; ++d) y(i, d) += a * v(i, d);
        });
  };
  // hv = (H + μ I) v at x0 by a forward difference of the forces; leaves x = x0.
  auto apply_hessian = [&](const Vector& v, const Vector& hv, double mu) {
    const double vmax = max_norm(v);
    const double eps = vmax > 0 ? 1e-7 * length_scale / vmax : 0;
    Kokkos::deep_copy(space, x, x0);
    axpy("dcm::newton::probe", x, eps, v);
    model.compute_forces();
    ++result.force_evaluations;
    Kokkos::parallel_for(
        "dcm::newton::hv", Policy(space, 0, n), KOKKOS_LAMBDA(const int i) {
          for (int d = 0; d < 3; ++d) hv(i, d) = -(f(i, d) - f0(i, d)) / eps + mu * v(i, d);
        });
    Kokkos::deep_copy(space, x, x0);
  };

  model.compute_forces();
  ++result.force_evaluations;
  double energy = model.energy();
  double mu = s.mu_start > 0 ? s.mu_start : 1e-3 * model.params().bonds.k_s;
  result.max_force = max_norm(f);
  const auto started = std::chrono::steady_clock::now();
  auto last_progress = started;
  const auto seconds_since = [](std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  };
  while (result.newton_steps < s.max_newton_steps) {
    if (result.max_force <= s.force_tol) {
      result.converged = true;
      break;
    }
    ++result.newton_steps;
    Kokkos::deep_copy(space, x0, x);
    Kokkos::deep_copy(space, f0, f);
    // Inner CG on (H + μ I) δ = F0 from δ = 0, stopped at negative curvature.
    Kokkos::deep_copy(space, delta, 0.0);
    Kokkos::deep_copy(space, r, f0);
    Kokkos::deep_copy(space, p, f0);
    double rr = cg_detail::dot(space, sums, r, r, "dcm::newton::dot");
    const double stop = s.cg_rel_tol * s.cg_rel_tol * rr;
    int it = 0;
    for (; it < s.max_cg_iterations && rr > stop; ++it) {
      apply_hessian(p, hp, mu);
      const double php = cg_detail::dot(space, sums, p, hp, "dcm::newton::dot");
      if (!(php > 0)) {
        if (it == 0) axpy("dcm::newton::steepest", delta, 1.0 / mu, p);  // fall back to a gradient step
        break;
      }
      const double alpha = rr / php;
      axpy("dcm::newton::x_update", delta, alpha, p);
      axpy("dcm::newton::r_update", r, -alpha, hp);
      const double rr_new = cg_detail::dot(space, sums, r, r, "dcm::newton::dot");
      const double beta = rr_new / rr;
      rr = rr_new;
      Kokkos::parallel_for(
          "dcm::newton::direction", Policy(space, 0, n), KOKKOS_LAMBDA(const int i) {
            for (int d = 0; d < 3; ++d) p(i, d) = r(i, d) + beta * p(i, d);
          });
    }
    // Try x0 + δ; accept on an energy decrease.
    Kokkos::deep_copy(space, x, x0);
    axpy("dcm::newton::step", x, 1.0, delta);
    double trial = INFINITY;
    try {
      model.compute_forces();
      ++result.force_evaluations;
      trial = model.energy();
    } catch (const NumericalError&) {
      trial = INFINITY;
    }
    if (trial < energy) {
      energy = trial;
      mu = std::fmax(mu / 3, 1e-9 * model.params().bonds.k_s);
      result.max_force = max_norm(f);
    } else {
      mu *= 10;
      Kokkos::deep_copy(space, x, x0);
      model.compute_forces();
      ++result.force_evaluations;
    }
    if (s.progress_s > 0 && seconds_since(last_progress) >= s.progress_s) {
      last_progress = std::chrono::steady_clock::now();
      std::printf("  Newton step %d: largest node force %.3e N (target %.1e N), %.0f s\n",
                  result.newton_steps, result.max_force, s.force_tol, seconds_since(started));
      std::fflush(stdout);
    }
    if (s.trace > 0 && result.newton_steps % s.trace == 0)
      std::fprintf(stderr, "  Newton %d: max |F| = %.3e N, E = %.10e J, mu = %.2e, CG %d%s\n",
                   result.newton_steps, result.max_force, energy, mu, it,
                   trial < INFINITY ? "" : " (overstretched: retry)");
  }
  // The step that used up max_newton_steps may have reached the tolerance: the loop's test did not see it.
  if (result.max_force <= s.force_tol) result.converged = true;
  return result;
}

}  // namespace dcm
