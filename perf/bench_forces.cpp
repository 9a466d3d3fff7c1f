// Force kernels per call, for icosphere meshes of 642 .. 40962 nodes, on the default execution space
// (threads: OMP_NUM_THREADS or --kokkos-threads). Rest state: the sphere of radius R; positions: the
// sphere with every coordinate scaled by a random factor in [0.99, 1.02], so every term does its full work.
// membrane_terms is the four membrane terms one kernel each (bonds, bending, area, volume), membrane_fused
// (and membrane_fused_portable, with the portable form of its edge pass) the same forces by
// kernels/membrane_forces.hpp (the geometry they read is updated once, untimed).
//   build/bin/bench_forces [--benchmark_filter=...]
// Reported: time per call and ns per node (counter "ns_per_node").
#include <random>

#include "core/kokkos_compat.hpp"
#include "core/update_geometry.hpp"
#include "kernels/membrane_forces.hpp"
#include "perf/bench_common.hpp"

namespace dcm {
namespace {

using bench::Exec;
using bench::Mem;

struct Fixture {
  MeshBuffers<Mem> mesh;
  BondRest<Mem> bonds;
  HingeRest<Mem> hinges;
  GeometryBuffers<Mem> geo;
  AreaRest<Mem> area_rest;
  VolumeRest<Mem> volume_rest;
  MembraneScratch<Mem> scratch;
  Kokkos::View<double* [3], Kokkos::LayoutRight, Mem> force;
  Kokkos::View<int, Mem> overstretched;
  explicit Fixture(int k)
      : mesh(upload_cells<Mem>({HostCell(make_icosphere(k, 3.25e-6))})),
        bonds(make_bond_rest(Exec(), mesh)),
        hinges(make_hinge_rest(Exec(), mesh)),
        geo(mesh),
        scratch(mesh),
        force("dcm::bench::force", mesh.n_nodes),
        overstretched("dcm::bench::overstretched") {
    update_geometry(Exec(), mesh, geo, 1e4);
    area_rest = make_area_rest(Exec(), mesh, geo);
    volume_rest = make_volume_rest(Exec(), mesh, geo);
    auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.x);
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(0.99, 1.02);
    for (int i = 0; i < mesh.n_nodes; ++i)
      for (int c = 0; c < 3; ++c) h(i, c) *= u(rng);
    Kokkos::deep_copy(mesh.x, h);
    update_geometry(Exec(), mesh, geo, 1e4);
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

// Table 1's constants (k_a, k_d as docs/MODEL.md maps them; their size does not change the cost).
void membrane_terms(benchmark::State& s) {
  run(s, [](const Exec& e, Fixture& f) {
    add_fene_pow_forces(e, f.mesh, f.bonds, FenePowParams{}, f.force, f.overstretched);
    add_bending_forces(e, f.mesh, f.hinges, 2.4e-19, f.force);
    add_area_forces(e, f.mesh, f.geo, f.area_rest, 6e-3, 6e-3, f.force);
    add_volume_forces(e, f.mesh, f.geo, f.volume_rest, 1e4, f.force);
  });
}
void membrane_fused(benchmark::State& s) {
  run(s, [](const Exec& e, Fixture& f) {
    add_membrane_forces(e, f.mesh, f.geo, f.bonds, FenePowParams{}, f.hinges, 2.4e-19, f.area_rest, 6e-3,
                        6e-3, f.volume_rest, 1e4, f.scratch, f.force, f.overstretched);
  });
}

// The same with the portable form of the edge pass (EdgePass<8>: what nvcc's host passes and compilers other
// than GCC and Clang run; membrane_fused is the explicit-vector pass there, kernels/membrane_edge_simd.hpp).
void membrane_fused_portable(benchmark::State& s) {
  run(s, [](const Exec& e, Fixture& f) {
    add_membrane_forces(e, f.mesh, f.geo, f.bonds, FenePowParams{}, f.hinges, 2.4e-19, f.area_rest, 6e-3,
                        6e-3, f.volume_rest, 1e4, f.scratch, f.force, f.overstretched,
                        MembraneEdgeKernel::lanes);
  });
}

#define DCM_MESHES DenseRange(3, 6, 1)->Unit(benchmark::kMicrosecond)
BENCHMARK(fene_pow)->DCM_MESHES;
BENCHMARK(bending)->DCM_MESHES;
BENCHMARK(bending_per_node)->DCM_MESHES;
BENCHMARK(membrane_terms)->DCM_MESHES;
BENCHMARK(membrane_fused)->DCM_MESHES;
BENCHMARK(membrane_fused_portable)->DCM_MESHES;

}  // namespace
}  // namespace dcm

DCM_BENCHMARK_MAIN()
