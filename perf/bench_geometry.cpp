// Geometry kernels per update, per kernel and in total, for icosphere meshes of 642 .. 40962 nodes,
// on the default execution space (threads: OMP_NUM_THREADS or --kokkos-threads).
//   build/bin/bench_geometry [--benchmark_filter=...]
// Reported: time per call and ns per node (counter "ns_per_node").
#include "core/kokkos_compat.hpp"
#include "core/update_geometry.hpp"
#include "perf/bench_common.hpp"

namespace dcm {
namespace {

using bench::Exec;
using bench::Mem;

struct Fixture {
  MeshBuffers<Mem> mesh;
  GeometryBuffers<Mem> geo;
  explicit Fixture(int k) : mesh(upload_cells<Mem>({HostCell(make_icosphere(k, 3.25e-6))})), geo(mesh) {
    update_geometry(Exec(), mesh, geo, 1e4);
    Exec().fence();
  }
};

template <class Kernel>
void run(benchmark::State& state, Kernel&& kernel) {
  bench::run_per_node<Fixture>(state, kernel);
}

void update_all(benchmark::State& s) {
  run(s, [](const Exec& e, Fixture& f) { update_geometry(e, f.mesh, f.geo, 1e4); });
}
void triangles(benchmark::State& s) {
  run(s, [](const Exec& e, Fixture& f) { compute_triangle_geometry(e, f.mesh, f.geo); });
}
void cell_measures(benchmark::State& s) {
  run(s, [](const Exec& e, Fixture& f) { compute_cell_measures(e, f.mesh, f.geo); });
}
void node_curvature(benchmark::State& s) {
  run(s, [](const Exec& e, Fixture& f) { compute_node_curvature(e, f.mesh, f.geo); });
}
void triangle_curvature(benchmark::State& s) {
  run(s, [](const Exec& e, Fixture& f) { compute_triangle_curvature(e, f.mesh, f.geo, 1e4); });
}
void rounded_triangles(benchmark::State& s) {
  run(s, [](const Exec& e, Fixture& f) { compute_rounded_triangles(e, f.mesh, f.geo); });
}

#define DCM_MESHES DenseRange(3, 6, 1)->Unit(benchmark::kMicrosecond)
BENCHMARK(update_all)->DCM_MESHES;
BENCHMARK(triangles)->DCM_MESHES;
BENCHMARK(cell_measures)->DCM_MESHES;
BENCHMARK(node_curvature)->DCM_MESHES;
BENCHMARK(triangle_curvature)->DCM_MESHES;
BENCHMARK(rounded_triangles)->DCM_MESHES;

}  // namespace
}  // namespace dcm

DCM_BENCHMARK_MAIN()
