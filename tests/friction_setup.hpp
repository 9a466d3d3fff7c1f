#pragma once
#include <algorithm>
// Test fixture shared by tests/test_solver.cpp and tests/test_multigrid.cpp: the friction operator Γ with
// the paper's parameters on perturbed icospheres, random vectors, and Γ assembled on the host with Eigen.
#include <Eigen/Dense>
#include <random>
#include <vector>

#include "core/host_copy.hpp"
#include "solvers/friction_operator.hpp"

namespace dcm::test_friction {

using Exec = Kokkos::DefaultExecutionSpace;
using Mem = Exec::memory_space;
using Vector = FrictionOperator<Mem>::Vector;
constexpr double kPi = 3.14159265358979323846;

// Table 1: η = 0.8 mPa·s, r = 3.25 µm, c = 1.5e-6 N·s/m.
// Cells of subdivision ks (each refined in `band`, core/band_refinement.cpp), randomly perturbed by up to
// 0.05 µm, 20 µm apart along x; each node's drag is 6πηr / N_cell.
struct FrictionSetup {
  std::vector<HostCell> cells;
  MeshBuffers<Mem> mesh;
  FrictionOperator<Mem> op;
  explicit FrictionSetup(int k, double c = 1.5e-6, unsigned seed = 7)
      : FrictionSetup(std::vector<int>{k}, c, seed) {}
  explicit FrictionSetup(const std::vector<int>& ks, double c = 1.5e-6, unsigned seed = 7,
                         const BandRefinement& band = {}) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-0.05e-6, 0.05e-6);
    for (std::size_t n = 0; n < ks.size(); ++n) {
      HostMesh m = make_icosphere(ks[n], 3.25e-6, band);
      for (auto& x : m.nodes)
        for (double& v : x) v += u(rng);
      translate(m, {20e-6 * static_cast<double>(n), 0, 0});
      cells.emplace_back(std::move(m));
    }
    mesh = upload_cells<Mem>(cells);
    Kokkos::View<double*, Kokkos::LayoutRight, Mem> drag("drag", mesh.n_nodes);
    auto dh = Kokkos::create_mirror_view(drag);
    for (int cell = 0; cell < mesh.n_cells; ++cell) {
      const int b = mesh.host_cell_node_begin[cell], e = mesh.host_cell_node_begin[cell + 1];
      for (int i = b; i < e; ++i) dh(i) = 6 * kPi * 0.8e-3 * 3.25e-6 / (e - b);
    }
    Kokkos::deep_copy(drag, dh);
    op = FrictionOperator<Mem>(mesh, drag, c);
    update_friction(Exec(), mesh, op);
  }
  Vector random_vector(unsigned seed, double scale = 1.0) const {
    return random_vector_of(mesh.n_nodes, seed, scale);
  }
  static Vector random_vector_of(int n, unsigned seed, double scale = 1.0) {
    Vector v("v", n);
    auto h = Kokkos::create_mirror_view(v);
    std::mt19937 rng(seed);
    std::normal_distribution<double> g(0, scale);
    for (int i = 0; i < n; ++i)
      for (int d = 0; d < 3; ++d) h(i, d) = g(rng);
    Kokkos::deep_copy(v, h);
    return v;
  }
  Vector apply(const Vector& v) const {
    Vector out("out", mesh.n_nodes);
    apply_friction(Exec(), mesh, op, v, out);
    return out;
  }
  // Substrate friction on random β (Σ = 1) and contact areas (a third of the triangles), γ_n = 8e9,
  // γ_t = 6e9 N·s/m³, a tilted plane normal; then update_friction().
  void enable_random_substrate(unsigned seed, bool lumped = false) {
    const int n_tris = mesh.n_tris;
    Kokkos::View<double* [3], Kokkos::LayoutRight, Mem> beta("beta", n_tris);
    Kokkos::View<double*, Kokkos::LayoutRight, Mem> area("area", n_tris);
    auto bh = Kokkos::create_mirror_view(beta);
    auto ah = Kokkos::create_mirror_view(area);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    for (int t = 0; t < n_tris; ++t) {
      // One corner in five gets a negative β (a centre of pressure outside the triangle).
      const double b0 = u(rng) - (t % 5 == 0 ? 0.9 : 0.0), b1 = u(rng), b2 = u(rng) + 0.5, sum = b0 + b1 + b2;
      bh(t, 0) = b0 / sum;
      bh(t, 1) = b1 / sum;
      bh(t, 2) = b2 / sum;
      ah(t) = t % 3 == 0 ? 1e-13 * u(rng) : 0.0;
    }
    Kokkos::deep_copy(beta, bh);
    Kokkos::deep_copy(area, ah);
    enable_substrate_friction(op, beta, area, 8e9, 6e9, Real3{0.2, -0.1, 1.0}, lumped);
    update_friction(Exec(), mesh, op);
  }
  // Γ assembled on the host from its definition (independent of the kernels): drag on the diagonal,
  // c n̂n̂ᵀ blocks coupling the two nodes of every bond, and the substrate blocks β_ti β_tj Γ_t if enabled.
  Eigen::MatrixXd assemble() const {
    const int n = mesh.n_nodes;
    const auto x = to_host_vector(mesh.x);
    const auto bonds = to_host_vector(mesh.bond);
    const auto drag = to_host_vector(op.node_drag);
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(3 * n, 3 * n);
    for (int i = 0; i < n; ++i) a.block<3, 3>(3 * i, 3 * i) += drag[i] * Eigen::Matrix3d::Identity();
    for (std::size_t b = 0; b < bonds.size() / 2; ++b) {
      const int i = bonds[2 * b], j = bonds[2 * b + 1];
      const Eigen::Vector3d d = Eigen::Vector3d(x[3 * j], x[3 * j + 1], x[3 * j + 2]) -
                                Eigen::Vector3d(x[3 * i], x[3 * i + 1], x[3 * i + 2]);
      const Eigen::Matrix3d pp = d.normalized() * d.normalized().transpose();
      const Eigen::Matrix3d nn = op.dashpot * pp + op.dashpot_transverse * (Eigen::Matrix3d::Identity() - pp);
      a.block<3, 3>(3 * i, 3 * i) += nn;
      a.block<3, 3>(3 * j, 3 * j) += nn;
      a.block<3, 3>(3 * i, 3 * j) -= nn;
      a.block<3, 3>(3 * j, 3 * i) -= nn;
    }
    if (op.substrate) {
      const auto tri = to_host_vector(mesh.tri);
      const auto beta = to_host_vector(op.tri_beta), area = to_host_vector(op.tri_contact_area);
      const Eigen::Vector3d sn(op.substrate_normal.x, op.substrate_normal.y, op.substrate_normal.z);
      const Eigen::Matrix3d g =
          op.gamma_n * sn * sn.transpose() + op.gamma_t * (Eigen::Matrix3d::Identity() - sn * sn.transpose());
      for (std::size_t t = 0; t < area.size(); ++t) {
        double positive[3], sum = 0;
        for (int i = 0; i < 3; ++i) sum += positive[i] = std::max(beta[3 * t + i], 0.0);
        for (int i = 0; i < 3; ++i)
          if (op.substrate_lumped)  // w_i Γ_t, w_i = max(β_i, 0) / Σ max(β, 0)
            a.block<3, 3>(3 * tri[3 * t + i], 3 * tri[3 * t + i]) += positive[i] / sum * area[t] * g;
          else
            for (int j = 0; j < 3; ++j)
              a.block<3, 3>(3 * tri[3 * t + i], 3 * tri[3 * t + j]) +=
                  beta[3 * t + i] * beta[3 * t + j] * area[t] * g;
      }
    }
    return a;
  }
};

}  // namespace dcm::test_friction
