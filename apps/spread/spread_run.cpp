// The time loop of a batch of spread members; one member is an ordinary run (apps/spread/spread_app.hpp).
// run_members() is the loop; the functions above it are its steps, in the order it calls them.
#include "apps/spread/spread_app.hpp"

namespace dcm {
namespace spread_app {

volatile std::sig_atomic_t g_stop = 0;

namespace {
extern "C" void on_signal(int) { g_stop = 1; }

// A time for a message: 9 significant digits (the sum of 0.02-s steps reads 0.034908, not
// 0.03490799999999795).
std::string short_time(double t) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", t);
  return text;
}

// A member's output folder: its checkpoint's for a restart, else output_dir_of().
std::string member_out_dir(const Member& m) {
  const std::string dir = m.restart
                              ? std::filesystem::path(m.so.restart).parent_path().lexically_normal().string()
                              : output_dir_of(m.options, m.scene);
  return dir.empty() ? "." : dir;
}

// Each member's output folder and file names; earlier outputs removed only once every member's folder is
// there, so that a refused batch removes nothing.
void prepare_output_folders(std::vector<Member>& ms) {
  for (Member& m : ms) {
    m.out_dir = m.restart ? member_out_dir(m) : prepare_output_dir(m.options, m.scene);
    m.checkpoint_path = m.out_dir + "/checkpoint.h5";
    m.wrote_checkpoint = m.restart.has_value();
    m.csv_tmp = m.out_dir + "/series.csv.part";
  }
  for (Member& m : ms)
    if (!m.restart)
      remove_earlier_outputs(
          m.out_dir, {"summary.json", "series.csv", "series.csv.part", "spread.h5", "spread.xmf",
                      "checkpoint.h5", "checkpoint.h5.tmp", "r_cc.png", "cells.png", "side_views.png"});
    else  // the plots of the run so far would be stale beside the continued data (--no-plot, or stopped)
      remove_earlier_outputs(m.out_dir, {"r_cc.png", "cells.png", "side_views.png"});
}

// The model of the members that are still running, each a cell (its rest state from its own mesh).
Model make_model(const std::vector<Member*>& running) {
  std::vector<HostCell> cells;
  std::vector<MechanicsParams> params;
  int first = 0;
  for (std::size_t k = 0; k < running.size(); ++k) {
    Member& m = *running[k];
    cells.emplace_back(m.mesh);
    params.push_back(m.params);
    m.cell = static_cast<int>(k);
    m.first_node = first;
    m.n = static_cast<int>(m.mesh.nodes.size());
    first += m.n;
  }
  return Model(Exec(), cells, params);
}

// A restart (a one-member run): the cell, the stepper and what the run had written, from the checkpoint.
void restore_from_checkpoint(Member& m, Model& model, Stepper& stepper) {
  const Checkpoint& c = *m.restart;
  model.restore_cell_state(c, m.cell);
  stepper.restore_cell_state(c, model, m.cell);
  const auto progress = m.p.fields();
  const std::vector<double>& saved = c.array("app.progress", progress.size());
  for (std::size_t i = 0; i < progress.size(); ++i) *progress[i] = saved[i];
  m.ts = c.array("app.t_s");
  m.rs = c.array("app.r_cc_m", m.ts.size());
  m.areas_c = c.array("app.contact_area_m2", m.ts.size());
  m.heights = c.array("app.height_m", m.ts.size());
  m.csv_text = c.text("app.series_csv");
  if (c.arrays.count("app.series_rows")) {
    m.series_rows = c.array("app.series_rows");
  } else {  // a checkpoint from before session 15: the CSV's digits, and the exact columns it kept
    m.series_rows = parse_series_rows(m.csv_text);
    const std::size_t w = kSeriesColumns.size();
    for (std::size_t i = 0; i < m.ts.size() && (i + 1) * w <= m.series_rows.size(); ++i) {
      m.series_rows[i * w + 0] = m.ts[i];
      m.series_rows[i * w + 1] = m.rs[i];
      m.series_rows[i * w + 2] = m.areas_c[i];
      m.series_rows[i * w + 7] = m.heights[i];
    }
  }
  if (c.arrays.count("app.pending_row")) m.pending_row = c.array("app.pending_row");  // since session 28
  if (c.arrays.count("app.contact_nodes")) {                                          // since session 32
    const std::vector<double>& n = c.array("app.contact_nodes", 3);
    m.contact_nodes = {n[0], n[1], n[2]};
  } else {
    m.contact_nodes.most = NAN;  // not known: the rows before the restart did not count them
  }
  if (c.arrays.count("app.h_last")) m.h_last = c.scalar("app.h_last");
  if (c.arrays.count("app.held_at_dt_min")) {  // since session 46
    const std::vector<double>& held = c.array("app.held_at_dt_min", 2);
    m.p.held = held[0];
    m.p.held_error_max = held[1];
  }
  if (c.arrays.count("app.contact_onset")) {                      // since session 36
    const std::vector<double>& v = c.array("app.contact_onset");  // 5 values (sessions 36-37) or 8
    if (v.size() != 5 && v.size() != 8)
      throw IoError(c.origin + ": 'app.contact_onset' holds " + std::to_string(v.size()) +
                    " values, this spread reads 5 or 8");
    m.onset.load(v);
  } else {
    m.onset_by_steps = false;  // the steps before the restart were not watched: the onset from the rows
  }
  m.frames_before = static_cast<int>(c.scalar("app.frames"));
  // A restart may ask for denser rows or frames (output.series_per_decade, output.frame_every_s): the next
  // row and frame then come when the new cadence asks from here, not at the stored times the old cadence
  // set. Only when that setting changed: a checkpoint taken with a row pending stores the next sample time
  // of the pending step's end, which a clamp from the stepper's time would move (a row more than the run
  // alone writes), so with the settings unchanged the stored times stay and the run continues bit for bit.
  const Scene saved_scene = Scene::from_string(c.text("scene"), "checkpoint");
  const double t = stepper.time(m.cell);
  if (static_cast<double>(saved_scene.get_int("output.series_per_decade")) != m.per_decade)
    m.p.next_sample = std::min(m.p.next_sample, t * std::pow(10.0, 1.0 / m.per_decade));
  if (saved_scene.get_real("output.frame_every_s") != m.frame_every)
    m.p.next_frame = std::min(m.p.next_frame, t + m.frame_every);
}

// spread.h5 (new, or resumed after the restart's frames) and series.csv.part with the rows so far.
void open_member_files(Member& m, const Model& model, const Stepper& stepper) {
  std::vector<int> tri, node_cell(m.n, 0);
  for (const Tri& t : m.mesh.triangles) tri.insert(tri.end(), t.begin(), t.end());
  if (!m.scene.get_bool("output.hdf5")) {
    m.h5.reset();
  } else if (m.restart) {
    m.h5 = std::make_unique<H5Output>(m.out_dir + "/spread.h5", H5Output::Resume{m.frames_before});
  } else {
    m.h5 = std::make_unique<H5Output>(m.out_dir + "/spread.h5");
    m.h5->write_text("scene", m.scene.to_toml());
    m.h5->write_mesh(model.cell_slice(model.positions(), m.cell).data(), m.n, tri.data(),
                     static_cast<int>(m.mesh.triangles.size()), node_cell.data());
  }
  for (std::size_t i = 0; i + kSeriesColumns.size() <= m.series_rows.size(); i += kSeriesColumns.size())
    append_h5_series(m, &m.series_rows[i]);
  m.csv.open(m.csv_tmp, std::ios::trunc);
  m.csv << m.csv_text;
  if (!m.csv) throw IoError(m.csv_tmp + ": cannot write");
  m.steps_before = static_cast<long long>(m.p.step);
  m.last = stepper.time(m.cell) >= m.t_end * (1 - 1e-12);
  m.last_checkpoint = std::chrono::steady_clock::now();
}

// The first line on the terminal: what runs, on what.
void print_banner(const std::vector<Member>& ms, const Stepper& stepper) {
  if (ms.size() > 1) {
    std::printf("dcm spread: a batch of %zu members (%d nodes each) in one model; %s\n", ms.size(), ms[0].n,
                kokkos_description().c_str());
    return;
  }
  const Member& m = ms.front();
  if (m.restart)
    std::printf(
        "dcm spread: restart from %s at t = %.6g s (step %lld), scene '%s', %d nodes, t_end = %.3g s; %s\n",
        m.so.restart.c_str(), stepper.time(m.cell), static_cast<long long>(m.p.step), m.scene.name().c_str(),
        m.n, m.t_end, kokkos_description().c_str());
  else
    std::printf("dcm spread: scene '%s', %d nodes, %s, t_end = %.3g s; %s\n", m.scene.name().c_str(), m.n,
                m.steps.adaptive ? ("adaptive steps from dt = " + detail::format_real(m.dt) + " s").c_str()
                                 : ("dt = " + detail::format_real(m.dt) + " s (" +
                                    std::to_string(std::max(1LL, std::llround(m.t_end / m.dt))) + " steps)")
                                       .c_str(),
                m.t_end, kokkos_description().c_str());
}

// Per cell, the cap on the next step (0: the member is not stepping); false when no member runs any more.
bool plan_step(std::vector<Member>& ms, const Stepper& stepper, std::vector<double>& cap) {
  bool any_running = false;
  for (Member& m : ms) {
    if (m.last || m.done) continue;
    any_running = true;
    m.t = stepper.time(m.cell);
    m.index = static_cast<long long>(m.p.step);
    // The last step lands on t_end (a fixed-step run's last step is up to 1.5 Δt long:
    // solvers/time_stepper.hpp).
    const double remaining = m.t_end - m.t;
    m.h_cap = m.steps.adaptive ? remaining : (remaining < 1.5 * m.dt ? remaining : INFINITY);
    cap[m.cell] = m.h_cap;
  }
  return any_running;
}

// After the step, the state at t + h that the sampled members' rows need (read once for all of them).
struct AfterStep {
  std::vector<double> energy, contact_area, contact_load, cell_area, cell_volume, x;
  bool any_row = false;

  void read(const std::vector<Member>& ms, const std::vector<double>& cap, Model& model) {
    any_row = false;
    for (const Member& m : ms) any_row = any_row || (!m.done && cap[m.cell] > 0 && m.sample);
    if (any_row) read_all(model);
  }
  // The state of every cell now, whether a member samples it or not.
  void read_all(Model& model) {
    model.energy(&energy);
    model.update_contact();  // the row's r_cc, contact area and load at t + h, as its other columns
    model.contact_area(&contact_area);
    model.contact_load(&contact_load);
    cell_area = to_host_vector(model.geometry().cell_area);
    cell_volume = to_host_vector(model.geometry().cell_volume);
    x = to_host_vector(model.positions());
  }
};

// A series row of member m for its step from t, h long, ending in the state `after` holds, with the step's
// energy balance: (E(t+h) − E(t))/h against the contact power minus the dissipation, both at the step's
// start with its velocity. Then the step's start energy (the row's 15th value, for a redo) and the number of
// nodes within h0 of the plane (16th).
std::vector<double> make_row(const Member& m, double t, double h, int iterations, double e0, double pc,
                             double dis, const AfterStep& after) {
  const double e_after = after.energy[m.cell], de = (e_after - e0) / h;
  const double area_c = after.contact_area[m.cell];
  double ztop = -INFINITY;
  int near = 0;
  for (int i = m.first_node; i < m.first_node + m.n; ++i) {
    ztop = std::max(ztop, after.x[3 * i + 2]);
    near += after.x[3 * i + 2] - m.plane_z < m.h0;
  }
  std::vector<double> row = {t + h,
                             std::sqrt(area_c / kPi),
                             area_c,
                             after.cell_area[m.cell],
                             after.cell_volume[m.cell],
                             static_cast<double>(iterations),
                             h,
                             ztop - m.plane_z,
                             after.contact_load[m.cell],
                             e_after,
                             de,
                             pc,
                             dis,
                             de - (pc - dis),
                             e0,
                             static_cast<double>(near)};
  return row;
}

// Before the step, on the state at t (the stepper calls it once the steps are planned and the step before
// is accepted): the last step's pending row, the frames due now, which members write a series row after this
// step, and their energy and powers at t.
struct BeforeStep {
  std::vector<Member>& ms;
  const std::vector<double>& cap;
  Model& model;
  const Stepper& stepper;
  NodeFields<Exec::memory_space>& fields;
  std::vector<double> e0, pc, dis;

  // The pending rows, now that their steps are accepted. A step the stepper has just taken again, shorter
  // (the time moved back), gets the row of the state it reaches instead: its start state, velocity and
  // powers are the same.
  void commit_pending_rows() {
    std::optional<AfterStep> now;  // read once, for every member whose last step was taken again
    for (Member& m : ms) {
      if (m.done || m.pending_row.empty()) continue;
      // A stop's row in a run that went on (not expected: every member reads the stop once per step, below)
      // is no row of an uninterrupted run.
      if (m.stop_sample) {
        m.pending_row.clear();
        continue;
      }
      const double t_now = stepper.time(m.cell);
      if (t_now != m.pending_row[0]) {
        if (!now) {
          now.emplace();
          now->read_all(model);
        }
        const std::vector<double>& old = m.pending_row;
        const double t0 = old[0] - old[6];
        std::vector<double> row =
            make_row(m, t0, t_now - t0, static_cast<int>(old[5]), old[14], old[11], old[12], *now);
        row[0] = t_now;
        m.pending_row = row;
        // The next sample time follows the row's own time, as record_row sets it (it had followed the end of
        // the step taken again, so the next row came up to that step's length too late: session 32).
        m.p.next_sample = t_now * std::pow(10.0, 1.0 / m.per_decade);
      }
      commit_row(m);
    }
  }

  // The contact's onset at the steps' resolution (spread_fits::OnsetTracker): every member that has seen no
  // contact since its last state without it, or one state with it (the onset is placed inside the step from
  // the first two), is shown the state at its time now. The contact is the stepper's
  // own, of the positions now (TimeStepper::step calls this after its last compute_forces(); until session 37
  // spread evaluated it again here, a contact pass per step until the first contact).
  void watch_onsets() {
    std::vector<double> area;
    for (Member& m : ms) {
      if (m.done || cap[m.cell] == 0 || !m.onset_by_steps || (m.onset.in_contact && !m.onset.refining))
        continue;
      if (area.empty()) model.contact_area(&area);
      m.onset.see(stepper.time(m.cell), area[m.cell]);
    }
  }

  void operator()(const std::vector<double>& h_planned) {
    commit_pending_rows();
    // Ctrl-C read once for every member (a batch's members decide their rows alike: a signal between two of
    // them gave one a stop row in a step that was not the last; found by review).
    const bool interrupted_now = g_stop;
    watch_onsets();
    bool any_sample = false;
    std::optional<FrameData> frame;  // computed once, for every member that writes a frame now
    for (Member& m : ms) {
      m.sample = false;
      if (m.done || cap[m.cell] == 0) continue;
      m.t = stepper.time(m.cell);  // not plan_step's: a rejection of the step before moves the time back
      const double t = m.t;
      Progress& p = m.p;
      const auto next_figure = static_cast<std::size_t>(p.next_figure);
      if (t >= p.next_frame - 1e-12 ||
          (next_figure < kFigureTimes.size() && t >= kFigureTimes[next_figure] - 1e-12)) {
        if (!frame) frame = frame_data(model, fields);
        write_frame(m, *frame, t);
        while (p.next_frame <= t + 1e-12) p.next_frame += m.frame_every;
        std::size_t f = next_figure;
        while (f < kFigureTimes.size() && kFigureTimes[f] <= t + 1e-12) ++f;
        p.next_figure = static_cast<double>(f);
      }
      // The run's last step always writes a row (the same test as account_step's m.last: a fixed-step run
      // whose steps add up to t_end within rounding ends on a step shorter than its cap).
      const bool ends_run = t + h_planned[m.cell] >= m.t_end * (1 - 1e-12);
      // A row when the step ends at or past the next sample time (its row's time is the step's end).
      m.sample = t + h_planned[m.cell] >= p.next_sample * (1 - 1e-12) || m.index < 10 ||
                 h_planned[m.cell] >= m.h_cap || ends_run;
      const bool stopping =
          interrupted_now || (m.so.max_steps > 0 && p.step + 1 >= static_cast<double>(m.so.max_steps));
      m.stop_sample = !m.sample && stopping;
      m.sample = m.sample || m.stop_sample;
      any_sample = any_sample || m.sample;
    }
    if (any_sample) {  // each cell's own sums (solvers/cortex_model.hpp): the bits of its run alone
      model.energy(&e0);
      model.contact_power(&pc);
      model.dissipation(&dis);
      for (Member& m : ms)
        if (m.sample) {
          m.e0 = e0[m.cell];
          m.pc = pc[m.cell];
          m.dis = dis[m.cell];
        }
    }
  }
};

// The row of a sampled member after its step r, pending until the next step accepts the step.
void record_row(std::vector<Member>& ms, Member& m, const StepReport& r, const AfterStep& after,
                const Model& model) {
  const double h = r.h, t = m.t;
  const double area_c = after.contact_area[m.cell];
  if (!(area_c >= 0)) {  // not finite: the state is no longer a cell
    const auto tri_area_c = to_host_vector(model.contact()->tri_contact_area);
    const int t0 = model.mesh().host_cell_tri_begin[m.cell],
              t1 = model.mesh().host_cell_tri_begin[m.cell + 1];
    int bad = t0;
    while (bad < t1 && tri_area_c[bad] >= 0) ++bad;
    stop_on_numerical_trouble(ms, "step " + std::to_string(m.index) + " (t = " + detail::format_real(t + h) +
                                      " s): the contact area is " + detail::format_real(area_c) +
                                      " m² (first at triangle " + std::to_string(bad - t0) + ")" +
                                      (ms.size() > 1 ? " of member " + m.out_dir : std::string()));
  }
  m.pending_row = make_row(m, t, h, r.iterations, m.e0, m.pc, m.dis, after);
  // The run's end: the time it was asked to reach, not the rounded sum of its steps.
  if (m.last && std::fabs(t + h - m.t_end) <= 1e-12 * m.t_end) m.pending_row[0] = m.t_end;
  if (!m.stop_sample) m.p.next_sample = (t + h) * std::pow(10.0, 1.0 / m.per_decade);
}

// The step's counts into the member's progress, and its row if it was sampled.
void account_step(std::vector<Member>& ms, Member& m, const StepReport& r, const AfterStep& after,
                  const Model& model, const Stepper& stepper) {
  Progress& p = m.p;
  p.step += 1;
  m.last = stepper.time(m.cell) >= m.t_end * (1 - 1e-12);
  p.cg_total += r.iterations;
  p.cg_max = std::max(p.cg_max, static_cast<double>(r.iterations));
  p.halved += r.halvings;
  p.rejected += r.rejections;
  if (r.held_at_dt_min) {
    p.held += 1;
    p.held_error_max = std::max(p.held_error_max, r.error_m);
  }
  if (r.redone_h > 0) m.h_last = r.redone_h;  // this step took the one before it again, shorter
  if (m.h_last > 0) {
    p.h_min = std::min(p.h_min, m.h_last);
    p.h_max = std::max(p.h_max, m.h_last);
  }
  m.h_last = r.h;
  if (m.sample) record_row(ms, m, r, after, model);
  m.stopped_at_max_steps = m.so.max_steps > 0 && p.step >= static_cast<double>(m.so.max_steps) && !m.last;
}

// One line of progress (simulated time, rate, ETA; for a batch, the slowest member).
void print_progress(const std::vector<Member>& ms, const Model& model, const Stepper& stepper,
                    const std::vector<StepReport>& rep, long long batch_steps, double wall) {
  if (ms.size() == 1) {
    const Member& m = ms.front();
    const double h = rep[0].h, rate = (m.p.step - m.steps_before) / wall;
    std::printf(
        "  t = %.4f s  r_cc = %.3f um  dt = %.2g s  CG %d it (last step, all tries%s)  %.0f steps/s  ETA "
        "%.0f s\n",
        stepper.time(0), std::sqrt(model.contact_area() / kPi) * 1e6, h, rep[0].iterations,
        rep[0].iterations == 0 ? "; 0: the warm start met the tolerance" : "", rate,
        (m.t_end - stepper.time(0)) / h / rate);
  } else {
    int running = 0;
    double slowest = 1;
    for (const Member& m : ms)
      if (!m.last && !m.done) {
        ++running;
        slowest = std::min(slowest, stepper.time(m.cell) / m.t_end);
      }
    std::printf(
        "  batch step %lld: %d of %zu members running, the slowest at %.1f%% of its t_end, %.0f "
        "batch steps/s\n",
        batch_steps, running, ms.size(), 100 * slowest, batch_steps / wall);
  }
  std::fflush(stdout);
}

// Members that reached their t_end: final state written; they leave the model, and the others continue in a
// model of their own cells, bit for bit (nothing a cell computes depends on the other cells, and each cell's
// rest state comes from its member's mesh): a finished cell costs nothing more.
void retire_finished(std::vector<Member>& ms, Model& model, Stepper& stepper,
                     NodeFields<Exec::memory_space>& fields, std::chrono::steady_clock::time_point wall0) {
  bool left = false;
  for (Member& m : ms)
    if (!m.done && m.last) {
      finish_member(m, model, stepper, fields, seconds_since(wall0));
      left = true;
    }
  std::vector<Member*> running;
  for (Member& m : ms)
    if (!m.done) running.push_back(&m);
  if (!left || running.empty()) return;
  std::vector<Checkpoint> state(running.size());
  for (std::size_t k = 0; k < running.size(); ++k) {
    model.save_cell_state(state[k], running[k]->cell);
    stepper.save_cell_state(state[k], model, running[k]->cell);
  }
  model = make_model(running);
  fields = NodeFields<Exec::memory_space>(model.mesh().n_nodes);
  stepper = Stepper(model, ms.front().steps);
  for (std::size_t k = 0; k < running.size(); ++k) {
    model.restore_cell_state(state[k], static_cast<int>(k));
    stepper.restore_cell_state(state[k], model, static_cast<int>(k));
  }
}

}  // namespace

// Runs the members as one batch (one member: the ordinary run). Forward Euler at the scene's fixed Δt (the
// paper's) or with adaptive, error-controlled steps, each member with its own steps; a step that would take
// a bond too close to d_max is taken again with half the step (solvers/time_stepper.hpp).
void run_members(std::vector<Member>& ms, bool quiet, int threads) {
  std::signal(SIGINT, on_signal);  // from the start: a stop during the set-up ends after the first step
  std::signal(SIGTERM, on_signal);
  for (Member& m : ms) prepare_member(m);
  for (std::size_t k = 1; k < ms.size(); ++k) {
    const std::string why = batch_difference(ms[0], ms[k]);
    if (!why.empty())
      throw SceneError("--batch: member " + std::to_string(k + 1) + " (" + ms[k].options.out_dir +
                       ") cannot share the batch: " + why);
  }
  if (ms.front().so.check) {  // everything above would have stopped a bad run; nothing is written
    for (const Member& m : ms) check_output_dir(member_out_dir(m));
    for (const Member& m : ms)
      if (!m.options.quiet)
        std::printf("spread: scene %s: ok (checked, nothing written)\n", m.scene.name().c_str());
    return;
  }
  prepare_output_folders(ms);
  KokkosSession kokkos(threads);
  const auto wall0 = std::chrono::steady_clock::now();

  std::vector<Member*> all;
  for (Member& m : ms) all.push_back(&m);
  Model model = make_model(all);
  NodeFields<Exec::memory_space> fields(model.mesh().n_nodes);
  Stepper stepper(model, ms.front().steps);
  for (Member& m : ms) {
    if (m.restart) restore_from_checkpoint(m, model, stepper);
    open_member_files(m, model, stepper);
  }
  if (!quiet) print_banner(ms, stepper);

  auto last_progress = std::chrono::steady_clock::now();
  std::vector<double> cap;
  AfterStep after;
  long long batch_steps = 0;
  for (;;) {
    cap.assign(model.n_cells(), 0.0);
    if (!plan_step(ms, stepper, cap)) break;
    std::vector<StepReport> rep;
    try {
      rep = stepper.step(model, ms.front().cg, cap, BeforeStep{ms, cap, model, stepper, fields, {}, {}, {}});
    } catch (const NumericalError& e) {
      const Member& m = ms.front();
      stop_on_numerical_trouble(ms, (ms.size() == 1 ? "step " + std::to_string(m.index) + " (t = " +
                                                          detail::format_real(stepper.time(0)) + " s): "
                                                    : "batch step " + std::to_string(batch_steps) + ": ") +
                                        e.what());
    }
    ++batch_steps;
    after.read(ms, cap, model);
    for (Member& m : ms)
      if (!m.done && cap[m.cell] != 0) account_step(ms, m, rep[m.cell], after, model, stepper);
    // Progress every 2 s of wall time, independent of the (log-spaced) series rows.
    if (!quiet && seconds_since(last_progress) > 2.0) {
      print_progress(ms, model, stepper, rep, batch_steps, seconds_since(wall0));
      last_progress = std::chrono::steady_clock::now();
    }
    bool stop_all = false;
    for (Member& m : ms)
      if (!m.done && m.stopped_at_max_steps) stop_all = true;
    // Ctrl-C during a step that wrote no row: one more step, which does (BeforeStep), so that series.csv ends
    // on the state the run stops in.
    bool unsampled = false;
    for (const Member& m : ms)
      if (!m.done && !m.last && !m.sample) unsampled = true;
    if (g_stop && !stop_all && unsampled) continue;
    if (g_stop || stop_all) {
      for (Member& m : ms)
        if (!m.done) m.interrupted = g_stop && !m.last;
      break;
    }
    for (Member& m : ms)
      if (!m.done && !m.last && m.checkpoint_every > 0 &&
          seconds_since(m.last_checkpoint) > m.checkpoint_every) {
        write_checkpoint_now(m, model, stepper, seconds_since(wall0));
        m.last_checkpoint = std::chrono::steady_clock::now();
      }
    retire_finished(ms, model, stepper, fields, wall0);
  }
  // The final state of the members still open (interrupted or stopped at --max-steps).
  for (Member& m : ms)
    if (!m.done) finish_member(m, model, stepper, fields, seconds_since(wall0));
  // The handlers stay: a second SIGINT while the files are closed (scan forwards its own to each member) must
  // not kill the process before it exits with 130.
  for (const Member& m : ms)
    if (m.stopped_at_max_steps && !m.options.quiet)
      std::printf("  stopped after --max-steps %lld at t = %s s; continue with: %s --restart %s\n",
                  m.so.max_steps, short_time(stepper.time(m.cell)).c_str(), program_path("spread").c_str(),
                  m.checkpoint_path.c_str());
  for (const Member& m : ms)
    if (m.interrupted)
      throw AppInterrupted("interrupted at t = " + short_time(stepper.time(m.cell)) + " s; " + m.out_dir +
                           "/" + (m.h5 ? "spread.h5, " : "") +
                           "series.csv and summary.json hold what was done; continue with: " +
                           program_path("spread") + " --restart " + m.checkpoint_path +
                           (m.h5 ? "; plots of it: python3 " + std::string(DCM_SOURCE_DIR) +
                                       "/scripts/plot_spread.py " + m.out_dir
                                 : std::string()));
}

}  // namespace spread_app
}  // namespace dcm
