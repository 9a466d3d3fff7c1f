#pragma once
// Forward Euler x ← x + h v (paper eq. 32) with the step-size logic of a run: a fixed step (the paper's), or
// adaptive steps with error control, and in both cases step halving when a FENE bond would come too close to
// d_max. Owns the simulated time. Design: docs/model/time_stepping.md.
//
// Per cell (the batched engine, docs/SCANS.md): every cell of the model keeps its own time, step, error
// estimate, rejections and halvings, and takes exactly the steps it takes alone: the same decisions in the
// same order, made per cell, with the solves of the other cells frozen while one cell redoes or halves its
// step. A cell whose cap is 0 (it reached its own t_end) does not step. A single run is a batch of one (the
// scalar step() below).
//
// Adaptive steps (settings.adaptive): the local error of the Euler step x₁ = x₀ + h v(x₀) is estimated
// against Heun's x₀ + h (v(x₀) + v(x₁))/2: e = (h/2) max_i |v_i(x₁) − v_i(x₀)| (m). v(x₁) is the next step's
// velocity, so the estimate costs no extra solve (first same as last). If e > tol the previous step is taken
// again, shorter; otherwise the next step is h · min(2, max(0.2, 0.9 √(tol/e))), within [dt_min, dt_max].
// With settings.contact_change = q > 0 a step is also taken again when it changed a cell's contact area by
// more than q relative (ρ = |ΔA| / max(A, Ā_t)), and the next step is at most h · 0.9 q / ρ: the contact
// area grows at first order in h, and the position error does not see how far the contact line moved.
//
// Fixed steps: the velocity solve starts from the linear extrapolation 2 v(t_n) − v(t_{n−1}) of the last two
// steps' velocities when both were one full step long (otherwise from v(t_n)): the same solution to the CG
// tolerance, in about half the iterations (docs/model/time_stepping.md). Not with adaptive steps, where the
// step length and rejections make the extrapolation a worse start than v(t_n).
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

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
  // adaptive: largest relative change of a cell's contact area per step, |ΔA_c| / max(A_c, Ā_t) (Ā_t: the
  // cell's mean triangle area); 0: off. The position error misses the contact line's motion in the
  // touch-down (docs/model/time_stepping.md, "Contact change per step").
  double contact_change = 0;
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
  double redone_h = 0;         // adaptive, with rejections: the new length of the previous step (s)
  // adaptive: the previous step was kept at dt_min although its error was above error_tol_m (the controller
  // cannot shorten it further). Not set for a contact change above contact_change alone: a triangle's first
  // touch changes a small contact area by more than any step resolves, with an error far below tolerance
  // (session 46: 2.8e-19 m against 1e-9 m at the first contact of a 70427-node cell).
  bool held_at_dt_min = false;
};

namespace stepper_detail {
// The stepper's kernels as free functions: a CUDA extended lambda may not sit in a private member function.

// Per segment (cell), max_i |a_i − b_i|² over its nodes, into m (host).
template <class ExecutionSpace, class Plan, class Vector>
void max_squared_difference(const ExecutionSpace& space, const Plan& sums, const Vector& a, const Vector& b,
                            std::vector<double>& m) {
  segmented_max(
      "dcm::batch::max_velocity_change", space, sums,
      KOKKOS_LAMBDA(const int i) {
        const double dx = a(i, 0) - b(i, 0), dy = a(i, 1) - b(i, 1), dz = a(i, 2) - b(i, 2);
        return dx * dx + dy * dy + dz * dz;
      },
      m);
}

// On the nodes of the cells with flag(c) ≠ 0: out = u + f_c (v − w), or out = u where f_c = 0; w empty
// stands for zero.
template <class ExecutionSpace, class Cells, class Values, class Vector>
void combine_nodes(const ExecutionSpace& space, const char* label, const Cells& node_cell, const Values& flag,
                   const Values& f, const Vector& out, const Vector& u, const Vector& v, const Vector& w) {
  const bool has_w = w.extent(0) > 0;
  Kokkos::parallel_for(
      label, Kokkos::RangePolicy<ExecutionSpace>(space, 0, out.extent(0)), KOKKOS_LAMBDA(const int i) {
        const int c = node_cell(i);
        if (flag(c) == 0) return;
        const double fc = f(c);
        for (int d = 0; d < 3; ++d)
          out(i, d) = fc == 0 ? u(i, d) : u(i, d) + fc * (has_w ? v(i, d) - w(i, d) : v(i, d));
      });
}

}  // namespace stepper_detail

template <class ExecutionSpace>
class TimeStepper {
 public:
  using Model = CortexModel<ExecutionSpace>;
  using Vector = typename Model::Vector;
  using Mem = typename Model::Mem;

  TimeStepper(const Model& model, const TimeStepSettings& settings)
      : settings_(settings),
        n_(model.n_cells()),
        t_(n_, 0.0),
        h_next_(n_, settings.dt),
        h_prev_(n_, 0.0),
        h_prev2_(n_, 0.0),
        has_prev_(n_, 0),
        has_prev2_(n_, 0),
        // Zeroed, not left uninitialised: a checkpoint holds them before they are first set (v_prev2_ in
        // adaptive runs never is), and a checkpoint must hold finite numbers.
        x_prev_("dcm::batch::x_prev", model.mesh().n_nodes),
        v_prev_("dcm::batch::v_prev", model.mesh().n_nodes),
        v_prev2_("dcm::batch::v_prev2", model.mesh().n_nodes),
        contact_prev_(n_, -1.0),
        contact_floor_(mean_triangle_areas(model)),
        cell_s_(std::vector<double>(n_, 0.0), "dcm::batch::factor"),
        cell_on_(std::vector<double>(n_, 0.0), "dcm::batch::on") {}

  const TimeStepSettings& settings() const { return settings_; }
  double time(int c) const { return t_.at(c); }
  double next_step(int c) const { return h_next_.at(c); }
  int n_cells() const { return n_; }

  // Cell c's stepper state: a batch member's checkpoint is that of its run alone.
  void save_cell_state(Checkpoint& ck, const Model& model, int c) const {
    ck.put("stepper.t", t_[c]);
    ck.put("stepper.h_next", h_next_[c]);
    ck.put("stepper.h_prev", h_prev_[c]);
    ck.put("stepper.has_prev", has_prev_[c] ? 1.0 : 0.0);
    ck.put("stepper.x_prev", model.cell_slice(x_prev_, c));
    ck.put("stepper.v_prev", model.cell_slice(v_prev_, c));
    ck.put("stepper.h_prev2", h_prev2_[c]);
    ck.put("stepper.has_prev2", has_prev2_[c] ? 1.0 : 0.0);
    ck.put("stepper.v_prev2", model.cell_slice(v_prev2_, c));
    ck.put("stepper.contact_prev", contact_prev_[c]);
  }
  // Cell c's stepper state from a checkpoint of it.
  void restore_cell_state(const Checkpoint& ck, const Model& model, int c) {
    t_.at(c) = ck.scalar("stepper.t");
    h_next_[c] = ck.scalar("stepper.h_next");
    h_prev_[c] = ck.scalar("stepper.h_prev");
    has_prev_[c] = ck.scalar("stepper.has_prev") != 0;
    model.set_cell_slice(x_prev_, c, ck.array("stepper.x_prev"));
    model.set_cell_slice(v_prev_, c, ck.array("stepper.v_prev"));
    // A checkpoint of a dcm before the extrapolated warm start has no second velocity: the first step after
    // the restart starts its solve from v(t_n).
    has_prev2_[c] = ck.arrays.count("stepper.has_prev2") && ck.scalar("stepper.has_prev2") != 0;
    // Older checkpoints have no contact area: the first step after the restart skips the contact check.
    contact_prev_[c] = ck.arrays.count("stepper.contact_prev") ? ck.scalar("stepper.contact_prev") : -1.0;
    if (has_prev2_[c]) {
      h_prev2_[c] = ck.scalar("stepper.h_prev2");
      model.set_cell_slice(v_prev2_, c, ck.array("stepper.v_prev2"));
    }
  }

  // A one-cell model: the time, and one step at most h_cap long; observe(h) is called once, after the
  // velocity of the step is known and before the positions move (a halving may still shorten h).
  double time() const { return t_.at(0); }
  template <class Observe>
  StepReport step(Model& model, const CgSettings& cg, double h_cap, Observe&& observe) {
    if (n_ != 1)
      throw std::logic_error("TimeStepper::step(h_cap): the model has several cells; give a cap per cell");
    return step(model, cg, std::vector<double>{h_cap},
                [&](const std::vector<double>& h) { observe(h[0]); })[0];
  }

  // One step of every cell c with h_cap[c] > 0, at most h_cap[c] long. observe(h) is called once, after the
  // velocities are known and before the positions move, with each cell's step (0: not stepping); the model's
  // forces and contact are then those of the current positions (the last compute_forces() was at them, after
  // any step taken again), so observe may read contact_area() without update_contact() (spread's onset does;
  // TimeStepper.ObserveSeesTheContactOfTheCurrentPositions).
  // Returns one report per cell (all zero for a cell that did not step).
  template <class Observe>
  std::vector<StepReport> step(Model& model, const CgSettings& cg, const std::vector<double>& h_cap,
                               Observe&& observe) {
    if (static_cast<int>(h_cap.size()) != n_) throw std::invalid_argument("TimeStepper: one cap per cell");
    std::vector<StepReport> rep(n_);
    std::vector<char> stepping(n_, 0);
    std::vector<double> h(n_, 0.0), h_solved(n_, 0.0);
    for (int c = 0; c < n_; ++c)
      if (h_cap[c] > 0) {
        stepping[c] = 1;
        // Fixed steps: a cap under 1.5 Δt is the rest of the run, taken as one step (no sliver of a step
        // after the last full one; an accumulated time a rounding short of t_end ends the run too).
        h[c] =
            !settings_.adaptive && h_cap[c] < 1.5 * settings_.dt ? h_cap[c] : std::min(h_next_[c], h_cap[c]);
      }
    if (!settings_.adaptive) extrapolate_warm_start(model, stepping);
    model.compute_forces();
    solve(model, cg, stepping, h, rep);
    h_solved = h;
    if (settings_.adaptive) {
      std::vector<char> checking(n_, 0);
      for (int c = 0; c < n_; ++c) checking[c] = stepping[c] && has_prev_[c];
      std::vector<double> areas;  // the contact areas of the current positions, once summed
      bool areas_current = false;
      while (any(checking)) {
        const std::vector<double> dv = velocity_change(model);
        const std::vector<double> rho = contact_change(model, areas);
        areas_current = settings_.contact_change > 0;
        std::vector<char> rejected(n_, 0);
        for (int c = 0; c < n_; ++c) {
          if (!checking[c]) continue;
          const double err = 0.5 * h_prev_[c] * dv[c];
          rep[c].error_m = err;
          const double q = settings_.contact_change;
          const bool contact_ok = !(q > 0) || rho[c] <= q;
          if ((err <= settings_.error_tol_m && contact_ok) || h_prev_[c] <= settings_.dt_min * (1 + 1e-12)) {
            rep[c].held_at_dt_min = !(err <= settings_.error_tol_m);
            double next = grow(h_prev_[c], err);
            // The contact-change limit, too, stays within [dt_min, dt_max] (it took steps below dt_min until
            // session 45, found by a helper's probe of extreme scenes).
            if (q > 0 && rho[c] > 0)
              next = std::max(settings_.dt_min, std::min(next, h_prev_[c] * std::max(0.2, 0.9 * q / rho[c])));
            h[c] = std::min(next, h_cap[c]);
            checking[c] = 0;
            continue;
          }
          double factor = err > settings_.error_tol_m ? shrink_factor(err) : 0.9;
          if (!contact_ok) factor = std::min(factor, std::max(0.2, 0.9 * q / rho[c]));
          const double shorter = std::max(settings_.dt_min, h_prev_[c] * factor);
          t_[c] += shorter - h_prev_[c];
          h_prev_[c] = shorter;
          rejected[c] = 1;
          ++rep[c].rejections;
        }
        if (!any(rejected)) break;
        redo_previous_step(model, rejected);
        model.compute_forces();
        areas_current = false;
        for (int c = 0; c < n_; ++c)
          if (rejected[c]) h_solved[c] = h_prev_[c];
        solve(model, cg, rejected, h_solved, rep);
      }
      for (int c = 0; c < n_; ++c)
        if (rep[c].rejections > 0) rep[c].redone_h = h_prev_[c];
      if (settings_.contact_change > 0) {  // A_c at the start of this step, for the next step's check
        if (!areas_current) areas = cell_contact_areas(model);
        for (int c = 0; c < n_; ++c)
          if (stepping[c]) contact_prev_[c] = areas[c];
      }
      // The implicit terms depend on h: solve again where the step changed by more than 10%.
      std::vector<char> again(n_, 0);
      for (int c = 0; c < n_; ++c)
        again[c] = stepping[c] && has_prev_[c] && std::fabs(h[c] - h_solved[c]) > 0.1 * h_solved[c];
      if (any(again)) solve(model, cg, again, h, rep);
    }
    observe(h);
    Kokkos::deep_copy(x_prev_, model.positions());
    if (!settings_.adaptive) {  // v(t_{n−1}) for the next step's extrapolated warm start
      combine_cells(model, stepping, std::vector<double>(n_, 0.0), v_prev2_, v_prev_, v_prev_, Vector(),
                    "dcm::stepper::keep_velocity");
      for (int c = 0; c < n_; ++c)
        if (stepping[c]) {
          h_prev2_[c] = h_prev_[c];
          has_prev2_[c] = has_prev_[c];
        }
    }
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
          throw NumericalError(
              which(c) + "a bond stays at its maximum length d_max even with the time step halved " +
              std::to_string(settings_.max_halvings) + " times (" + model.describe_most_extended_bond(c) +
              "; the forces on the cortex exceed what its bonds hold)");
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
  std::string which(int c) const { return n_ > 1 ? "cell " + std::to_string(c) + ": " : ""; }
  static bool any(const std::vector<char>& flags) {
    for (const char f : flags)
      if (f) return true;
    return false;
  }

  // The velocity solve of the cells in `set`, each with its step h[c]; a solve that does not converge (the
  // implicit stiffness of a bond close to d_max makes Γ + h K badly conditioned) is retried with h/2. The
  // other cells keep their velocity.
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
              which(c) +
              "conjugate gradients diverged: the residual is not finite; the largest force is "
              "at node " +
              std::to_string(model.largest_force_node()));
        if (rep[c].halvings >= settings_.max_halvings ||
            rep[c].unconverged_solves >= settings_.max_solve_halvings)
          throw NumericalError(which(c) + Model::unconverged_message(r[c], cg) +
                               (r[c].breakdown ? model.describe_breakdown(c) : std::string()) +
                               ", even with the time step halved " + std::to_string(rep[c].halvings) +
                               " times; largest force at node " + std::to_string(model.largest_force_node()));
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
    stepper_detail::max_squared_difference(model.space(), model.mesh().node_sums, a, b, m);
    for (double& v : m) v = std::sqrt(v);
    return m;
  }

  // Each cell's contact area (m²) at the current positions (the contact of the last compute_forces()).
  std::vector<double> cell_contact_areas(const Model& model) const {
    std::vector<double> a(n_, 0.0);
    model.contact_area(&a);
    return a;
  }
  // ρ_c = |A_c − A_c(start of the last step)| / max(A_c, Ā_t) per cell; zeros when the criterion is off.
  // a: receives the areas A_c (left as it is when the criterion is off).
  std::vector<double> contact_change(const Model& model, std::vector<double>& a) const {
    std::vector<double> rho(n_, 0.0);
    if (!(settings_.contact_change > 0)) return rho;
    a = cell_contact_areas(model);
    for (int c = 0; c < n_; ++c)  // < 0: no previous area (first step, older checkpoint), no check
      rho[c] =
          contact_prev_[c] < 0 ? 0.0 : std::fabs(a[c] - contact_prev_[c]) / std::max(a[c], contact_floor_[c]);
    return rho;
  }
  static std::vector<double> mean_triangle_areas(const Model& model) {
    const std::vector<double> area = to_host_vector(model.geometry().cell_area);
    const std::vector<int>& begin = model.mesh().host_cell_tri_begin;
    std::vector<double> mean(area.size());
    for (std::size_t c = 0; c < area.size(); ++c) mean[c] = area[c] / (begin[c + 1] - begin[c]);
    return mean;
  }

  // The start of the velocity solve on the flagged cells whose last two steps were equally long (a fixed
  // step): v = v(t_n) + (v(t_n) − v(t_{n−1})); the others start from v(t_n), the model's last velocity.
  void extrapolate_warm_start(Model& model, const std::vector<char>& cells) {
    std::vector<char> extrapolated(n_, 0);
    for (int c = 0; c < n_; ++c)
      extrapolated[c] = cells[c] && has_prev_[c] && has_prev2_[c] && h_prev_[c] == h_prev2_[c];
    combine_cells(model, extrapolated, std::vector<double>(n_, 1.0), model.velocity(), v_prev_, v_prev_,
                  v_prev2_, "dcm::stepper::extrapolate_velocity");
  }
  // x = x_prev + h_prev v_prev on the flagged cells.
  void redo_previous_step(Model& model, const std::vector<char>& cells) {
    combine_cells(model, cells, h_prev_, model.positions(), x_prev_, v_prev_, Vector(), "dcm::stepper::redo");
  }
  // x += h v on the flagged cells (forward Euler, paper eq. 32).
  void advance(Model& model, const std::vector<char>& cells, const std::vector<double>& h) {
    combine_cells(model, cells, h, model.positions(), model.positions(), model.velocity(), Vector(),
                  "dcm::integrator::euler");
  }
  // x = x_prev on the flagged cells.
  void restore_positions(Model& model, const std::vector<char>& cells) {
    combine_cells(model, cells, std::vector<double>(n_, 0.0), model.positions(), x_prev_, x_prev_, Vector(),
                  "dcm::stepper::restore");
  }
  // On the nodes of the flagged cells: out = u + s_c (v − w), or out = u where s_c = 0 (a copy, whatever v
  // holds: a restore after a failed step must not multiply a non-finite velocity by 0). w: an empty View
  // stands for zero.
  void combine_cells(const Model& model, const std::vector<char>& cells, const std::vector<double>& s,
                     const Vector& out, const Vector& u, const Vector& v, const Vector& w,
                     const char* label) {
    if (!any(cells)) return;
    std::vector<double> factor(n_, 0.0);
    for (int c = 0; c < n_; ++c)
      if (cells[c]) factor[c] = s[c];
    cell_s_.assign(factor);
    cell_on_.assign(std::vector<double>(cells.begin(), cells.end()));
    stepper_detail::combine_nodes(model.space(), label, model.mesh().node_cell, cell_on_.values,
                                  cell_s_.values, out, u, v, w);
  }

  TimeStepSettings settings_;
  int n_;
  std::vector<double> t_, h_next_, h_prev_, h_prev2_;
  std::vector<char> has_prev_, has_prev2_;
  Vector x_prev_, v_prev_, v_prev2_;  // v_prev2_: v(t_{n−1}), fixed steps only
  std::vector<double> contact_prev_;  // contact area per cell at the start of the last step (m²; −1: none)
  std::vector<double> contact_floor_;      // its floor in ρ: the cell's mean triangle area (m²)
  PerCell<double, Mem> cell_s_, cell_on_;  // combine_cells()'s factor and flag per cell
};

}  // namespace dcm
