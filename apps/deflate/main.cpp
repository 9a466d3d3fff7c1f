// deflate: the paper's biconcave start (MODEL.md section 1; paper, "Materials and methods"): a sphered cell
// whose target volume is lowered to a fraction of the sphere's and relaxed to mechanical equilibrium. The
// sphere is the rest state of the bonds and the area terms; the hinges rest flat (no spontaneous curvature).
// Quasi-static deflation of the sphere ends on the stomatocyte side; starting from the sphere squashed along
// z
// (--squash, the rest state unchanged) it ends biconcave. Outputs in --out: summary.json (area, volume,
// reduced volume, diameter, centre and largest thickness, against the Evans–Fung cell), profile.csv
// (thickness against the distance from the axis), shape.csv (the node positions), deflate.h5/.xmf (the mesh
// with two frames, the squashed start and the equilibrium, for ParaView). docs/VALIDATION.md, "Biconcave
// start".
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "apps/common/app_cli.hpp"
#include "apps/common/mechanics_setup.hpp"
#include "core/errors.hpp"
#include "core/h5_output.hpp"
#include "core/host_copy.hpp"
#include "core/json_writer.hpp"
#include "core/scene.hpp"
#include "solvers/newton_equilibrium.hpp"

namespace {

// The closed surface's extent along the vertical line through (px, py): the highest minus the lowest point
// where the line meets a triangle (NaN: it meets fewer than two).
double thickness_along_z(const std::vector<double>& x, const std::vector<dcm::Tri>& tris, double px,
                         double py) {
  double lo = INFINITY, hi = -INFINITY;
  int hits = 0;
  for (const dcm::Tri& t : tris) {
    const double* a = &x[3 * t[0]];
    const double* b = &x[3 * t[1]];
    const double* q = &x[3 * t[2]];
    const double det = (b[0] - a[0]) * (q[1] - a[1]) - (q[0] - a[0]) * (b[1] - a[1]);
    if (det == 0) continue;  // a vertical triangle: its neighbours hold the crossing
    const double u = ((px - a[0]) * (q[1] - a[1]) - (q[0] - a[0]) * (py - a[1])) / det;
    const double v = ((b[0] - a[0]) * (py - a[1]) - (px - a[0]) * (b[1] - a[1])) / det;
    if (u < 0 || v < 0 || u + v > 1) continue;
    const double z = a[2] + u * (b[2] - a[2]) + v * (q[2] - a[2]);
    lo = std::min(lo, z);
    hi = std::max(hi, z);
    ++hits;
  }
  return hits >= 2 ? hi - lo : NAN;
}

using Exec = Kokkos::DefaultExecutionSpace;

struct Options {
  int nodes = 642;
  double volume_fraction = 0.644;  // the Evans–Fung cell's reduced volume
  double squash = 0.45;            // z scale of the start (1: the sphere itself)
  std::string out = "out/deflate";
  int threads = 0;
  bool quiet = false;
  bool check = false;             // --check: the options and the output folder only, nothing written or run
  std::vector<std::string> sets;  // cortex.* overrides of the deflation's constants
};

int level_of(int nodes) {
  for (int k = 0; k <= 6; ++k)
    if (10 * (1 << (2 * k)) + 2 == nodes) return k;
  return -1;
}

void run(const Options& o) {
  const int level = level_of(o.nodes);
  if (level < 2 || level > 5)
    throw dcm::SceneError("--nodes = " + std::to_string(o.nodes) +
                          " is not allowed: choose 162, 642, 2562 or 10242 (icosphere node counts)");
  if (!(o.volume_fraction >= 0.3 && o.volume_fraction <= 1))
    throw dcm::SceneError("--volume-fraction = " + dcm::detail::format_real(o.volume_fraction) +
                          " is out of range: allowed 0.3 .. 1");
  if (!(o.squash >= 0.1 && o.squash <= 1))
    throw dcm::SceneError("--squash = " + dcm::detail::format_real(o.squash) +
                          " is out of range: allowed 0.1 .. 1");
  dcm::Scene scene = dcm::Scene::defaults();  // Table 1 cortex
  scene.set("mesh.nodes=" + std::to_string(o.nodes));
  scene.set("contact.plane=false");
  for (const std::string& set : o.sets) {
    if (set.rfind("cortex.", 0) != 0)
      throw dcm::SceneError("--set " + set + ": deflate takes cortex.* keys only (the mesh: --nodes)");
    scene.set(set);
  }
  scene.validate();
  if (!(scene.get_real("cortex.k_v") > 0))
    throw dcm::SceneError("cortex.k_v = " + dcm::detail::format_real(scene.get_real("cortex.k_v")) +
                          " is not allowed: deflate needs the volume constraint, which sets the volume it "
                          "deflates to (allowed > 0)");
  // The mechanics' own checks before any file is touched (a refused run leaves an earlier one's files alone).
  const dcm::MechanicsParams params = dcm::mechanics_from_scene(scene);
  // The folder is checked before the equilibrium's seconds, as the other apps do, and made after it: a run
  // stopped by Ctrl-C or failing leaves no empty folder and an earlier run's files alone.
  dcm::check_output_dir(o.out);
  if (o.check) {
    if (!o.quiet) std::printf("deflate: ok (checked, nothing written)\n");
    return;
  }
  const dcm::HostMesh sphere = dcm::cell_mesh_from_scene(scene);
  dcm::CortexModel<Exec> model(Exec(), {dcm::HostCell(sphere)}, params);
  model.set_flat_bending_rest();
  // The icosphere's own volume (the constructor's geometry, before the squash): the rest volume the target
  // scales.
  const double mesh_volume = dcm::to_host_vector(model.geometry().cell_volume)[0];
  {
    auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), model.positions());
    for (std::size_t i = 0; i < x.extent(0); ++i) x(i, 2) *= o.squash;
    Kokkos::deep_copy(model.positions(), x);
  }
  const std::vector<double> x_start = dcm::to_host_vector(model.positions());
  model.scale_rest_volume(o.volume_fraction);
  dcm::NewtonSettings ns;
  ns.force_tol = 1e-16;
  ns.max_newton_steps = 1000;
  if (!o.quiet) ns.progress_s = 10;
  const double edge = 4.0 * scene.get_real("mesh.radius_m") / std::sqrt(static_cast<double>(o.nodes));
  const dcm::NewtonResult r = dcm::newton_equilibrium(model, ns, edge);
  model.compute_forces();  // geometry of the final shape (and, when it failed, the forces the message names)
  if (!r.converged)
    throw dcm::NumericalError("no equilibrium after " + std::to_string(r.newton_steps) +
                              " Newton steps; the largest force is at " + model.describe_largest_force());
  std::error_code ec;
  std::filesystem::create_directories(o.out, ec);
  if (ec || !std::filesystem::is_directory(o.out))
    throw dcm::IoError("--out " + o.out + ": cannot create the folder (" + ec.message() + ")");
  dcm::remove_earlier_outputs(o.out,
                              {"summary.json", "profile.csv", "shape.csv", "deflate.h5", "deflate.xmf"});
  const auto x = dcm::to_host_vector(model.positions());
  const double area = dcm::to_host_vector(model.geometry().cell_area)[0];
  const double volume = dcm::to_host_vector(model.geometry().cell_volume)[0];
  const double pi = std::acos(-1.0);
  const double reduced = 6 * std::sqrt(pi) * volume / std::pow(area, 1.5);
  // The volume reached against the target, both as fractions of the icosphere mesh's own volume (the rest
  // volume the target scales; 3.4% below 4/3 π R³ on 162 nodes): a soft volume term stops short of it.
  const double fraction = volume / mesh_volume;
  // Symmetry axis: z (the squash direction); centre: the node centroid.
  const int n = o.nodes;
  double c[3] = {0, 0, 0};
  for (int i = 0; i < n; ++i)
    for (int d = 0; d < 3; ++d) c[d] += x[3 * i + d] / n;
  double rho_max = 0;
  for (int i = 0; i < n; ++i) rho_max = std::max(rho_max, std::hypot(x[3 * i] - c[0], x[3 * i + 1] - c[1]));
  // Thickness profile: the surface's extent along vertical lines through the mesh's triangles, at rho = 0 and
  // on rings out to 97.5% of the radius, averaged over 16 directions (session 28; until then the z-range of
  // the nodes in a ring of rho, which reads the ring's thickest point and was up to 60% high at the rim).
  const int rows = 2 * std::max(4, static_cast<int>(std::lround(std::sqrt(n / 4.0))));
  std::ofstream prof(o.out + "/profile.csv");
  prof << "rho_m,thickness_m\n";
  double t_centre = NAN, t_max = 0, rho_at_max = 0;
  for (int b = 0; b < rows; ++b) {
    const double rho = 0.975 * rho_max * b / (rows - 1);
    const int directions = b == 0 ? 1 : 16;
    double sum = 0;
    int hits = 0;
    for (int k = 0; k < directions; ++k) {
      const double phi = 2 * pi * (k + 0.5) / directions;
      const double t =
          thickness_along_z(x, sphere.triangles, c[0] + rho * std::cos(phi), c[1] + rho * std::sin(phi));
      if (std::isfinite(t)) sum += t, ++hits;
    }
    if (hits == 0) continue;
    const double t = sum / hits;
    if (b == 0) t_centre = t;
    if (t > t_max) t_max = t, rho_at_max = rho;
    char line[96];
    std::snprintf(line, sizeof line, "%.9g,%.9g\n", rho, t);
    prof << line;
  }
  std::ofstream shape(o.out + "/shape.csv");
  shape << "x_m,y_m,z_m\n";
  for (int i = 0; i < n; ++i) {
    char line[96];
    std::snprintf(line, sizeof line, "%.12g,%.12g,%.12g\n", x[3 * i], x[3 * i + 1], x[3 * i + 2]);
    shape << line;
  }
  if (!prof || !shape) throw dcm::IoError(o.out + ": cannot write profile.csv / shape.csv");
  {  // deflate.h5/.xmf: the mesh, frame 0 the squashed start, frame 1 the equilibrium (time = frame index)
    std::vector<int> tri, node_cell(n, 0);
    for (const dcm::Tri& t : sphere.triangles) tri.insert(tri.end(), t.begin(), t.end());
    dcm::H5Output h5(o.out + "/deflate.h5");
    h5.write_text("scene", scene.to_toml());
    h5.write_mesh(x_start.data(), n, tri.data(), static_cast<int>(sphere.triangles.size()), node_cell.data());
    h5.write_frame(0.0, x_start.data(), {});
    h5.write_frame(1.0, x.data(), {});
    h5.close();
  }
  const double sphere_area = 4 * pi * std::pow(scene.get_real("mesh.radius_m"), 2);
  dcm::JsonObject json;
  json.add("nodes", n)
      .add("volume_fraction_target", o.volume_fraction)
      .add("volume_fraction_reached", fraction)
      .add("squash", o.squash)
      .add("sets", o.sets)
      .add("newton_steps", r.newton_steps)
      .add("max_force_N", r.max_force)
      .add("area_m2", area)
      .add("area_over_sphere", area / sphere_area)
      .add("volume_m3", volume)
      .add("reduced_volume", reduced)
      .add("diameter_m", 2 * rho_max)
      .add("thickness_centre_m", t_centre)
      .add("thickness_max_m", t_max)
      .add("rho_of_thickness_max_m", rho_at_max)
      .add("biconcave", t_centre < t_max)
      .add("evans_fung_diameter_m", 7.82e-6)
      .add("evans_fung_thickness_centre_m", 0.810e-6)
      .add("evans_fung_thickness_max_m", 2.566e-6)
      .add("evans_fung_rho_of_thickness_max_m", 2.738e-6)
      .add("evans_fung_reduced_volume", 0.644);
  json.write(o.out + "/summary.json");
  if (std::fabs(fraction / o.volume_fraction - 1) > 0.01)
    std::fprintf(stderr,
                 "deflate: warning: the volume reached V/V0 = %.3f (V0 the icosphere's), not the target "
                 "%.3f: the volume term "
                 "(cortex.k_v = %.3g) is too soft against the area terms to deflate the cell that far\n",
                 fraction, o.volume_fraction, scene.get_real("cortex.k_v"));
  if (!o.quiet)
    std::printf(
        "deflate: %d nodes, V/V0 -> %.3f (V0 the icosphere's) from a start squashed to %.2f: %d Newton "
        "steps; reduced "
        "volume "
        "%.3f, area %.4f of the sphere's, diameter %.2f um, thickness %.2f um at the centre, %.2f um at rho "
        "= "
        "%.2f um (%s); Evans-Fung: 7.82, 0.81, 2.57 at 2.74 um -> %s\n",
        n, fraction, o.squash, r.newton_steps, reduced, area / sphere_area, 2e6 * rho_max, 1e6 * t_centre,
        1e6 * t_max, 1e6 * rho_at_max, t_centre < t_max ? "biconcave" : "not biconcave", o.out.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "deflate: the paper's biconcave start, a sphered cell deflated and relaxed (docs/VALIDATION.md)",
      "deflate"};
  app.footer(
      "Writes in --out: summary.json (area, volume, reduced volume, diameter, centre and largest thickness,\n"
      "against the Evans-Fung cell), profile.csv (thickness against the distance from the axis), shape.csv\n"
      "(node positions), deflate.h5 + deflate.xmf (the squashed start and the equilibrium, for ParaView).\n"
      "Run time: a few seconds on 642 nodes (the default), minutes on 2562.\n"
      "Examples:\n  deflate\n"
      "  deflate --nodes 2562 --out out/deflate2562\n"
      "Exit codes: 0 success, 2 bad input or an unwritable --out (one line on stderr, nothing written),\n3 "
      "numerical failure (the "
      "Newton iteration did not converge), 1 internal error.");
  Options o;
  app.add_option("--nodes", o.nodes, "icosphere node count: 162, 642, 2562 or 10242 (default 642)");
  app.add_option("--volume-fraction", o.volume_fraction,
                 "target volume / sphere volume, 0.3 .. 1 (default 0.644)");
  app.add_option("--squash", o.squash, "z scale of the start, 0.1 .. 1 (1: the sphere; default 0.45)");
  app.add_option("--out", o.out, "output folder (default out/deflate)");
  app.add_option("--threads", o.threads, "host threads (0 or not given: OMP_NUM_THREADS, else all cores)")
      ->check(CLI::Range(0, 4096));
  app.add_flag("--quiet", o.quiet, "print only errors");
  app.add_flag(
      "--check", o.check,
      "only check the options and the output folder (exit 0, or 2 with the error); write and run nothing");
  app.add_option(
         "--set", o.sets,
         "a cortex.* constant of the deflation, one KEY=VALUE per --set, repeat it for more (e.g. softer "
         "springs: --set cortex.k_s_N_per_m=3.2e-8); default Table 1")
      ->type_name("KEY=VALUE");
  dcm::one_value_per_use(app.get_option("--set"));
  return dcm::run_app(app, argc, argv, [&] {
    dcm::KokkosSession kokkos(o.threads);
    run(o);
  });
}
