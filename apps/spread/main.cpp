// spread: the paper's cell-spreading experiment (its Figures 1, 4–6). A cell placed just above an adhesive
// plane (its lowest node contact.start_gap_m above it, within the range h0) spreads under the overdamped
// dynamics Γ v = F (paper eqs. 30–32): Maugis–Dugdale adhesion of the rounded triangles, substrate friction,
// the cortex terms and dashpots of the scene. Writes to <out>/:
//   series.csv   t_s,r_cc_m,contact_area_m2,area_m2,volume_m3,cg_iterations,dt_s,height_m,contact_load_N,
//                elastic_energy_J,dE_dt_W,contact_power_W,dissipation_W,energy_residual_W
//                (log-spaced in time: output.series_per_decade rows per decade, every step at the start, and
//                the last step; each row the state at its t_s, the end of its step, written once the next
//                step has accepted that step; contact_power_W and dissipation_W are the step's, at its start
//                with its velocity, dE_dt_W the change over it: the energy balance of the step)
//   spread.h5/.xmf  mesh, series (every column of series.csv), frames (every output.frame_every_s and at
//                t = 0.1, 0.35, 0.9 s) with the per-node normal force and pressure, cortex tension (eq. 1)
//                and stretch; not with output.hdf5 = false
//   summary.json r_cc_final_m, contact_angle_deg, early_exponent (+ window, contact_onset_s), late_exponent
//                (from the window's end to the run's), height_final_m,
//                steps, wall_s, mean_cg_iterations, energy balance, warnings (steps that did not resolve the
//                run), ...
// A new run removes an earlier run's files from its folder first (a restart continues them).
//   r_cc.png, cells.png, side_views.png (scripts/plot_spread.py) unless --no-plot
//   checkpoint.h5 the state at the end, on Ctrl-C and every output.checkpoint_every_s of wall time;
//                `spread --restart <out>/checkpoint.h5` continues a stopped run bit for bit; a finished run
//                continued to a later t_end differs from one run there directly (docs/CHECKPOINTS.md)
// Ctrl-C (SIGINT) or SIGTERM: the loop stops after the current step, a checkpoint is written, the files are
// closed and valid, the summary says "interrupted": true; exit code 130.
//
// A batch (`spread --batch MEMBERS.txt`, one member per line: `[SCENE.toml] [--set KEY=VALUE]... --out DIR`):
// the members are cells of one model (the batched engine, docs/SCANS.md): one launch per kernel for all,
// per-cell constants, CG and time steps. Each member's folder gets exactly the files its run alone writes,
// with the same numbers (wall_s excepted: the batch's). Members must need the same kernels and settings
// (mesh size, solver and time-step options); the first difference is named.
#include <CLI/CLI.hpp>

#include "apps/spread/spread_app.hpp"

namespace dcm {
namespace spread_app {
namespace {

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
}  // namespace spread_app
}  // namespace dcm

int main(int argc, char** argv) {
  CLI::App app(
      "Cell spreading on an adhesive plane (the paper's Figures 1, 4-6). Without a scene file it runs the\n"
      "built-in defaults with a plane: the paper's Hategan case (2562 nodes, 1.2 s at dt = 6 us, some "
      "minutes;\n"
      "scenes/default.toml is the short main job); the paper's cases are in scenes/ "
      "(hategan2004_sphered.toml,\n"
      "...).",
      "spread");
  dcm::AppOptions options;
  dcm::spread_app::SpreadOptions so;
  dcm::add_common_options(
      app, options,
      {"scenes/default.toml", "scenes/hategan2004_sphered.toml --out out/hategan",
       "scenes/hategan2004_biconcave.toml --set mesh.nodes=642 --set time.adaptive=true --out out/bic642",
       "--restart out/hategan/checkpoint.h5 --set time.t_end_s=4"},
      true);
  app.add_flag(
      "--no-plot", [&](std::int64_t) { so.plot = false; }, "Do not write the PNG plots");
  std::vector<double> window;
  app.add_option(
         "--early-window-s", window,
         "Time window FROM,TO (s) of the early power-law fit, counted, as the fit counts time, from the "
         "contact's onset (summary.json contact_onset_s) (default: the scene's output.early_window_from_s "
         "and "
         "output.early_window_to_s, 0.01,0.1 unless the scene sets them; a --restart keeps the run's own "
         "unless given)")
      ->type_name("FROM,TO")
      ->delimiter(',')
      ->expected(2);
  app.add_option(
         "--restart", so.restart,
         "Continue the run whose checkpoint this is (<out>/checkpoint.h5), in its folder; the scene "
         "comes from the checkpoint (--set may change time.t_end_s and output.* except output.dir and "
         "output.hdf5)")
      ->check(CLI::ExistingFile);
  app.add_option("--max-steps", so.max_steps,
                 "Stop after this many steps in all (a checkpoint is written; --restart continues)")
      ->check(CLI::Range(1LL, 1000000000000LL));
  app.add_option(
         "--batch", so.batch,
         "Run the members listed in this file as one batch (one model, one launch per kernel for all; "
         "docs/SCANS.md): one member per line, [SCENE.toml] [--set KEY=VALUE]... --out DIR (\"double "
         "quotes\" around a word with spaces, \\\" and \\\\ inside one, # at a word's start begins a "
         "comment). Each "
         "member's folder gets what its run alone writes, with the same numbers")
      ->check(CLI::ExistingFile);
  return dcm::run_app(app, argc, argv, [&] {
    so.check = options.check;
    if (window.size() == 2) {
      so.early_from_s = window[0];
      so.early_to_s = window[1];
      so.early_window_given = true;
    }
    dcm::spread_app::run(options, so);
  });
}
