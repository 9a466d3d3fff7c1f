#pragma once
// What every dcm benchmark shares: the timing loop reporting ns per node, and main().
#include <benchmark/benchmark.h>

#include "core/kokkos_compat.hpp"

namespace dcm::bench {

using Exec = Kokkos::DefaultExecutionSpace;
using Mem = Exec::memory_space;

// Builds Fixture(state.range(0)) (an icosphere level), times kernel(space, fixture) with a fence after each
// call, and reports the node count and ns per node.
template <class Fixture, class Kernel>
void run_per_node(benchmark::State& state, Kernel&& kernel) {
  Fixture f(static_cast<int>(state.range(0)));
  const Exec space;
  for (auto _ : state) {
    kernel(space, f);
    space.fence();
  }
  state.counters["nodes"] = f.mesh.n_nodes;
  state.counters["ns_per_node"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * f.mesh.n_nodes * 1e-9,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

inline int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  KokkosSession kokkos;
  benchmark::AddCustomContext("kokkos", kokkos_description());
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}

}  // namespace dcm::bench

#define DCM_BENCHMARK_MAIN() \
  int main(int argc, char** argv) { return dcm::bench::main(argc, argv); }
