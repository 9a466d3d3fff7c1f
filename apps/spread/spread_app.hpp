#pragma once
// The spread app's parts (apps/spread/main.cpp describes the app): a member is one spreading run, its scene,
// its cell in the model, its output files and its progress.
//   spread_member.cpp  the scene and checks of a member, the batch file, the series format
//   spread_output.cpp  frames, checkpoints, the summary and plots of a finished member
//   spread_run.cpp     the time loop of a batch of members (one member: an ordinary run)
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
namespace spread_app {

using Exec = Kokkos::DefaultExecutionSpace;
inline constexpr double kPi = 3.14159265358979323846;
using Model = CortexModel<Exec>;
using Stepper = TimeStepper<Exec>;
using spread_fits::CapFit;
using spread_fits::contact_onset;
using spread_fits::final_growth;
using spread_fits::fit_cap;
using spread_fits::fit_exponent;

// Set by SIGINT / SIGTERM (spread_run.cpp): the loop stops after the current step.
extern volatile std::sig_atomic_t g_stop;

struct SpreadOptions {
  bool plot = true;
  // Window of the early power-law fit, s after the contact's onset: the scene's output.early_window_from_s
  // and output.early_window_to_s (defaults 10 ms, after the first triangles have touched down, to 0.1 s, the
  // paper's t^1/2 regime at 100 ms; docs/model/spread.md), or --early-window-s (set_early_window).
  double early_from_s = 1e-2, early_to_s = 1e-1;
  bool early_window_given = false;  // --early-window-s on the command line (a restart keeps the run's own)
  std::string restart;              // checkpoint to continue from
  long long max_steps = 0;          // stop after this many steps (counted from the run's start), 0: no limit
  bool check = false;               // validate the scene and options, write nothing, run nothing
  std::string batch;                // file with one member per line: run them as one batch
};

// The columns of series.csv and of spread.h5's /series, one row per sample.
inline const std::vector<std::string> kSeriesColumns = {"t_s",
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

std::string series_header();

// The rows of a series.csv text (header first), as kSeriesColumns values each: the HDF5 series of a
// checkpoint written before app.series_rows existed.
std::vector<double> parse_series_rows(const std::string& csv_text);

double seconds_since(std::chrono::steady_clock::time_point t0);

// What the run of one member has done so far: everything a restart needs besides the model and the stepper.
struct Progress {
  double step = 0, next_figure = 0, next_frame = 0, next_sample = 0, cg_total = 0, cg_max = 0;
  double worst_residual = 0, worst_residual_scale = 0, halved = 0, rejected = 0, h_min = INFINITY, h_max = 0;
  double wall_before = 0;  // wall seconds of earlier segments of a restarted run
  // Adaptive steps kept at time.dt_min_s above the tolerance (StepReport::held_at_dt_min) and the largest
  // error among them (m); in the checkpoint as app.held_at_dt_min since session 46, not in fields().
  double held = 0, held_error_max = 0;
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
  double plane_z = 0, h0 = 0, edge_mean = 0, dt = 0, t_end = 0, frame_every = 0, per_decade = 0,
         checkpoint_every = 0;
  std::string out_dir, checkpoint_path, csv_tmp;
  int cell = 0, first_node = 0, n = 0;
  Progress p;
  std::vector<double> ts, rs, areas_c, heights;  // series columns the summary's fits use
  std::vector<double> series_rows;               // every series row (kSeriesColumns values each), for HDF5
  spread_fits::ContactNodes contact_nodes;       // over the series rows (summary.json, the binding note)
  spread_fits::OnsetTracker onset;               // the contact's onset at the steps' resolution
  bool onset_by_steps = true;  // false: continued from a checkpoint before session 36 (rows)
  std::string csv_text = series_header();
  // The row of the last sampled step (kSeriesColumns values, then the step's start energy and the nodes
  // within h0 of the plane), written once the next step has accepted that step: an adaptive step may take the
  // one before it again, shorter (solvers/time_stepper.hpp), and the row then describes the state that step
  // reaches instead.
  std::vector<double> pending_row;
  double h_last = 0;  // the last step's length, into dt_min/max_taken_s once the next step accepts it
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
  // The step a stop (Ctrl-C, --max-steps) ends on is sampled, so that series.csv reaches the state
  // summary.json reports; its row goes into the stopped run's series only, not into its checkpoint, and moves
  // no sample time, so that a continuation writes the rows of an uninterrupted run.
  bool stop_sample = false;
};

inline const std::vector<double> kFigureTimes = {0.1, 0.35, 0.9};  // paper Figures 1 and 6

// The scene, its checks and the placed cell of one member; nothing is written.
void prepare_member(Member& m);

// Why member b cannot join member a's batch ("" if it can): what is not per cell must be the same.
std::string batch_difference(const Member& a, const Member& b);

// The members of --batch FILE: one per line, `[SCENE.toml] [--set KEY=VALUE]... --out DIR`; # comments.
std::vector<Member> read_batch(const std::string& path, const AppOptions& common, const SpreadOptions& so);

// Positions and per-node fields of every cell on the host, once for all members that write a frame now.
struct FrameData {
  std::vector<double> x, tension, stretch, normal_force, normal_pressure;
};
FrameData frame_data(Model& model, NodeFields<Exec::memory_space>& fields);

// One series row into spread.h5's /series (nothing with output.hdf5 = false).
void append_h5_series(Member& m, const double* row);
// The member's pending row (if any) into series.csv.part, spread.h5 and the fits' columns.
void commit_row(Member& m);
// The member's slice of a frame into spread.h5 at time t (nothing with output.hdf5 = false).
void write_frame(Member& m, const FrameData& d, double t);
// A checkpoint at a step boundary: the member's cell, its stepper state, and what it has written
// (docs/CHECKPOINTS.md): the checkpoint of the same run alone.
void write_checkpoint_now(Member& m, const Model& model, const Stepper& stepper, double wall);
// Numerical trouble ends the run (exit 3) with every member's files closed: what was done stays readable, no
// NaN row.
[[noreturn]] void stop_on_numerical_trouble(std::vector<Member>& ms, const std::string& what);
// The end of a member's run: checkpoint, final frame, files closed, summary and plots.
void finish_member(Member& m, Model& model, const Stepper& stepper, NodeFields<Exec::memory_space>& fields,
                   double wall_now);

// Runs the members as one batch (one member: the ordinary run); spread_run.cpp.
void run_members(std::vector<Member>& ms, bool quiet, int threads);

}  // namespace spread_app
}  // namespace dcm
