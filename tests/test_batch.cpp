// The batched engine (docs/SCANS.md, "The batched engine: design"): cells with different constants in one
// set of buffers compute, bit for bit, what each computes alone — per-cell CG, per-cell constants in every
// kernel, fixed-order per-cell sums.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include "core/host_copy.hpp"
#include "solvers/time_stepper.hpp"
#include "tests/model_params.hpp"

namespace dcm {
namespace {

using Exec = Kokkos::DefaultExecutionSpace;

// Table 1 on a plane the sphere of radius r just overlaps (contact radius a), with the spreading scene's
// solver options (multigrid, implicit bending and tension, lumped substrate friction). The friction weights
// are the load shares (contact.friction_weights = "lumped"), not the default area weights: their jumps
// provoke the halvings and rejections these tests need to exercise.
MechanicsParams spreading(double r, double a) {
  MechanicsParams p = test_params::spreading_on_plane(r, a);
  p.area_friction_weights = false;
  return p;
}

// Every constant a Figure 5 style scan sweeps, changed.
MechanicsParams other_constants(double r, double a) {
  MechanicsParams p = spreading(r, a);
  p.bonds = {4.0e-6, 2.5};
  p.k_b = 480e-21;
  p.k_area_local = 18e-3;
  p.k_area_global = 3e-3;
  p.k_volume = 3e3;
  p.dashpot = 0.8e-6;
  p.viscosity = 1.6e-3;
  p.contact.material = md_material(1600e3, 0.4, 2e-3, 30e-9);
  p.gamma_n = 16e9;
  p.gamma_t = 3e9;
  return p;
}

void perturb(CortexModel<Exec>& model, int first_node, int n, double amplitude, unsigned seed) {
  auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), model.positions());
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  for (int i = first_node; i < first_node + n; ++i)
    for (int d = 0; d < 3; ++d) x(i, d) += u(rng);
  Kokkos::deep_copy(model.positions(), x);
}

// Cell c's part of a [n][3] view, from node `first` on.
std::vector<double> part(const Kokkos::View<double* [3], Kokkos::LayoutRight, Exec::memory_space>& v,
                         int first, int n) {
  const auto all = to_host_vector(v);
  return std::vector<double>(all.begin() + 3 * first, all.begin() + 3 * (first + n));
}

// The cells of a batch share a mesh size: the multigrid's V-cycle has as many levels as the finest cell
// needs, so a coarser cell would get extra (identity-transfer) smoothing levels and a different
// preconditioner than alone (docs/SCANS.md).
TEST(Batch, PerCellCgSolvesEachCellAsAlone) {
  const double r = 3.25e-6, a = 0.3e-6;
  const HostMesh small = make_icosphere(3, r), large = make_icosphere(3, 1.1 * r);
  const int n0 = static_cast<int>(small.nodes.size()), n1 = static_cast<int>(large.nodes.size());
  const MechanicsParams p0 = spreading(r, a), p1 = other_constants(r, a);
  CortexModel<Exec> batch(Exec(), {HostCell(small), HostCell(large)}, std::vector<MechanicsParams>{p0, p1});
  CortexModel<Exec> alone0(Exec(), {HostCell(small)}, p0), alone1(Exec(), {HostCell(large)}, p1);
  perturb(batch, 0, n0, 0.03e-6, 1);
  perturb(batch, n0, n1, 0.05e-6, 2);
  perturb(alone0, 0, n0, 0.03e-6, 1);
  perturb(alone1, 0, n1, 0.05e-6, 2);
  CgSettings cg;  // the paper's absolute 1e-14 N
  for (CortexModel<Exec>* m : {&batch, &alone0, &alone1}) {
    m->compute_forces();
    ASSERT_TRUE(m->solve_velocity(cg, 6e-6).converged);
  }
  EXPECT_EQ(part(batch.velocity(), 0, n0), part(alone0.velocity(), 0, n0));
  EXPECT_EQ(part(batch.velocity(), n0, n1), part(alone1.velocity(), 0, n1));
  ASSERT_EQ(batch.cell_solves().size(), 2u);
  EXPECT_EQ(batch.cell_solves()[0].iterations, alone0.cell_solves()[0].iterations);
  EXPECT_EQ(batch.cell_solves()[1].iterations, alone1.cell_solves()[0].iterations);
  EXPECT_NE(batch.cell_solves()[0].iterations, batch.cell_solves()[1].iterations)
      << "the cells converge after different iteration counts (else the freeze is not exercised)";
  std::printf("  CG iterations: cell 0 %d, cell 1 %d\n", batch.cell_solves()[0].iterations,
              batch.cell_solves()[1].iterations);
}

// The multigrid's level 0 holds a cell's bending where that cell's own bending_ratio() asks for it
// (MultigridSettings::Bending::automatic): a cell whose long step puts its bending in solves, in a batch
// with a cell whose short step leaves it out, exactly as each does alone.
TEST(Batch, BendingInThePreconditionerIsChosenPerCell) {
  const double r = 3.25e-6, a = 0.3e-6;
  const HostMesh sphere = make_icosphere(3, r);
  const int n = static_cast<int>(sphere.nodes.size());
  const MechanicsParams p = spreading(r, a);
  const std::vector<double> dt = {6e-6, 2e-2};  // β ≈ 2e-4 and 0.6 on 642 nodes
  CortexModel<Exec> batch(Exec(), {HostCell(sphere), HostCell(sphere)}, std::vector<MechanicsParams>{p, p});
  CortexModel<Exec> alone0(Exec(), {HostCell(sphere)}, p), alone1(Exec(), {HostCell(sphere)}, p);
  perturb(batch, 0, n, 0.03e-6, 1);
  perturb(batch, n, n, 0.05e-6, 2);
  perturb(alone0, 0, n, 0.03e-6, 1);
  perturb(alone1, 0, n, 0.05e-6, 2);
  CgSettings cg;
  for (CortexModel<Exec>* m : {&batch, &alone0, &alone1}) m->compute_forces();
  ASSERT_TRUE(batch.solve_velocity(cg, dt, nullptr).converged);
  ASSERT_TRUE(alone0.solve_velocity(cg, dt[0]).converged);
  ASSERT_TRUE(alone1.solve_velocity(cg, dt[1]).converged);
  EXPECT_FALSE(alone0.last_bending_preconditioned());
  EXPECT_TRUE(alone1.last_bending_preconditioned());
  EXPECT_TRUE(batch.last_bending_preconditioned());
  EXPECT_EQ(part(batch.velocity(), 0, n), part(alone0.velocity(), 0, n));
  EXPECT_EQ(part(batch.velocity(), n, n), part(alone1.velocity(), 0, n));
  EXPECT_EQ(batch.cell_solves()[0].iterations, alone0.cell_solves()[0].iterations);
  EXPECT_EQ(batch.cell_solves()[1].iterations, alone1.cell_solves()[0].iterations);
  std::printf("  beta %.2g (alone, short step) and %.2g (batch): CG iterations %d and %d\n",
              alone0.last_bending_ratio(), batch.last_bending_ratio(), batch.cell_solves()[0].iterations,
              batch.cell_solves()[1].iterations);
}

TEST(Batch, CellsWithDifferentConstantsStepExactlyAsAlone) {
  const double r = 3.25e-6, a = 0.3e-6;
  const HostMesh sphere = make_icosphere(3, r);
  const int n = static_cast<int>(sphere.nodes.size());
  const MechanicsParams p0 = spreading(r, a), p1 = other_constants(r, a);
  CortexModel<Exec> batch(Exec(), {HostCell(sphere), HostCell(sphere)}, std::vector<MechanicsParams>{p0, p1});
  CortexModel<Exec> alone0(Exec(), {HostCell(sphere)}, p0), alone1(Exec(), {HostCell(sphere)}, p1);
  TimeStepSettings s;  // the paper's fixed step: cell 1 halves its first step (a bond near d_max), cell 0 not
  s.dt = 6e-6;
  TimeStepper<Exec> tb(batch, s), t0(alone0, s), t1(alone1, s);
  const CgSettings cg{};
  int halvings[2] = {0, 0};
  for (int k = 0; k < 40; ++k) {
    const std::vector<StepReport> rb =
        tb.step(batch, cg, std::vector<double>{INFINITY, INFINITY}, [](const std::vector<double>&) {});
    const StepReport r0 = t0.step(alone0, cg, INFINITY, [](double) {});
    const StepReport r1 = t1.step(alone1, cg, INFINITY, [](double) {});
    ASSERT_EQ(rb[0].h, r0.h) << "step " << k;
    ASSERT_EQ(rb[1].h, r1.h) << "step " << k;
    halvings[0] += r0.halvings;
    halvings[1] += r1.halvings;
  }
  EXPECT_EQ(halvings[0], 0);
  EXPECT_GT(halvings[1], 0) << "a halving of one cell only is exercised";
  const auto b0 = part(batch.positions(), 0, n), b1 = part(batch.positions(), n, n);
  EXPECT_EQ(b0, part(alone0.positions(), 0, n));
  EXPECT_EQ(b1, part(alone1.positions(), 0, n));
  // The two cells did move differently: the constants reached the kernels.
  double diff = 0;
  for (std::size_t i = 0; i < b0.size(); ++i) diff = std::fmax(diff, std::fabs(b0[i] - b1[i]));
  EXPECT_GT(diff, 1e-9) << "largest coordinate difference between the cells (m)";
  EXPECT_GT(alone0.contact_area(), 0.0);
  std::printf("  after 40 steps the cells differ by up to %.3g m\n", diff);
}

// Adaptive steps: each cell of the batch takes its own steps (lengths, rejections, halvings) and stops at
// its own end time, exactly as alone.
TEST(Batch, EachCellTakesItsOwnAdaptiveStepsAsAlone) {
  const double r = 3.25e-6, a = 0.3e-6;
  const HostMesh sphere = make_icosphere(3, r);
  const int n = static_cast<int>(sphere.nodes.size());
  const MechanicsParams p0 = spreading(r, a), p1 = other_constants(r, a);
  TimeStepSettings s;
  s.dt = 6e-6;
  s.adaptive = true;
  s.error_tol_m = 1e-9;
  const double t_end[2] = {4e-4, 2.5e-4};
  const CgSettings cg{};
  // Alone: the single-run stepper.
  std::vector<std::vector<double>> alone_h(2), alone_x(2);
  int alone_rejections[2] = {0, 0}, alone_halvings[2] = {0, 0};
  for (int c = 0; c < 2; ++c) {
    CortexModel<Exec> m(Exec(), {HostCell(sphere)}, c == 0 ? p0 : p1);
    TimeStepper<Exec> stepper(m, s);
    while (stepper.time() < t_end[c]) {
      const StepReport rep = stepper.step(m, cg, t_end[c] - stepper.time(), [](double) {});
      alone_h[c].push_back(rep.h);
      alone_rejections[c] += rep.rejections;
      alone_halvings[c] += rep.halvings;
    }
    alone_x[c] = to_host_vector(m.positions());
  }
  // Batched.
  CortexModel<Exec> batch(Exec(), {HostCell(sphere), HostCell(sphere)}, std::vector<MechanicsParams>{p0, p1});
  TimeStepper<Exec> stepper(batch, s);
  std::vector<std::vector<double>> batch_h(2);
  for (;;) {
    std::vector<double> cap(2);
    for (int c = 0; c < 2; ++c) cap[c] = stepper.time(c) < t_end[c] ? t_end[c] - stepper.time(c) : 0.0;
    if (cap[0] == 0 && cap[1] == 0) break;
    const std::vector<StepReport> rep = stepper.step(batch, cg, cap, [](const std::vector<double>&) {});
    for (int c = 0; c < 2; ++c)
      if (cap[c] > 0) batch_h[c].push_back(rep[c].h);
  }
  for (int c = 0; c < 2; ++c) {
    EXPECT_EQ(batch_h[c], alone_h[c]) << "cell " << c << ": the step lengths";
    EXPECT_EQ(stepper.time(c), t_end[c]);
    EXPECT_EQ(part(batch.positions(), c * n, n), alone_x[c]) << "cell " << c;
  }
  EXPECT_NE(alone_h[0].size(), alone_h[1].size()) << "the cells take different numbers of steps";
  EXPECT_GT(alone_rejections[0] + alone_rejections[1] + alone_halvings[0] + alone_halvings[1], 0)
      << "a rejection or halving is exercised";
  std::printf("  steps %zu / %zu, rejections %d / %d, halvings %d / %d\n", alone_h[0].size(),
              alone_h[1].size(), alone_rejections[0], alone_rejections[1], alone_halvings[0],
              alone_halvings[1]);
}

// The crease at the contact line (kernels/contact_crease.hpp) reads each cell's own W, h0 and fillet radius:
// two cells with different ones step in a batch exactly as alone (until session 35 every cell of a batch got
// cell 0's, and this comparison failed).
TEST(Batch, CreaseConstantsArePerCell) {
  const double r = 3.25e-6, a = 0.3e-6;
  const HostMesh sphere = make_icosphere(3, r);
  const int n = static_cast<int>(sphere.nodes.size());
  MechanicsParams p0 = spreading(r, a), p1 = other_constants(r, a);
  p0.crease_radius = 1.0e-8;
  p1.crease_radius = 2.5e-8;
  CortexModel<Exec> batch(Exec(), {HostCell(sphere), HostCell(sphere)}, std::vector<MechanicsParams>{p0, p1});
  CortexModel<Exec> alone0(Exec(), {HostCell(sphere)}, p0), alone1(Exec(), {HostCell(sphere)}, p1);
  TimeStepSettings s;
  s.dt = 6e-6;
  TimeStepper<Exec> tb(batch, s), t0(alone0, s), t1(alone1, s);
  const CgSettings cg{};
  for (int k = 0; k < 10; ++k) {
    tb.step(batch, cg, std::vector<double>{INFINITY, INFINITY}, [](const std::vector<double>&) {});
    t0.step(alone0, cg, INFINITY, [](double) {});
    t1.step(alone1, cg, INFINITY, [](double) {});
  }
  EXPECT_EQ(part(batch.positions(), 0, n), part(alone0.positions(), 0, n));
  EXPECT_EQ(part(batch.positions(), n, n), part(alone1.positions(), 0, n));
  // The crease acted: cell 1 alone with cell 0's crease radius ends elsewhere.
  MechanicsParams p1_other_rho = p1;
  p1_other_rho.crease_radius = p0.crease_radius;
  CortexModel<Exec> other(Exec(), {HostCell(sphere)}, p1_other_rho);
  TimeStepper<Exec> to(other, s);
  for (int k = 0; k < 10; ++k) to.step(other, cg, INFINITY, [](double) {});
  const auto x1 = part(alone1.positions(), 0, n), xo = part(other.positions(), 0, n);
  double diff = 0;
  for (std::size_t i = 0; i < x1.size(); ++i) diff = std::fmax(diff, std::fabs(x1[i] - xo[i]));
  EXPECT_GT(diff, 1e-13) << "largest coordinate difference made by the crease radius (m)";
  std::printf("  the crease radius moved cell 1 by up to %.3g m in 10 steps\n", diff);
}

TEST(Batch, CellsThatNeedDifferentKernelsCannotShareABatch) {
  const double r = 3.25e-6, a = 0.3e-6;
  const HostMesh sphere = make_icosphere(2, r);
  MechanicsParams p1 = spreading(r, a);
  p1.k_b = 0;  // no bending term in cell 1
  try {
    CortexModel<Exec> batch(Exec(), {HostCell(sphere), HostCell(sphere)},
                            std::vector<MechanicsParams>{spreading(r, a), p1});
    FAIL() << "accepted a batch whose cells need different terms";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("bending"), std::string::npos) << e.what();
  }
  MechanicsParams p2 = spreading(r, a);
  p2.contact.quadrature_points = 7;
  EXPECT_THROW(CortexModel<Exec>(Exec(), {HostCell(sphere), HostCell(sphere)},
                                 std::vector<MechanicsParams>{spreading(r, a), p2}),
               std::invalid_argument);
}

}  // namespace
}  // namespace dcm
