// geometry: build the scene's cell mesh, compute its geometry on the device, print a report and write
// <out>/geometry.h5 (+ .xmf for ParaView) and <out>/geometry.json.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "apps/common/app_cli.hpp"
#include "apps/common/mechanics_setup.hpp"
#include "core/h5_output.hpp"
#include "core/host_copy.hpp"
#include "core/json_writer.hpp"
#include "core/kokkos_compat.hpp"
#include "core/update_geometry.hpp"

namespace dcm {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Stats {
  double min = INFINITY, max = -INFINITY, sum = 0;
  long long n = 0;
  void add(double v) {
    min = std::fmin(min, v);
    max = std::fmax(max, v);
    sum += v;
    ++n;
  }
  double mean() const { return n ? sum / n : 0; }
};

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void run(const AppOptions& options) {
  const Scene scene = load_scene(options, {"name=geometry"});  // not out/default, the main job's folder
  if (stop_after_check("geometry", options, scene)) return;
  const std::string out = prepare_output_dir(options, scene);
  // An earlier run's files go first: one that cannot be replaced (a folder in its place) stops the run
  // before it writes anything (it wrote geometry.json and .h5 and then failed on the .xmf until session 42).
  remove_earlier_outputs(out, {"geometry.json", "geometry.h5", "geometry.xmf", "geometry.xmf.tmp"});
  KokkosSession kokkos(options.threads);
  using Exec = Kokkos::DefaultExecutionSpace;
  using Mem = Exec::memory_space;

  auto t0 = std::chrono::steady_clock::now();
  const std::vector<HostCell> cells{HostCell(cell_mesh_from_scene(scene))};
  const double t_generate = seconds_since(t0);
  t0 = std::chrono::steady_clock::now();
  const MeshBuffers<Mem> mesh = upload_cells<Mem>(cells);
  const GeometryBuffers<Mem> geo(mesh);
  const double t_upload = seconds_since(t0);
  const double h_min = scene.get_real("geometry.h_min_per_m");
  const Exec space;
  update_geometry(space, mesh, geo, h_min);  // warm-up
  space.fence();
  const int reps = 20;
  t0 = std::chrono::steady_clock::now();
  for (int r = 0; r < reps; ++r) update_geometry(space, mesh, geo, h_min);
  space.fence();
  const double t_geometry = seconds_since(t0) / reps;

  const auto x = to_host_vector(mesh.x);
  const auto node_h = to_host_vector(geo.node_mean_curvature);
  const auto node_area = to_host_vector(geo.node_area);
  const auto node_k = to_host_vector(geo.node_curvature);
  const auto node_n = to_host_vector(geo.node_normal);
  const auto tri_h = to_host_vector(geo.tri_mean_curvature);
  const auto tri_r = to_host_vector(geo.tri_sphere_radius);
  const double area = to_host_vector(geo.cell_area)[0], volume = to_host_vector(geo.cell_volume)[0];
  const Topology& topo = cells[0].topology;
  const HostMesh& hm = cells[0].mesh;

  Stats h, r, edge;
  long long clamped = 0;
  for (double v : node_h) h.add(v);
  for (std::size_t t = 0; t < tri_r.size(); ++t) {
    r.add(tri_r[t]);
    clamped += tri_h[t] <= h_min;
  }
  for (const auto& e : topo.edges) {
    const double* a = &x[3 * e[0]];
    const double* b = &x[3 * e[1]];
    edge.add(std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                       (a[2] - b[2]) * (a[2] - b[2])));
  }
  const double reduced_volume = 6 * std::sqrt(kPi) * volume / std::pow(area, 1.5);
  const std::string shape = scene.get_string("mesh.shape");
  const long long nodes = static_cast<long long>(hm.nodes.size());

  if (!options.quiet) {
    std::printf("dcm geometry: scene '%s' (%s)\n", scene.name().c_str(), scene.origin().c_str());
    std::printf("  %s\n", kokkos_description().c_str());
    char refined[96] = "";
    if (scene.get_int("mesh.refine_levels") > 0)
      std::snprintf(refined, sizeof refined, ", refined %lld levels in %g-%g deg",
                    scene.get_int("mesh.refine_levels"), scene.get_real("mesh.refine_from_deg"),
                    scene.get_real("mesh.refine_to_deg"));
    std::printf("  mesh         %s, %lld nodes (%lld subdivisions%s), %zu bonds, %zu triangles, %zu hinges\n",
                shape.c_str(), nodes, scene.get_int("mesh.subdivisions"), refined, topo.edges.size(),
                hm.triangles.size(), topo.hinges.size());
    std::printf("  worst angle  %.3g deg (smallest interior angle of any triangle)\n",
                smallest_angle_deg(hm));
    std::printf("  topology     Euler characteristic %d, closed, consistently oriented\n",
                topo.euler_characteristic);
    std::printf("  edge length  min %.4g  mean %.4g  max %.4g um\n", edge.min * 1e6, edge.mean() * 1e6,
                edge.max * 1e6);
    std::printf("  area         %.6g um^2", area * 1e12);
    if (shape == "sphere") {
      const double rad = scene.get_real("mesh.radius_m");
      std::printf("   (4 pi R^2 = %.6g, %+.3f%%)\n", 4 * kPi * rad * rad * 1e12,
                  100 * (area / (4 * kPi * rad * rad) - 1));
      std::printf("  volume       %.6g um^3   (4/3 pi R^3 = %.6g, %+.3f%%)\n", volume * 1e18,
                  4 * kPi * rad * rad * rad / 3 * 1e18, 100 * (volume / (4 * kPi * rad * rad * rad / 3) - 1));
    } else {
      // The continuum Evans-Fung cell's area and volume at D = 7.82 um, scaled to this cell's diameter (D^2,
      // D^3; until session 41 every diameter was compared with the 7.82-um values).
      const double d_um = scene.get_real("mesh.diameter_m") * 1e6, k = d_um / 7.82;
      const double a_ref = 134.09 * k * k, v_ref = 94.10 * k * k * k;
      std::printf("   (Evans-Fung at D = %.4g um: %.6g, %+.3f%%)\n", d_um, a_ref,
                  100 * (area * 1e12 / a_ref - 1));
      std::printf("  volume       %.6g um^3   (Evans-Fung at D = %.4g um: %.6g, %+.3f%%)\n", volume * 1e18,
                  d_um, v_ref, 100 * (volume * 1e18 / v_ref - 1));
    }
    std::printf("  reduced vol. %.4f  (6 sqrt(pi) V / A^1.5; 1 for a sphere)\n", reduced_volume);
    std::printf("  node H       min %.4g  mean %.4g  max %.4g 1/um\n", h.min * 1e-6, h.mean() * 1e-6,
                h.max * 1e-6);
    std::printf(
        "  rounded tri. radius min %.4g  mean %.4g  max %.4g um; %lld of %zu clamped at H_min = %g 1/m\n",
        r.min * 1e6, r.mean() * 1e6, r.max * 1e6, clamped, tri_r.size(), h_min);
    std::printf(
        "  timing       mesh %.3g ms, upload %.3g ms, geometry kernels %.3g us per update (%.3g ns/node)\n",
        t_generate * 1e3, t_upload * 1e3, t_geometry * 1e6, t_geometry * 1e9 / nodes);
  }

  JsonObject summary;
  summary.add("scene", scene.name())
      .add("shape", shape)
      .add("nodes", nodes)
      .add("bonds", static_cast<long long>(topo.edges.size()))
      .add("triangles", static_cast<long long>(hm.triangles.size()))
      .add("refine_levels", scene.get_int("mesh.refine_levels"))
      .add("smallest_angle_deg", smallest_angle_deg(hm))
      .add("euler_characteristic", topo.euler_characteristic)
      .add("area_m2", area)
      .add("volume_m3", volume)
      .add("reduced_volume", reduced_volume)
      .add("node_mean_curvature_min_per_m", h.min)
      .add("node_mean_curvature_mean_per_m", h.mean())
      .add("node_mean_curvature_max_per_m", h.max)
      .add("rounded_triangle_radius_min_m", r.min)
      .add("rounded_triangle_radius_max_m", r.max)
      .add("clamped_triangles", clamped)
      .add("geometry_update_s", t_geometry)
      .add("backend", kokkos_description());
  summary.write(out + "/geometry.json");

  if (scene.get_bool("output.hdf5")) {
    std::vector<int> tri, node_cell(hm.nodes.size(), 0);
    for (const Tri& t : hm.triangles) tri.insert(tri.end(), t.begin(), t.end());
    H5Output h5(out + "/geometry.h5");
    h5.write_text("scene", scene.to_toml());
    h5.write_mesh(x.data(), static_cast<int>(nodes), tri.data(), static_cast<int>(hm.triangles.size()),
                  node_cell.data());
    h5.write_frame(0.0, x.data(),
                   {{"mean_curvature_per_m", 1, node_h.data()},
                    {"mixed_area_m2", 1, node_area.data()},
                    {"curvature_vector_per_m", 3, node_k.data()},
                    {"normal", 3, node_n.data()}});
    h5.close();
  }
  if (!options.quiet)
    std::printf(
        "  wrote        %s/geometry.json%s\n", out.c_str(),
        scene.get_bool("output.hdf5") ? (", " + out + "/geometry.h5, " + out + "/geometry.xmf").c_str() : "");
}

}  // namespace
}  // namespace dcm

int main(int argc, char** argv) {
  CLI::App app(
      "Builds the scene's cell mesh and reports its geometry: area, volume, curvature, rounded\n"
      "triangles. Writes <out>/geometry.json, and <out>/geometry.h5 with geometry.xmf (ParaView).",
      "geometry");
  dcm::AppOptions options;
  dcm::add_common_options(app, options,
                          {"scenes/evans_fung.toml", "--set mesh.nodes=10242 --out out/sphere10k"});
  return dcm::run_app(app, argc, argv, [&] { dcm::run(options); });
}
