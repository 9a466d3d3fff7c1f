// Frames, checkpoints, and the summary and plots of a finished spread member (apps/spread/spread_app.hpp).
#include "apps/spread/spread_app.hpp"

namespace dcm {
namespace spread_app {

FrameData frame_data(Model& model, NodeFields<Exec::memory_space>& fields) {
  model.node_fields(fields);
  return {to_host_vector(model.positions()), to_host_vector(fields.tension), to_host_vector(fields.stretch),
          to_host_vector(fields.normal_force), to_host_vector(fields.normal_pressure)};
}

void append_h5_series(Member& m, const double* row) {
  if (!m.h5) return;
  std::vector<std::pair<std::string, double>> named;
  for (std::size_t k = 0; k < kSeriesColumns.size(); ++k) named.emplace_back(kSeriesColumns[k], row[k]);
  m.h5->append_series(named);
}

void commit_row(Member& m) {
  if (m.pending_row.empty()) return;
  const std::vector<double>& row = m.pending_row;
  Progress& p = m.p;
  p.worst_residual = std::max(p.worst_residual, std::fabs(row[13]));
  p.worst_residual_scale = std::max(p.worst_residual_scale, std::fabs(row[12]) + std::fabs(row[11]));
  char line[512];
  std::snprintf(line, sizeof line,
                "%.9g,%.9g,%.9g,%.9g,%.9g,%d,%.6g,%.9g,%.9g,%.12g,%.12g,%.12g,%.12g,%.12g\n", row[0], row[1],
                row[2], row[3], row[4], static_cast<int>(row[5]), row[6], row[7], row[8], row[9], row[10],
                row[11], row[12], row[13]);
  m.csv << line;
  m.csv_text += line;
  m.ts.push_back(row[0]);
  m.rs.push_back(row[1]);
  m.areas_c.push_back(row[2]);
  m.heights.push_back(row[7]);
  m.series_rows.insert(m.series_rows.end(), row.begin(), row.begin() + kSeriesColumns.size());
  m.onset.row(row[0], row[1] > 0);
  if (row.size() > kSeriesColumns.size() + 1)  // a row pending in a checkpoint before session 32 has no count
    m.contact_nodes.add_row(row[kSeriesColumns.size() + 1], row[0], row[1]);
  append_h5_series(m, row.data());
  m.pending_row.clear();
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
  // a stop's own row (Member::stop_sample) is not the continuation's
  c.put("app.pending_row", m.stop_sample ? std::vector<double>{} : m.pending_row);
  c.put("app.contact_nodes", std::vector<double>{m.contact_nodes.most, m.contact_nodes.t, m.contact_nodes.r});
  c.put("app.h_last", m.h_last);
  c.put("app.held_at_dt_min", std::vector<double>{m.p.held, m.p.held_error_max});
  if (m.onset_by_steps) c.put("app.contact_onset", m.onset.save());
  c.put("app.early_window_s", std::vector<double>{m.so.early_from_s, m.so.early_to_s});
  c.put("app.frames", m.h5 ? static_cast<double>(m.h5->frames()) : 0.0);
  if (m.h5) m.h5->flush();
  write_checkpoint(m.checkpoint_path, c);
  m.wrote_checkpoint = true;
}

[[noreturn]] void stop_on_numerical_trouble(std::vector<Member>& ms, const std::string& what) {
  for (Member& m : ms) {
    if (m.done) continue;
    commit_row(m);
    if (m.h5) m.h5->close();
    m.csv.close();
    std::rename(m.csv_tmp.c_str(), (m.out_dir + "/series.csv").c_str());
  }
  const Member& m = ms.front();
  throw NumericalError(what + " — try a smaller time.dt_s or time.adaptive = true" +
                       (ms.size() == 1 && m.wrote_checkpoint ? "; the last checkpoint is " + m.checkpoint_path
                                                             : std::string()));
}

void finish_member(Member& m, Model& model, const Stepper& stepper, NodeFields<Exec::memory_space>& fields,
                   double wall_now) {
  write_checkpoint_now(m, model, stepper,
                       wall_now);  // with the last row pending: a continuation may redo its step
  commit_row(m);
  if (m.h_last > 0) {
    m.p.h_min = std::min(m.p.h_min, m.h_last);
    m.p.h_max = std::max(m.p.h_max, m.h_last);
  }
  model.compute_forces();
  // r_cc of the end state (the last row's, when the last step wrote one; not an older row's when a run stops
  // early)
  model.update_contact();
  std::vector<double> area_c;
  model.contact_area(&area_c);
  const double r_final = std::sqrt(area_c[m.cell] / kPi);
  // A run that reached t_end reports t_end: its steps' sum differs from it by rounding only (a fixed-step run
  // of 5000 steps of 6 µs sums to 0.02999999999999871 s).
  const double t_sum = stepper.time(m.cell);
  const double t = std::abs(t_sum - m.t_end) <= 1e-12 * m.t_end ? m.t_end : t_sum;
  write_frame(m, frame_data(model, fields), t);
  m.csv.close();
  std::rename(m.csv_tmp.c_str(), (m.out_dir + "/series.csv").c_str());
  if (m.h5) m.h5->close();
  m.done = true;

  const long long done = static_cast<long long>(m.p.step);
  const auto x = model.cell_slice(model.positions(), m.cell);
  double ztop = -INFINITY, zlow = INFINITY;
  int near_final = 0;         // nodes within h0 of the plane at the end
  std::vector<double> depth;  // how far each node below the plane is
  for (int i = 0; i < m.n; ++i) {
    ztop = std::max(ztop, x[3 * i + 2]);
    zlow = std::min(zlow, x[3 * i + 2]);
    near_final += x[3 * i + 2] - m.plane_z < m.h0;
    if (x[3 * i + 2] < m.plane_z) depth.push_back(m.plane_z - x[3 * i + 2]);
  }
  double depth_typical = 0;
  const int deep = spread_fits::folded_nodes(depth, m.h0, depth_typical);
  const CapFit cap = fit_cap(x, m.plane_z, false), cap_free = fit_cap(x, m.plane_z, true);
  int used = 0;
  const SpreadOptions& so = m.so;
  // The early exponent counts time from the contact's onset (spread_fits.hpp; docs/model/spread.md), found at
  // the steps' resolution (or, for a run continued from a checkpoint before session 36, from the rows); the
  // slope against the run's own clock is kept beside it (early_exponent_run_time, spread's only one before
  // session 34).
  const double onset_rows = contact_onset(m.ts, m.rs);
  const double onset = m.onset_by_steps ? m.onset.onset : onset_rows;
  const double onset_or_0 = std::isnan(onset) ? 0.0 : onset;  // a run that never touched: its own clock
  const double alpha = fit_exponent(m.ts, m.rs, so.early_from_s, so.early_to_s, used, onset_or_0);
  int used_run_time = 0;
  const double alpha_run_time = fit_exponent(m.ts, m.rs, so.early_from_s, so.early_to_s, used_run_time);
  // The later regime: the slope from the early window's end to the rows' end, since the onset as the early
  // fit counts (the paper: "no clear second power-law regime, but merely a slowing down"; the Cuvelier set's
  // 20-100 s). NaN (null) with fewer than three rows with contact there.
  int used_late = 0;
  const double late_to = m.ts.empty() ? 0.0 : m.ts.back() - onset_or_0;
  const double alpha_late = fit_exponent(m.ts, m.rs, so.early_to_s, late_to, used_late, onset_or_0);
  // Whether the cell still spreads at the end: r_cc's growth over the last tenth of the series (its last row
  // is the end state's, except in a run stopped between rows).
  const double t_rows = m.ts.empty() ? t : m.ts.back();
  const double growth = final_growth(m.ts, m.rs, 0.9 * t_rows);
  // Where the rows end inside the early window (counted from the onset): the fit saw only its part up to
  // there (the Cuvelier set's 2-20 s window of a 20-s run whose contact began at 0.42 s). NaN (null) when the
  // rows reach past the window's end, end before its start, or the run has no contact (no onset).
  const double rows_reach = t_rows - onset;  // NaN without an onset
  const double window_cut_at =
      rows_reach < so.early_to_s * (1 - 1e-9) && rows_reach > so.early_from_s && !m.ts.empty() ? rows_reach
                                                                                               : NAN;
  // The t_end that covers the window, rounded up to 4 significant digits (printed with %.4g: never short).
  const double t_cover = onset + so.early_to_s;
  const double digit = std::pow(10.0, std::floor(std::log10(t_cover)) - 3);
  const double t_cover_up = std::ceil(t_cover / digit * (1 - 1e-12)) * digit;
  const double wall = m.p.wall_before + wall_now;
  const Progress& p = m.p;
  // A run that ends but did not resolve its dynamics says so (stderr, also with --quiet, and summary.json's
  // "warnings"): energy bookkeeping off by more than half of the powers (unless adaptive steps at their cap
  // explain it: the note below), or more step halvings than steps (healthy runs: below 0.25 and none;
  // docs/model/spread.md, "Energy balance").
  const double residual_rel = p.worst_residual_scale > 0 ? p.worst_residual / p.worst_residual_scale : 0.0;
  std::vector<std::string> warnings;
  char text[512];
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
  // Results outside what the model can say (session 40, found by probing extreme scenes; each ran to exit 0
  // with an empty warnings list before; a W too strong for the contact law to hold is refused up front,
  // spread_member.cpp):
  // nodes folded into the substrate (the paper's law pushes back only on triangles that face the plane, so
  // membrane that buckles or folds over at the rim can pass into it: 0.34 um with soft area terms and Table
  // 1's bending, 0.41 um at the biconcave cell's rim on 642 nodes, session 40);
  if (deep > 0) {
    const double guard_depth = m.scene.get_real("contact.guard_depth_m");
    const double guard_k = m.scene.get_real("contact.guard_stiffness_Pa_per_m");
    // 10 W/h0²: the Dugdale stress W/h0 at h0/10 past the guard depth (2.5e13 Pa/m for Table 1)
    const double suggested = 10 * m.scene.get_real("contact.W_J_per_m2") / (m.h0 * m.h0);
    char remedy[240];
    if (guard_k > 0 && m.plane_z - zlow <= 1.5 * guard_depth)
      std::snprintf(remedy, sizeof remedy,
                    "the substrate guard holds it near contact.guard_depth_m = %.3g um", guard_depth * 1e6);
    else if (guard_k > 0)
      std::snprintf(remedy, sizeof remedy,
                    "the substrate guard (contact.guard_stiffness_Pa_per_m = %.3g) is too soft to hold it at "
                    "contact.guard_depth_m = %.3g um: raise it (10 W/h0^2 = %.3g)",
                    guard_k, guard_depth * 1e6, suggested);
    else
      std::snprintf(remedy, sizeof remedy,
                    "the shape near those nodes is not physical; contact.guard_stiffness_Pa_per_m = %.3g (10 "
                    "W/h0^2) pushes it back past contact.guard_depth_m = %.3g um",
                    suggested, guard_depth * 1e6);
    std::snprintf(text, sizeof text,
                  "%d node(s) end up to %.3g um below the plane, more than 3 times the bound membrane's "
                  "typical depth (%.3g um): the membrane folds into the substrate there, which the contact "
                  "pushes back only where its triangles face the plane; %s",
                  deep, (m.plane_z - zlow) * 1e6, depth_typical * 1e6, remedy);
    warnings.emplace_back(text);
  }
  // no step moved the cell (every CG solve stopped at once: the forces were below the absolute tolerance);
  if (done > 0 && p.cg_max == 0) {
    std::snprintf(text, sizeof text,
                  "no step moved the cell: every CG solve stopped at 0 iterations, its forces below "
                  "solver.cg_abs_tol_N = %.3g N; lower solver.cg_abs_tol_N",
                  m.cg.abs_tol);
    warnings.emplace_back(text);
  }
  // the contact came and went (a fixed step that throws the cell off the plane: no substrate friction);
  const double r_most = m.rs.empty() ? 0.0 : *std::max_element(m.rs.begin(), m.rs.end());
  if (r_most > 0 && !(r_final > 0) && !m.interrupted && !m.stopped_at_max_steps) {
    std::snprintf(
        text, sizeof text,
        "the cell lost its contact (r_cc reached %.3g um, 0 at the end): the steps do not resolve the "
        "contact; use time.adaptive = true or a smaller time.dt_s",
        r_most * 1e6);
    warnings.emplace_back(text);
  }
  // the cell never touched the plane (a run that ended while it was still falling or too far to adhere: every
  // fit is null, and nothing else would say why; session 42, found by a helper's review);
  if (!(r_most > 0) && !(r_final > 0) && done > 0 && !m.interrupted && !m.stopped_at_max_steps) {
    std::snprintf(text, sizeof text,
                  "the cell never touched the plane (r_cc stayed 0 up to t = %.4g s): nothing spread and the "
                  "fits are null; run longer (time.t_end_s) or start closer (contact.start_gap_m below "
                  "contact.h0_m)",
                  t);
    warnings.emplace_back(text);
  }
  // the volume far from the start's with the volume term on (the paper conserves V0: "trial runs conserving
  // V0"; a W or a load too strong for cortex.k_v, or an x_max near 1, lost 13-30% with no word; session 45,
  // found by a helper's probe of extreme scenes; the paper's scene loses 7.9% by 1.2 s on 2562 nodes);
  const auto volume = [&](const auto& node) {
    double v = 0;
    for (const Tri& tri : m.mesh.triangles) {
      const Vec3 a = node(tri[0]), b = node(tri[1]), c = node(tri[2]);
      v += (a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) +
            a[2] * (b[0] * c[1] - b[1] * c[0])) /
           6;
    }
    return v;
  };
  const double v_start = volume([&](int i) { return m.mesh.nodes[i]; });
  const double v_end = volume([&](int i) { return Vec3{x[3 * i], x[3 * i + 1], x[3 * i + 2]}; });
  const double k_v = m.scene.get_real("cortex.k_v");
  if (k_v > 0 && v_start > 0 && std::abs(v_end / v_start - 1) > 0.1) {
    std::snprintf(
        text, sizeof text,
        "the cell's volume changed by %+.1f%% since the start (cortex.k_v = %.3g Pa holds it): more "
        "than 10%%, for a cell the paper keeps at its volume; the load on it is too strong for the "
        "volume term (contact.W_J_per_m2, cortex.x_max near 1, gravity): a stiffer cortex.k_v holds it",
        100 * (v_end / v_start - 1), k_v);
    warnings.emplace_back(text);
  }
  // adaptive steps kept at time.dt_min_s above the tolerance: there the controller did not control the error
  // (a dt_min set too high for the scene; session 46, from session 45's list of what deserves an issue);
  if (p.held > 0) {
    std::snprintf(text, sizeof text,
                  "%.0f step(s) were kept at time.dt_min_s = %.3g s with the error estimate (largest %.3g m) "
                  "above time.error_tol_m = %.3g m: those steps do not meet the tolerance; lower "
                  "time.dt_min_s",
                  p.held, stepper.settings().dt_min, p.held_error_max, stepper.settings().error_tol_m);
    warnings.emplace_back(text);
  }
  // and a fixed-step run of a few steps (time.dt_s near t_end), which nothing above can judge.
  if (!stepper.settings().adaptive && done > 0 && done < 5 && !m.interrupted && !m.stopped_at_max_steps) {
    std::snprintf(
        text, sizeof text,
        "the run took %lld step(s) of time.dt_s = %.3g s: too few to resolve anything; use a smaller "
        "time.dt_s or time.adaptive = true",
        done, m.dt);
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
      .add("steps_held_at_dt_min", static_cast<long long>(p.held))
      .add("adaptive", stepper.settings().adaptive)
      .add("dt_min_taken_s", std::isfinite(p.h_min) ? p.h_min : 0.0)
      .add("dt_max_taken_s", p.h_max)
      .add("r_cc_final_m", r_final)
      .add("contact_angle_deg", cap.angle_deg)
      .add("cap_radius_m", cap.radius)
      .add("contact_angle_free_deg", cap_free.angle_deg)
      .add("cap_radius_free_m", cap_free.radius)
      .add("early_exponent", alpha)
      .add("early_window_s", std::vector<double>{so.early_from_s, so.early_to_s})
      .add("early_window_rows", used)
      .add("early_window_cut_at_s", window_cut_at)
      .add("contact_onset_s", onset)
      .add("contact_onset_by", m.onset_by_steps ? "steps" : "rows")
      .add("early_exponent_run_time", alpha_run_time)
      .add("late_exponent", alpha_late)
      .add("late_window_s", late_to > so.early_to_s ? std::vector<double>{so.early_to_s, late_to}
                                                    : std::vector<double>{NAN, NAN})
      .add("late_window_rows", used_late)
      .add("r_cc_growth_last_tenth", growth)
      .add("contact_nodes_final", near_final)
      .add("contact_nodes_most", m.contact_nodes.most)
      .add("contact_nodes_most_from_s", m.contact_nodes.t)
      .add("r_cc_growth_since_contact_nodes_most_m", m.contact_nodes.growth_since(r_final))
      .add("mesh_edge_mean_m", m.edge_mean)
      .add("height_final_m", ztop - m.plane_z)
      .add("deepest_node_below_plane_m", m.plane_z - zlow)
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
    char exponent[200];
    char window_end[64];  // where the rows end inside the window (a run stopped or ended early), else its end
    if (std::isfinite(window_cut_at))
      std::snprintf(window_end, sizeof window_end, "%.4g s (the rows' end; window to %g s)", window_cut_at,
                    so.early_to_s);
    else
      std::snprintf(window_end, sizeof window_end, "%g s", so.early_to_s);
    if (std::isfinite(alpha) && onset > 0)
      std::snprintf(exponent, sizeof exponent, "%.3f over %g-%s after the contact at %.4g s", alpha,
                    so.early_from_s, window_end, onset);
    else if (std::isfinite(alpha))
      std::snprintf(exponent, sizeof exponent, "%.3f over t = %g-%s", alpha, so.early_from_s, window_end);
    else
      std::snprintf(exponent, sizeof exponent, "none (%d rows with contact %g-%g s after its onset)", used,
                    so.early_from_s, so.early_to_s);
    char later[96] = "";  // the later regime's slope, where the rows reach past the early window
    if (std::isfinite(alpha_late))
      std::snprintf(later, sizeof later, ", then %.3f over %g-%.4g s", alpha_late, so.early_to_s, late_to);
    std::printf(
        "  %sr_cc = %.3f um, contact angle %.1f deg (free membrane %.1f), early exponent %s%s, height %.3f "
        "um; "
        "%lld steps in %.1f s, mean CG %.1f\n",
        m.cell > 0 || !m.so.batch.empty() ? (m.out_dir + ": ").c_str() : "", r_final * 1e6, cap.angle_deg,
        cap_free.angle_deg, exponent, later, (ztop - m.plane_z) * 1e6, done, wall,
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
  // Said for a run that reached its t_end with an exponent (a stopped run is told how to continue below; a
  // window with fewer than three rows has no exponent, and the summary line says so).
  if (!m.options.quiet && std::isfinite(window_cut_at) && std::isfinite(alpha) && !m.interrupted &&
      !m.stopped_at_max_steps)
    std::printf(
        "  %snote: the run ended %.4g s after the contact's onset, inside the early window (%g-%g s after "
        "it): the early exponent is fitted over %g-%.4g s; run to time.t_end_s >= %.4g for the whole "
        "window\n",
        m.cell > 0 || !m.so.batch.empty() ? (m.out_dir + ": ").c_str() : "", window_cut_at, so.early_from_s,
        so.early_to_s, so.early_from_s, window_cut_at, t_cover_up);
  // An early window that opens while the contact is a triangle or two (the Cuvelier set's 0.01-0.1 s): its
  // slope is that of single triangles touching down (a ratio of radii of ten and more), not a power law.
  double r_start = NAN;  // r_cc at the window's first row with contact
  for (std::size_t i = 0; i < m.ts.size() && i < m.rs.size() && std::isnan(r_start); ++i)
    if (m.ts[i] - onset_or_0 >= so.early_from_s * (1 - 1e-9) && m.rs[i] > 0) r_start = m.rs[i];
  if (!m.options.quiet && std::isfinite(alpha) && r_start < 0.5 * m.edge_mean)
    std::printf(
        "  %snote: the early window opens when the contact is smaller than a triangle (r_cc %.3g um %g s "
        "after the onset; mesh edge %.3g um): its exponent follows the first triangles touching down, not a "
        "power law; open it later (output.early_window_from_s or --early-window-s) or use a finer mesh\n",
        m.cell > 0 || !m.so.batch.empty() ? (m.out_dir + ": ").c_str() : "", r_start * 1e6, so.early_from_s,
        m.edge_mean * 1e6);
  // A cell still spreading at the end (r_cc up by 1% or more over the last tenth of the run; one still on
  // t^(1/2) gives 5%): its final values are not the spread-out cell's. Not said of a run stopped before its
  // t_end (Ctrl-C, --max-steps): it is told to continue to that t_end instead.
  if (!m.options.quiet && growth >= 0.01 && !m.interrupted && !m.stopped_at_max_steps)
    std::printf(
        "  %snote: r_cc grew %.1f%% over the last tenth of the run (t = %.3g-%.3g s): the cell is still "
        "spreading, the final values are not those of the spread-out cell; continue with %s --restart "
        "'%s' --set time.t_end_s=%g\n",
        m.cell > 0 || !m.so.batch.empty() ? (m.out_dir + ": ").c_str() : "", 100 * growth, 0.9 * t_rows,
        t_rows, program_path("spread").c_str(), m.checkpoint_path.c_str(), 2 * t);
  // The contact front past a node ring that did not come down: the membrane already bound is being stretched
  // outward (docs/model/contact_line.md, "The line held at a node ring").
  if (!m.options.quiet && m.contact_nodes.grew_by_stretching(r_final, m.edge_mean))
    std::printf(
        "  %snote: r_cc grew %.3g um after the last node came within contact.h0_m of the plane (t = %.3g s, "
        "%.0f nodes), more than the mesh's mean edge (%.3g um): the contact grows by stretching the membrane "
        "already bound, not by binding more of it; pins on the bound nodes (contact.pin_friction_N_s_per_m, "
        "the paper's option) hold it (docs/model/contact_line.md)\n",
        m.cell > 0 || !m.so.batch.empty() ? (m.out_dir + ": ").c_str() : "",
        m.contact_nodes.growth_since(r_final) * 1e6, m.contact_nodes.t, m.contact_nodes.most,
        m.edge_mean * 1e6);
  if (so.plot && !m.interrupted && !m.stopped_at_max_steps) {
    const std::string cmd = std::string(DCM_PYTHON3) + " '" + DCM_SOURCE_DIR + "/scripts/plot_spread.py' " +
                            (m.options.quiet ? "--quiet '" : "'") + m.out_dir + "'";
    std::fflush(stdout);  // this run's lines before the plotter's
    if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "spread: plotting failed (%s)\n", cmd.c_str());
  }
}

}  // namespace spread_app
}  // namespace dcm
