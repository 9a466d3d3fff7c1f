// Area (eqs. 27, 28) and volume (eq. 29) constraints: forces are minus the gradient of the energies
// (central finite differences), vanish at the rest shape, have zero net force and torque, restore a
// scaled sphere radially, act on each cell alone, and agree between execution spaces.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>

#include "core/host_copy.hpp"
#include "core/update_geometry.hpp"
#include "kernels/area_constraints.hpp"
#include "kernels/volume_constraint.hpp"

namespace dcm {
namespace {

constexpr double kHMin = 1e4;  // 1/m; irrelevant here (update_geometry needs one)
constexpr double kRadius = 3.25e-6;

struct Constants {
  double k_a = 0, k_d = 0, k_v = 0;  // N/m, N/m, Pa
};
constexpr Constants kLocal{1.0, 0, 0}, kGlobal{0, 1.0, 0}, kVolume{0, 0, 1e4}, kAll{1.0, 0.5, 1e4};

// One set of buffers whose rest state is the geometry of the cells it was built from; positions can then
// be replaced and the constraint energy and forces evaluated.
template <class ExecutionSpace = Kokkos::DefaultExecutionSpace>
struct ConstraintSystem {
  using Mem = typename ExecutionSpace::memory_space;
  ExecutionSpace space;
  MeshBuffers<Mem> mesh;
  GeometryBuffers<Mem> geo;
  AreaRest<Mem> area_rest;
  VolumeRest<Mem> volume_rest;
  Kokkos::View<double* [3], Kokkos::LayoutRight, Mem> force;

  explicit ConstraintSystem(const std::vector<HostCell>& rest_cells)
      : mesh(upload_cells<Mem>(rest_cells)), geo(mesh), force("force", mesh.n_nodes) {
    update_geometry(space, mesh, geo, kHMin);
    area_rest = make_area_rest(space, mesh, geo);
    volume_rest = make_volume_rest(space, mesh, geo);
  }
  std::vector<double> positions() const { return to_host_vector(mesh.x); }
  void set_positions(const std::vector<double>& x) {
    auto h = Kokkos::create_mirror_view(mesh.x);
    for (int i = 0; i < mesh.n_nodes; ++i)
      for (int d = 0; d < 3; ++d) h(i, d) = x[3 * i + d];
    Kokkos::deep_copy(mesh.x, h);
    update_geometry(space, mesh, geo, kHMin);
  }
  double energy(const Constants& k) const {
    return area_energy(space, mesh, geo, area_rest, k.k_a, k.k_d) +
           volume_energy(space, mesh, geo, volume_rest, k.k_v);
  }
  std::vector<double> forces(const Constants& k) const {
    Kokkos::deep_copy(force, 0.0);
    add_area_forces(space, mesh, geo, area_rest, k.k_a, k.k_d, force);
    add_volume_forces(space, mesh, geo, volume_rest, k.k_v, force);
    space.fence();
    return to_host_vector(force);
  }
};

double mean_edge_length(const HostCell& cell) {
  double sum = 0;
  for (const auto& e : cell.topology.edges) {
    const Vec3 &a = cell.mesh.nodes[e[0]], &b = cell.mesh.nodes[e[1]];
    sum += std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                     (a[2] - b[2]) * (a[2] - b[2]));
  }
  return sum / static_cast<double>(cell.topology.edges.size());
}

// Every coordinate of nodes [begin, end) moved by a uniform random amount in [-amplitude, amplitude].
void perturb(std::vector<double>& x, int begin, int end, double amplitude, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  for (int i = 3 * begin; i < 3 * end; ++i) x[i] += u(rng);
}

double vec_norm(const double* v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }
double max_node_norm(const std::vector<double>& f) {
  double m = 0;
  for (std::size_t i = 0; i < f.size(); i += 3) m = std::max(m, vec_norm(&f[i]));
  return m;
}

// max_i |F_i + dE/dx_i| / max_i |F_i|, dE/dx_i by central differences with step h.
double gradient_error(ConstraintSystem<>& s, const Constants& k, double h) {
  const std::vector<double> x0 = s.positions();
  const std::vector<double> f = s.forces(k);
  std::vector<double> x = x0;
  double worst = 0;
  for (int i = 0; i < s.mesh.n_nodes; ++i) {
    double diff[3];
    for (int d = 0; d < 3; ++d) {
      x[3 * i + d] = x0[3 * i + d] + h;
      s.set_positions(x);
      const double ep = s.energy(k);
      x[3 * i + d] = x0[3 * i + d] - h;
      s.set_positions(x);
      const double em = s.energy(k);
      x[3 * i + d] = x0[3 * i + d];
      diff[d] = f[3 * i + d] + (ep - em) / (2 * h);
    }
    worst = std::max(worst, vec_norm(diff));
  }
  s.set_positions(x0);
  return worst / max_node_norm(f);
}

// |sum_i F_i| / sum_i |F_i| and |sum_i x_i x F_i| / sum_i |x_i| |F_i| over nodes [begin, end).
void net_force_and_torque(const std::vector<double>& x, const std::vector<double>& f, int begin, int end,
                          double& force_rel, double& torque_rel) {
  double net[3] = {0, 0, 0}, torque[3] = {0, 0, 0}, scale_f = 0, scale_t = 0;
  for (int i = begin; i < end; ++i) {
    const double* p = &x[3 * i];
    const double* q = &f[3 * i];
    for (int d = 0; d < 3; ++d) net[d] += q[d];
    torque[0] += p[1] * q[2] - p[2] * q[1];
    torque[1] += p[2] * q[0] - p[0] * q[2];
    torque[2] += p[0] * q[1] - p[1] * q[0];
    scale_f += vec_norm(q);
    scale_t += vec_norm(p) * vec_norm(q);
  }
  force_rel = vec_norm(net) / scale_f;
  torque_rel = vec_norm(torque) / scale_t;
}

struct Term {
  const char* name;
  Constants k;
};
const Term kTerms[] = {
    {"local area (k_a)", kLocal}, {"global area (k_d)", kGlobal}, {"volume (k_v)", kVolume}};

// A k = 2 icosphere, rest = unperturbed, every node moved by up to 5% of the mean edge length.
ConstraintSystem<> perturbed_sphere(double& edge) {
  const HostCell cell(make_icosphere(2, kRadius));
  edge = mean_edge_length(cell);
  ConstraintSystem<> s({cell});
  std::vector<double> x = s.positions();
  perturb(x, 0, s.mesh.n_nodes, 0.05 * edge, 12345u);
  s.set_positions(x);
  return s;
}

// Icosphere (cell 0) and an Evans-Fung cell translated by 20 um (cell 1), both k = 2, in one buffer set.
std::vector<HostCell> two_cells() {
  HostMesh rbc = make_evans_fung(2);
  translate(rbc, {20e-6, 0, 0});
  return {HostCell(make_icosphere(2, kRadius)), HostCell(rbc)};
}

TEST(Constraints, ForcesAreMinusEnergyGradientOnPerturbedSphere) {
  double edge = 0;
  ConstraintSystem<> s = perturbed_sphere(edge);
  std::printf("  perturbed icosphere k=2 (%d nodes), max |F + grad E| / max |F| at FD steps h:\n",
              s.mesh.n_nodes);
  std::printf("    term                h = 1e-3 edge   h = 1e-4 edge\n");
  for (const Term& term : kTerms) {
    EXPECT_GT(max_node_norm(s.forces(term.k)), 0) << term.name;
    const double coarse = gradient_error(s, term.k, 1e-3 * edge),
                 err = gradient_error(s, term.k, 1e-4 * edge);
    std::printf("    %-18s  %.2e        %.2e\n", term.name, coarse, err);
    EXPECT_LT(err, 1e-6) << term.name;
  }
}

TEST(Constraints, ForcesAreMinusEnergyGradientOnTwoCells) {
  const std::vector<HostCell> cells = two_cells();
  const double edge = std::min(mean_edge_length(cells[0]), mean_edge_length(cells[1]));
  ConstraintSystem<> s(cells);
  std::vector<double> x = s.positions();
  perturb(x, 0, s.mesh.n_nodes, 0.05 * edge, 777u);
  s.set_positions(x);
  std::printf("  icosphere + Evans-Fung, k=2 (%d nodes), FD step h = 1e-4 edge:\n", s.mesh.n_nodes);
  for (const Term& term : kTerms) {
    const double err = gradient_error(s, term.k, 1e-4 * edge);
    std::printf("    %-18s  max |F + grad E| / max |F| = %.2e\n", term.name, err);
    EXPECT_LT(err, 1e-6) << term.name;
  }
}

TEST(Constraints, ZeroAtRestShape) {
  ConstraintSystem<> s(two_cells());
  EXPECT_EQ(s.energy(kAll), 0.0);
  for (double f : s.forces(kAll)) EXPECT_EQ(f, 0.0);
}

TEST(Constraints, NetForceAndTorqueVanish) {
  const std::vector<HostCell> cells = two_cells();
  ConstraintSystem<> s(cells);
  std::vector<double> x = s.positions();
  perturb(x, 0, s.mesh.n_nodes, 0.05 * mean_edge_length(cells[0]), 99u);
  s.set_positions(x);
  for (const Term& term : kTerms) {
    const std::vector<double> f = s.forces(term.k);
    for (int c = 0; c < 2; ++c) {  // per cell: the terms are internal to each cell
      double fr = 0, tr = 0;
      net_force_and_torque(x, f, s.mesh.host_cell_node_begin[c], s.mesh.host_cell_node_begin[c + 1], fr, tr);
      EXPECT_LT(fr, 1e-13) << term.name << ", cell " << c;
      EXPECT_LT(tr, 1e-13) << term.name << ", cell " << c;
    }
  }
}

// Perfect icosphere scaled by s about its centre: V = s^3 V*, forces restoring and radial on nodes that
// lie on two or more mirror planes; equal on symmetry-equivalent nodes.
TEST(VolumeConstraint, UniformScalingGivesRadialRestoringForces) {
  const HostMesh rest = make_icosphere(2, kRadius);
  ConstraintSystem<> sys({HostCell(rest)});
  const std::vector<double> x0 = sys.positions();
  // Symmetry class of each node: its sorted dot products with the 12 icosahedron vertices (the nodes
  // without parents).
  std::vector<int> vertices;
  for (int i = 0; i < sys.mesh.n_nodes; ++i)
    if (rest.parents[i][0] < 0) vertices.push_back(i);
  ASSERT_EQ(vertices.size(), 12u);
  std::map<std::vector<long long>, std::vector<int>> classes;
  for (int i = 0; i < sys.mesh.n_nodes; ++i) {
    std::vector<long long> key;
    for (int v : vertices) {
      const double d =
          (x0[3 * i] * x0[3 * v] + x0[3 * i + 1] * x0[3 * v + 1] + x0[3 * i + 2] * x0[3 * v + 2]) /
          (kRadius * kRadius);
      key.push_back(std::llround(d * 1e9));
    }
    std::sort(key.begin(), key.end());
    classes[key].push_back(i);
  }
  ASSERT_EQ(classes.size(), 4u);  // k = 2: 12 vertices, 30 edge midpoints, 60 on edges, 60 inside faces
  for (double scale : {1.02, 0.98}) {
    std::vector<double> x = x0;
    for (double& c : x) c *= scale;
    sys.set_positions(x);
    const double v = to_host_vector(sys.geo.cell_volume)[0],
                 v_rest = to_host_vector(sys.volume_rest.cell_volume)[0];
    EXPECT_NEAR(v / v_rest, scale * scale * scale, 1e-13);
    const std::vector<double> f = sys.forces(kVolume);
    // Euler: V is homogeneous of degree 3, so sum_i x_i . dV/dx_i = 3 V.
    double virial = 0;
    for (int i = 0; i < sys.mesh.n_nodes; ++i)
      for (int d = 0; d < 3; ++d) virial += x[3 * i + d] * f[3 * i + d];
    const double expected = -3 * kVolume.k_v * (v - v_rest) / v_rest * v;
    EXPECT_NEAR(virial, expected, 1e-12 * std::fabs(expected)) << "s = " << scale;
    double worst_tangential_60 = 0;
    for (const auto& entry : classes) {
      const std::vector<int>& nodes = entry.second;
      const double magnitude = vec_norm(&f[3 * nodes[0]]);
      for (int i : nodes) {
        const double* fi = &f[3 * i];
        const double radial =
            (fi[0] * x[3 * i] + fi[1] * x[3 * i + 1] + fi[2] * x[3 * i + 2]) / (scale * kRadius);
        EXPECT_LT(radial * (scale - 1), 0) << "node " << i << " s = " << scale;  // restoring
        EXPECT_NEAR(vec_norm(fi), magnitude, 1e-12 * magnitude) << "node " << i;
        double t[3];
        for (int d = 0; d < 3; ++d) t[d] = fi[d] - radial * x[3 * i + d] / (scale * kRadius);
        const double tangential = vec_norm(t);
        if (nodes.size() <= 30)  // on >= 2 mirror planes: exactly radial
          EXPECT_LT(tangential, 1e-12 * magnitude) << "node " << i;
        else
          worst_tangential_60 = std::max(worst_tangential_60, tangential / magnitude);
      }
    }
    std::printf("  s = %.2f: |F| per class equal; tangential/|F| on one-mirror nodes up to %.2e\n", scale,
                worst_tangential_60);
  }
}

// Perturbing cell 1 only leaves cell 0 force-free (its own area and volume are at rest), and cell 1 gets
// the forces it would get alone.
TEST(Constraints, EachCellFeelsOnlyItsOwnAreaAndVolume) {
  const std::vector<HostCell> cells = two_cells();
  ConstraintSystem<> both(cells);
  ConstraintSystem<> alone({cells[1]});
  const int n0 = both.mesh.host_cell_node_begin[1];
  std::vector<double> x = both.positions(), x1 = alone.positions();
  // Cell 1 inflated by 1% about its centre and perturbed: its area and volume are away from rest.
  auto deform = [&](std::vector<double>& y, int begin, int end) {
    for (int i = 3 * begin; i < 3 * end; i += 3) {
      y[i] = 20e-6 + 1.01 * (y[i] - 20e-6);
      y[i + 1] *= 1.01;
      y[i + 2] *= 1.01;
    }
    perturb(y, begin, end, 0.05 * mean_edge_length(cells[1]), 4242u);
  };
  deform(x, n0, both.mesh.n_nodes);
  deform(x1, 0, alone.mesh.n_nodes);
  both.set_positions(x);
  alone.set_positions(x1);
  const std::vector<double> f = both.forces(kAll), f1 = alone.forces(kAll);
  for (int i = 0; i < 3 * n0; ++i) EXPECT_EQ(f[i], 0.0) << "cell 0, entry " << i;
  const double scale = max_node_norm(f1);
  EXPECT_GT(scale, 0);
  for (std::size_t i = 0; i < f1.size(); ++i) EXPECT_NEAR(f[3 * n0 + i], f1[i], 1e-12 * scale) << i;
  EXPECT_NEAR(both.energy(kAll), alone.energy(kAll), 1e-12 * alone.energy(kAll));
}

TEST(Constraints, DegenerateRestShapeIsRejected) {
  HostMesh m = make_icosphere(1, kRadius);
  const Tri& t = m.triangles[0];
  m.nodes[t[1]] = m.nodes[t[0]];  // two corners of a triangle at one point: triangles collapse
  using Mem = Kokkos::DefaultExecutionSpace::memory_space;
  const Kokkos::DefaultExecutionSpace space;
  const MeshBuffers<Mem> mesh = upload_cells<Mem>({HostCell(m)});
  const GeometryBuffers<Mem> geo(mesh);
  update_geometry(space, mesh, geo, kHMin);
  EXPECT_THROW(make_area_rest(space, mesh, geo), std::invalid_argument);
  EXPECT_NO_THROW(make_volume_rest(space, mesh, geo));
}

// The same forces and energies from Serial and OpenMP (gathers: identical arithmetic per node; only the
// cell-area/volume reductions may round differently).
#if defined(KOKKOS_ENABLE_SERIAL) && defined(KOKKOS_ENABLE_OPENMP)
template <class ExecutionSpace>
std::vector<double> forces_on(const std::vector<HostCell>& cells, const std::vector<double>& x,
                              double& energy) {
  ConstraintSystem<ExecutionSpace> s(cells);
  s.set_positions(x);
  energy = s.energy(kAll);
  return s.forces(kAll);
}

TEST(Backends, ConstraintsSerialAndOpenMPAgree) {
  HostMesh rbc = make_evans_fung(4);
  translate(rbc, {20e-6, 0, 0});
  const std::vector<HostCell> cells{HostCell(make_icosphere(4, kRadius)), HostCell(rbc)};
  std::vector<double> x = ConstraintSystem<Kokkos::Serial>(cells).positions();
  perturb(x, 0, static_cast<int>(x.size() / 3), 0.05 * mean_edge_length(cells[1]), 31u);
  double es = 0, eo = 0;
  const std::vector<double> fs = forces_on<Kokkos::Serial>(cells, x, es);
  const std::vector<double> fo = forces_on<Kokkos::OpenMP>(cells, x, eo);
  ASSERT_EQ(fs.size(), fo.size());
  const double scale = max_node_norm(fs);
  for (std::size_t i = 0; i < fs.size(); ++i) EXPECT_LE(std::fabs(fs[i] - fo[i]), 1e-12 * scale) << i;
  EXPECT_NEAR(es, eo, 1e-12 * es);
}
#endif

}  // namespace
}  // namespace dcm
