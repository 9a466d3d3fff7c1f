// stretch: the optical-tweezers experiment of the paper (its Figure 2; Mills et al. 2004): the outermost
// nodes of the cell, 2.5% at each end (the paper's 5% in total; --pulled-fraction), are pulled along x with
// ±F/n each, the cell is brought to equilibrium, and the axial and transverse diameters D_A (x extent) and
// D_T (y extent) are recorded for every force. Writes <out>/series.csv (F_N,DA_m,DT_m,newton_steps,
// max_residual_force_N), <out>/summary.json,
// <out>/stretch.h5 (+ .xmf) with one frame per force (the frame's "time" is the force in pN: ParaView's time
// control steps through the forces and reads them in pN; the series group holds series.csv's columns), and
// <out>/stretch.png against ../shared/data/stretching when plotting is available.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

#include "apps/common/app_cli.hpp"
#include "apps/common/mechanics_setup.hpp"
#include "apps/common/stretch_setup.hpp"
#include "core/h5_output.hpp"
#include "core/host_copy.hpp"
#include "core/json_writer.hpp"
#include "core/kokkos_compat.hpp"
#include "dcm_config.hpp"
#include "solvers/newton_equilibrium.hpp"

namespace dcm {
namespace {

using Exec = Kokkos::DefaultExecutionSpace;

struct StretchOptions {
  std::vector<double> forces_pN = {0,       15.987,  19.338,  30.754,  38.365,  47.245, 67.964, 87.837,
                                   108.949, 130.513, 150.809, 172.374, 192.688, 200};  // Mills 2004 + 200
  double pulled_fraction = 0.025;  // per end: the paper's "outermost 5% of the nodes" in total
  bool no_plot = false;
};

void run(const AppOptions& options, const StretchOptions& so) {
  // Without a scene file: the paper's experiment, a 2562-node Evans-Fung cell with Table 1 constants.
  const Scene scene = load_scene(options, {"name=stretch", "mesh.shape=evans_fung"}, true);
  if (so.forces_pN.empty())
    throw SceneError(
        "--forces-pN is empty: give at least one force, 0 .. 10000 pN (e.g. --forces-pN 0,50,100)");
  for (std::size_t i = 0; i < so.forces_pN.size(); ++i) {
    const double f = so.forces_pN[i];
    if (!(f >= 0 && f <= 1e4))
      throw SceneError("--forces-pN = " + detail::format_real(f) + " is out of range: allowed 0 .. 10000");
    // each frame is timed by its force: a repeated force gives two frames at one time in ParaView
    for (std::size_t j = 0; j < i; ++j)
      if (so.forces_pN[j] == f)
        throw SceneError("--forces-pN = " + detail::format_real(f) +
                         " is given twice: allowed each force once (stretch.xmf times its frames by F)");
  }
  check_pulled_fraction(so.pulled_fraction);
  check_no_plane("stretch", scene);
  // Every check before the output folder is touched (--check included): a refused run leaves an earlier
  // run's files alone.
  MechanicsParams params = mechanics_from_scene(scene);
  if (stop_after_check("stretch", options, scene)) return;
  const std::string out = prepare_output_dir(options, scene);
  remove_earlier_outputs(
      out, {"series.csv", "series.csv.tmp", "summary.json", "stretch.h5", "stretch.xmf", "stretch.png"});
  KokkosSession kokkos(options.threads);
  const auto wall0 = std::chrono::steady_clock::now();

  const HostMesh mesh = cell_mesh_from_scene(scene);
  const auto [left, right] = pulled_nodes(mesh, so.pulled_fraction);
  CortexModel<Exec> model(Exec(), {HostCell(mesh)}, params);
  const int n = model.mesh().n_nodes;
  const double edge = mean_edge_length(mesh, build_topology(mesh));
  if (!options.quiet)
    std::printf("dcm stretch: scene '%s', %s, %d nodes, %zu pulled at each end; %s\n", scene.name().c_str(),
                scene.get_string("mesh.shape").c_str(), n, left.size(), kokkos_description().c_str());

  std::vector<int> tri, node_cell(n, 0);
  for (const Tri& t : mesh.triangles) tri.insert(tri.end(), t.begin(), t.end());
  std::unique_ptr<H5Output> h5;  // none with output.hdf5 = false
  if (scene.get_bool("output.hdf5")) {
    h5 = std::make_unique<H5Output>(out + "/stretch.h5");
    h5->write_text("scene", scene.to_toml());
    const auto x0 = to_host_vector(model.positions());
    h5->write_mesh(x0.data(), n, tri.data(), static_cast<int>(mesh.triangles.size()), node_cell.data());
  }
  std::ofstream csv(out + "/series.csv.tmp");
  csv << "F_N,DA_m,DT_m,newton_steps,max_residual_force_N\n";
  std::vector<double> forces, da, dt;
  auto ext = Kokkos::create_mirror_view(model.external_force());
  install_stop_handler();  // Ctrl-C: stop after the current force, keep the forces done
  bool interrupted = false;
  for (double f_pN : so.forces_pN) {
    if (stop_requested()) {
      interrupted = true;
      break;
    }
    const double f = f_pN * 1e-12;
    Kokkos::deep_copy(ext, 0.0);
    for (int i : left) ext(i, 0) = -f / left.size();
    for (int i : right) ext(i, 0) = f / right.size();
    Kokkos::deep_copy(model.external_force(), ext);
    NewtonSettings ns;
    ns.force_tol = std::max(1e-4 * 200e-12 / left.size(), 1e-17);
    if (const char* trace = std::getenv("DCM_NEWTON_TRACE")) ns.trace = std::atoi(trace);
    // A force that fails keeps the forces that did converge (series.csv, stretch.h5), then stops.
    const auto fail = [&](const std::string& why) {
      csv.close();
      std::rename((out + "/series.csv.tmp").c_str(), (out + "/series.csv").c_str());
      if (h5) h5->close();
      throw NumericalError("stretch at F = " + detail::format_real(f_pN) + " pN " + why +
                           "; series.csv holds the forces before it");
    };
    NewtonResult r;
    try {
      r = newton_equilibrium(model, ns, edge);
    } catch (const NumericalError& e) {  // (a solve inside that throws: session 40)
      fail(std::string("failed: ") + e.what());
    }
    const auto x = to_host_vector(model.positions());
    const auto [d_axial, d_transverse] = axial_transverse_diameters(x);
    if (!options.quiet)
      std::printf("  F = %7.2f pN   D_A = %6.3f um   D_T = %6.3f um   (%d Newton steps, residual %.2g N%s)\n",
                  f_pN, d_axial * 1e6, d_transverse * 1e6, r.newton_steps, r.max_force,
                  r.converged ? "" : ", NOT CONVERGED");
    std::fflush(stdout);
    if (!r.converged) {
      model.compute_forces();  // the forces at the last iterate, for the message
      fail("did not reach equilibrium in " + std::to_string(r.newton_steps) +
           " Newton steps; the largest force is at " + model.describe_largest_force());
    }
    forces.push_back(f);
    da.push_back(d_axial);
    dt.push_back(d_transverse);
    char line[256];
    std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g,%d,%.6g\n", f, da.back(), dt.back(), r.newton_steps,
                  r.max_force);
    csv << line;
    if (h5) {
      const auto ext_h = to_host_vector(model.external_force());
      h5->write_frame(f_pN, x.data(), {{"external_force_N", 3, ext_h.data()}});
      h5->append_series({{"F_N", f}, {"DA_m", da.back()}, {"DT_m", dt.back()}});
    }
  }
  csv.close();
  std::rename((out + "/series.csv.tmp").c_str(), (out + "/series.csv").c_str());
  if (h5) h5->close();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  JsonObject summary;
  summary.add("scene", scene.name())
      .add("nodes", n)
      .add("pulled_nodes_per_end", static_cast<long long>(left.size()))
      .add("forces_N", forces)
      .add("DA_m", da)
      .add("DT_m", dt)
      .add("wall_s", wall)
      .add("interrupted", interrupted);
  summary.write(out + "/summary.json");
  if (interrupted)
    throw AppInterrupted("interrupted after " + std::to_string(forces.size()) + " of " +
                         std::to_string(so.forces_pN.size()) + " forces; " + out +
                         "/series.csv, summary.json" + (h5 ? " and stretch.h5" : "") + " hold them");
  if (!options.quiet)
    std::printf("  wrote %s/series.csv, summary.json%s (%.1f s)\n", out.c_str(), h5 ? ", stretch.h5" : "",
                wall);
  if (!so.no_plot) {  // stretch.png against Mills 2004 and Suresh 2005 (../shared/data/stretching)
    const std::string cmd = std::string(DCM_PYTHON3) + " '" + DCM_SOURCE_DIR + "/scripts/plot_stretch.py' '" +
                            out + "'" + (options.quiet ? " > /dev/null" : "");
    std::fflush(stdout);  // this run's lines before the plotter's
    if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "stretch: plotting failed (%s)\n", cmd.c_str());
  }
}

}  // namespace
}  // namespace dcm

int main(int argc, char** argv) {
  CLI::App app(
      "The optical-tweezers stretching experiment (paper Figure 2): pull the outermost nodes at both\n"
      "ends with +-F/n, find the equilibrium, record the axial and transverse diameters. Without a scene\n"
      "file it runs the paper's case: a 2562-node Evans-Fung cell with the Table 1 constants.",
      "stretch");
  dcm::AppOptions options;
  dcm::StretchOptions so;
  dcm::add_common_options(app, options,
                          {"", "--set mesh.nodes=642 --forces-pN 0,50,100,200 --out out/stretch642",
                           "scenes/stretch.toml --pulled-fraction 0.05"},
                          true);
  app.add_flag("--no-plot", so.no_plot, "Do not draw stretch.png");
  app.add_option(
         "--pulled-fraction", so.pulled_fraction,
         "Fraction of all nodes pulled at each end (default 0.025: the paper's outermost 5% of the nodes in\n"
         "total; 0.05 reads it as 5% at each end)")
      ->check(CLI::Range(0.001, 0.25));
  app.add_option("--forces-pN", so.forces_pN,
                 "Stretching forces in pN, comma-separated, 0 .. 10000 (default: the Mills 2004 forces and "
                 "200: 0,15.987,19.338,30.754,38.365,47.245,67.964,87.837,108.949,130.513,150.809,172.374,"
                 "192.688,200)")
      ->type_name("F1,F2,...")
      ->delimiter(',');
  // "--forces-pN 0,50 SCENE": SCENE is the scene file, not a force
  dcm::one_value_per_use(app.get_option("--forces-pN"));
  return dcm::run_app(app, argc, argv, [&] { dcm::run(options, so); });
}
