// contact-probe: the contact of every triangle of a spread checkpoint with the plane, as CSV on stdout: where
// the triangle is, its rounded sphere (radius, overlap with the plane), its regime, its load and how eq. 19
// shares the load among its three nodes. For asking why a cell spreads or stops (docs/VALIDATION.md,
// "Where the contact line is held"). The scene is the checkpoint's; --set changes contact or geometry keys
// to see what they would do to the same shape.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "apps/common/app_cli.hpp"
#include "apps/common/mechanics_setup.hpp"
#include "core/checkpoint.hpp"
#include "core/errors.hpp"
#include "core/scene.hpp"

namespace {

using Exec = Kokkos::DefaultExecutionSpace;

template <class V>
auto host(const V& v) {
  return Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), v);
}

void probe(const std::string& path, const std::vector<std::string>& sets, bool all) {
  const dcm::Checkpoint c = dcm::read_checkpoint(path);
  if (c.text("app") != "spread")
    throw dcm::IoError(path + ": a checkpoint of '" + c.text("app") + "', not of spread");
  dcm::Scene scene = dcm::Scene::from_string(c.text("scene"), path);
  for (const std::string& s : sets) {
    const std::string key = s.substr(0, s.find('='));
    if (key.rfind("contact.", 0) != 0 && key.rfind("geometry.", 0) != 0 && key.rfind("cortex.E_Pa", 0) != 0 &&
        key.rfind("cortex.nu", 0) != 0)
      throw dcm::SceneError("--set " + s +
                            ": only contact.*, geometry.*, cortex.E_Pa and cortex.nu may change "
                            "(the shape is the checkpoint's)");
    // Keys the triangles' loads and regimes do not depend on would be accepted and change nothing.
    for (const char* ignored :
         {"contact.crease_radius_m", "contact.friction_weights", "contact.friction_zone",
          "contact.start_gap_m", "contact.gamma_n_N_s_per_m3", "contact.gamma_t_N_s_per_m3",
          "contact.pin_friction_N_s_per_m", "contact.guard_depth_m", "contact.guard_stiffness_Pa_per_m"})
      if (key == ignored)
        throw dcm::SceneError("--set " + s + ": " + key +
                              " does not change the contact loads this probe reports (the crease, the "
                              "substrate friction, the guard and the start gap act elsewhere)");
    scene.set(s);
  }
  scene.validate();
  if (!scene.get_bool("contact.plane"))
    throw dcm::SceneError(
        "contact.plane = false: there is no plane to probe (the checkpoint's scene has none, "
        "or --set turned it off)");
  dcm::CortexModel<Exec> model(Exec(), {dcm::HostCell(dcm::cell_mesh_from_scene(scene))},
                               dcm::mechanics_from_scene(scene));
  model.restore_cell_state(c, 0);
  model.compute_forces();
  model.refresh_curvature();  // the spheres below (compute_forces() leaves them out for contact.law =
                              // derjaguin)
  const auto x = host(model.positions());
  const auto tri = host(model.mesh().tri);
  const auto& geo = model.geometry();
  const auto radius = host(geo.tri_sphere_radius);
  const auto centre = host(geo.tri_sphere_center);
  const auto normal = host(geo.tri_normal);
  const auto& cb = *model.contact();
  const auto node_load = host(cb.tri_node_load);
  const auto load = host(cb.tri_load);
  const auto regime = host(cb.tri_regime);
  const auto area_c = host(cb.tri_contact_area);
  const double plane_z = scene.get_real("contact.plane_z_m");
  const int n = model.mesh().n_nodes;
  double cx = 0, cy = 0;
  for (int i = 0; i < n; ++i) cx += x(i, 0) / n, cy += x(i, 1) / n;
  // What was probed goes to stderr: stdout is plain CSV (a '#' line would be taken for the header by numpy's
  // genfromtxt(names=True) and by csv.reader).
  std::fprintf(
      stderr,
      "contact-probe: %s at t = %.9g s; plane z = %g m; axis through the node centroid (%.6g, %.6g) m\n",
      path.c_str(), c.scalar("stepper.t"), plane_z, cx + 0.0, cy + 0.0);
  std::printf(
      "triangle,r_m,z_min_m,z_max_m,normal_z,sphere_radius_m,sphere_overlap_m,regime,load_N,"
      "node0,node1,node2,z0_m,z1_m,z2_m,f0_N,f1_N,f2_N,contact_area_m2\n");
  for (int t = 0; t < model.mesh().n_tris; ++t) {
    if (!all && regime(t) == dcm::kNoContact) continue;
    double z[3], r = 0;
    for (int k = 0; k < 3; ++k) {
      const int i = tri(t, k);
      z[k] = x(i, 2) - plane_z;
      r += std::hypot(x(i, 0) - cx, x(i, 1) - cy) / 3;
    }
    std::printf("%d,%.6e,%.6e,%.6e,%.9g,%.6e,%.6e,%d,%.17g,%d,%d,%d,%.6e,%.6e,%.6e,%.17g,%.17g,%.17g,%.17g\n",
                t, r, std::min({z[0], z[1], z[2]}), std::max({z[0], z[1], z[2]}), normal(t, 2) + 0.0,
                radius(t), radius(t) - (centre(t, 2) - plane_z), regime(t), load(t) + 0.0, tri(t, 0),
                tri(t, 1), tri(t, 2), z[0], z[1], z[2], node_load(t, 0) + 0.0, node_load(t, 1) + 0.0,
                node_load(t, 2) + 0.0,
                area_c(t));  // + 0.0: no "-0" in the CSV
  }
  // The CSV is the output: a write that failed (a full disk, a closed file) must not end in exit 0.
  if (std::fflush(stdout) != 0 || std::ferror(stdout))
    throw dcm::IoError(
        "standard output: the write failed (a full disk or a closed file?); the CSV is incomplete");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "contact-probe: per-triangle contact of a spread checkpoint with the plane, as CSV on stdout (what\n"
      "was probed: one line on stderr)\n"
      "(regime 0 none, 1 gap branch, 2 quadrature/exact, 3 small disc, 4 full contact; loads repulsive > 0)",
      "contact-probe"};
  app.footer(
      "Columns: triangle, r_m (mean distance of its nodes from the axis), z_min_m, z_max_m (above the "
      "plane),\n"
      "normal_z, sphere_radius_m and sphere_overlap_m (its rounded sphere), regime, load_N, node0..2,\n"
      "z0_m..z2_m, f0_N..f2_N (the nodes' shares of the load), contact_area_m2.\n"
      "With contact.law = derjaguin (flat triangles) the sphere columns are the rounded sphere's all the "
      "same\n"
      "(that law does not use it), f0_N..f2_N are the normal forces on the corners, and the regime is 2\n"
      "(part of the triangle below h0/sqrt(3)), 4 (all of it) or 1 (within h0 only).\n"
      "Examples:\n  contact-probe out/default/checkpoint.h5 > contact.csv\n"
      "  contact-probe out/default/checkpoint.h5 --set contact.quadrature_points=16 --all > all.csv\n"
      "Exit codes: 0 success, 2 bad input or an unreadable checkpoint (one line on stderr), 1 internal "
      "error.");
  std::string path;
  std::vector<std::string> sets;
  bool all = false;
  app.add_option("CHECKPOINT", path, "checkpoint.h5 written by spread")->required();
  app.add_option("--set", sets, "KEY=VALUE: change a contact.*, geometry.*, cortex.E_Pa or cortex.nu key")
      ->allow_extra_args(false);
  app.add_flag(
      "--all", all,
      "every triangle; without it, those whose rounded sphere reaches within h0 of the plane (regime "
      ">= 1, the gap branch included: a small sphere of a wall triangle can reach the plane while the "
      "triangle itself lies far above it)");
  int threads = 0;
  app.add_option("--threads", threads, "Host threads (0 or not given: OMP_NUM_THREADS, else all cores)")
      ->check(CLI::Range(0, 4096));
  return dcm::run_app(app, argc, argv, [&] {
    dcm::KokkosSession kokkos(threads);
    probe(path, sets, all);
  });
}
