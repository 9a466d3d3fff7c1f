// spread: the paper's cell-spreading experiment (its Figures 1, 4–6). A cell placed just above an adhesive
// plane (its lowest node contact.start_gap_m above it, within the range h0) spreads under the overdamped
// dynamics Γ v = F (paper eqs. 30–32): Maugis–Dugdale adhesion of the rounded triangles, substrate friction,
// the cortex terms and dashpots of the scene. Writes to <out>/:
//   series.csv   t_s,r_cc_m,contact_area_m2,area_m2,volume_m3,cg_iterations,dt_s,height_m,contact_load_N,
//                elastic_energy_J,dE_dt_W,contact_power_W,dissipation_W,energy_residual_W
//                (log-spaced in time: output.series_per_decade rows per decade, and every step at the start)
//   spread.h5/.xmf  mesh, series (every column of series.csv), frames (every output.frame_every_s and at
//                t = 0.1, 0.35, 0.9 s) with the per-node normal force and pressure, cortex tension (eq. 1)
//                and stretch; not with output.hdf5 = false
//   summary.json r_cc_final_m, contact_angle_deg, early_exponent (+ window), height_final_m, steps, wall_s,
//                mean_cg_iterations, energy balance, warnings (steps that did not resolve the run), ...
// A new run removes an earlier run's files from its folder first (a restart continues them).
//   r_cc.png, cells.png, side_views.png (scripts/plot_spread.py) unless --no-plot
//   checkpoint.h5 the state at the end, on Ctrl-C and every output.checkpoint_every_s of wall time;
//                `spread --restart <out>/checkpoint.h5` continues bit for bit (docs/CHECKPOINTS.md)
// Ctrl-C (SIGINT) or SIGTERM: the loop stops after the current step, a checkpoint is written, the files are
// closed and valid, the summary says "interrupted": true; exit code 130.
//
// A batch (`spread --batch MEMBERS.txt`, one member per line: `[SCENE.toml] [--set KEY=VALUE]... --out DIR`):
// the members are cells of one model (the batched engine, docs/SCANS.md): one launch per kernel for all,
// per-cell constants, CG and time steps. Each member's folder gets exactly the files its run alone writes,
// with the same numbers (wall_s excepted: the batch's). Members must need the same kernels and settings
// (mesh size, solver and time-step options); the first difference is named.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "apps/common/app_cli.hpp"
#include "apps/common/mechanics_setup.hpp"
#include "apps/spread/spread_fits.hpp"
#include "core/checkpoint.hpp"
#include "core/h5_output.hpp"
#include "core/host_copy.hpp"
#include "core/json_writer.hpp"
#include "core/kokkos_compat.hpp"
#include "dcm_config.hpp"
#include "solvers/time_stepper.hpp"

namespace dcm {
namespace {

using Exec = Kokkos::DefaultExecutionSpace;
constexpr double kPi = 3.14159265358979323846;

volatile std::sig_atomic_t g_stop = 0;
extern "C" void on_signal(int) { g_stop = 1; }

struct SpreadOptions {
  bool plot = true;
  // Window of the early power-law fit: from 10 ms (after the first triangles have touched down, r_cc of a few
  // edge lengths) to 0.1 s (the paper: still the t^1/2 regime at 100 ms). docs/model/spread.md.
  double early_from_s = 1e-2, early_to_s = 1e-1;
  std::string restart;      // checkpoint to continue from
  long long max_steps = 0;  // stop after this many steps (counted from the run's start), 0: no limit
  bool check = false;       // validate the scene and options, write nothing, run nothing
  std::string batch;        // file with one member per line: run them as one batch
};

// The columns of series.csv and of spread.h5's /series, one row per sample.
const std::vector<std::string> kSeriesColumns = {"t_s",
                                                 "r_cc_m",
                                                 "contact_area_m2",
                                                 "area_m2",
                                                 "volume_m3",
                                                 "cg_iterations",
                                                 "dt_s",
                                                 "height_m",
                                                 "contact_load_N",
                                                 "elastic_energy_J",
                                                 "dE_dt_W",
                                                 "contact_power_W",
                                                 "dissipation_W",
                                                 "energy_residual_W"};

std::string series_header() {
  std::string h;
  for (const std::string& c : kSeriesColumns) h += (h.empty() ? "" : ",") + c;
  return h + "\n";
}

// The rows of a series.csv text (header first), as kSeriesColumns values each: the HDF5 series of a
// checkpoint written before app.series_rows existed.
std::vector<double> parse_series_rows(const std::string& csv_text) {
  std::vector<double> rows;
  std::size_t pos = csv_text.find('\n');
  while (pos != std::string::npos && pos + 1 < csv_text.size()) {
    const std::size_t end = csv_text.find('\n', pos + 1);
    const std::string line = csv_text.substr(pos + 1, end == std::string::npos ? end : end - pos - 1);
    const char* c = line.c_str();
    for (std::size_t k = 0; k < kSeriesColumns.size(); ++k) {
      char* next = nullptr;
      rows.push_back(std::strtod(c, &next));
      c = *next == ',' ? next + 1 : next;
    }
    pos = end;
  }
  return rows;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

using spread_fits::CapFit;
using spread_fits::fit_cap;
using spread_fits::fit_exponent;

// The scene of a run: from the file and --set, or, for a restart, from its checkpoint with only the keys
// that do not change the physics allowed to change (a longer t_end, output settings).
Scene spread_scene(const AppOptions& options, const SpreadOptions& so, const Checkpoint* restart) {
  if (!restart) {
    Scene scene = load_scene(options, {"name=spread", "contact.plane=true"});
    if (!scene.was_set(
            "contact.plane")) {  // spread's own default, also under a scene file that leaves it out
      scene.set("contact.plane=true");
      scene.validate();
    }
    return scene;
  }
  if (!options.scene_path.empty())
    throw SceneError("--restart " + so.restart +
                     ": a restart takes its scene from the checkpoint; give no "
                     "scene file (change t_end with --set time.t_end_s=...)");
  if (!options.out_dir.empty())
    throw SceneError("--restart " + so.restart + " with --out " + options.out_dir +
                     ": a restart continues in the folder of its checkpoint; give no --out");
  Scene scene = Scene::from_string(restart->text("scene"), so.restart);
  for (const std::string& set : options.sets) {
    const std::string key = set.substr(0, set.find('='));
    if ((key != "time.t_end_s" && key.rfind("output.", 0) != 0) || key == "output.hdf5" ||
        key == "output.dir")
      throw SceneError(
          "--set " + set +
          " with --restart: only time.t_end_s and output.* (but output.hdf5 and output.dir) may "
          "change on a restart (the rest would not continue the same run; the run continues in its "
          "folder, its spread.h5 continues or stays absent)");
    scene.set(set);
  }
  scene.validate();
  // t_end = the checkpoint's time finishes the run without a step (a run killed between its last checkpoint
  // and its summary: scan resumes such members); an earlier t_end cannot continue it.
  const double t_done = restart->scalar("stepper.t");
  if (scene.get_real("time.t_end_s") < t_done * (1 - 1e-12))
    throw SceneError("time.t_end_s = " + detail::format_real(scene.get_real("time.t_end_s")) +
                     " is not allowed with --restart " + so.restart + ": the checkpoint is at t = " +
                     detail::format_real(t_done) + " s; continue with --set time.t_end_s=<a later time>");
  return scene;
}

// What the run of one member has done so far: everything a restart needs besides the model and the stepper.
struct Progress {
  double step = 0, next_figure = 0, next_frame = 0, next_sample = 0, cg_total = 0, cg_max = 0;
  double worst_residual = 0, worst_residual_scale = 0, halved = 0, rejected = 0, h_min = INFINITY, h_max = 0;
  double wall_before = 0;             // wall seconds of earlier segments of a restarted run
  std::array<double*, 13> fields() {  // in the checkpoint's app.progress order
    return {&step,   &next_figure,    &next_frame,           &next_sample, &cg_total,
            &cg_max, &worst_residual, &worst_residual_scale, &halved,      &rejected,
            &h_min,  &h_max,          &wall_before};
  }
};

// One spreading run: its scene and settings, its cell in the model, its output files and its progress.
struct Member {
  AppOptions options;
  SpreadOptions so;
  std::optional<Checkpoint> restart;
  Scene scene;
  HostMesh mesh;  // placed: its lowest node start_gap_m above the plane
  MechanicsParams params;
  TimeStepSettings steps;
  CgSettings cg;
  double plane_z = 0, dt = 0, t_end = 0, frame_every = 0, per_decade = 0, checkpoint_every = 0;
  std::string out_dir, checkpoint_path, csv_tmp;
  int cell = 0, first_node = 0, n = 0;
  Progress p;
  std::vector<double> ts, rs, areas_c, heights;  // series columns the summary's fits use
  std::vector<double> series_rows;               // every series row (kSeriesColumns values each), for HDF5
  std::string csv_text = series_header();
  int frames_before = 0;
  std::ofstream csv;
  std::unique_ptr<H5Output> h5;   // spread.h5; null with output.hdf5 = false
  bool wrote_checkpoint = false;  // this run (or the one it continues) has a checkpoint
  bool last = false, interrupted = false, stopped_at_max_steps = false, done = false;
  long long steps_before = 0;
  std::chrono::steady_clock::time_point last_checkpoint;
  // the step in progress
  double t = 0, h_cap = 0, e0 = 0, pc = 0, dis = 0;
  long long index = 0;
  bool sample = false;
};

const std::vector<double> kFigureTimes = {0.1, 0.35, 0.9};  // paper Figures 1 and 6

// The scene, its checks and the placed cell of one member; nothing is written.
void prepare_member(Member& m) {
  const SpreadOptions& so = m.so;
  if (!so.restart.empty()) {
    m.restart = read_checkpoint(so.restart);
    if (m.restart->text("app") != "spread")
      throw IoError(so.restart + ": a checkpoint of '" + m.restart->text("app") + "', not of spread");
    const double steps_done = m.restart->array("app.progress").at(0);  // Progress::step
    if (so.max_steps > 0 && static_cast<double>(so.max_steps) <= steps_done)
      throw SceneError("--max-steps " + std::to_string(so.max_steps) + " is not allowed with --restart " +
                       so.restart + ": the run has done " + detail::format_real(steps_done) +
                       " steps (--max-steps counts from the run's start); give a larger count");
  }
  m.scene = spread_scene(m.options, so, m.restart ? &*m.restart : nullptr);
  const Scene& scene = m.scene;
  if (!scene.get_bool("contact.plane"))
    throw SceneError(
        "contact.plane = false: spread needs the substrate plane (set contact.plane = true, or leave "
        "the key out)");
  if (!(so.early_from_s > 0 && so.early_to_s > so.early_from_s))
    throw SceneError("--early-window-s = " + detail::format_real(so.early_from_s) + "," +
                     detail::format_real(so.early_to_s) + " is not allowed: need 0 < from < to");
  const double h0 = scene.get_real("contact.h0_m"), gap = scene.get_real("contact.start_gap_m");
  const bool falls =
      scene.get_real("body.gravity_m_per_s2") > 0 && scene.get_real("body.density_excess_kg_per_m3") > 0;
  if (!(gap < h0) && !falls)
    throw SceneError("contact.start_gap_m = " + detail::format_real(gap) +
                     " is not allowed: it must be below contact.h0_m = " + detail::format_real(h0) +
                     " (the cell starts within the range of adhesion), unless gravity brings the cell down "
                     "(body.gravity_m_per_s2 > 0 with body.density_excess_kg_per_m3 > 0)");
  if (!(gap < h0)) {
    // The cell has to sink to the plane. Its weight is spread over the nodes, so the force vector's norm is
    // Δρ V g / √N: the CG's absolute tolerance must lie well below it, or the solve returns v = 0 and the
    // cell hangs in the fluid (the paper's 1e-14 N is larger than a 642-node RBC's weight norm, 4e-15 N).
    const double r = scene.get_string("mesh.shape") == "sphere" ? scene.get_real("mesh.radius_m")
                                                                : scene.get_real("mesh.diameter_m") / 2;
    const double weight = scene.get_real("body.density_excess_kg_per_m3") * 4.0 / 3.0 * kPi * r * r * r *
                          scene.get_real("body.gravity_m_per_s2");
    const double norm = weight / std::sqrt(static_cast<double>(scene.get_int("mesh.nodes")));
    const auto g3 = [](double v) {
      char b[32];
      std::snprintf(b, sizeof b, "%.3g", v);
      return std::string(b);
    };
    if (scene.get_real("solver.cg_abs_tol_N") > 1e-3 * norm)
      throw SceneError("solver.cg_abs_tol_N = " + g3(scene.get_real("solver.cg_abs_tol_N")) +
                       " is too large for a cell that sinks to the plane (contact.start_gap_m >= "
                       "contact.h0_m): its weight per "
                       "node, " +
                       g3(norm) + " N in norm, needs a tolerance <= " + g3(1e-3 * norm) + " N");
  }
  m.dt = scene.get_real("time.dt_s");
  m.t_end = scene.get_real("time.t_end_s");
  m.steps = steps_from_scene(scene);
  m.cg = cg_settings_from_scene(scene);
  m.frame_every = scene.get_real("output.frame_every_s");
  m.per_decade = static_cast<double>(scene.get_int("output.series_per_decade"));
  m.checkpoint_every = scene.get_real("output.checkpoint_every_s");
  m.plane_z = scene.get_real("contact.plane_z_m");
  m.mesh = cell_mesh_from_scene(scene);
  double zmin = INFINITY;
  for (const auto& x : m.mesh.nodes) zmin = std::min(zmin, x[2]);
  for (auto& x : m.mesh.nodes) x[2] += m.plane_z + gap - zmin;
  m.params = mechanics_from_scene(scene);
}

// Why member b cannot join member a's batch ("" if it can): what is not per cell must be the same.
std::string batch_difference(const Member& a, const Member& b) {
  const auto g = [](double v) { return detail::format_real(v); };
  if (a.mesh.nodes.size() != b.mesh.nodes.size())
    return "mesh.nodes = " + std::to_string(b.mesh.nodes.size()) + " (the batch has " +
           std::to_string(a.mesh.nodes.size()) + "; a batch shares one mesh size)";
  const struct {
    const char* key;
    double x, y;
  } reals[] = {{"time.dt_s", a.steps.dt, b.steps.dt},
               {"time.adaptive", a.steps.adaptive ? 1.0 : 0.0, b.steps.adaptive ? 1.0 : 0.0},
               {"time.error_tol_m", a.steps.error_tol_m, b.steps.error_tol_m},
               {"time.dt_min_s", a.steps.dt_min, b.steps.dt_min},
               {"time.dt_max_s", a.steps.dt_max, b.steps.dt_max},
               {"solver.cg_abs_tol_N", a.cg.abs_tol, b.cg.abs_tol},
               {"solver.cg_rel_tol", a.cg.rel_tol, b.cg.rel_tol},
               {"solver.cg_max_iterations", static_cast<double>(a.cg.max_iterations),
                static_cast<double>(b.cg.max_iterations)}};
  for (const auto& r : reals)
    if (r.x != r.y) return std::string(r.key) + " = " + g(r.y) + " (the batch has " + g(r.x) + ")";
  const std::string why = batch_mismatch(a.params, b.params);
  return why.empty() ? "" : "the scene: " + why;
}

using Model = CortexModel<Exec>;
using Stepper = TimeStepper<Exec>;

// Positions and per-node fields of every cell on the host, once for all members that write a frame now.
struct FrameData {
  std::vector<double> x, tension, stretch, normal_force, normal_pressure;
};
FrameData frame_data(Model& model, NodeFields<Exec::memory_space>& fields) {
  model.node_fields(fields);
  return {to_host_vector(model.positions()), to_host_vector(fields.tension), to_host_vector(fields.stretch),
          to_host_vector(fields.normal_force), to_host_vector(fields.normal_pressure)};
}

// One series row into spread.h5's /series (nothing with output.hdf5 = false).
void append_h5_series(Member& m, const double* row) {
  if (!m.h5) return;
  std::vector<std::pair<std::string, double>> named;
  for (std::size_t k = 0; k < kSeriesColumns.size(); ++k) named.emplace_back(kSeriesColumns[k], row[k]);
  m.h5->append_series(named);
}

void write_frame(Member& m, const FrameData& d, double t) {
  if (!m.h5) return;
  const auto slice = [&](const std::vector<double>& all, int per_node) {
    return std::vector<double>(all.begin() + per_node * m.first_node,
                               all.begin() + per_node * (m.first_node + m.n));
  };
  const auto x = slice(d.x, 3), tension = slice(d.tension, 1), stretch = slice(d.stretch, 1);
  const auto fn = slice(d.normal_force, 1), pn = slice(d.normal_pressure, 1);
  m.h5->write_frame(t, x.data(),
                    {{"cortex_tension_J_per_m2", 1, tension.data()},
                     {"stretch", 1, stretch.data()},
                     {"normal_force_N", 1, fn.data()},
                     {"normal_pressure_Pa", 1, pn.data()}});
}

// A checkpoint at a step boundary: the member's cell, its stepper state, and what it has written
// (docs/CHECKPOINTS.md): the checkpoint of the same run alone.
void write_checkpoint_now(Member& m, const Model& model, const Stepper& stepper, double wall) {
  Checkpoint c;
  c.put_text("app", "spread");
  c.put_text("scene", m.scene.to_toml());
  model.save_cell_state(c, m.cell);
  stepper.save_cell_state(c, model, m.cell);
  std::vector<double> progress;
  for (double* f : m.p.fields()) progress.push_back(f == &m.p.wall_before ? m.p.wall_before + wall : *f);
  c.put("app.progress", progress);
  c.put("app.t_s", m.ts);
  c.put("app.r_cc_m", m.rs);
  c.put("app.contact_area_m2", m.areas_c);
  c.put("app.height_m", m.heights);
  c.put_text("app.series_csv", m.csv_text);
  c.put("app.series_rows", m.series_rows);
  c.put("app.frames", m.h5 ? static_cast<double>(m.h5->frames()) : 0.0);
  if (m.h5) m.h5->flush();
  write_checkpoint(m.checkpoint_path, c);
  m.wrote_checkpoint = true;
}

// Numerical trouble ends the run (exit 3) with every member's files closed: what was done stays readable, no
// NaN row.
[[noreturn]] void stop_on_numerical_trouble(std::vector<Member>& ms, const std::string& what) {
  for (Member& m : ms) {
    if (m.done) continue;
    if (m.h5) m.h5->close();
    m.csv.close();
    std::rename(m.csv_tmp.c_str(), (m.out_dir + "/series.csv").c_str());
  }
  const Member& m = ms.front();
  throw NumericalError(what + " — try a smaller time.dt_s or time.adaptive = true" +
                       (ms.size() == 1 && m.wrote_checkpoint ? "; the last checkpoint is " + m.checkpoint_path
                                                             : std::string()));
}

// The end of a member's run: checkpoint, final frame, files closed, summary and plots.
void finish_member(Member& m, Model& model, const Stepper& stepper, NodeFields<Exec::memory_space>& fields,
                   double wall_now) {
  write_checkpoint_now(m, model, stepper, wall_now);
  model.compute_forces();
  const double t = stepper.time(m.cell);
  write_frame(m, frame_data(model, fields), t);
  m.csv.close();
  std::rename(m.csv_tmp.c_str(), (m.out_dir + "/series.csv").c_str());
  if (m.h5) m.h5->close();
  m.done = true;

  const long long done = static_cast<long long>(m.p.step);
  const auto x = model.cell_slice(model.positions(), m.cell);
  double ztop = -INFINITY;
  for (int i = 0; i < m.n; ++i) ztop = std::max(ztop, x[3 * i + 2]);
  const CapFit cap = fit_cap(x, m.plane_z, false), cap_free = fit_cap(x, m.plane_z, true);
  int used = 0;
  const SpreadOptions& so = m.so;
  const double alpha = fit_exponent(m.ts, m.rs, so.early_from_s, so.early_to_s, used);
  const double wall = m.p.wall_before + wall_now;
  const Progress& p = m.p;
  // A run that ends but did not resolve its dynamics says so (stderr, also with --quiet, and summary.json's
  // "warnings"): energy bookkeeping off by more than half of the powers (unless adaptive steps at their cap
  // explain it: the note below), or more step halvings than steps (healthy runs: below 0.25 and none;
  // docs/model/spread.md, "Energy balance").
  const double residual_rel = p.worst_residual_scale > 0 ? p.worst_residual / p.worst_residual_scale : 0.0;
  std::vector<std::string> warnings;
  char text[320];
  const bool long_adaptive_steps = stepper.settings().adaptive && p.h_max >= 0.99 * stepper.settings().dt_max;
  if (residual_rel > 0.5 && !long_adaptive_steps) {  // with long adaptive steps: the note below
    std::snprintf(
        text, sizeof text,
        "the energy balance is off by %.2g of the powers (energy_residual_relative): the steps do not "
        "resolve this run; use a smaller time.dt_s or time.adaptive = true",
        residual_rel);
    warnings.emplace_back(text);
  }
  if (p.halved > static_cast<double>(done) && done > 0) {
    std::snprintf(
        text, sizeof text,
        "%.0f step halvings in %lld steps (bonds near d_max): time.dt_s is too long for this scene; "
        "use a smaller one or time.adaptive = true",
        p.halved, done);
    warnings.emplace_back(text);
  }
  for (const std::string& w : warnings)
    std::fprintf(stderr, "spread: warning: %s%s\n",
                 m.cell > 0 || !m.so.batch.empty() ? (m.out_dir + ": ").c_str() : "", w.c_str());
  JsonObject summary;
  summary.add("scene", m.scene.name())
      .add("nodes", m.n)
      .add("interrupted", m.interrupted)
      .add("stopped_at_max_steps", m.stopped_at_max_steps)
      .add("restarted_from", so.restart)
      .add("t_end_s", t)
      .add("halved_steps", static_cast<long long>(p.halved))
      .add("rejected_steps", static_cast<long long>(p.rejected))
      .add("adaptive", stepper.settings().adaptive)
      .add("dt_min_taken_s", std::isfinite(p.h_min) ? p.h_min : 0.0)
      .add("dt_max_taken_s", p.h_max)
      .add("r_cc_final_m", m.rs.empty() ? 0.0 : m.rs.back())
      .add("contact_angle_deg", cap.angle_deg)
      .add("cap_radius_m", cap.radius)
      .add("contact_angle_free_deg", cap_free.angle_deg)
      .add("cap_radius_free_m", cap_free.radius)
      .add("early_exponent", alpha)
      .add("early_window_s", std::vector<double>{so.early_from_s, so.early_to_s})
      .add("early_window_rows", used)
      .add("height_final_m", ztop - m.plane_z)
      .add("steps", done)
      .add("dt_s", m.dt)
      .add("wall_s", wall)
      .add("mean_cg_iterations", done > 0 ? p.cg_total / done : 0.0)
      .add("max_cg_iterations", static_cast<long long>(p.cg_max))
      .add("energy_residual_max_W", p.worst_residual)
      .add("energy_residual_relative", residual_rel)
      .add("checkpoint", m.checkpoint_path)
      .add("warnings", warnings);
  summary.write(m.out_dir + "/summary.json");
  if (!m.options.quiet) {
    // No exponent (null in summary.json) when fewer than three series rows with contact lie in the window.
    char exponent[96];
    if (std::isfinite(alpha))
      std::snprintf(exponent, sizeof exponent, "%.3f", alpha);
    else
      std::snprintf(exponent, sizeof exponent, "none (%d rows with contact in the window)", used);
    std::printf(
        "  %sr_cc = %.3f um, contact angle %.1f deg (free membrane %.1f), early exponent %s (t in [%g, %g] "
        "s), height %.3f um; "
        "%lld steps in %.1f s, mean CG %.1f\n",
        m.cell > 0 || !m.so.batch.empty() ? (m.out_dir + ": ").c_str() : "",
        (m.rs.empty() ? 0.0 : m.rs.back()) * 1e6, cap.angle_deg, cap_free.angle_deg, exponent,
        so.early_from_s, so.early_to_s, (ztop - m.plane_z) * 1e6, done, wall,
        done > 0 ? p.cg_total / done : 0.0);
  }
  // Adaptive steps control the position error, not the energy bookkeeping: say when the longest steps left
  // the energy balance unresolved (docs/model/spread.md, "Energy balance").
  const double dt_max = stepper.settings().dt_max;
  if (!m.options.quiet && long_adaptive_steps && residual_rel > 0.01)
    std::printf(
        "  note: the energy residual is %.2g of the powers with steps up to time.dt_max_s = %g s; r_cc is "
        "controlled by time.error_tol_m, the energy balance is not resolved at these steps: lower "
        "time.dt_max_s to resolve it\n",
        residual_rel, dt_max);
  if (so.plot && !m.interrupted && !m.stopped_at_max_steps) {
    const std::string cmd = std::string(DCM_PYTHON3) + " '" + DCM_SOURCE_DIR + "/scripts/plot_spread.py' " +
                            (m.options.quiet ? "--quiet '" : "'") + m.out_dir + "'";
    std::fflush(stdout);  // this run's lines before the plotter's
    if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "spread: plotting failed (%s)\n", cmd.c_str());
  }
}

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
    for (const Member& m : ms)
      if (!m.options.quiet)
        std::printf("spread: scene %s: ok (checked, nothing written)\n", m.scene.name().c_str());
    return;
  }
  for (Member& m : ms) {
    m.out_dir = m.restart ? std::filesystem::path(m.so.restart).parent_path().lexically_normal().string()
                          : prepare_output_dir(m.options, m.scene);
    if (m.out_dir.empty()) m.out_dir = ".";
    m.checkpoint_path = m.out_dir + "/checkpoint.h5";
    m.wrote_checkpoint = m.restart.has_value();
    m.csv_tmp = m.out_dir + "/series.csv.part";
  }
  for (Member& m : ms)  // only once every member's folder is there: a refused batch removes nothing
    if (!m.restart)
      remove_earlier_outputs(
          m.out_dir, {"summary.json", "series.csv", "series.csv.part", "spread.h5", "spread.xmf",
                      "checkpoint.h5", "checkpoint.h5.tmp", "r_cc.png", "cells.png", "side_views.png"});
  KokkosSession kokkos(threads);
  const auto wall0 = std::chrono::steady_clock::now();

  // The model of the members that are still running, each a cell (its rest state from its own mesh).
  const auto make_model = [&](const std::vector<Member*>& running) {
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
  };
  std::vector<Member*> all;
  for (Member& m : ms) all.push_back(&m);
  Model model = make_model(all);
  NodeFields<Exec::memory_space> fields(model.mesh().n_nodes);
  Stepper stepper(model, ms.front().steps);
  for (Member& m : ms) {
    if (m.restart) {  // a restart is a one-member run
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
      m.frames_before = static_cast<int>(c.scalar("app.frames"));
    }
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
    if (quiet) continue;
    if (m.restart)
      std::printf(
          "dcm spread: restart from %s at t = %.6g s (step %lld), scene '%s', %d nodes, t_end = %.3g s; %s\n",
          m.so.restart.c_str(), stepper.time(m.cell), static_cast<long long>(m.p.step),
          m.scene.name().c_str(), m.n, m.t_end, kokkos_description().c_str());
    else if (ms.size() == 1)
      std::printf(
          "dcm spread: scene '%s', %d nodes, %s, t_end = %.3g s; %s\n", m.scene.name().c_str(), m.n,
          m.steps.adaptive
              ? ("adaptive steps from dt = " + detail::format_real(m.dt) + " s").c_str()
              : ("dt = " + detail::format_real(m.dt) + " s (" +
                 std::to_string(static_cast<long long>(std::ceil(m.t_end / m.dt * (1 - 1e-12)))) + " steps)")
                    .c_str(),
          m.t_end, kokkos_description().c_str());
  }
  if (!quiet && ms.size() > 1)
    std::printf("dcm spread: a batch of %zu members (%d nodes each) in one model; %s\n", ms.size(), ms[0].n,
                kokkos_description().c_str());

  auto last_progress = std::chrono::steady_clock::now();
  std::vector<double> cap, e0, pc, dis, e1, area_cells, load_cells;
  long long batch_steps = 0;
  for (;;) {
    bool any_running = false;
    cap.assign(model.n_cells(), 0.0);
    for (Member& m : ms) {
      if (m.last || m.done) continue;
      any_running = true;
      m.t = stepper.time(m.cell);
      m.index = static_cast<long long>(m.p.step);
      // The last step lands on t_end (a fixed-step run's last step may be up to 1.5 Δt long, as before).
      const double remaining = m.t_end - m.t;
      m.h_cap = m.steps.adaptive ? remaining : (remaining < 1.5 * m.dt ? remaining : INFINITY);
      cap[m.cell] = m.h_cap;
    }
    if (!any_running) break;
    std::vector<StepReport> rep;
    try {
      rep = stepper.step(model, ms.front().cg, cap, [&](const std::vector<double>& h_planned) {
        bool any_sample = false;
        std::optional<FrameData> frame;  // computed once, for every member that writes a frame now
        for (Member& m : ms) {
          m.sample = false;
          if (m.done || cap[m.cell] == 0) continue;
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
          m.sample = t >= p.next_sample || m.index < 10 || h_planned[m.cell] >= m.h_cap;
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
      });
    } catch (const NumericalError& e) {
      const Member& m = ms.front();
      stop_on_numerical_trouble(ms, (ms.size() == 1 ? "step " + std::to_string(m.index) + " (t = " +
                                                          detail::format_real(stepper.time(0)) + " s): "
                                                    : "batch step " + std::to_string(batch_steps) + ": ") +
                                        e.what());
    }
    ++batch_steps;
    bool any_row = false;
    for (Member& m : ms) any_row = any_row || (!m.done && cap[m.cell] > 0 && m.sample);
    if (any_row) {  // after the step: each sampled member's row
      model.energy(&e1);
      model.contact_area(&area_cells);
      model.contact_load(&load_cells);
    }
    const std::vector<double> cell_area =
        any_row ? to_host_vector(model.geometry().cell_area) : std::vector<double>();
    const std::vector<double> cell_volume =
        any_row ? to_host_vector(model.geometry().cell_volume) : std::vector<double>();
    const std::vector<double> x_all = any_row ? to_host_vector(model.positions()) : std::vector<double>();
    for (Member& m : ms) {
      if (m.done || cap[m.cell] == 0) continue;
      const StepReport& r = rep[m.cell];
      Progress& p = m.p;
      p.step += 1;
      const double h = r.h, t = m.t;
      m.last = stepper.time(m.cell) >= m.t_end * (1 - 1e-12);
      p.cg_total += r.iterations;
      p.cg_max = std::max(p.cg_max, static_cast<double>(r.iterations));
      p.halved += r.halvings;
      p.rejected += r.rejections;
      p.h_min = std::min(p.h_min, h);
      p.h_max = std::max(p.h_max, h);
      if (m.sample) {
        // Energy balance of the step: (E(t+h) − E(t))/h against the contact power minus the dissipation.
        const double e_after = e1[m.cell], de = (e_after - m.e0) / h, residual = de - (m.pc - m.dis);
        p.worst_residual = std::max(p.worst_residual, std::fabs(residual));
        p.worst_residual_scale = std::max(p.worst_residual_scale, std::fabs(m.dis) + std::fabs(m.pc));
        const double area_c = area_cells[m.cell];
        if (!(area_c >= 0)) {  // not finite: the state is no longer a cell
          const auto tri_area_c = to_host_vector(model.contact()->tri_contact_area);
          const int t0 = model.mesh().host_cell_tri_begin[m.cell],
                    t1 = model.mesh().host_cell_tri_begin[m.cell + 1];
          int bad = t0;
          while (bad < t1 && tri_area_c[bad] >= 0) ++bad;
          stop_on_numerical_trouble(ms, "step " + std::to_string(m.index) +
                                            " (t = " + detail::format_real(t + h) +
                                            " s): the contact area is " + detail::format_real(area_c) +
                                            " m² (first at triangle " + std::to_string(bad - t0) + ")" +
                                            (ms.size() > 1 ? " of member " + m.out_dir : std::string()));
        }
        const double r_cc = std::sqrt(area_c / kPi);
        double ztop = -INFINITY;
        for (int i = m.first_node; i < m.first_node + m.n; ++i) ztop = std::max(ztop, x_all[3 * i + 2]);
        const double row[] = {t + h,
                              r_cc,
                              area_c,
                              cell_area[m.cell],
                              cell_volume[m.cell],
                              static_cast<double>(r.iterations),
                              h,
                              ztop - m.plane_z,
                              load_cells[m.cell],
                              e_after,
                              de,
                              m.pc,
                              m.dis,
                              residual};
        static_assert(sizeof row / sizeof row[0] == 14, "one value per series column");
        char line[512];
        std::snprintf(line, sizeof line,
                      "%.9g,%.9g,%.9g,%.9g,%.9g,%d,%.6g,%.9g,%.9g,%.12g,%.6g,%.6g,%.6g,%.6g\n", row[0],
                      row[1], row[2], row[3], row[4], r.iterations, row[6], row[7], row[8], row[9], row[10],
                      row[11], row[12], row[13]);
        m.csv << line;
        m.csv_text += line;
        m.ts.push_back(t + h);
        m.rs.push_back(r_cc);
        m.areas_c.push_back(area_c);
        m.heights.push_back(ztop - m.plane_z);
        m.series_rows.insert(m.series_rows.end(), row, row + kSeriesColumns.size());
        append_h5_series(m, row);
        p.next_sample = (t + h) * std::pow(10.0, 1.0 / m.per_decade);
      }
      m.stopped_at_max_steps = m.so.max_steps > 0 && p.step >= static_cast<double>(m.so.max_steps) && !m.last;
    }
    // Progress every 2 s of wall time, independent of the (log-spaced) series rows.
    if (!quiet && seconds_since(last_progress) > 2.0) {
      const double wall = seconds_since(wall0);
      if (ms.size() == 1) {
        const Member& m = ms.front();
        const double h = rep[0].h, rate = (m.p.step - m.steps_before) / wall;
        std::printf("  t = %.4f s  r_cc = %.3f um  dt = %.2g s  CG %d it  %.0f steps/s  ETA %.0f s\n",
                    stepper.time(0), std::sqrt(model.contact_area() / kPi) * 1e6, h, rep[0].iterations, rate,
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
      last_progress = std::chrono::steady_clock::now();
    }
    bool stop_all = false;
    for (Member& m : ms)
      if (!m.done && m.stopped_at_max_steps) stop_all = true;
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
    // Members that reached their t_end: final state written; they leave the model, and the others continue
    // in a model of their own cells, bit for bit (nothing a cell computes depends on the other cells, and
    // each cell's rest state comes from its member's mesh): a finished cell costs nothing more.
    bool left = false;
    for (Member& m : ms)
      if (!m.done && m.last) {
        finish_member(m, model, stepper, fields, seconds_since(wall0));
        left = true;
      }
    std::vector<Member*> running;
    for (Member& m : ms)
      if (!m.done) running.push_back(&m);
    if (left && !running.empty()) {
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
  }
  // The final state of the members still open (interrupted or stopped at --max-steps).
  for (Member& m : ms)
    if (!m.done) finish_member(m, model, stepper, fields, seconds_since(wall0));
  // The handlers stay: a second SIGINT while the files are closed (scan forwards its own to each member) must
  // not kill the process before it exits with 130.
  for (const Member& m : ms)
    if (m.stopped_at_max_steps && !m.options.quiet)
      std::printf("  stopped after --max-steps %lld at t = %s s; continue with: spread --restart %s\n",
                  m.so.max_steps, detail::format_real(stepper.time(m.cell)).c_str(),
                  m.checkpoint_path.c_str());
  for (const Member& m : ms)
    if (m.interrupted)
      throw AppInterrupted("interrupted at t = " + detail::format_real(stepper.time(m.cell)) + " s; " +
                           m.out_dir + "/" + (m.h5 ? "spread.h5, " : "") +
                           "series.csv and summary.json hold what was done; continue with: spread "
                           "--restart " +
                           m.checkpoint_path);
}

// Splits a member line into words; "double quotes" keep spaces.
std::vector<std::string> split_words(const std::string& line) {
  std::vector<std::string> words;
  std::string w;
  bool quoted = false, have = false;
  for (const char ch : line) {
    if (ch == '"') {
      quoted = !quoted;
      have = true;
    } else if (!quoted && (ch == ' ' || ch == '\t')) {
      if (have) words.push_back(w);
      w.clear();
      have = false;
    } else {
      w += ch;
      have = true;
    }
  }
  if (quoted) throw SceneError("an unclosed \" in: " + line);
  if (have) words.push_back(w);
  return words;
}

// The members of --batch FILE: one per line, `[SCENE.toml] [--set KEY=VALUE]... --out DIR`; # comments.
std::vector<Member> read_batch(const std::string& path, const AppOptions& common, const SpreadOptions& so) {
  std::ifstream in(path);
  if (!in) throw IoError(path + ": cannot read the batch file");
  std::vector<Member> ms;
  std::string line;
  int number = 0;
  std::vector<std::string> outs;
  while (std::getline(in, line)) {
    ++number;
    const std::string where = path + ":" + std::to_string(number) + ": ";
    const std::vector<std::string> words = split_words(line.substr(0, line.find('#')));
    if (words.empty()) continue;
    Member& m = ms.emplace_back();
    m.options.quiet = common.quiet;
    m.options.threads = common.threads;
    m.so = so;
    for (std::size_t k = 0; k < words.size(); ++k) {
      const std::string& w = words[k];
      if ((w == "--set" || w == "--out") && k + 1 < words.size()) {
        (w == "--set" ? m.options.sets.push_back(words[k + 1]) : void(m.options.out_dir = words[k + 1]));
        ++k;
      } else if (w.rfind("--", 0) != 0 && k == 0) {
        if (!std::filesystem::exists(w)) throw SceneError(where + "scene file " + w + " does not exist");
        m.options.scene_path = w;
      } else {
        throw SceneError(where + "'" + w +
                         "' is not allowed: a member line is [SCENE.toml] [--set KEY=VALUE]... --out DIR");
      }
    }
    if (m.options.out_dir.empty()) throw SceneError(where + "a member needs --out DIR (its own folder)");
    for (const std::string& o : outs)
      if (o == m.options.out_dir)
        throw SceneError(where + "--out " + o + " is already another member's folder");
    outs.push_back(m.options.out_dir);
  }
  if (ms.empty()) throw SceneError(path + ": no member in the batch file");
  return ms;
}

void run(const AppOptions& options, const SpreadOptions& so) {
  if (!so.batch.empty()) {
    if (!so.restart.empty())
      throw SceneError("--batch with --restart: a restart continues one run; restart the member alone");
    if (!options.scene_path.empty() || !options.sets.empty() || !options.out_dir.empty())
      throw SceneError("--batch: give the scene, --set and --out of each member in the batch file, not here");
    std::vector<Member> ms = read_batch(so.batch, options, so);
    run_members(ms, options.quiet, options.threads);
    return;
  }
  std::vector<Member> ms(1);
  ms[0].options = options;
  ms[0].so = so;
  run_members(ms, options.quiet, options.threads);
}

}  // namespace
}  // namespace dcm
int main(int argc, char** argv) {
  CLI::App app(
      "Cell spreading on an adhesive plane (the paper's Figures 1, 4-6). Without a scene file it runs the\n"
      "built-in defaults with a plane; the paper's cases are in scenes/ (hategan2004_sphered.toml, ...).",
      "spread");
  dcm::AppOptions options;
  dcm::SpreadOptions so;
  dcm::add_common_options(
      app, options,
      {"scenes/default.toml", "scenes/hategan2004_sphered.toml --out out/hategan",
       "scenes/hategan2004_biconcave.toml --set mesh.nodes=642 --set time.adaptive=true --out out/bic642",
       "--restart out/hategan/checkpoint.h5 --set time.t_end_s=4"});
  app.add_flag(
      "--no-plot", [&](std::int64_t) { so.plot = false; }, "Do not write the PNG plots");
  std::vector<double> window;
  app.add_option("--early-window-s", window,
                 "Time window FROM,TO (s) of the early power-law fit (default 0.01,0.1)")
      ->delimiter(',')
      ->expected(2);
  app.add_option("--restart", so.restart,
                 "Continue the run whose checkpoint this is (<out>/checkpoint.h5), in its folder; the scene "
                 "comes from the checkpoint (--set may change time.t_end_s and output.* only)")
      ->check(CLI::ExistingFile);
  app.add_option("--max-steps", so.max_steps,
                 "Stop after this many steps in all (a checkpoint is written; --restart continues)")
      ->check(CLI::Range(1LL, 1000000000000LL));
  app.add_option(
         "--batch", so.batch,
         "Run the members listed in this file as one batch (one model, one launch per kernel for all; "
         "docs/SCANS.md): one member per line, [SCENE.toml] [--set KEY=VALUE]... --out DIR. Each "
         "member's folder gets what its run alone writes, with the same numbers")
      ->check(CLI::ExistingFile);
  return dcm::run_app(app, argc, argv, [&] {
    so.check = options.check;
    if (window.size() == 2) {
      so.early_from_s = window[0];
      so.early_to_s = window[1];
    }
    dcm::run(options, so);
  });
}
