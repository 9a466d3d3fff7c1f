// Area (local + global) and volume constraint forces per call, for icosphere meshes of 642 .. 40962 nodes,
// on the default execution space (threads: OMP_NUM_THREADS or --kokkos-threads). The geometry is
// updated once before timing (the forces read it); the rest state is the unperturbed sphere and the
// nodes are then moved, so every coefficient is non-zero.
//   build/bin/bench_constraints [--benchmark_filter=...]
// Reported: time per call and ns per node (counter "ns_per_node").
#include <random>

#include "core/kokkos_compat.hpp"
#include "core/update_geometry.hpp"
#include "kernels/area_constraints.hpp"
#include "kernels/volume_constraint.hpp"
#include "perf/bench_common.hpp"

namespace dcm {
namespace {

using bench::Exec;
using bench::Mem;

struct Fixture {
  MeshBuffers<Mem> mesh;
  GeometryBuffers<Mem> geo;
  AreaRest<Mem> area_rest;
  VolumeRest<Mem> volume_rest;
  Kokkos::View<double* [3], Kokkos::LayoutRight, Mem> force;
  explicit Fixture(int k)
      : mesh(upload_cells<Mem>({HostCell(make_icosphere(k, 3.25e-6))})),
        geo(mesh),
        force("force", mesh.n_nodes) {
    const Exec space;
    update_geometry(space, mesh, geo, 1e4);
    area_rest = make_area_rest(space, mesh, geo);
    volume_rest = make_volume_rest(space, mesh, geo);
    auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.x);
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(0.99, 1.02);
    for (int i = 0; i < mesh.n_nodes; ++i)
      for (int d = 0; d < 3; ++d) h(i, d) *= u(rng);
    Kokkos::deep_copy(mesh.x, h);
    update_geometry(space, mesh, geo, 1e4);
    space.fence();
  }
};

template <class Kernel>
void run(benchmark::State& state, Kernel&& kernel) {
  bench::run_per_node<Fixture>(state, kernel);
}

void area_forces(benchmark::State& s) {
  run(s,
      [](const Exec& e, Fixture& f) { add_area_forces(e, f.mesh, f.geo, f.area_rest, 1.0, 1.0, f.force); });
}
void area_forces_local(benchmark::State& s) {
  run(s,
      [](const Exec& e, Fixture& f) { add_area_forces(e, f.mesh, f.geo, f.area_rest, 1.0, 0.0, f.force); });
}
void area_forces_global(benchmark::State& s) {
  run(s,
      [](const Exec& e, Fixture& f) { add_area_forces(e, f.mesh, f.geo, f.area_rest, 0.0, 1.0, f.force); });
}
void volume_forces(benchmark::State& s) {
  run(s, [](const Exec& e, Fixture& f) { add_volume_forces(e, f.mesh, f.geo, f.volume_rest, 1e4, f.force); });
}

#define DCM_MESHES DenseRange(3, 6, 1)->Unit(benchmark::kMicrosecond)
BENCHMARK(area_forces)->DCM_MESHES;
BENCHMARK(area_forces_local)->DCM_MESHES;
BENCHMARK(area_forces_global)->DCM_MESHES;
BENCHMARK(volume_forces)->DCM_MESHES;

}  // namespace
}  // namespace dcm

DCM_BENCHMARK_MAIN()
