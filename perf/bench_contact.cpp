// The plane-contact kernel (kernels/plane_contact.hpp) per call, for a rigid icosphere of radius 3.25 µm
// pressed into the plane to a contact radius a = R/2 with Table 1's contact law (E = 800 kPa, ν = 0.4,
// W = 1 mJ/m², h0 = 20 nm), for the exact polar integration (rule 0) and the paper's 1-, 3-, 7-, 16-point
// rules (the broad phase, the candidates' list, the Maugis–Dugdale states and the narrow phase); and the
// node gather.
//   build/bin/bench_contact [--benchmark_filter=...]
// Reported: time per call, "contact_triangles" (triangles with a non-zero load) and
// "ns_per_contact_triangle" (the call's time over them; the other triangles cost a broad-phase test only).
#include <cmath>

#include "core/host_copy.hpp"
#include "core/update_geometry.hpp"
#include "kernels/plane_contact.hpp"
#include "perf/bench_common.hpp"

namespace dcm {
namespace {

using bench::Exec;
using bench::Mem;

struct Fixture {
  MeshBuffers<Mem> mesh;
  GeometryBuffers<Mem> geo;
  ContactBuffers<Mem> contact;
  Kokkos::View<double* [3], Kokkos::LayoutRight, Mem> force;
  PlaneContactParams params;
  int in_contact = 0;
  Fixture(int k, int rule)
      : mesh(pressed_sphere(k)), geo(mesh), contact(mesh.n_tris), force("force", mesh.n_nodes) {
    params.material = md_material(800e3, 0.4, 1e-3, 20e-9);
    params.quadrature_points = rule;
    update_geometry(Exec(), mesh, geo, 1e4);
    compute_plane_contact(Exec(), mesh, geo, Plane{}, params, contact);
    const auto load = to_host_vector(contact.tri_load);
    for (double f : load) in_contact += f != 0;
  }
  static MeshBuffers<Mem> pressed_sphere(int k) {
    const double r = 3.25e-6, a = 0.5 * r;
    HostMesh m = make_icosphere(k, r);
    for (auto& x : m.nodes) x[2] += r - (r - std::sqrt(r * r - a * a));
    return upload_cells<Mem>({HostCell(m)});
  }
};

void contact(benchmark::State& state) {
  Fixture f(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const Exec space;
  for (auto _ : state) {
    compute_plane_contact(space, f.mesh, f.geo, Plane{}, f.params, f.contact);
    space.fence();
  }
  state.counters["nodes"] = f.mesh.n_nodes;
  state.counters["contact_triangles"] = f.in_contact;
  state.counters["ns_per_contact_triangle"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * f.in_contact * 1e-9,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void gather(benchmark::State& state) {
  Fixture f(static_cast<int>(state.range(0)), 0);
  const Exec space;
  for (auto _ : state) {
    add_plane_contact_forces(space, f.mesh, Plane{}, f.contact, f.force);
    space.fence();
  }
  state.counters["nodes"] = f.mesh.n_nodes;
  state.counters["ns_per_node"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * f.mesh.n_nodes * 1e-9,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

BENCHMARK(contact)->ArgsProduct({{3, 4, 5}, {0, 1, 3, 7, 16}})->Unit(benchmark::kMicrosecond);
BENCHMARK(gather)->DenseRange(3, 5, 1)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace dcm

DCM_BENCHMARK_MAIN()
