// The fused membrane pass (kernels/membrane_forces.hpp) against the per-term kernels it replaces: the same
// forces, the same hinge scratch (gradient, -M, cos(theta - theta*)) that the implicit bending stiffness
// reads, the same overstretch flag, on two cells with different constants; and the model's choice.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "core/host_copy.hpp"
#include "core/update_geometry.hpp"
#include "kernels/membrane_forces.hpp"

namespace dcm {
namespace {

using Exec = Kokkos::DefaultExecutionSpace;
using Mem = Exec::memory_space;
using Vector = Kokkos::View<double* [3], Kokkos::LayoutRight, Mem>;

// Two cells of 162 nodes (the second 10 µm away), rest state the spheres, then every coordinate scaled by
// a random factor in [0.97, 1.03]; hinge rest angles 0 (so every hinge bends) in the first half of the hinges
// (cell 0 here), the sphere's in the rest. Constants per cell, deliberately different. Also built on other
// cells (uneven_cells()).
struct TwoCells {
  Exec space;
  MeshBuffers<Mem> mesh;
  GeometryBuffers<Mem> geo;
  BondRest<Mem> bonds;
  HingeRest<Mem> hinges;
  AreaRest<Mem> area;
  VolumeRest<Mem> volume;
  PerCell<FenePowParams, Mem> bond_params{{FenePowParams{3.2e-6, 2.05}, FenePowParams{6.4e-6, 2.6}}};
  PerCell<double, Mem> k_b{{2.4e-19, 7e-19}}, k_a{{6e-3, 0.0}}, k_d{{6e-3, 2e-2}}, k_v{{1e4, 3e3}};
  MembraneScratch<Mem> scratch;
  Kokkos::View<int, Mem> overstretched{"overstretched"};

  static std::vector<HostCell> cells() {
    HostMesh a = make_icosphere(2, 3.25e-6), b = make_icosphere(2, 2.5e-6);
    translate(b, {10e-6, 0, 0});
    return {HostCell(a), HostCell(b)};
  }
  // Three cells of 30, 480 and 120 edges: the second and third start inside a batch of 8 lanes (batches with
  // two cells in them) and the edge count, 630, leaves a last batch that overlaps the one before it. Their
  // constants: set three rows after construction.
  static std::vector<HostCell> uneven_cells() {
    HostMesh a = make_icosphere(0, 1.5e-6), b = make_icosphere(2, 3.25e-6), c = make_icosphere(1, 2e-6);
    translate(b, {10e-6, 0, 0});
    translate(c, {20e-6, 0, 0});
    return {HostCell(a), HostCell(b), HostCell(c)};
  }
  explicit TwoCells(const std::vector<HostCell>& list = cells())
      : mesh(upload_cells<Mem>(list)), geo(mesh), scratch(mesh) {
    update_geometry(space, mesh, geo, 1e4);
    bonds = make_bond_rest(space, mesh);
    hinges = make_hinge_rest(space, mesh);
    area = make_area_rest(space, mesh, geo);
    volume = make_volume_rest(space, mesh, geo);
    auto trig = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), hinges.rest_trig);
    const int cell0_hinges = static_cast<int>(trig.extent(0)) / 2;
    for (int h = 0; h < cell0_hinges; ++h) {
      trig(h, 0) = 1;
      trig(h, 1) = 0;
    }
    Kokkos::deep_copy(hinges.rest_trig, trig);
    auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh.x);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.97, 1.03);
    for (int i = 0; i < mesh.n_nodes; ++i)
      for (int d = 0; d < 3; ++d) x(i, d) *= u(rng);
    Kokkos::deep_copy(mesh.x, x);
    update_geometry(space, mesh, geo, 1e4);
  }
  // Forces and overstretch flag of the per-term kernels (fused = false) or the fused pass with the given form
  // of its edge pass.
  std::vector<double> forces(bool fused, int* flag = nullptr,
                             MembraneEdgeKernel kernel = MembraneEdgeKernel::fastest) {
    Vector f("f", mesh.n_nodes);
    Kokkos::deep_copy(overstretched, -1);
    // The hinge scratch is written by either path: start from NaN, so that what a pass leaves out shows.
    Kokkos::deep_copy(hinges.hinge_grad, std::nan(""));
    Kokkos::deep_copy(hinges.hinge_moment, std::nan(""));
    Kokkos::deep_copy(hinges.hinge_cos_delta, std::nan(""));
    if (fused) {
      add_membrane_forces(space, mesh, geo, bonds, bond_params.table(), hinges, k_b.table(), area,
                          k_a.table(), k_d.table(), volume, k_v.table(), scratch, f, overstretched, kernel);
    } else {
      add_fene_pow_forces(space, mesh, bonds, bond_params.table(), f, overstretched);
      add_bending_forces(space, mesh, hinges, k_b.table(), f);
      add_area_forces(space, mesh, geo, area, k_a.table(), k_d.table(), f);
      add_volume_forces(space, mesh, geo, volume, k_v.table(), f);
    }
    if (flag) Kokkos::deep_copy(*flag, overstretched);
    return to_host_vector(f);
  }
  std::vector<double> hinge_scratch() const {
    const auto g = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), hinges.hinge_grad);
    std::vector<double> s(g.data(), g.data() + g.size()), m = to_host_vector(hinges.hinge_moment),
                                                          c = to_host_vector(hinges.hinge_cos_delta);
    s.insert(s.end(), m.begin(), m.end());
    s.insert(s.end(), c.begin(), c.end());
    return s;
  }
};

double max_abs(const std::vector<double>& v) {
  double m = 0;
  for (double a : v) m = std::max(m, std::abs(a));
  return m;
}
// Infinite where either side is not finite (a slot or scratch entry a pass left out stays NaN).
double max_diff(const std::vector<double>& a, const std::vector<double>& b) {
  double m = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    const double d = std::abs(a[k] - b[k]);
    if (!std::isfinite(d)) return HUGE_VAL;
    m = std::max(m, d);
  }
  return m;
}

// Three rows of constants, one per cell of TwoCells::uneven_cells(), deliberately different.
void set_uneven_constants(TwoCells& s) {
  s.bond_params = PerCell<FenePowParams, Mem>({{3.2e-6, 2.05}, {6.4e-6, 2.6}, {4e-6, 2.2}});
  s.k_b = PerCell<double, Mem>({2.4e-19, 7e-19, 1e-19});
  s.k_a = PerCell<double, Mem>({6e-3, 0.0, 3e-3});
  s.k_d = PerCell<double, Mem>({6e-3, 2e-2, 1e-2});
  s.k_v = PerCell<double, Mem>({1e4, 3e3, 5e3});
}

#if defined(DCM_MEMBRANE_EDGE_SIMD)
// The vector pass's lengths and reciprocals (with AVX-512: estimates refined by Newton steps) against the
// scalar square roots and division, over the squares' whole range in SI units (edges of 1 nm to 100 µm) and
// gaps down to 1e-12 of d_max²: within 1e-15 relative (a few ulp; 6.8e-16 measured; after one Newton step
// instead of two the estimates would be good to ~2^-28 = 4e-9 only).
TEST(MembraneForces, VectorRootsMatchTheScalarOnes) {
  using membrane_detail::vd8;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> decade(-18.0, -8.0), unit(0.0, 1.0);
  double worst = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    vd8 e2, n1, n2, gap;
    for (int l = 0; l < 8; ++l) {
      e2[l] = std::pow(10.0, decade(rng));
      n1[l] = std::pow(10.0, 2 * decade(rng)) * (0.5 + unit(rng));
      n2[l] = std::pow(10.0, 2 * decade(rng)) * (0.5 + unit(rng));
      gap[l] = e2[l] * std::pow(10.0, -12 * unit(rng));
    }
    vd8 v[7];
    membrane_detail::VectorRoots{}(e2, n1, n2, gap, v[0], v[1], v[2], v[3], v[4], v[5], v[6]);
    for (int l = 0; l < 8; ++l) {
      double s[7];
      membrane_detail::ScalarRoots{}(e2[l], n1[l], n2[l], gap[l], s[0], s[1], s[2], s[3], s[4], s[5], s[6]);
      for (int k = 0; k < 7; ++k) worst = std::max(worst, std::abs(v[k][l] - s[k]) / s[k]);
    }
  }
  EXPECT_LT(worst, 1e-15);
#if defined(__AVX512F__)
  EXPECT_GT(worst, 0.0);  // the forms differ in the last bits (a guard against comparing one with itself)
#else
  EXPECT_EQ(worst, 0.0);  // without AVX-512 the vector form is the scalar one's square roots and division
#endif
}
#endif

// The build's form of the edge pass: GCC and Clang host builds compile the vector pass (a broken guard in
// kernels/membrane_edge_simd.hpp would silently fall back to the portable one: slower, and no test would
// fail); -DDCM_NO_MEMBRANE_SIMD, nvcc and hipcc the portable one.
TEST(MembraneForces, TheBuildHasTheExpectedFormOfTheEdgePass) {
#if defined(__GNUC__) && !defined(__CUDACC__) && !defined(__HIPCC__) && !defined(SYCL_LANGUAGE_VERSION) && \
    !defined(DCM_NO_MEMBRANE_SIMD)
  constexpr bool expect_vector_pass = true;
#else
  constexpr bool expect_vector_pass = false;
#endif
#if defined(DCM_MEMBRANE_EDGE_SIMD)
  constexpr bool has_vector_pass = true;
#else
  constexpr bool has_vector_pass = false;
#endif
  EXPECT_EQ(has_vector_pass, expect_vector_pass);
  constexpr bool host_memory = Kokkos::SpaceAccessibility<Kokkos::HostSpace, Mem>::accessible;
  EXPECT_EQ(MembraneScratch<Mem>::kHostSimd, has_vector_pass && host_memory);
}

TEST(MembraneForces, BondsAndHingesAreNumberedAlike) {
  TwoCells s;
  EXPECT_TRUE(bonds_match_hinges(s.mesh));
}

// The three forms of the edge pass: the build's fastest (the vector pass on GCC / Clang host builds), the
// portable lanes, one edge per work item.
const MembraneEdgeKernel kEdgeKernels[] = {MembraneEdgeKernel::fastest, MembraneEdgeKernel::lanes,
                                           MembraneEdgeKernel::one_edge};

TEST(MembraneForces, FusedPassEqualsThePerTermKernels) {
  TwoCells s;
  const std::vector<double> per_term = s.forces(false), scratch_per_term = s.hinge_scratch();
  ASSERT_GT(max_abs(per_term), 0);
  for (const MembraneEdgeKernel kernel : kEdgeKernels) {
    const std::vector<double> fused = s.forces(true, nullptr, kernel), scratch_fused = s.hinge_scratch();
    EXPECT_LE(max_diff(per_term, fused), 1e-11 * max_abs(per_term)) << "edge kernel " << int(kernel);
    EXPECT_LE(max_diff(scratch_per_term, scratch_fused), 1e-11 * max_abs(scratch_per_term))
        << "edge kernel " << int(kernel);
  }
  // Each term alone also matches (a term dropped or doubled by the fused pass would show here, even where
  // another term dominates the sum): switch all but one off by zeroing its constants.
  const PerCell<double, Mem> zero{{0.0, 0.0}};
  for (int term = 0; term < 4; ++term) {
    TwoCells t;
    if (term != 1) t.k_b = zero;
    if (term != 2) t.k_a = zero, t.k_d = zero;
    if (term != 3) t.k_v = zero;
    if (term != 0)
      t.bond_params = PerCell<FenePowParams, Mem>({FenePowParams{0.0, 2.05}, FenePowParams{0.0, 2.6}});
    const std::vector<double> a = t.forces(false);
    ASSERT_GT(max_abs(a), 0) << "term " << term;
    for (const MembraneEdgeKernel kernel : kEdgeKernels)
      EXPECT_LE(max_diff(a, t.forces(true, nullptr, kernel)), 1e-11 * max_abs(a))
          << "term " << term << ", edge kernel " << int(kernel);
  }
}

TEST(MembraneForces, BatchesAcrossCellsAndAnUnevenLastBatchEqualThePerTermKernels) {
  TwoCells s(TwoCells::uneven_cells());
  ASSERT_EQ(s.mesh.n_hinges, 630);  // not a multiple of 8: the last batch overlaps
  set_uneven_constants(s);
  const std::vector<double> per_term = s.forces(false), scratch_per_term = s.hinge_scratch();
  ASSERT_GT(max_abs(per_term), 0);
  for (const MembraneEdgeKernel kernel : kEdgeKernels) {
    const std::vector<double> fused = s.forces(true, nullptr, kernel), scratch_fused = s.hinge_scratch();
    EXPECT_LE(max_diff(per_term, fused), 1e-11 * max_abs(per_term)) << "edge kernel " << int(kernel);
    EXPECT_LE(max_diff(scratch_per_term, scratch_fused), 1e-11 * max_abs(scratch_per_term))
        << "edge kernel " << int(kernel);
    // Every cell's own forces, so that a small cell's error does not hide under a large cell's forces.
    const std::vector<int> begin = s.mesh.host_cell_node_begin;
    for (int c = 0; c < 3; ++c) {
      const auto from = per_term.begin() + 3 * begin[c], to = per_term.begin() + 3 * begin[c + 1];
      const std::vector<double> a(from, to),
          b(fused.begin() + 3 * begin[c], fused.begin() + 3 * begin[c + 1]);
      EXPECT_LE(max_diff(a, b), 1e-11 * max_abs(a)) << "cell " << c << ", edge kernel " << int(kernel);
    }
  }
}

TEST(MembraneForces, OverstretchedBondInTheOverlappingLastBatchIsFlagged) {
  TwoCells s(TwoCells::uneven_cells());
  set_uneven_constants(s);
  // Edges 624..629 are the last batch's own lanes (base 622, lanes 2..7). Give edge 627 alone a rest length
  // a tenth of its length: only it passes d_max, and both passes must name it.
  auto rest = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), s.bonds.rest_length);
  rest(627) *= 0.1;
  Kokkos::deep_copy(s.bonds.rest_length, rest);
  int flag_terms = -2;
  s.forces(false, &flag_terms);
  EXPECT_EQ(flag_terms, 627);
  for (const MembraneEdgeKernel kernel : kEdgeKernels) {
    int flag_fused = -2;
    const std::vector<double> fused = s.forces(true, &flag_fused, kernel);
    EXPECT_EQ(flag_fused, 627) << "edge kernel " << int(kernel);
    for (double f : fused) EXPECT_TRUE(std::isfinite(f));
  }
}

TEST(MembraneForces, OverstretchedBondIsFlaggedLikeThePerTermKernel) {
  TwoCells s;
  int flag_fused = -2, flag_terms = -2;
  s.forces(true, &flag_fused);
  EXPECT_EQ(flag_fused, -1);
  // Pull node 5 of cell 1 outwards by 3 µm: its bonds pass d_max (x_max d* ≈ 1.3 µm here).
  auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), s.mesh.x);
  const int node = 162 + 5;
  x(node, 2) += 3e-6;
  Kokkos::deep_copy(s.mesh.x, x);
  update_geometry(s.space, s.mesh, s.geo, 1e4);
  s.forces(false, &flag_terms);
  ASSERT_GE(flag_terms, 0);
  const auto bond = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), s.mesh.bond);
  EXPECT_TRUE(bond(flag_terms, 0) == node || bond(flag_terms, 1) == node) << "bond " << flag_terms;
  for (const MembraneEdgeKernel kernel : kEdgeKernels) {
    const std::vector<double> fused = s.forces(true, &flag_fused, kernel);
    ASSERT_GE(flag_fused, 0) << "edge kernel " << int(kernel);
    EXPECT_TRUE(bond(flag_fused, 0) == node || bond(flag_fused, 1) == node) << "bond " << flag_fused;
    for (double f : fused) EXPECT_TRUE(std::isfinite(f));  // the bad bonds add nothing, and no NaN
  }
}

}  // namespace
}  // namespace dcm
