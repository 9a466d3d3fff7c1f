// spread: the paper's cell-spreading experiment (its Figures 1, 4–6). A cell placed just above an adhesive
// plane (its lowest node contact.start_gap_m above it, within the range h0) spreads under the overdamped
// dynamics Γ v = F (paper eqs. 30–32): Maugis–Dugdale adhesion of the rounded triangles, substrate friction,
// the cortex terms and dashpots of the scene. Writes to <out>/:
//   series.csv   t_s,r_cc_m,contact_area_m2,area_m2,volume_m3,cg_iterations,dt_s,height_m,contact_load_N,
//                elastic_energy_J,dE_dt_W,contact_power_W,dissipation_W,energy_residual_W
//                (log-spaced in time: output.series_per_decade rows per decade, and every step at the start)
//   spread.h5/.xmf  mesh, series, frames (every output.frame_every_s and at t = 0.1, 0.35, 0.9 s) with the
//                per-node normal force and pressure, cortex tension (eq. 1) and stretch
//   summary.json r_cc_final_m, contact_angle_deg, early_exponent (+ window), height_final_m, steps, wall_s,
//                mean_cg_iterations, energy balance, ...
//   r_cc.png, cells.png, side_views.png (scripts/plot_spread.py) unless --no-plot
//   checkpoint.h5 the state at the end, on Ctrl-C and every output.checkpoint_every_s of wall time;
//                `spread --restart <out>/checkpoint.h5` continues bit for bit (docs/CHECKPOINTS.md)
// Ctrl-C (SIGINT) or SIGTERM: the loop stops after the current step, a checkpoint is written, the files are
// closed and valid, the summary says "interrupted": true; exit code 130.
#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "apps/common/app_cli.hpp"
#include "apps/common/mechanics_setup.hpp"
#include "core/checkpoint.hpp"
#include "core/h5_output.hpp"
#include "core/host_copy.hpp"
#include "core/json_writer.hpp"
#include "core/kokkos_compat.hpp"
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
};

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Sphere through a set of nodes (algebraic least squares |x|² = 2 c·x + d); the contact angle from the
// centre's height h_c above the plane: θ = π − acos(h_c / R). Two node sets:
//   paper: the top 95% of the nodes by height (the paper's method). It keeps most of the flat, adhered base
//          (only the lowest 5% of the nodes are dropped, a third of them lie in the contact), which pulls the
//          sphere down: on ideal caps it reads 88° for a true 65° cap and 112° for 97° (docs/VALIDATION.md).
//   free:  the nodes higher than 10% of the cell's height: the free membrane only, the true cap angle.
struct CapFit {
  double radius = NAN, centre_height = NAN, angle_deg = NAN;
};
CapFit fit_cap(const std::vector<double>& x, double plane_z, bool free_membrane) {
  const int n = static_cast<int>(x.size() / 3);
  std::vector<double> z(n);
  for (int i = 0; i < n; ++i) z[i] = x[3 * i + 2];
  std::vector<double> sorted = z;
  std::sort(sorted.begin(), sorted.end());
  const double cut = free_membrane ? plane_z + 0.1 * (sorted.back() - plane_z)
                                   : sorted[static_cast<std::size_t>(0.05 * (n - 1))];
  Eigen::MatrixXd a(n, 4);
  Eigen::VectorXd b(n);
  int m = 0;
  for (int i = 0; i < n; ++i) {
    if (z[i] < cut) continue;
    a.row(m) << 2 * x[3 * i], 2 * x[3 * i + 1], 2 * x[3 * i + 2], 1.0;
    b(m) = x[3 * i] * x[3 * i] + x[3 * i + 1] * x[3 * i + 1] + x[3 * i + 2] * x[3 * i + 2];
    ++m;
  }
  CapFit f;
  if (m < 4) return f;
  const Eigen::Vector4d s = a.topRows(m).colPivHouseholderQr().solve(b.head(m));
  f.radius = std::sqrt(s(3) + s(0) * s(0) + s(1) * s(1) + s(2) * s(2));
  f.centre_height = s(2) - plane_z;
  f.angle_deg = (kPi - std::acos(std::clamp(f.centre_height / f.radius, -1.0, 1.0))) * 180 / kPi;
  return f;
}

// Least-squares slope of log r against log t over the rows with from ≤ t ≤ to and r > 0.
double fit_exponent(const std::vector<double>& t, const std::vector<double>& r, double from, double to,
                    int& used) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  used = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (t[i] < from || t[i] > to || !(r[i] > 0)) continue;
    const double lx = std::log(t[i]), ly = std::log(r[i]);
    sx += lx;
    sy += ly;
    sxx += lx * lx;
    sxy += lx * ly;
    ++used;
  }
  if (used < 3) return NAN;
  return (used * sxy - sx * sy) / (used * sxx - sx * sx);
}

// The scene of a run: from the file and --set, or, for a restart, from its checkpoint with only the keys
// that do not change the physics allowed to change (a longer t_end, output settings).
Scene spread_scene(const AppOptions& options, const SpreadOptions& so, const Checkpoint* restart) {
  if (!restart) return load_scene(options, {"name=spread", "contact.plane=true"});
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
    if (key != "time.t_end_s" && key.rfind("output.", 0) != 0)
      throw SceneError("--set " + set +
                       " with --restart: only time.t_end_s and output.* may change on a "
                       "restart (the rest would not continue the same run)");
    scene.set(set);
  }
  scene.validate();
  return scene;
}

void run(const AppOptions& options, const SpreadOptions& so) {
  std::signal(SIGINT, on_signal);  // from the start: a stop during the set-up ends after the first step
  std::signal(SIGTERM, on_signal);
  std::optional<Checkpoint> restart;
  if (!so.restart.empty()) {
    restart = read_checkpoint(so.restart);
    if (restart->text("app") != "spread")
      throw IoError(so.restart + ": a checkpoint of '" + restart->text("app") + "', not of spread");
  }
  const Scene scene = spread_scene(options, so, restart ? &*restart : nullptr);
  if (!scene.get_bool("contact.plane"))
    throw SceneError("contact.plane = false: spread needs the substrate plane (set contact.plane = true)");
  if (!(so.early_from_s > 0 && so.early_to_s > so.early_from_s))
    throw SceneError("--early-window-s = " + std::to_string(so.early_from_s) + "," +
                     std::to_string(so.early_to_s) + " is not allowed: need 0 < from < to");
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
  const double dt = scene.get_real("time.dt_s"), t_end = scene.get_real("time.t_end_s");
  const TimeStepSettings step_settings = steps_from_scene(scene);
  if (so.check) {  // everything above would have stopped a bad run; nothing is written
    std::printf("spread: scene %s: ok (checked, nothing written)\n", scene.name().c_str());
    return;
  }
  const std::string out = restart
                              ? std::filesystem::path(so.restart).parent_path().lexically_normal().string()
                              : prepare_output_dir(options, scene);
  const std::string out_dir = out.empty() ? "." : out;
  KokkosSession kokkos(options.threads);
  const auto wall0 = std::chrono::steady_clock::now();

  // The cell, its lowest node `gap` above the plane.
  HostMesh mesh = cell_mesh_from_scene(scene);
  const double plane_z = scene.get_real("contact.plane_z_m");
  double zmin = INFINITY;
  for (const auto& x : mesh.nodes) zmin = std::min(zmin, x[2]);
  for (auto& x : mesh.nodes) x[2] += plane_z + gap - zmin;
  const MechanicsParams params = mechanics_from_scene(scene);
  CortexModel<Exec> model(Exec(), {HostCell(mesh)}, params);
  const int n = model.mesh().n_nodes;
  NodeFields<Exec::memory_space> fields(n);
  TimeStepper<Exec> stepper(n, step_settings);

  const long long steps = std::llround(t_end / dt);  // fixed steps; adaptive ones are counted as they go
  const double frame_every = scene.get_real("output.frame_every_s");
  const double per_decade = static_cast<double>(scene.get_int("output.series_per_decade"));
  const double checkpoint_every = scene.get_real("output.checkpoint_every_s");
  const std::string checkpoint_path = out_dir + "/checkpoint.h5";
  const CgSettings cg = cg_settings_from_scene(scene);

  // What the run has done so far: everything a restart needs besides the model and the stepper.
  const std::vector<double> figure_times = {0.1, 0.35, 0.9};  // paper Figures 1 and 6
  struct Progress {
    double step = 0, next_figure = 0, next_frame = 0, next_sample = 0, cg_total = 0, cg_max = 0;
    double worst_residual = 0, worst_residual_scale = 0, halved = 0, rejected = 0, h_min = INFINITY,
           h_max = 0;
    double wall_before = 0;  // wall seconds of earlier segments of a restarted run
  } p;
  std::vector<double> ts, rs, areas_c, heights;  // the series rows (HDF5 /series)
  std::string csv_text =
      "t_s,r_cc_m,contact_area_m2,area_m2,volume_m3,cg_iterations,dt_s,height_m,contact_load_N,"
      "elastic_energy_J,dE_dt_W,contact_power_W,dissipation_W,energy_residual_W\n";
  int frames_before = 0;
  if (restart) {
    const Checkpoint& c = *restart;
    model.restore_state(c);
    stepper.restore_state(c);
    double* fields_of_p[] = {&p.step,       &p.next_figure, &p.next_frame,     &p.next_sample,
                             &p.cg_total,   &p.cg_max,      &p.worst_residual, &p.worst_residual_scale,
                             &p.halved,     &p.rejected,    &p.h_min,          &p.h_max,
                             &p.wall_before};
    const std::vector<double>& saved = c.array("app.progress", std::size(fields_of_p));
    for (std::size_t i = 0; i < std::size(fields_of_p); ++i) *fields_of_p[i] = saved[i];
    ts = c.array("app.t_s");
    rs = c.array("app.r_cc_m", ts.size());
    areas_c = c.array("app.contact_area_m2", ts.size());
    heights = c.array("app.height_m", ts.size());
    csv_text = c.text("app.series_csv");
    frames_before = static_cast<int>(c.scalar("app.frames"));
  }

  std::vector<int> tri, node_cell(n, 0);
  for (const Tri& t : mesh.triangles) tri.insert(tri.end(), t.begin(), t.end());
  std::optional<H5Output> h5_storage;
  if (restart) {
    h5_storage.emplace(out_dir + "/spread.h5", H5Output::Resume{frames_before});
  } else {
    h5_storage.emplace(out_dir + "/spread.h5");
    h5_storage->write_text("scene", scene.to_toml());
    h5_storage->write_mesh(to_host_vector(model.positions()).data(), n, tri.data(),
                           static_cast<int>(mesh.triangles.size()), node_cell.data());
  }
  H5Output& h5 = *h5_storage;
  const auto append_h5_row = [&](std::size_t i) {
    h5.append_series(
        {{"t_s", ts[i]}, {"r_cc_m", rs[i]}, {"contact_area_m2", areas_c[i]}, {"height_m", heights[i]}});
  };
  for (std::size_t i = 0; i < ts.size(); ++i) append_h5_row(i);
  const std::string csv_tmp = out_dir + "/series.csv.part";
  std::ofstream csv(csv_tmp, std::ios::trunc);
  csv << csv_text;
  if (!csv) throw IoError(csv_tmp + ": cannot write");
  if (!options.quiet) {
    if (restart)
      std::printf(
          "dcm spread: restart from %s at t = %.6g s (step %lld), scene '%s', %d nodes, t_end = %.3g s; %s\n",
          so.restart.c_str(), stepper.time(), static_cast<long long>(p.step), scene.name().c_str(), n, t_end,
          kokkos_description().c_str());
    else
      std::printf("dcm spread: scene '%s', %d nodes, dt = %.3g s, t_end = %.3g s (%lld steps); %s\n",
                  scene.name().c_str(), n, dt, t_end, steps, kokkos_description().c_str());
  }

  auto write_frame = [&](double t) {
    model.node_fields(fields);
    const auto x = to_host_vector(model.positions());
    const auto tension = to_host_vector(fields.tension), stretch = to_host_vector(fields.stretch);
    const auto fn = to_host_vector(fields.normal_force), pn = to_host_vector(fields.normal_pressure);
    h5.write_frame(t, x.data(),
                   {{"cortex_tension_J_per_m2", 1, tension.data()},
                    {"stretch", 1, stretch.data()},
                    {"normal_force_N", 1, fn.data()},
                    {"normal_pressure_Pa", 1, pn.data()}});
  };
  // A checkpoint at a step boundary: model, stepper, and what the run has written (docs/CHECKPOINTS.md).
  auto write_checkpoint_now = [&] {
    Checkpoint c;
    c.put_text("app", "spread");
    c.put_text("scene", scene.to_toml());
    model.save_state(c);
    stepper.save_state(c);
    c.put("app.progress", {p.step, p.next_figure, p.next_frame, p.next_sample, p.cg_total, p.cg_max,
                           p.worst_residual, p.worst_residual_scale, p.halved, p.rejected, p.h_min, p.h_max,
                           p.wall_before + seconds_since(wall0)});
    c.put("app.t_s", ts);
    c.put("app.r_cc_m", rs);
    c.put("app.contact_area_m2", areas_c);
    c.put("app.height_m", heights);
    c.put_text("app.series_csv", csv_text);
    c.put("app.frames", static_cast<double>(h5.frames()));
    h5.flush();
    write_checkpoint(checkpoint_path, c);
  };
  auto last_checkpoint = std::chrono::steady_clock::now();
  // Numerical trouble ends the run (exit 3) with the files closed: what was done stays readable, no NaN row.
  auto stop_on_numerical_trouble = [&](const std::string& what) {
    h5.close();
    csv.close();
    std::rename(csv_tmp.c_str(), (out_dir + "/series.csv").c_str());
    throw NumericalError(what + " — try a smaller time.dt_s or time.adaptive = true" +
                         (std::filesystem::exists(checkpoint_path)
                              ? "; the last checkpoint is " + checkpoint_path
                              : std::string()));
  };

  // Forward Euler at the scene's fixed Δt (the paper's) or with adaptive, error-controlled steps; a step
  // that would take a bond too close to d_max is taken again with half the step (solvers/time_stepper.hpp).
  auto last_progress = std::chrono::steady_clock::now();
  bool interrupted = false, stopped_at_max_steps = false;
  const long long steps_before = static_cast<long long>(p.step);
  bool last = stepper.time() >= t_end * (1 - 1e-12);
  while (!last) {
    const double t = stepper.time();
    const long long index = static_cast<long long>(p.step);
    // The last step lands on t_end (a fixed-step run's last step may be up to 1.5 Δt long, as before).
    const double remaining = t_end - t;
    const double h_cap =
        stepper.settings().adaptive ? remaining : (remaining < 1.5 * dt ? remaining : INFINITY);
    double e0 = 0, pc = 0, dis = 0;
    bool sample = false;
    StepReport rep;
    try {
      rep = stepper.step(model, cg, h_cap, [&](double h_planned) {
        const auto next_figure = static_cast<std::size_t>(p.next_figure);
        if (t >= p.next_frame - 1e-12 ||
            (next_figure < figure_times.size() && t >= figure_times[next_figure] - 1e-12)) {
          write_frame(t);
          while (p.next_frame <= t + 1e-12) p.next_frame += frame_every;
          std::size_t f = next_figure;
          while (f < figure_times.size() && figure_times[f] <= t + 1e-12) ++f;
          p.next_figure = static_cast<double>(f);
        }
        sample = t >= p.next_sample || index < 10 || h_planned >= h_cap;
        if (sample) {
          e0 = model.energy();
          pc = model.contact_power();
          dis = model.dissipation();
        }
      });
    } catch (const NumericalError& e) {
      stop_on_numerical_trouble("step " + std::to_string(index) + " (t = " + std::to_string(stepper.time()) +
                                " s): " + e.what());
    }
    p.step += 1;
    const double h = rep.h;
    last = stepper.time() >= t_end * (1 - 1e-12);
    p.cg_total += rep.iterations;
    p.cg_max = std::max(p.cg_max, static_cast<double>(rep.iterations));
    p.halved += rep.halvings;
    p.rejected += rep.rejections;
    p.h_min = std::min(p.h_min, h);
    p.h_max = std::max(p.h_max, h);
    if (sample) {
      // Energy balance of the step: (E(t+h) − E(t))/h against the contact power minus the dissipation.
      const double e1 = model.energy(), de = (e1 - e0) / h, residual = de - (pc - dis);
      p.worst_residual = std::max(p.worst_residual, std::fabs(residual));
      p.worst_residual_scale = std::max(p.worst_residual_scale, std::fabs(dis) + std::fabs(pc));
      const double area_c = model.contact_area();
      if (!(area_c >= 0)) {  // not finite: the state is no longer a cell
        const auto tri_area_c = to_host_vector(model.contact()->tri_contact_area);
        const auto bad =
            std::find_if(tri_area_c.begin(), tri_area_c.end(), [](double a) { return !(a >= 0); });
        stop_on_numerical_trouble("step " + std::to_string(index) + " (t = " + std::to_string(t + h) +
                                  " s): the contact area is " + detail::format_real(area_c) +
                                  " m² (first at triangle " + std::to_string(bad - tri_area_c.begin()) + ")");
      }
      const double r_cc = std::sqrt(area_c / kPi);
      const auto xh = to_host_vector(model.positions());
      double ztop = -INFINITY;
      for (int i = 0; i < n; ++i) ztop = std::max(ztop, xh[3 * i + 2]);
      const double area = to_host_vector(model.geometry().cell_area)[0];
      const double volume = to_host_vector(model.geometry().cell_volume)[0];
      char line[512];
      std::snprintf(line, sizeof line,
                    "%.9g,%.9g,%.9g,%.9g,%.9g,%d,%.6g,%.9g,%.9g,%.12g,%.6g,%.6g,%.6g,%.6g\n", t + h, r_cc,
                    area_c, area, volume, rep.iterations, h, ztop - plane_z, model.contact_load(), e1, de, pc,
                    dis, residual);
      csv << line;
      csv_text += line;
      ts.push_back(t + h);
      rs.push_back(r_cc);
      areas_c.push_back(area_c);
      heights.push_back(ztop - plane_z);
      append_h5_row(ts.size() - 1);
      p.next_sample = (t + h) * std::pow(10.0, 1.0 / per_decade);
    }
    // Progress every 2 s of wall time, independent of the (log-spaced) series rows.
    if (!options.quiet && seconds_since(last_progress) > 2.0) {
      const double wall = seconds_since(wall0), rate = (p.step - steps_before) / wall;
      std::printf("  t = %.4f s  r_cc = %.3f um  dt = %.2g s  CG %d it  %.0f steps/s  ETA %.0f s\n",
                  stepper.time(), std::sqrt(model.contact_area() / kPi) * 1e6, h, rep.iterations, rate,
                  (t_end - stepper.time()) / h / rate);
      std::fflush(stdout);
      last_progress = std::chrono::steady_clock::now();
    }
    stopped_at_max_steps = so.max_steps > 0 && p.step >= static_cast<double>(so.max_steps) && !last;
    if (g_stop || stopped_at_max_steps) {
      interrupted = g_stop && !last;
      break;
    }
    if (checkpoint_every > 0 && seconds_since(last_checkpoint) > checkpoint_every) {
      write_checkpoint_now();
      last_checkpoint = std::chrono::steady_clock::now();
    }
  }
  // The final state: a checkpoint (a restart continues from here, e.g. with a longer t_end), then its frame.
  write_checkpoint_now();
  model.compute_forces();
  write_frame(stepper.time());
  const double t = stepper.time();
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  csv.close();
  std::rename(csv_tmp.c_str(), (out_dir + "/series.csv").c_str());
  h5.close();

  const long long done = static_cast<long long>(p.step);
  const auto x = to_host_vector(model.positions());
  double ztop = -INFINITY;
  for (int i = 0; i < n; ++i) ztop = std::max(ztop, x[3 * i + 2]);
  const CapFit cap = fit_cap(x, plane_z, false), cap_free = fit_cap(x, plane_z, true);
  int used = 0;
  const double alpha = fit_exponent(ts, rs, so.early_from_s, so.early_to_s, used);
  const double wall = p.wall_before + seconds_since(wall0);
  JsonObject summary;
  summary.add("scene", scene.name())
      .add("nodes", n)
      .add("interrupted", interrupted)
      .add("stopped_at_max_steps", stopped_at_max_steps)
      .add("restarted_from", so.restart)
      .add("t_end_s", t)
      .add("halved_steps", static_cast<long long>(p.halved))
      .add("rejected_steps", static_cast<long long>(p.rejected))
      .add("adaptive", stepper.settings().adaptive)
      .add("dt_min_taken_s", std::isfinite(p.h_min) ? p.h_min : 0.0)
      .add("dt_max_taken_s", p.h_max)
      .add("r_cc_final_m", rs.empty() ? 0.0 : rs.back())
      .add("contact_angle_deg", cap.angle_deg)
      .add("cap_radius_m", cap.radius)
      .add("contact_angle_free_deg", cap_free.angle_deg)
      .add("cap_radius_free_m", cap_free.radius)
      .add("early_exponent", alpha)
      .add("early_window_s", std::vector<double>{so.early_from_s, so.early_to_s})
      .add("early_window_rows", used)
      .add("height_final_m", ztop - plane_z)
      .add("steps", done)
      .add("dt_s", dt)
      .add("wall_s", wall)
      .add("mean_cg_iterations", done > 0 ? p.cg_total / done : 0.0)
      .add("max_cg_iterations", static_cast<long long>(p.cg_max))
      .add("energy_residual_max_W", p.worst_residual)
      .add("energy_residual_relative",
           p.worst_residual_scale > 0 ? p.worst_residual / p.worst_residual_scale : 0.0)
      .add("checkpoint", checkpoint_path);
  summary.write(out_dir + "/summary.json");
  if (!options.quiet)
    std::printf(
        "  r_cc = %.3f um, contact angle %.1f deg (free membrane %.1f), early exponent %.3f (t in [%g, %g] "
        "s), height %.3f um; "
        "%lld steps in %.1f s, mean CG %.1f\n",
        (rs.empty() ? 0.0 : rs.back()) * 1e6, cap.angle_deg, cap_free.angle_deg, alpha, so.early_from_s,
        so.early_to_s, (ztop - plane_z) * 1e6, done, wall, done > 0 ? p.cg_total / done : 0.0);
  if (so.plot && !interrupted && !stopped_at_max_steps) {
    const std::string cmd =
        std::string(DCM_PYTHON3) + " '" + DCM_SOURCE_DIR + "/scripts/plot_spread.py' '" + out_dir + "'";
    if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "spread: plotting failed (%s)\n", cmd.c_str());
  }
  if (interrupted)
    throw AppInterrupted("interrupted at t = " + std::to_string(t) + " s; " + out_dir +
                         "/spread.h5, series.csv and summary.json hold what was done; continue with: spread "
                         "--restart " +
                         checkpoint_path);
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
  dcm::add_common_options(app, options);
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
  app.add_flag("--check", so.check,
               "Only check the scene and the options (exit 0, or 2 with the error); write and run nothing");
  return dcm::run_app(app, argc, argv, [&] {
    if (window.size() == 2) {
      so.early_from_s = window[0];
      so.early_to_s = window[1];
    }
    dcm::run(options, so);
  });
}
