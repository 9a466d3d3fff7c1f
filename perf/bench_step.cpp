// bench_step: whole time steps of the two kinds of scene, on every execution space of this Kokkos build, with
// the time of each Kokkos kernel taken from the Kokkos Tools callbacks (Kokkos fences around each kernel, so
// the times are the kernels' own, on the CPU backends and on CUDA alike):
//   stretch: the paper's optical-tweezers cell, ±100 pN on the outermost 5% of the nodes at each end, no
//   plane; spread:  the sphered cell pressed 50 nm into the adhesive plane (contact from the first step);
//   diagonal: the stretch scene without dashpots, global area and volume terms (always implicit when present)
//            and implicit terms (Δt = 0.1 µs): Γ is the drag alone, a diagonal the solve inverts per node
//            without a CG iteration (what a scene does not need costs nothing).
// Table 1 parameters and the solver defaults of the scenes (multigrid PCG to 1e-14 N, implicit bending and
// tension). One row per (space, threads, scene, nodes, kernel): µs per step and ns per node per step; the
// kernel "step" is the whole step (host work, copies and fences included), "other" what no kernel covers.
// The last column, thread_round_trip_ns, is the OpenMP threads' cache-line round trip measured around the
// reported block (0 for one thread): where a VM's two CPUs sit (one die or two) changes every two-thread time
// (perf/speedup.py splits the runs by it).
//   bench_step [--levels 3,4,5,6] [--scenes stretch,spread,diagonal] [--steps N] [--warmup N] [--threads 1,2]
//              [--repeat N] [--rounds R] [--set KEY=VALUE]...
// --repeat N runs each case N times from the same start (warm-up and timed steps) and reports the run with
// the shortest step time, kernels included (the best of N: a shared machine's slow spells drop out).
// --rounds R runs the whole sequence of children R times, one thread count after the other in each round,
// and reports for every case the round with the shortest step (its kernel rows with it): a slow spell that
// lasts longer than one case's repeats then spoils one round, not one thread count, so the 1- and 2-thread
// rows of a table are both from quiet moments (docs/PERFORMANCE.md, "Session 12"). The rows are printed when
// all rounds are done; with one round they stream as each case finishes.
// Each OpenMP thread count runs in a child process of this binary (OMP_NUM_THREADS is fixed at Kokkos start);
// Serial and Cuda run once, in the first. --no-kernel-times leaves the Kokkos Tools callbacks out (no fence
// around each kernel: on a GPU the fences add a synchronisation per launch) and prints the "step" row alone,
// with 0 launches. CSV on stdout (docs/PERFORMANCE.md turns it into tables).
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "apps/common/mechanics_setup.hpp"
#include "apps/common/stretch_setup.hpp"
#include "core/kokkos_compat.hpp"
#include "core/scene.hpp"
#include "solvers/cortex_model_impl.hpp"  // the model on Kokkos::Serial too (--serial)

#if defined(KOKKOS_ENABLE_OPENMP) && defined(_OPENMP)
#include <omp.h>
#endif

namespace {

using Clock = std::chrono::steady_clock;

// Kokkos Tools: accumulated seconds per kernel label.
struct KernelTimes {
  std::map<std::string, double> seconds;
  std::map<std::string, long> launches;
  std::vector<std::pair<std::string, Clock::time_point>> open;  // indexed by the kernel id handed out
  bool on = false;
};
KernelTimes g_times;

void begin_kernel(const char* name, std::uint32_t, std::uint64_t* id) {
  *id = g_times.open.size();
  g_times.open.emplace_back(name, Clock::now());
}
void end_kernel(std::uint64_t id) {
  const auto& [name, t0] = g_times.open[id];
  if (g_times.on) {
    g_times.seconds[name] += std::chrono::duration<double>(Clock::now() - t0).count();
    ++g_times.launches[name];
  }
  if (id + 1 == g_times.open.size()) g_times.open.pop_back();
}
void install_kernel_timer() {
  namespace KT = Kokkos::Tools::Experimental;
  KT::set_begin_parallel_for_callback(begin_kernel);
  KT::set_end_parallel_for_callback(end_kernel);
  KT::set_begin_parallel_reduce_callback(begin_kernel);
  KT::set_end_parallel_reduce_callback(end_kernel);
  KT::set_begin_parallel_scan_callback(begin_kernel);
  KT::set_end_parallel_scan_callback(end_kernel);
}

// The round trip of one cache line between OpenMP threads 0 and 1 (ns; 0 with fewer than two threads): on a
// VM whose virtual CPUs the host moves between dies it changes from run to run (165 ns on one die, 440 ns
// across dies in session 23), and with it every kernel's two-thread time, so each row carries it.
double thread_round_trip_ns() {
#if defined(KOKKOS_ENABLE_OPENMP) && defined(_OPENMP)
  if (omp_get_max_threads() < 2) return 0;
  // Up to 20000 round trips or 20 ms, whichever ends first: on a busy machine the two threads are not always
  // running at once (then the number is large, and says so).
  constexpr long kTrips = 20000, kStop = -1;
  const auto budget = std::chrono::milliseconds(20);
  alignas(64) std::atomic<long> flag{0};
  double ns = 0;
#pragma omp parallel num_threads(2)
  {
    const bool first = omp_get_thread_num() == 0;
#pragma omp barrier
    if (first) {
      const auto t0 = Clock::now();
      long trips = 0;
      while (trips < kTrips && (trips % 256 != 0 || Clock::now() - t0 < budget)) {
        flag.store(2 * trips + 1, std::memory_order_release);
        while (flag.load(std::memory_order_acquire) != 2 * trips + 2) {
        }
        ++trips;
      }
      ns = std::chrono::duration<double>(Clock::now() - t0).count() * 1e9 / (trips > 0 ? trips : 1);
      flag.store(kStop, std::memory_order_release);
    } else {
      for (long seen; (seen = flag.load(std::memory_order_acquire)) != kStop;)
        if (seen % 2 == 1) flag.store(seen + 1, std::memory_order_release);
    }
  }
  return ns;
#else
  return 0;
#endif
}

struct Options {
  std::vector<int> levels{3, 4, 5, 6};
  std::vector<std::string> scenes{"stretch", "spread", "diagonal"};
  std::vector<int> threads{1, 2};
  int steps = 20, warmup = 5, repeat = 1, rounds = 1;
  bool child = false, serial = true, cuda = true, kernel_times = true;
  std::vector<std::string> sets;  // scene overrides for every case (applied last)
};

dcm::Scene scene_for(const std::string& kind, int level, const std::vector<std::string>& sets) {
  dcm::Scene s = dcm::Scene::defaults();
  s.set("mesh.nodes=" + std::to_string(10 * (1 << (2 * level)) + 2));
  if (kind == "stretch" || kind == "diagonal") {
    s.set("contact.plane=false");
  }
  if (kind == "diagonal") {
    for (const char* k :
         {"cortex.c_N_s_per_m=0", "cortex.k_d=0", "cortex.k_v=0", "solver.implicit_bending=false",
          "solver.implicit_tension=false", "solver.implicit_bonds=false", "time.dt_s=1e-7"})
      s.set(k);
  } else if (kind == "spread") {
    s.set("contact.plane=true");
    s.set("contact.start_gap_m=-50e-9");
  }
  for (const std::string& set : sets) s.set(set);
  s.validate();
  return s;
}

template <class Exec>
void run_case(const std::string& space_name, int threads, const std::string& kind, int level,
              const Options& o) {
  const dcm::Scene scene = scene_for(kind, level, o.sets);
  dcm::HostMesh mesh = dcm::cell_mesh_from_scene(scene);
  if (kind == "spread") {
    double zmin = 1e300;
    for (const auto& x : mesh.nodes) zmin = std::min(zmin, x[2]);
    for (auto& x : mesh.nodes) x[2] += scene.get_real("contact.start_gap_m") - zmin;
  }
  const dcm::CgSettings cg = dcm::cg_settings_from_scene(scene);
  int n = 0;
  std::map<std::string, double> best_kernels;
  std::map<std::string, long> best_launches;
  double step_s = INFINITY, round_trip_ns = 0;
  long iterations = 0;
  // Each repetition starts again from the same state (a new model: the steps of every block are the same
  // steps); the block with the shortest step time is reported.
  for (int rep = 0; rep < o.repeat; ++rep) {
    dcm::CortexModel<Exec> model(Exec(), {dcm::HostCell(mesh)}, dcm::mechanics_from_scene(scene));
    n = model.mesh().n_nodes;
    if (kind != "spread") {
      const auto [left, right] = dcm::pulled_nodes(mesh, 0.05);
      auto f = Kokkos::create_mirror_view(model.external_force());
      Kokkos::deep_copy(f, 0.0);
      for (int i : left) f(i, 0) = -100e-12 / left.size();
      for (int i : right) f(i, 0) = 100e-12 / right.size();
      Kokkos::deep_copy(model.external_force(), f);
    }
    dcm::TimeStepper<Exec> stepper(model, dcm::steps_from_scene(scene));
    for (int s = 0; s < o.warmup; ++s) stepper.step(model, cg, 1.0, [](double) {});
    g_times.seconds.clear();
    g_times.launches.clear();
    const bool threaded = threads > 1 && space_name == "OpenMP";
    const double trip_before = threaded ? thread_round_trip_ns() : 0;
    g_times.on = true;
    long its = 0;
    const auto t0 = Clock::now();
    for (int s = 0; s < o.steps; ++s) its += stepper.step(model, cg, 1.0, [](double) {}).iterations;
    Exec().fence();  // a device's last kernels may still run when step() returns
    const double block_s = std::chrono::duration<double>(Clock::now() - t0).count() / o.steps;
    g_times.on = false;
    const double trip_after = threaded ? thread_round_trip_ns() : 0;
    if (block_s < step_s) {
      step_s = block_s;
      best_kernels = g_times.seconds;
      best_launches = g_times.launches;
      iterations = its;
      round_trip_ns = 0.5 * (trip_before + trip_after);
    }
  }
  const auto row = [&](const std::string& kernel, double seconds_per_step, double launches_per_step) {
    std::printf("%s,%d,%s,%d,%s,%.3f,%.2f,%.2f,%.2f,%.0f\n", space_name.c_str(), threads, kind.c_str(), n,
                kernel.c_str(), seconds_per_step * 1e6, seconds_per_step * 1e9 / n,
                static_cast<double>(iterations) / o.steps, launches_per_step, round_trip_ns);
  };
  double covered = 0;
  long launches = 0;
  for (const auto& [name, sec] : best_kernels) {  // (empty with --no-kernel-times)
    const long count = best_launches[name];
    row(name, sec / o.steps, static_cast<double>(count) / o.steps);
    covered += sec / o.steps;
    launches += count;
  }
  if (o.kernel_times) row("other", step_s - covered, 0);
  row("step", step_s, static_cast<double>(launches) / o.steps);
  std::fflush(stdout);
}

void run_all(const Options& o, int threads) {
  for (const std::string& kind : o.scenes)
    for (int level : o.levels) {
      if (o.serial) run_case<Kokkos::Serial>("Serial", 1, kind, level, o);
#if defined(KOKKOS_ENABLE_OPENMP)
      run_case<Kokkos::OpenMP>("OpenMP", threads, kind, level, o);
#endif
#if defined(KOKKOS_ENABLE_CUDA)
      if (o.cuda) run_case<Kokkos::Cuda>("Cuda", 0, kind, level, o);
#endif
    }
}

std::string join(const std::vector<int>& v) {
  std::string s;
  for (int x : v) s += (s.empty() ? "" : ",") + std::to_string(x);
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench_step: per-kernel time of whole steps (stretch and spread scenes) on every backend, CSV",
               "bench_step"};
  Options o;
  std::string scenes = "stretch,spread,diagonal";
  app.add_option("--levels", o.levels, "icosphere levels (3: 642 nodes ... 6: 40962)")
      ->delimiter(',')
      ->check(CLI::Range(0, 6));
  app.add_option("--scenes", scenes, "stretch, spread, diagonal (comma-separated)");
  app.add_option("--threads", o.threads, "OpenMP thread counts, one child process each")
      ->delimiter(',')
      ->check(CLI::Range(1, 1024));
  app.add_option("--steps", o.steps, "timed steps per case")->check(CLI::Range(1, 1000000));
  app.add_option("--warmup", o.warmup, "untimed steps first")->check(CLI::Range(0, 1000000));
  app.add_option("--repeat", o.repeat,
                 "runs of each case from the same start (warm-up + timed steps); the fastest is reported")
      ->check(CLI::Range(1, 1000));
  app.add_option("--rounds", o.rounds,
                 "runs of the whole sequence of thread counts; each case reports its fastest round")
      ->check(CLI::Range(1, 1000));
  app.add_option("--set", o.sets,
                 "KEY=VALUE: a scene key for every case, e.g. --set solver.cg_abs_tol_N=4e-14");
  bool round_trip_only = false;
  app.add_flag("--round-trip", round_trip_only,
               "only measure the two OpenMP threads' cache-line round trip (ns) and print it");
  app.add_flag("--child", o.child, "(internal) run one thread count, no header, no Serial unless --serial");
  app.add_flag("--serial,!--no-serial", o.serial, "also time the Serial space");
  app.add_flag("--cuda,!--no-cuda", o.cuda,
               "also time the Cuda space (when this Kokkos has it; in the first child only)");
  app.add_flag(
      "--kernel-times,!--no-kernel-times", o.kernel_times,
      "time each kernel (Kokkos fences around every kernel; on a GPU that adds a synchronisation per "
      "launch to the step); --no-kernel-times: the whole step alone, unfenced");
  CLI11_PARSE(app, argc, argv);
  if (round_trip_only) {
    std::printf("thread_round_trip_ns,%.0f\n", thread_round_trip_ns());
    return 0;
  }
  o.scenes.clear();
  std::stringstream ss(scenes);
  for (std::string k; std::getline(ss, k, ',');) {
    if (k != "stretch" && k != "spread" && k != "diagonal") {
      std::cerr << "bench_step: error: --scenes: '" << k
                << "' is not allowed: choose stretch, spread, diagonal\n";
      return 2;
    }
    o.scenes.push_back(k);
  }
  try {  // the --set keys, once, before any child starts
    for (const std::string& kind : o.scenes) scene_for(kind, o.levels.empty() ? 3 : o.levels[0], o.sets);
  } catch (const std::exception& e) {
    std::cerr << "bench_step: error: " << e.what() << "\n";
    return 2;
  }
  if (o.child) {
    try {
      dcm::KokkosSession kokkos;
      if (o.kernel_times) install_kernel_timer();
      run_all(o, std::atoi(std::getenv("OMP_NUM_THREADS") ? std::getenv("OMP_NUM_THREADS") : "0"));
    } catch (const std::exception& e) {
      std::cerr << "bench_step: error: " << e.what() << "\n";
      return 1;
    }
    return 0;
  }
  std::printf(
      "space,threads,scene,nodes,kernel,us_per_step,ns_per_node,cg_iterations_per_step,launches_per_step,"
      "thread_round_trip_ns\n");
  std::fflush(stdout);
  char self[4096];
  const ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
  if (len <= 0) {
    std::cerr << "bench_step: error: cannot find this program's path (/proc/self/exe)\n";
    return 1;
  }
  self[len] = '\0';
  // The rows of each case (space, threads, scene, nodes) in the order they first came, and the fastest
  // round's rows of it (--rounds).
  std::vector<std::string> order;
  std::map<std::string, std::pair<double, std::vector<std::string>>> best;
  for (int round = 0; round < o.rounds; ++round)
    for (std::size_t k = 0; k < o.threads.size(); ++k) {
      std::string cmd = "OMP_NUM_THREADS=" + std::to_string(o.threads[k]) + " OMP_PROC_BIND=false '" + self +
                        "' --child --levels " + join(o.levels) + " --scenes " + scenes + " --steps " +
                        std::to_string(o.steps) + " --warmup " + std::to_string(o.warmup) + " --repeat " +
                        std::to_string(o.repeat) + (k == 0 && o.serial ? " --serial" : " --no-serial") +
                        (k == 0 && o.cuda ? " --cuda" : " --no-cuda") +
                        (o.kernel_times ? "" : " --no-kernel-times");
      for (const std::string& set : o.sets) cmd += " --set '" + set + "'";
      const auto failed = [&] {
        std::cerr << "bench_step: error: the run with " << o.threads[k] << " OpenMP threads failed\n";
        return 1;
      };
      if (o.rounds == 1) {
        if (std::system(cmd.c_str()) != 0) return failed();
        continue;
      }
      std::fprintf(stderr, "bench_step: round %d of %d, %d OpenMP thread(s)\n", round + 1, o.rounds,
                   o.threads[k]);  // (the rows come when every round is done)
      FILE* child = popen(cmd.c_str(), "r");
      if (!child) return failed();
      std::vector<std::string> rows;  // of the case being read
      char line[4096];
      while (std::fgets(line, sizeof line, child)) {
        const std::string row(line);
        rows.push_back(row);
        // space,threads,scene,nodes,kernel,us_per_step,...: a case ends with its "step" row
        std::vector<std::string> field;
        std::stringstream fs(row);
        for (std::string f; std::getline(fs, f, ',');) field.push_back(f);
        if (field.size() < 6 || field[4] != "step") continue;
        const std::string key = field[0] + "," + field[1] + "," + field[2] + "," + field[3];
        const double us = std::atof(field[5].c_str());
        const auto it = best.find(key);
        if (it == best.end()) order.push_back(key);
        if (it == best.end() || us < it->second.first) best[key] = {us, rows};
        rows.clear();
      }
      if (pclose(child) != 0) return failed();
    }
  for (const std::string& key : order)
    for (const std::string& row : best[key].second) std::fputs(row.c_str(), stdout);
  return 0;
}
