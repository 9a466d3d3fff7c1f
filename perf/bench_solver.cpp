// Solving Γ v = F (η = 0.8 mPa·s, r = 3.25 µm, bond dashpots c_b = 1.5e-6 N·s/m: Table 1's c per bond, the
// reading of sessions 1-28; the apps' default since session 29 is c_b = 4c/√3, docs/MODEL.md "Table 1's c")
// on a randomly perturbed icosphere of 642, 2562 or 10242 nodes, random pN-scale right-hand side, cold start,
// to 1e-8 relative, with each preconditioner; and the per-step set-up of each.
//   build/bin/bench_solver [--benchmark_filter=...]
// Counters: iterations (PCG), nodes. Time per solve is the benchmark's own time.
#include <random>

#include "core/kokkos_compat.hpp"
#include "perf/bench_common.hpp"
#include "solvers/multigrid.hpp"
#include "solvers/pcg.hpp"
#include "solvers/rigid_modes.hpp"

namespace dcm {
namespace {

using bench::Exec;
using bench::Mem;
using Vector = FrictionOperator<Mem>::Vector;

struct Fixture {
  std::vector<HostCell> cells;
  MeshBuffers<Mem> mesh;
  FrictionOperator<Mem> op;
  Multigrid<Mem> mg;
  RigidModes<Mem> rigid;
  DeflationWorkspace<Mem> deflation;
  Vector f, v;
  CgWorkspace<Mem> w;
  explicit Fixture(int k) {
    HostMesh m = make_icosphere(k, 3.25e-6);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-0.05e-6, 0.05e-6);
    for (auto& x : m.nodes)
      for (double& c : x) c += u(rng);
    cells.emplace_back(std::move(m));
    mesh = upload_cells<Mem>(cells);
    Kokkos::View<double*, Kokkos::LayoutRight, Mem> drag("drag", mesh.n_nodes);
    Kokkos::deep_copy(drag, 6 * 3.14159265358979323846 * 0.8e-3 * 3.25e-6 / mesh.n_nodes);
    op = FrictionOperator<Mem>(mesh, drag, 1.5e-6);
    mg = make_multigrid(cells, mesh);
    rigid = RigidModes<Mem>(mesh.n_cells);
    deflation = DeflationWorkspace<Mem>(mesh.n_nodes);
    w = CgWorkspace<Mem>(mesh.n_nodes);
    f = Vector("f", mesh.n_nodes);
    v = Vector("v", mesh.n_nodes);
    auto h = Kokkos::create_mirror_view(f);
    std::normal_distribution<double> g(0, 1e-12);
    for (int i = 0; i < mesh.n_nodes; ++i)
      for (int d = 0; d < 3; ++d) h(i, d) = g(rng);
    Kokkos::deep_copy(f, h);
    const Exec space;
    update_friction(space, mesh, op);
    update_multigrid(space, mesh, op, mg);
    update_rigid_modes(space, mesh, op, rigid);
    space.fence();
  }
};

enum Kind { kBlockJacobi, kRigid, kRigidDeflated, kMultigrid, kMultigridDeflated };

void solve(benchmark::State& state, Kind kind) {
  Fixture fx(static_cast<int>(state.range(0)));
  const Exec space;
  CgSettings settings;
  settings.abs_tol = 0;
  settings.rel_tol = 1e-8;
  settings.max_iterations = 100000;
  auto apply = [&](const Vector& in, const Vector& out) { apply_friction(space, fx.mesh, fx.op, in, out); };
  auto bj = [&](const Vector& in, const Vector& out) { apply_block_jacobi(space, fx.op, in, out); };
  auto mg = [&](const Vector& in, const Vector& out) { apply_multigrid(space, fx.mg, in, out); };
  auto precondition = [&](const Vector& in, const Vector& out) {
    switch (kind) {
      case kBlockJacobi:
        bj(in, out);
        break;
      case kRigid:
        apply_rigid_two_level(space, fx.mesh, fx.op, fx.rigid, in, out);
        break;
      case kRigidDeflated:
        apply_rigid_deflated(space, fx.mesh, fx.op, fx.rigid, bj, fx.deflation, in, out);
        break;
      case kMultigrid:
        mg(in, out);
        break;
      case kMultigridDeflated:
        apply_rigid_deflated(space, fx.mesh, fx.op, fx.rigid, mg, fx.deflation, in, out);
        break;
    }
  };
  CgResult r;
  for (auto _ : state) {
    Kokkos::deep_copy(space, fx.v, 0.0);
    r = pcg_solve(space, apply, precondition, fx.f, fx.v, fx.w, settings);
    space.fence();
  }
  state.counters["nodes"] = fx.mesh.n_nodes;
  state.counters["iterations"] = r.iterations;
  state.counters["converged"] = r.converged ? 1 : 0;
}

void setup(benchmark::State& state, Kind kind) {
  Fixture fx(static_cast<int>(state.range(0)));
  const Exec space;
  for (auto _ : state) {
    update_friction(space, fx.mesh, fx.op);  // block-Jacobi's set-up; the others add to it
    if (kind == kRigid) update_rigid_modes(space, fx.mesh, fx.op, fx.rigid);
    if (kind == kMultigrid) update_multigrid(space, fx.mesh, fx.op, fx.mg);
    space.fence();
  }
  state.counters["nodes"] = fx.mesh.n_nodes;
}

void solve_block_jacobi(benchmark::State& s) { solve(s, kBlockJacobi); }
void solve_rigid_two_level(benchmark::State& s) { solve(s, kRigid); }
void solve_rigid_deflated(benchmark::State& s) { solve(s, kRigidDeflated); }
void solve_multigrid(benchmark::State& s) { solve(s, kMultigrid); }
void solve_multigrid_rigid_deflated(benchmark::State& s) { solve(s, kMultigridDeflated); }
void setup_block_jacobi(benchmark::State& s) { setup(s, kBlockJacobi); }
void setup_rigid_two_level(benchmark::State& s) { setup(s, kRigid); }
void setup_multigrid(benchmark::State& s) { setup(s, kMultigrid); }

#define DCM_MESHES DenseRange(3, 5, 1)->Unit(benchmark::kMillisecond)
BENCHMARK(solve_block_jacobi)->DCM_MESHES->Iterations(1);
BENCHMARK(solve_rigid_two_level)->DCM_MESHES->Iterations(1);
BENCHMARK(solve_rigid_deflated)->DCM_MESHES->Iterations(1);
BENCHMARK(solve_multigrid)->DCM_MESHES;
BENCHMARK(solve_multigrid_rigid_deflated)->DCM_MESHES;
BENCHMARK(setup_block_jacobi)->DCM_MESHES;
BENCHMARK(setup_rigid_two_level)->DCM_MESHES;
BENCHMARK(setup_multigrid)->DCM_MESHES;

}  // namespace
}  // namespace dcm

DCM_BENCHMARK_MAIN()
