#pragma once
// The time stepper of a batch (docs/SCANS.md, "The batched engine: design", point 4): every cell of the
// model keeps its own time, step, error estimate, rejections and halvings, and takes exactly the steps
// TimeStepper (solvers/time_stepper.hpp) takes for it alone: the same decisions in the same order, made per
// cell, with the solves of the other cells frozen while one cell redoes or halves its step. A cell whose cap
// is 0 (it reached its own t_end) does not step; it still shares the launches.
//
// One batch step: forces of all cells; the velocity solve of the stepping cells, each with its own step;
// the adaptive error check per cell (a rejected cell moves back and solves again, alone in effect); the
// bond-extension guard per cell (a cell that would take a bond too close to d_max halves its step).
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "solvers/time_stepper.hpp"

namespace dcm {

template <class ExecutionSpace>
class BatchStepper {
 public:
  using Model = CortexModel<ExecutionSpace>;
  using Vector = typename Model::Vector;
  using Mem = typename Model::Mem;

  BatchStepper(const Model& model, const TimeStepSettings& settings)
      : settings_(settings),
        n_(model.n_cells()),
        t_(n_, 0.0),
        h_next_(n_, settings.dt),
        h_prev_(n_, 0.0),
        has_prev_(n_, 0),
        x_prev_(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::batch::x_prev"), model.mesh().n_nodes),
        v_prev_(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::batch::v_prev"), model.mesh().n_nodes),
        cell_h_(std::vector<double>(n_, 0.0), "dcm::batch::h") {}

  const TimeStepSettings& settings() const { return settings_; }
  double time(int c) const { return t_.at(c); }
  double next_step(int c) const { return h_next_.at(c); }
  int n_cells() const { return n_; }

  // Cell c's stepper state under TimeStepper's names (save_state there): a batch member's checkpoint is that
  // of its one-cell run, and a one-cell BatchStepper restores a TimeStepper checkpoint.
  void save_cell_state(Checkpoint& ck, const Model& model, int c) const {
    ck.put("stepper.t", t_[c]);
    ck.put("stepper.h_next", h_next_[c]);
    ck.put("stepper.h_prev", h_prev_[c]);
    ck.put("stepper.has_prev", has_prev_[c] ? 1.0 : 0.0);
    ck.put("stepper.x_prev", model.cell_slice(x_prev_, c));
    ck.put("stepper.v_prev", model.cell_slice(v_prev_, c));
  }
  // One-cell batches only (a restart continues one run).
  void restore_state(const Checkpoint& ck) {
    if (n_ != 1) throw std::logic_error("BatchStepper::restore_state: a checkpoint holds one cell");
    t_[0] = ck.scalar("stepper.t");
    h_next_[0] = ck.scalar("stepper.h_next");
    h_prev_[0] = ck.scalar("stepper.h_prev");
    has_prev_[0] = ck.scalar("stepper.has_prev") != 0;
    const std::size_t size = 3 * x_prev_.extent(0);
    from_host_vector(x_prev_, ck.array("stepper.x_prev", size));
    from_host_vector(v_prev_, ck.array("stepper.v_prev", size));
  }

  // One step of every cell c with h_cap[c] > 0, at most h_cap[c] long. observe(h) is called once, after the
  // velocities are known and before the positions move, with each cell's step (0: not stepping).
  // Returns one report per cell (all zero for a cell that did not step).
  template <class Observe>
  std::vector<StepReport> step(Model& model, const CgSettings& cg, const std::vector<double>& h_cap,
                               Observe&& observe) {
    if (static_cast<int>(h_cap.size()) != n_) throw std::invalid_argument("BatchStepper: one cap per cell");
    std::vector<StepReport> rep(n_);
    std::vector<char> stepping(n_, 0);
    std::vector<double> h(n_, 0.0), h_solved(n_, 0.0);
    for (int c = 0; c < n_; ++c)
      if (h_cap[c] > 0) {
        stepping[c] = 1;
        h[c] = std::min(h_next_[c], h_cap[c]);
      }
    model.compute_forces();
    solve(model, cg, stepping, h, rep);
    h_solved = h;
    if (settings_.adaptive) {
      std::vector<char> checking(n_, 0);
      for (int c = 0; c < n_; ++c) checking[c] = stepping[c] && has_prev_[c];
      while (any(checking)) {
        const std::vector<double> dv = velocity_change(model);
        std::vector<char> rejected(n_, 0);
        for (int c = 0; c < n_; ++c) {
          if (!checking[c]) continue;
          const double err = 0.5 * h_prev_[c] * dv[c];
          rep[c].error_m = err;
          if (err <= settings_.error_tol_m || h_prev_[c] <= settings_.dt_min * (1 + 1e-12)) {
            h[c] = std::min(grow(h_prev_[c], err), h_cap[c]);
            checking[c] = 0;
            continue;
          }
          const double shorter = std::max(settings_.dt_min, h_prev_[c] * shrink_factor(err));
          t_[c] += shorter - h_prev_[c];
          h_prev_[c] = shorter;
          rejected[c] = 1;
          ++rep[c].rejections;
        }
        if (!any(rejected)) break;
        redo_previous_step(model, rejected);
        model.compute_forces();
        for (int c = 0; c < n_; ++c)
          if (rejected[c]) h_solved[c] = h_prev_[c];
        solve(model, cg, rejected, h_solved, rep);
      }
      // The implicit terms depend on h: solve again where the step changed by more than 10%.
      std::vector<char> again(n_, 0);
      for (int c = 0; c < n_; ++c)
        again[c] = stepping[c] && has_prev_[c] && std::fabs(h[c] - h_solved[c]) > 0.1 * h_solved[c];
      if (any(again)) solve(model, cg, again, h, rep);
    }
    observe(h);
    Kokkos::deep_copy(x_prev_, model.positions());
    Kokkos::deep_copy(v_prev_, model.velocity());
    const std::vector<double> ext_start = model.cell_max_bond_extension();
    std::vector<double> ext_limit(n_);
    for (int c = 0; c < n_; ++c) ext_limit[c] = std::max(0.999, ext_start[c] + 0.5 * (1.0 - ext_start[c]));
    std::vector<char> moving = stepping;
    while (any(moving)) {
      advance(model, moving, h);
      const std::vector<double> ext = model.cell_max_bond_extension();
      std::vector<char> over(n_, 0);
      for (int c = 0; c < n_; ++c) {
        if (!moving[c] || ext[c] < ext_limit[c]) continue;
        if (rep[c].halvings == settings_.max_halvings)
          throw NumericalError("cell " + std::to_string(c) +
                               ": a bond stays at its maximum length d_max even with the time step halved " +
                               std::to_string(settings_.max_halvings) + " times");
        over[c] = 1;
        h[c] *= 0.5;
        ++rep[c].halvings;
      }
      if (any(over)) restore_positions(model, over);
      moving = over;
    }
    for (int c = 0; c < n_; ++c) {
      if (!stepping[c]) continue;
      t_[c] += h[c];
      h_prev_[c] = h[c];
      has_prev_[c] = 1;
      h_next_[c] = settings_.adaptive ? h[c] : settings_.dt;
      rep[c].h = h[c];
    }
    return rep;
  }

 private:
  static bool any(const std::vector<char>& flags) {
    for (const char f : flags)
      if (f) return true;
    return false;
  }

  // The velocity solve of the cells in `set`, each with its step h[c] (halved for a cell whose solve does
  // not converge, as TimeStepper::solve does); the other cells keep their velocity.
  void solve(Model& model, const CgSettings& cg, const std::vector<char>& set, std::vector<double>& h,
             std::vector<StepReport>& rep) {
    std::vector<char> pending = set;
    while (any(pending)) {
      std::vector<char> frozen(n_);
      std::vector<double> dt(n_);
      for (int c = 0; c < n_; ++c) {
        frozen[c] = !pending[c];
        dt[c] = pending[c] ? h[c] : h_next_[c];  // a frozen cell's step only keeps the operator's structure
      }
      model.solve_velocity(cg, dt, &frozen, false);
      const std::vector<CgResult>& r = model.cell_solves();
      for (int c = 0; c < n_; ++c) {
        if (!pending[c]) continue;
        rep[c].iterations += r[c].iterations;
        if (r[c].converged) {
          pending[c] = 0;
          continue;
        }
        if (!(r[c].residual_norm < INFINITY))
          throw NumericalError(
              "cell " + std::to_string(c) +
              ": conjugate gradients diverged: the residual is not finite; the largest force is "
              "at node " +
              std::to_string(model.largest_force_node()));
        if (rep[c].halvings >= settings_.max_halvings ||
            rep[c].unconverged_solves >= settings_.max_solve_halvings)
          throw NumericalError("cell " + std::to_string(c) + ": " + Model::unconverged_message(r[c], cg) +
                               ", even with the time step halved " + std::to_string(rep[c].halvings) +
                               " times");
        h[c] *= 0.5;
        ++rep[c].halvings;
        ++rep[c].unconverged_solves;
      }
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

  // Per cell, max_i |v_i − v_prev_i| over its nodes.
  std::vector<double> velocity_change(const Model& model) const {
    const auto a = model.velocity();
    const auto b = v_prev_;
    std::vector<double> m;
    segmented_max(
        "dcm::batch::max_velocity_change", model.space(), model.mesh().node_sums,
        KOKKOS_LAMBDA(const int i) {
          const double dx = a(i, 0) - b(i, 0), dy = a(i, 1) - b(i, 1), dz = a(i, 2) - b(i, 2);
          return dx * dx + dy * dy + dz * dz;
        },
        m);
    for (double& v : m) v = std::sqrt(v);
    return m;
  }

  // x = x_prev + h_prev v_prev on the flagged cells.
  void redo_previous_step(Model& model, const std::vector<char>& cells) {
    std::vector<double> h(n_, 0.0);
    for (int c = 0; c < n_; ++c)
      if (cells[c]) h[c] = h_prev_[c];
    cell_h_.assign(h);
    const auto x = model.positions();
    const auto x0 = x_prev_, v0 = v_prev_;
    const auto hc = cell_h_.values;
    const auto node_cell = model.mesh().node_cell;
    Kokkos::parallel_for(
        "dcm::batch::redo", Kokkos::RangePolicy<ExecutionSpace>(model.space(), 0, x.extent(0)),
        KOKKOS_LAMBDA(const int i) {
          const double step = hc(node_cell(i));
          if (step != 0)
            for (int d = 0; d < 3; ++d) x(i, d) = x0(i, d) + step * v0(i, d);
        });
  }

  // x += h v on the flagged cells (forward Euler, paper eq. 32).
  void advance(Model& model, const std::vector<char>& cells, const std::vector<double>& h) {
    std::vector<double> step(n_, 0.0);
    for (int c = 0; c < n_; ++c)
      if (cells[c]) step[c] = h[c];
    cell_h_.assign(step);
    const auto x = model.positions();
    const auto v = model.velocity();
    const auto hc = cell_h_.values;
    const auto node_cell = model.mesh().node_cell;
    Kokkos::parallel_for(
        "dcm::batch::euler", Kokkos::RangePolicy<ExecutionSpace>(model.space(), 0, x.extent(0)),
        KOKKOS_LAMBDA(const int i) {
          const double s = hc(node_cell(i));
          if (s != 0)
            for (int d = 0; d < 3; ++d) x(i, d) += s * v(i, d);
        });
  }

  // x = x_prev on the flagged cells.
  void restore_positions(Model& model, const std::vector<char>& cells) {
    std::vector<double> flag(n_, 0.0);
    for (int c = 0; c < n_; ++c) flag[c] = cells[c] ? 1.0 : 0.0;
    cell_h_.assign(flag);
    const auto x = model.positions();
    const auto x0 = x_prev_;
    const auto hc = cell_h_.values;
    const auto node_cell = model.mesh().node_cell;
    Kokkos::parallel_for(
        "dcm::batch::restore", Kokkos::RangePolicy<ExecutionSpace>(model.space(), 0, x.extent(0)),
        KOKKOS_LAMBDA(const int i) {
          if (hc(node_cell(i)) != 0)
            for (int d = 0; d < 3; ++d) x(i, d) = x0(i, d);
        });
  }

  TimeStepSettings settings_;
  int n_;
  std::vector<double> t_, h_next_, h_prev_;
  std::vector<char> has_prev_;
  Vector x_prev_, v_prev_;
  PerCell<double, Mem> cell_h_;
};

}  // namespace dcm
