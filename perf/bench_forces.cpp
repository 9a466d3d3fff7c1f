// Force kernels per call, for icosphere meshes of 642 .. 40962 nodes, on the default execution space
// (threads: OMP_NUM_THREADS or --kokkos-threads). Rest state: the sphere of radius R; positions: the
// sphere scaled by 1.02, so every bond is stretched and every term does its full work.
//   build/bin/bench_forces [--benchmark_filter=...]
// Reported: time per call and ns per node (counter "ns_per_node").
#include "core/kokkos_compat.hpp"
#include "kernels/bending.hpp"
#include "kernels/fene_pow_bonds.hpp"
#include "perf/bench_common.hpp"

namespace dcm {
namespace {

using bench::Exec;
using bench::Mem;

struct Fixture {
  MeshBuffers<Mem> mesh;
  BondRest<Mem> bonds;
  HingeRest<Mem> hinges;
  Kokkos::View<double* [3], Kokkos::LayoutRight, Mem> force;
  Kokkos::View<int, Mem> overstretched;
  explicit Fixture(int k)
      : mesh(upload_cells<Mem>({HostCell(make_icosphere(k, 3.25e-6))})),
        bonds(make_bond_rest(Exec(), mesh)),
        hinges(make_hinge_rest(Exec(), mesh)),
        force("dcm::bench::force", mesh.n_nodes),
        overstretched("dcm::bench::overstretched") {
    HostMesh stretched = make_icosphere(k, 1.02 * 3.25e-6);
    auto h = Kokkos::create_mirror_view(mesh.x);
    for (int i = 0; i < mesh.n_nodes; ++i)
      for (int c = 0; c < 3; ++c) h(i, c) = stretched.nodes[i][c];
    Kokkos::deep_copy(mesh.x, h);
    // Bending against a flatter rest shape, so that sin(theta - theta*) != 0 everywhere.
    set_hinge_rest_angles(hinges, {0.0});
    Kokkos::deep_copy(overstretched, -1);
    Exec().fence();
  }
};

template <class Kernel>
void run(benchmark::State& state, Kernel&& kernel) {
  bench::run_per_node<Fixture>(state, kernel);
}

void fene_pow(benchmark::State& s) {
  run(s, [](const Exec& e, Fixture& f) {
    add_fene_pow_forces(e, f.mesh, f.bonds, FenePowParams{}, f.force, f.overstretched);
  });
}
void bending(benchmark::State& s) {
  run(s, [](const Exec& e, Fixture& f) { add_bending_forces(e, f.mesh, f.hinges, 2.4e-19, f.force); });
}
void bending_per_node(benchmark::State& s) {
  run(s,
      [](const Exec& e, Fixture& f) { add_bending_forces_per_node(e, f.mesh, f.hinges, 2.4e-19, f.force); });
}

#define DCM_MESHES DenseRange(3, 6, 1)->Unit(benchmark::kMicrosecond)
BENCHMARK(fene_pow)->DCM_MESHES;
BENCHMARK(bending)->DCM_MESHES;
BENCHMARK(bending_per_node)->DCM_MESHES;

}  // namespace
}  // namespace dcm

DCM_BENCHMARK_MAIN()
