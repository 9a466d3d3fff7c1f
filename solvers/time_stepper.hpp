#pragma once
// Forward Euler x ← x + h v (paper eq. 32) with the step-size logic of a run: a fixed step (the paper's), or
// adaptive steps with error control, and in both cases step halving when a FENE bond would come too close to
// d_max. Owns the simulated time. Design: docs/model/time_stepping.md.
//
// Adaptive steps (settings.adaptive): the local error of the Euler step x₁ = x₀ + h v(x₀) is estimated
// against Heun's x₀ + h (v(x₀) + v(x₁))/2: e = (h/2) max_i |v_i(x₁) − v_i(x₀)| (m). v(x₁) is the next step's
// velocity, so the estimate costs no extra solve (first same as last). If e > tol the previous step is taken
// again, shorter; otherwise the next step is h · min(2, max(0.2, 0.9 √(tol/e))), within [dt_min, dt_max].
#include <cmath>

#include "core/checkpoint.hpp"
#include "core/errors.hpp"
#include "core/host_copy.hpp"
#include "solvers/cortex_model.hpp"

namespace dcm {

struct TimeStepSettings {
  double dt = 6e-6;                     // s: the fixed step, or the first step when adaptive
  bool adaptive = false;                // error-controlled steps
  double error_tol_m = 1e-9;            // m: allowed local position error per step (adaptive)
  double dt_min = 1e-9, dt_max = 1e-3;  // s: bounds of the adaptive step
  int max_halvings = 20;  // halvings for a bond near d_max before the run stops (NumericalError)
  // Halvings for a velocity solve that does not converge: if h/64 does not help, the operator is not the
  // problem a shorter step solves (indefinite or non-finite); the run stops instead of crawling.
  int max_solve_halvings = 6;
};

struct StepReport {
  double h = 0;        // length of the step taken (s)
  int iterations = 0;  // CG iterations of all solves in this step
  int halvings = 0;    // retries with h/2: a bond came too close to d_max, or the solve did not converge
  int rejections = 0;  // adaptive: times the previous step was taken again, shorter
  int unconverged_solves = 0;  // solves that reached the CG iteration cap (each retried with h/2)
  double error_m = 0;          // adaptive: the error estimate of the previous step (m)
};

template <class ExecutionSpace>
class TimeStepper {
 public:
  using Model = CortexModel<ExecutionSpace>;
  using Vector = typename Model::Vector;

  TimeStepper(int n_nodes, const TimeStepSettings& settings)
      : settings_(settings),
        h_next_(settings.dt),
        x_prev_(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::stepper::x_prev"), n_nodes),
        v_prev_(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::stepper::v_prev"), n_nodes) {}

  double time() const { return t_; }
  double next_step() const { return h_next_; }
  const TimeStepSettings& settings() const { return settings_; }

  // Everything the next step depends on, for a bit-identical restart (the settings come from the scene).
  void save_state(Checkpoint& c) const {
    c.put("stepper.t", t_);
    c.put("stepper.h_next", h_next_);
    c.put("stepper.h_prev", h_prev_);
    c.put("stepper.has_prev", has_prev_ ? 1.0 : 0.0);
    c.put("stepper.x_prev", to_host_vector(x_prev_));
    c.put("stepper.v_prev", to_host_vector(v_prev_));
  }
  void restore_state(const Checkpoint& c) {
    t_ = c.scalar("stepper.t");
    h_next_ = c.scalar("stepper.h_next");
    h_prev_ = c.scalar("stepper.h_prev");
    has_prev_ = c.scalar("stepper.has_prev") != 0;
    const std::size_t size = 3 * x_prev_.extent(0);
    from_host_vector(x_prev_, c.array("stepper.x_prev", size));
    from_host_vector(v_prev_, c.array("stepper.v_prev", size));
  }

  // One step, at most h_cap long (the caller's t_end). observe(h) is called once, after the velocity of the
  // step is known and before the positions move (the caller samples energies there); h is the step about to
  // be taken (a halving may still shorten it).
  template <class Observe>
  StepReport step(Model& model, const CgSettings& cg, double h_cap, Observe&& observe) {
    StepReport rep;
    double h = std::min(h_next_, h_cap);
    model.compute_forces();
    solve(model, cg, h, rep);
    double h_solved = h;  // the step the implicit terms of the last solve were built for
    if (settings_.adaptive && has_prev_) {
      for (;;) {
        const double err = 0.5 * h_prev_ * max_difference(model.space(), model.velocity(), v_prev_);
        rep.error_m = err;
        if (err <= settings_.error_tol_m || h_prev_ <= settings_.dt_min * (1 + 1e-12)) {
          h = std::min(grow(h_prev_, err), h_cap);
          break;
        }
        // Take the previous step again, shorter: x = x_prev + h' v_prev.
        const double shorter = std::max(settings_.dt_min, h_prev_ * shrink_factor(err));
        t_ += shorter - h_prev_;
        h_prev_ = shorter;
        redo_previous_step(model);
        ++rep.rejections;
        model.compute_forces();
        h_solved = h_prev_;
        solve(model, cg, h_solved, rep);
      }
      // The implicit terms of the solve (bonds, bending, global constraints) depend on h: solve again when
      // the step changed by more than 10%.
      if (std::fabs(h - h_solved) > 0.1 * h_solved) solve(model, cg, h, rep);
    }
    observe(h);
    Kokkos::deep_copy(x_prev_, model.positions());
    Kokkos::deep_copy(v_prev_, model.velocity());
    // A step may take the most extended bond at most half-way from its length to d_max (and always to
    // 0.999 d_max): bonds approach x_max, as the paper's spread cells do, but never cross it.
    const double ext_start = model.max_bond_extension();
    const double ext_limit = std::max(0.999, ext_start + 0.5 * (1.0 - ext_start));
    for (;;) {
      model.advance(h);
      if (model.max_bond_extension() < ext_limit) break;
      if (rep.halvings == settings_.max_halvings)
        throw NumericalError("a bond stays at its maximum length d_max even with the time step halved " +
                             std::to_string(settings_.max_halvings) + " times");
      Kokkos::deep_copy(model.positions(), x_prev_);
      h *= 0.5;
      ++rep.halvings;
    }
    t_ += h;
    h_prev_ = h;
    has_prev_ = true;
    // Fixed steps return to dt after a halving; adaptive ones start the next step's solve with this step's
    // length (the error estimate then sets it).
    h_next_ = settings_.adaptive ? h : settings_.dt;
    rep.h = h;
    return rep;
  }

 private:
  // The velocity solve with the implicit terms of a step h; a solve that does not converge (the implicit
  // stiffness of a bond close to d_max makes Γ + h K badly conditioned) is retried with h/2.
  void solve(Model& model, const CgSettings& cg, double& h, StepReport& rep) {
    for (;;) {
      const CgResult r = model.solve_velocity(cg, h, false);
      rep.iterations += r.iterations;
      if (r.converged) return;
      if (rep.halvings >= settings_.max_halvings || rep.unconverged_solves >= settings_.max_solve_halvings)
        throw NumericalError(Model::unconverged_message(r, cg) + ", even with the time step halved " +
                             std::to_string(rep.halvings) + " times; largest force at node " +
                             std::to_string(model.largest_force_node()));
      h *= 0.5;
      ++rep.halvings;
      ++rep.unconverged_solves;
    }
  }
  double grow(double h, double err) const {
    const double factor =
        err > 0 ? std::min(2.0, std::max(0.2, 0.9 * std::sqrt(settings_.error_tol_m / err))) : 2.0;
    return std::min(settings_.dt_max, std::max(settings_.dt_min, h * factor));
  }
  double shrink_factor(double err) const {
    return std::min(0.9, std::max(0.2, 0.9 * std::sqrt(settings_.error_tol_m / err)));
  }
  void redo_previous_step(Model& model) {
    const auto x = model.positions();
    const auto x0 = x_prev_, v0 = v_prev_;
    const double h = h_prev_;
    Kokkos::parallel_for(
        "dcm::stepper::redo", Kokkos::RangePolicy<ExecutionSpace>(model.space(), 0, x.extent(0)),
        KOKKOS_LAMBDA(const int i) {
          for (int d = 0; d < 3; ++d) x(i, d) = x0(i, d) + h * v0(i, d);
        });
  }
  static double max_difference(const ExecutionSpace& space, const Vector& a, const Vector& b) {
    double m = 0;
    Kokkos::parallel_reduce(
        "dcm::stepper::max_velocity_change", Kokkos::RangePolicy<ExecutionSpace>(space, 0, a.extent(0)),
        KOKKOS_LAMBDA(const int i, double& acc) {
          const double dx = a(i, 0) - b(i, 0), dy = a(i, 1) - b(i, 1), dz = a(i, 2) - b(i, 2);
          const double d = dx * dx + dy * dy + dz * dz;
          if (d > acc) acc = d;
        },
        Kokkos::Max<double>(m));
    return std::sqrt(m);
  }

  TimeStepSettings settings_;
  double t_ = 0, h_next_ = 0, h_prev_ = 0;
  bool has_prev_ = false;
  Vector x_prev_, v_prev_;
};

}  // namespace dcm
