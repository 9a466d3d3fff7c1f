#pragma once
// Geometric multigrid V-cycle preconditioner for Γ (solvers/friction_operator.hpp) on the icosphere
// subdivision hierarchy (solvers/multigrid_setup.hpp).
//   make_multigrid(cells, mesh)          once per mesh: P, R = Pᵀ, patterns, Galerkin recipes
//   update_multigrid(space, mesh, op, mg) once per step, after update_friction(): A_0 = Γ assembled into
//                                         3×3 blocks from the cached n̂_b (+ an approximation of the
//                                         implicit bending, mg_detail::update_bending_axes), A_{l+1} = Pᵀ A_l
//                                         P, block inverses, the coarsest level (12 nodes per cell) inverted
//                                         densely; in two parts, update_multigrid_operator() (A_0, the
//                                         CG's operator too) and update_multigrid_hierarchy() (the rest)
//   apply_multigrid(space, mg, r, z)     z = M⁻¹ r, one V-cycle; the PCG precondition(r, z) callable
// Smoother: ν sweeps of damped block-Jacobi x ← x + ω D⁻¹ (b − A x) before and the same ν after the
// coarse correction. D is symmetric, so the post-smoother is the adjoint of the pre-smoother and the
// V-cycle is a symmetric operator; it is positive definite when every smoother is an A-norm contraction
// (ω λ_max(D⁻¹A) < 2; on level 0 A ≤ 3 D since each dashpot [M −M; −M M] ≤ 2 diag(M, M) and each substrate
// block ββᵀ ⊗ Γ_t ≤ 3 diag(β²) ⊗ Γ_t; ω = 0.6) and the
// coarsest solve is exact. Expectations (tests/test_multigrid.cpp): R = Pᵀ, uᵀM⁻¹w = wᵀM⁻¹u, uᵀM⁻¹u > 0,
// PCG agrees with an Eigen solve, iteration counts nearly independent of the mesh size.
// Without a hierarchy (a mesh not from make_icosphere/make_evans_fung) `available` is false, `note`
// says why, and apply_multigrid is plain block-Jacobi.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/buffers.hpp"
#include "core/errors.hpp"
#include "core/host_copy.hpp"
#include "core/small_launch.hpp"
#include "kernels/bending.hpp"
#include "solvers/bending_stiffness.hpp"
#include "solvers/block_sparse.hpp"
#include "solvers/friction_operator.hpp"
#include "solvers/multigrid_setup.hpp"
#include "solvers/tension_stiffness.hpp"

namespace dcm {

struct MultigridSettings {
  int sweeps = 2;        // ν pre- and ν post-smoothing sweeps
  double damping = 0.6;  // ω
  // The implicit bending stiffness (solvers/bending_stiffness.hpp) in the preconditioner: level 0 then holds
  // a positive semi-definite approximation of it on the bond pattern (docs/model/solver.md, "Bending in the
  // preconditioner"); the operator the CG applies stays exact. `off`: never (make_multigrid() builds no
  // recipe for it); `on`: every step; `automatic`: in the steps where a cell's bending is strong against its
  // dashpots, bending_ratio() >= kAutoRatio (solvers/cortex_model.hpp decides, step by step and cell by
  // cell, from each cell's Δt). Where the dashpots dominate it costs its assembly and saves no iterations.
  enum class Bending { automatic, on, off };
  Bending bending = Bending::automatic;
  static constexpr double kAutoRatio = 0.15;
  // Levels 1.. with at most this many rows (all cells together) run on one host thread (Kokkos::Serial)
  // when the solve runs on OpenMP: on the small levels a parallel launch costs more than the work it shares
  // (docs/model/solver.md, "Small levels on one thread"). 0: every level on the solve's space. Other
  // backends (CUDA) always keep every level on their space. The results are the same to the bit.
  int serial_rows = 1024;
};

// How strongly the implicit bending stiffens the soft (normal) modes of a cell against its dashpots, the
// measure MultigridSettings::Bending::automatic decides by (docs/model/solver.md): a normal displacement at
// the mesh scale h meets the bending's Δt k_b / h² and the dashpots' c (h/R)² + c_t (the axial dashpot c
// through the facet angle, a transverse one c_t directly), so
//   β = Δt k_b / (h² (c h²/R² + c_t)),
// with h the cell's mean rest bond length and R the radius of the sphere of its rest area. On the paper's
// parameters and Δt = 6 µs β ≈ 0.003 / 0.04 / 0.7 on 2562 / 10242 / 40962 nodes.
KOKKOS_INLINE_FUNCTION double bending_ratio(double dt_k_b, double h, double radius, double c, double c_t) {
  const double dashpots = c * h * h / (radius * radius) + c_t;
  return dashpots > 0 ? dt_k_b / (h * h * dashpots) : (dt_k_b > 0 ? 1e300 : 0.0);
}

template <class MemorySpace>
struct MultigridLevel {
  template <class T>
  using View = Kokkos::View<T, Kokkos::LayoutRight, MemorySpace>;
  BlockCsr<MemorySpace> a;
  // To the next coarser level (empty on the coarsest): fine i ← ½(x_c[prolong(i,0)] + x_c[prolong(i,1)]).
  View<int* [2]> prolong;
  View<int*> restrict_offsets, restrict_fine;
  View<double*> restrict_weight;
  // How this level's blocks are made from the finer level's (empty on level 0).
  View<int*> galerkin_offsets, galerkin_source;
  View<double*> galerkin_weight;
  View<double*[3]> b, x, r;  // right-hand side and iterate (levels ≥ 1), residual
  View<double* [3]> t;       // the smoother's second iterate
};

template <class MemorySpace>
struct Multigrid {
  template <class T>
  using View = Kokkos::View<T, Kokkos::LayoutRight, MemorySpace>;
  static constexpr int kCoarseNodes = 12;  // per cell: the icosahedron
  static constexpr int kCoarseDofs = 3 * kCoarseNodes;
  bool available = false;
  std::string note;
  MultigridSettings settings;
  int n_cells = 0;
  View<int*> fine_slot_bond;  // level 0: the bond of each off-diagonal slot, −1 on the diagonal
  // Level 0: per slot (i, j) the triangle corners (t, c_i, c_j) with tri(t, c_i) = i, tri(t, c_j) = j, packed
  // as 16 t + 4 c_i + c_j, in the order of i's triangle corners (the implicit tension blocks; topology only).
  View<int*> fine_slot_tension_offsets, fine_slot_tension;
  // Bending in the preconditioner (settings.bending not off, a mesh with hinges): per
  // slot (i, j) the hinge roles (h, a, b) with hinge(h, a) = i, hinge(h, b) = j, packed as 16 h + 4 a + b, in
  // hinge order; the wings' cross pair (2, 3) is left out and each wing's diagonal entry listed twice (the
  // approximation stays positive semi-definite). bending_axis: per hinge N̂ and √s α_a (a = 0..3) of the step.
  View<int*> fine_slot_bending_offsets, fine_slot_bending;
  View<double* [7]> bending_axis;
  // Per cell, the Δt k_b level 0 holds (0: that cell's level 0 is its operator's blocks, to the bit), and its
  // staging copy; update_multigrid_operator() fills them.
  View<double*> bending_dt_k_b;
  typename View<double*>::host_mirror_type bending_dt_k_b_host;
  // Level 0's blocks without the bending (the CG's operator) while level 0 holds it; else empty.
  View<double* [6]> operator_values;
  bool bending_in_level0 = false;  // of the last update_multigrid_operator()
  std::vector<MultigridLevel<MemorySpace>> levels;
  View<double***> coarse_inverse;  // per cell, the inverse of the coarsest operator (36 × 36)
  typename View<double***>::host_mirror_type coarse_inverse_host;
  // The operator's level-0 blocks (Γ, implicit bonds and tension; without the bending the preconditioner
  // may hold): what the CG applies.
  BlockCsr<MemorySpace> fine_operator() const {
    BlockCsr<MemorySpace> a = levels[0].a;
    if (bending_in_level0) a.values = operator_values;
    return a;
  }
};

namespace mg_detail {

template <class V>
V upload_vector(const std::string& label, const std::vector<typename V::non_const_value_type>& v) {
  V out(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::mg::" + label), v.size());
  auto h = Kokkos::create_mirror_view(out);
  for (std::size_t i = 0; i < v.size(); ++i) h(i) = v[i];
  Kokkos::deep_copy(out, h);
  return out;
}

template <class MemorySpace>
BlockCsr<MemorySpace> allocate_blocks(const HostSparsePattern& p) {
  using B = BlockCsr<MemorySpace>;
  B a;
  a.n_rows = p.rows();
  a.nnz = static_cast<int>(p.cols.size());
  a.row_offsets = upload_vector<typename B::template View<int*>>("row_offsets", p.offsets);
  a.cols = upload_vector<typename B::template View<int*>>("cols", p.cols);
  std::vector<int> diag(a.n_rows);
  for (int i = 0; i < a.n_rows; ++i) diag[i] = p.slot(i, i);
  a.diag_slot = upload_vector<typename B::template View<int*>>("diag_slot", diag);
  a.values = typename B::template View<double* [6]>(
      Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::mg::values"), a.nnz);
  a.diag_inverse = typename B::template View<double* [6]>(
      Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::mg::diag_inverse"), a.n_rows);
  return a;
}

// In-place inverse of a dense SPD matrix (n × n, row-major) by Cholesky; false if not positive definite.
inline bool invert_spd(std::vector<double>& a, int n) {
  std::vector<double> l(n * n, 0.0);
  for (int j = 0; j < n; ++j) {
    double d = a[j * n + j];
    for (int k = 0; k < j; ++k) d -= l[j * n + k] * l[j * n + k];
    if (!(d > 0)) return false;
    l[j * n + j] = std::sqrt(d);
    for (int i = j + 1; i < n; ++i) {
      double s = a[i * n + j];
      for (int k = 0; k < j; ++k) s -= l[i * n + k] * l[j * n + k];
      l[i * n + j] = s / l[j * n + j];
    }
  }
  // Columns of A⁻¹: solve L Lᵀ x = e_c.
  std::vector<double> y(n);
  for (int c = 0; c < n; ++c) {
    for (int i = 0; i < n; ++i) {
      double s = i == c ? 1.0 : 0.0;
      for (int k = 0; k < i; ++k) s -= l[i * n + k] * y[k];
      y[i] = s / l[i * n + i];
    }
    for (int i = n - 1; i >= 0; --i) {
      double s = y[i];
      for (int k = i + 1; k < n; ++k) s -= l[k * n + i] * y[k];
      y[i] = s / l[i * n + i];
    }
    for (int i = 0; i < n; ++i) a[i * n + c] = y[i];
  }
  return true;
}

}  // namespace mg_detail

// Symbolic set-up, once per mesh. `cells` are the HostCells given to upload_cells(), in the same order.
template <class MemorySpace>
Multigrid<MemorySpace> make_multigrid(const std::vector<HostCell>& cells,
                                      const MeshBuffers<MemorySpace>& mesh,
                                      const MultigridSettings& settings = {}) {
  using M = Multigrid<MemorySpace>;
  using IV = typename M::template View<int*>;
  using DV = typename M::template View<double*>;
  const HostHierarchy h = make_hierarchy(cells, mesh.n_nodes, to_host_vector(mesh.bond));
  M mg;
  mg.available = h.available;
  mg.note = h.note;
  mg.settings = settings;
  mg.n_cells = h.n_cells;
  mg.fine_slot_bond = mg_detail::upload_vector<IV>("fine_slot_bond", h.fine_slot_bond);
  const int n_levels = h.available ? static_cast<int>(h.transfers.size()) + 1 : 1;
  mg.levels.resize(n_levels);
  std::vector<int> row_cell = to_host_vector(mesh.node_cell);  // of the level being built
  for (int l = 0; l < n_levels; ++l) {
    MultigridLevel<MemorySpace>& lv = mg.levels[l];
    lv.a = mg_detail::allocate_blocks<MemorySpace>(l == 0 ? h.fine : h.transfers[l - 1].coarse);
    const int n = lv.a.n_rows;
    lv.a.row_cell = mg_detail::upload_vector<IV>("row_cell", row_cell);
    lv.r = typename MultigridLevel<MemorySpace>::template View<double* [3]>("dcm::mg::r", n);
    lv.t = typename MultigridLevel<MemorySpace>::template View<double* [3]>("dcm::mg::t", n);
    if (l > 0) {
      lv.b = typename MultigridLevel<MemorySpace>::template View<double* [3]>("dcm::mg::b", n);
      lv.x = typename MultigridLevel<MemorySpace>::template View<double* [3]>("dcm::mg::x", n);
      const HostTransfer& t = h.transfers[l - 1];
      lv.galerkin_offsets = mg_detail::upload_vector<IV>("galerkin_offsets", t.galerkin_offsets);
      lv.galerkin_source = mg_detail::upload_vector<IV>("galerkin_source", t.galerkin_source);
      lv.galerkin_weight = mg_detail::upload_vector<DV>("galerkin_weight", t.galerkin_weight);
    }
    if (l + 1 < n_levels) {
      const HostTransfer& t = h.transfers[l];
      lv.prolong = typename MultigridLevel<MemorySpace>::template View<int* [2]>(
          Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::mg::prolong"), n);
      auto ph = Kokkos::create_mirror_view(lv.prolong);
      for (int i = 0; i < n; ++i) {
        ph(i, 0) = t.prolong[i][0];
        ph(i, 1) = t.prolong[i][1];
      }
      Kokkos::deep_copy(lv.prolong, ph);
      lv.restrict_offsets = mg_detail::upload_vector<IV>("restrict_offsets", t.restrict_offsets);
      lv.restrict_fine = mg_detail::upload_vector<IV>("restrict_fine", t.restrict_fine);
      lv.restrict_weight = mg_detail::upload_vector<DV>("restrict_weight", t.restrict_weight);
      std::vector<int> coarse_cell(h.transfers[l].coarse.rows(), 0);  // a coarse node's fine children's cell
      for (int i = 0; i < n; ++i) coarse_cell[t.prolong[i][0]] = coarse_cell[t.prolong[i][1]] = row_cell[i];
      row_cell = coarse_cell;
    }
  }
  {  // the triangle corners of each fine slot, for the implicit tension blocks
    const auto tri = to_host_vector(mesh.tri);
    const auto tri_off = to_host_vector(mesh.node_tri_offsets),
               corners = to_host_vector(mesh.node_tri_corners);
    const std::vector<int>& row_off = h.fine.offsets;
    const std::vector<int>& cols = h.fine.cols;
    std::vector<int> offsets(1, 0), entries;
    for (int i = 0; i + 1 < static_cast<int>(row_off.size()); ++i)
      for (int sl = row_off[i]; sl < row_off[i + 1]; ++sl) {
        for (int q = tri_off[i]; q < tri_off[i + 1]; ++q) {
          const int t = corners[q] / 3, ci = corners[q] % 3;
          for (int cj = 0; cj < 3; ++cj)
            if (tri[3 * t + cj] == cols[sl]) entries.push_back(16 * t + 4 * ci + cj);  // split by shifts
        }
        offsets.push_back(static_cast<int>(entries.size()));
      }
    mg.fine_slot_tension_offsets = mg_detail::upload_vector<IV>("fine_slot_tension_offsets", offsets);
    mg.fine_slot_tension = mg_detail::upload_vector<IV>("fine_slot_tension", entries);
  }
  if (settings.bending != MultigridSettings::Bending::off &&
      mesh.n_hinges > 0) {  // the bending blocks of each slot
    const auto hinge = to_host_vector(mesh.hinge);
    std::vector<std::vector<int>> per_slot(h.fine.cols.size());
    for (int e = 0; e < mesh.n_hinges; ++e)
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) {
          if ((a == 2 && b == 3) || (a == 3 && b == 2)) continue;  // the wings are not bond neighbours
          const int i = hinge[4 * e + a], j = hinge[4 * e + b];
          const int sl = h.fine.slot(i, j);
          if (sl >= h.fine.offsets[i + 1] || h.fine.cols[sl] != j)
            throw std::logic_error("multigrid: a hinge couples nodes that are not bond neighbours");
          per_slot[sl].push_back(16 * e + 4 * a + b);
          if (a == b && a >= 2) per_slot[sl].push_back(16 * e + 4 * a + b);
        }
    std::vector<int> offsets(1, 0), entries;
    for (const auto& v : per_slot) {
      entries.insert(entries.end(), v.begin(), v.end());
      offsets.push_back(static_cast<int>(entries.size()));
    }
    mg.fine_slot_bending_offsets = mg_detail::upload_vector<IV>("fine_slot_bending_offsets", offsets);
    mg.fine_slot_bending = mg_detail::upload_vector<IV>("fine_slot_bending", entries);
    mg.bending_axis = typename M::template View<double* [7]>("dcm::mg::bending_axis", mesh.n_hinges);
    mg.bending_dt_k_b = DV("dcm::mg::bending_dt_k_b", mesh.n_cells);
    mg.bending_dt_k_b_host = Kokkos::create_mirror_view(mg.bending_dt_k_b);
    mg.operator_values = typename M::template View<double* [6]>(
        Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::mg::operator_values"), mg.levels[0].a.nnz);
  }
  if (h.available) {
    mg.coarse_inverse = typename M::template View<double***>("dcm::mg::coarse_inverse", mg.n_cells,
                                                             M::kCoarseDofs, M::kCoarseDofs);
    mg.coarse_inverse_host = Kokkos::create_mirror_view(mg.coarse_inverse);
  }
  return mg;
}

namespace mg_detail {

// Level l's blocks A_l = Pᵀ A_{l−1} P from level l − 1's, and their inverted diagonal.
template <class ExecutionSpace, class MemorySpace>
void galerkin_level(const ExecutionSpace& space, const Multigrid<MemorySpace>& mg, std::size_t l) {
  const auto fine = mg.levels[l - 1].a.values;
  const MultigridLevel<MemorySpace>& lv = mg.levels[l];
  const auto val = lv.a.values;
  const auto goff = lv.galerkin_offsets;
  const auto src = lv.galerkin_source;
  const auto w = lv.galerkin_weight;
  Kokkos::parallel_for(
      "dcm::mg::galerkin", Kokkos::RangePolicy<ExecutionSpace>(space, 0, lv.a.nnz),
      KOKKOS_LAMBDA(const int s) {
        double blk[6] = {0, 0, 0, 0, 0, 0};
        for (int q = goff(s); q < goff(s + 1); ++q)
          for (int k = 0; k < 6; ++k) blk[k] += w(q) * fine(src(q), k);
        for (int k = 0; k < 6; ++k) val(s, k) = blk[k];
      });
  block_csr_invert_diagonal(space, lv.a);
}

// The per-hinge factors of level 0's bending blocks (update_multigrid_hierarchy adds them). Level 0 = the
// operator's blocks + a positive semi-definite approximation of the implicit bending
// Δt k_b max(cos(θ − θ*), 0) ∇θ ∇θᵀ per hinge (solvers/bending_stiffness.hpp) on the bond pattern: each
// role's gradient ∇_a θ is replaced by its component α_a N̂ along the hinge's normal N̂ (the direction of
// ∇_k θ + ∇_l θ; exact for a flat hinge, where all four gradients are normal), and the wings' cross block
// s α_k α_l N̂N̂ᵀ, which is not on the pattern, by s (α_k² + α_l²) N̂N̂ᵀ on their diagonals: per hinge
// s [(Σ_a α_a N̂·u_a)² + (α_k N̂·u_k − α_l N̂·u_l)²] ≥ 0 for every u. Every block is a multiple of N̂N̂ᵀ.
template <class ExecutionSpace, class MemorySpace>
void update_bending_axes(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                         const HingeRest<MemorySpace>& hinges, const Multigrid<MemorySpace>& mg) {
  const auto g = hinges.hinge_grad;
  const auto cos_delta = hinges.hinge_cos_delta;
  const auto dt_k_b = mg.bending_dt_k_b;  // per cell; 0 where the cell's level 0 leaves the bending out
  const auto hinge_cell = mesh.hinge_cell;
  const auto axis = mg.bending_axis;
  Kokkos::parallel_for(
      "dcm::mg::bending_axis", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_hinges),
      KOKKOS_LAMBDA(const int h) {
        if (dt_k_b(hinge_cell(h)) == 0) {  // a cell left out: exact zeros, whatever its gradients hold
          for (int k = 0; k < 7; ++k) axis(h, k) = 0;
          return;
        }
        const Real3 wings{g(h, 2, 0) + g(h, 3, 0), g(h, 2, 1) + g(h, 3, 1), g(h, 2, 2) + g(h, 3, 2)};
        const double len = norm(wings);
        const Real3 n = len > 0 ? (1.0 / len) * wings : Real3{0, 0, 0};
        const double s = math::sqrt(dt_k_b(hinge_cell(h)) * math::max(cos_delta(h), 0.0));
        axis(h, 0) = n.x;
        axis(h, 1) = n.y;
        axis(h, 2) = n.z;
        for (int a = 0; a < 4; ++a)
          axis(h, 3 + a) = s * (g(h, a, 0) * n.x + g(h, a, 1) * n.y + g(h, a, 2) * n.z);
      });
}

}  // namespace mg_detail

// Numeric set-up, once per step after update_friction(space, mesh, op), in two parts:
// update_multigrid_operator() assembles level 0's blocks, which are also the CG's operator (fine_operator()),
// and update_multigrid_hierarchy() builds what only the V-cycle needs (level 0's bending, the smoothers'
// block inverses, the Galerkin levels, the coarsest inverses); a solve whose warm start already meets the
// tolerance applies no preconditioner and needs only the first (CortexModel::solve_velocity builds the second
// on the first preconditioner application). update_multigrid() does both.
// Level 0 holds the bending's approximation when the caller passes the hinges and the bending stiffness and
// make_multigrid() built its recipe (settings.bending not off), for the cells bending_cells selects (every
// cell when null); the caller decides step by step (MultigridSettings::Bending). A cell left out gets exactly
// its blocks without the bending, so its preconditioner does not depend on the other cells of a batch.
template <class ExecutionSpace, class MemorySpace>
void update_multigrid_operator(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                               const FrictionOperator<MemorySpace>& op, Multigrid<MemorySpace>& mg,
                               const TensionStiffness<MemorySpace>* tension = nullptr,
                               const HingeRest<MemorySpace>* hinges = nullptr,
                               const BendingStiffness<MemorySpace>* bending = nullptr,
                               const std::vector<char>* bending_cells = nullptr) {
  mg.bending_in_level0 = false;
  if (hinges != nullptr && bending != nullptr && mg.operator_values.extent(0) > 0) {
    for (int c = 0; c < static_cast<int>(mg.bending_dt_k_b_host.extent(0)); ++c) {
      const bool in = bending_cells == nullptr || (*bending_cells)[c] != 0;
      mg.bending_dt_k_b_host(c) = in ? bending->dt_k_b_host(c) : 0.0;
      mg.bending_in_level0 = mg.bending_in_level0 || in;
    }
    if (mg.bending_in_level0) Kokkos::deep_copy(mg.bending_dt_k_b, mg.bending_dt_k_b_host);
  }
  {  // level 0: Γ's blocks, ζ_i I + Σ_b c n̂n̂ᵀ on the diagonal, −c n̂n̂ᵀ for each bond
    const BlockCsr<MemorySpace>& a = mg.levels[0].a;
    const auto off = a.row_offsets;
    const auto val = a.values;
    const bool with_bending = mg.bending_in_level0;
    const auto out = with_bending ? mg.operator_values : val;  // assemble_fine: the operator's blocks
    const auto slot_bond = mg.fine_slot_bond;
    const auto node_off = mesh.node_bond_offsets;
    const auto node_bonds = mesh.node_bonds;
    const auto dir = op.bond_dir;
    const auto drag = op.node_drag;
    const auto coef = op.cell_coef;  // per cell (FrictionCoef); update_friction() filled it
    const auto node_cell = mesh.node_cell;
    // Substrate friction blocks β_ti β_tj Γ_t (solvers/friction_operator.hpp) lie on the same pattern: the
    // corners of a triangle are bond neighbours.
    const auto cols = a.cols;
    const auto substrate = substrate_blocks(mesh, op);
    const auto bond_k = op.bond_stiffness_dt;
    const bool stiff = bond_k.extent(0) > 0;
    // The implicit tension blocks (ê_i · ê_j) n_t n_tᵀ (solvers/tension_stiffness.hpp) lie on the same
    // pattern.
    const bool with_tension = tension != nullptr;
    const auto t_edge = with_tension ? tension->edge : decltype(tension->edge)();
    const auto t_normal = with_tension ? tension->normal : decltype(tension->normal)();
    const auto slot_t_off = mg.fine_slot_tension_offsets;
    const auto slot_t = mg.fine_slot_tension;
    Kokkos::parallel_for(
        "dcm::mg::assemble_fine", Kokkos::RangePolicy<ExecutionSpace>(space, 0, a.n_rows),
        KOKKOS_LAMBDA(const int i) {
          const double c = coef(node_cell(i), kDashpot), c_t = coef(node_cell(i), kDashpotTransverse);
          for (int s = off(i); s < off(i + 1); ++s) {
            double blk[6] = {0, 0, 0, 0, 0, 0};
            const int b = slot_bond(s);
            const int first = b >= 0 ? 0 : node_off(i), last = b >= 0 ? 1 : node_off(i + 1);
            const double sign = b >= 0 ? -1.0 : 1.0;
            if (b < 0) blk[0] = blk[1] = blk[2] = drag(i);
            for (int t = first; t < last; ++t) {
              const int bb = b >= 0 ? b : node_bonds(t);
              add_dashpot_block(load3(dir, bb), c + (stiff ? bond_k(bb) : 0.0), c_t, sign, blk);
            }
            substrate.add_block(i, cols(s), blk);
            if (with_tension)
              for (int q = slot_t_off(s); q < slot_t_off(s + 1); ++q) {
                const int t = slot_t(q) >> 4, ci = (slot_t(q) >> 2) & 3,
                          cj = slot_t(q) & 3;  // 16 t + 4 ci + cj
                const double w = t_edge(t, ci, 0) * t_edge(t, cj, 0) + t_edge(t, ci, 1) * t_edge(t, cj, 1) +
                                 t_edge(t, ci, 2) * t_edge(t, cj, 2);
                add_dashpot_block(load3(t_normal, t), w, 0.0, 1.0, blk);  // w n_t n_tᵀ
              }
            for (int k = 0; k < 6; ++k) out(s, k) = blk[k];
          }
        });
  }
}

// The V-cycle's part of the set-up (above), after update_multigrid_operator() at the same positions; hinges:
// the same as given there (for level 0's bending).
template <class ExecutionSpace, class MemorySpace>
void update_multigrid_hierarchy(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                                Multigrid<MemorySpace>& mg, const HingeRest<MemorySpace>* hinges = nullptr) {
  if (mg.bending_in_level0 && hinges == nullptr)
    throw std::logic_error(
        "update_multigrid_hierarchy: level 0 holds the bending; pass the hinges given to "
        "update_multigrid_operator()");
  {
    const BlockCsr<MemorySpace>& a = mg.levels[0].a;
    const auto val = a.values;
    if (mg.bending_in_level0) {  // the preconditioner's level 0: the operator's blocks + the bending's
      mg_detail::update_bending_axes(space, mesh, *hinges, mg);
      const auto op_val = mg.operator_values;
      const auto bend_off = mg.fine_slot_bending_offsets;
      const auto bend = mg.fine_slot_bending;
      const auto axis = mg.bending_axis;
      Kokkos::parallel_for(
          "dcm::mg::add_bending", Kokkos::RangePolicy<ExecutionSpace>(space, 0, a.nnz),
          KOKKOS_LAMBDA(const int s) {
            double blk[6];
            for (int k = 0; k < 6; ++k) blk[k] = op_val(s, k);
            for (int q = bend_off(s); q < bend_off(s + 1); ++q) {
              const int h = bend(q) >> 4, ra = (bend(q) >> 2) & 3, rb = bend(q) & 3;  // 16 h + 4 a + b
              add_dashpot_block(Real3{axis(h, 0), axis(h, 1), axis(h, 2)}, axis(h, 3 + ra) * axis(h, 3 + rb),
                                0.0, 1.0, blk);  // s α_a α_b N̂N̂ᵀ
            }
            for (int k = 0; k < 6; ++k) val(s, k) = blk[k];
          });
    }
    block_csr_invert_diagonal(space, a);
  }
  for (std::size_t l = 1; l < mg.levels.size(); ++l) {  // A_l = Pᵀ A_{l−1} P
    on_small_space(space, mg.levels[l].a.n_rows <= mg.settings.serial_rows,
                   [&](const auto& s) { mg_detail::galerkin_level(s, mg, l); });
  }
  if (!mg.available) return;
  // Coarsest level: 12 nodes per cell, uncoupled cells; dense Cholesky inverse on the host.
  constexpr int n = Multigrid<MemorySpace>::kCoarseDofs, nodes = Multigrid<MemorySpace>::kCoarseNodes;
  const BlockCsr<MemorySpace>& a = mg.levels.back().a;
  const auto off = to_host_vector(a.row_offsets), cols = to_host_vector(a.cols);
  const auto val = to_host_vector(a.values);
  std::vector<double> dense(n * n);
  for (int c = 0; c < mg.n_cells; ++c) {
    std::fill(dense.begin(), dense.end(), 0.0);
    for (int i = 0; i < nodes; ++i) {
      const int row = c * nodes + i;
      for (int s = off[row]; s < off[row + 1]; ++s) {
        const int j = cols[s] - c * nodes;
        if (j < 0 || j >= nodes) throw std::logic_error("multigrid: coarsest level couples two cells");
        const double* b = &val[6 * s];
        const double blk[3][3] = {{b[0], b[3], b[4]}, {b[3], b[1], b[5]}, {b[4], b[5], b[2]}};
        for (int p = 0; p < 3; ++p)
          for (int q = 0; q < 3; ++q) dense[(3 * i + p) * n + 3 * j + q] = blk[p][q];
      }
    }
    if (!mg_detail::invert_spd(dense, n))
      throw NumericalError(
          "the velocity solve's operator (friction + dt x implicit stiffness) is not positive "
          "definite on the coarsest multigrid level of cell " +
          std::to_string(c) + " (a non-finite position or a negative coefficient)");
    for (int p = 0; p < n; ++p)
      for (int q = 0; q < n; ++q) mg.coarse_inverse_host(c, p, q) = dense[p * n + q];
  }
  Kokkos::deep_copy(space, mg.coarse_inverse, mg.coarse_inverse_host);
  space.fence();  // the host mirror is rewritten next step
}

// Both parts of the numeric set-up (above).
template <class ExecutionSpace, class MemorySpace>
void update_multigrid(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                      const FrictionOperator<MemorySpace>& op, Multigrid<MemorySpace>& mg,
                      const TensionStiffness<MemorySpace>* tension = nullptr,
                      const HingeRest<MemorySpace>* hinges = nullptr,
                      const BendingStiffness<MemorySpace>* bending = nullptr,
                      const std::vector<char>* bending_cells = nullptr) {
  update_multigrid_operator(space, mesh, op, mg, tension, hinges, bending, bending_cells);
  update_multigrid_hierarchy(space, mesh, mg, hinges);
}

namespace mg_detail {

template <class ExecutionSpace, class MemorySpace, class Vector>
void coarse_solve(const ExecutionSpace& space, const Multigrid<MemorySpace>& mg, const Vector& b,
                  const Vector& x, const CellFlags<MemorySpace>& active) {
  constexpr int n = Multigrid<MemorySpace>::kCoarseDofs, nodes = Multigrid<MemorySpace>::kCoarseNodes;
  const auto inv = mg.coarse_inverse;
  Kokkos::parallel_for(
      "dcm::mg::coarse_solve", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mg.n_cells * n),
      KOKKOS_LAMBDA(const int q) {
        const int c = q / n, p = q % n;
        if (skipped(active, c)) return;
        double s = 0;
        for (int k = 0; k < n; ++k) s += inv(c, p, k) * b(c * nodes + k / 3, k % 3);
        x(c * nodes + p / 3, p % 3) = s;
      });
}

template <class ExecutionSpace, class MemorySpace, class Vector>
void restrict_residual(const ExecutionSpace& space, const MultigridLevel<MemorySpace>& fine,
                       const MultigridLevel<MemorySpace>& coarse, const Vector& r, const Vector& out,
                       const CellFlags<MemorySpace>& active) {
  const auto row_cell = coarse.a.row_cell;
  const auto off = fine.restrict_offsets;
  const auto idx = fine.restrict_fine;
  const auto w = fine.restrict_weight;
  Kokkos::parallel_for(
      "dcm::mg::restrict", Kokkos::RangePolicy<ExecutionSpace>(space, 0, out.extent(0)),
      KOKKOS_LAMBDA(const int I) {
        if (skipped(active, row_cell(I))) return;
        Real3 acc{0, 0, 0};
        for (int q = off(I); q < off(I + 1); ++q) acc += w(q) * load3(r, idx(q));
        store3(out, I, acc);
      });
}

template <class ExecutionSpace, class MemorySpace, class Vector>
void prolong_add(const ExecutionSpace& space, const MultigridLevel<MemorySpace>& fine, const Vector& coarse,
                 const Vector& x, const CellFlags<MemorySpace>& active) {
  const auto p = fine.prolong;
  const auto row_cell = fine.a.row_cell;
  Kokkos::parallel_for(
      "dcm::mg::prolong", Kokkos::RangePolicy<ExecutionSpace>(space, 0, x.extent(0)),
      KOKKOS_LAMBDA(const int i) {
        if (skipped(active, row_cell(i))) return;
        store3(x, i, load3(x, i) + 0.5 * (load3(coarse, p(i, 0)) + load3(coarse, p(i, 1))));
      });
}

template <class ExecutionSpace, class MemorySpace, class Vector>
void vcycle(const ExecutionSpace& space, const Multigrid<MemorySpace>& mg, std::size_t l, const Vector& b,
            const Vector& x, const CellFlags<MemorySpace>& active) {
  const MultigridLevel<MemorySpace>& lv = mg.levels[l];
  if constexpr (SmallLaunchSpace<ExecutionSpace>::kAvailable) {
    if (l > 0 && lv.a.n_rows <= mg.settings.serial_rows) {  // this level and the coarser ones on one thread
      on_small_space(space, true, [&](const auto& s) { vcycle(s, mg, l, b, x, active); });
      return;
    }
  }
  if (l + 1 == mg.levels.size()) {
    coarse_solve(space, mg, b, x, active);
    return;
  }
  // Damped block-Jacobi sweeps, each one pass (block_jacobi_sweep) between x and the level's second iterate
  // t; the first sweep (from 0) writes t, so that after ν pre- and ν post-sweeps the result is in x.
  const double omega = mg.settings.damping;
  const int nu = mg.settings.sweeps;
  const Vector& t = lv.t;
  const Vector& pre = nu % 2 == 0 ? x : t;              // where the pre-smoothed iterate ends
  const Vector& other = nu % 2 == 0 ? t : x;            // the other buffer
  block_jacobi_step(space, lv.a, omega, b, t, active);  // t = ω D⁻¹ b, the first sweep from 0
  for (int s = 1; s < nu; ++s)
    block_jacobi_sweep(space, lv.a, omega, b, s % 2 ? t : x, s % 2 ? x : t, active);
  block_csr_residual(space, lv.a, b, pre, lv.r, active);
  const MultigridLevel<MemorySpace>& next = mg.levels[l + 1];
  restrict_residual(space, lv, next, lv.r, next.b, active);
  vcycle(space, mg, l + 1, next.b, next.x, active);
  prolong_add(space, lv, next.x, pre, active);
  for (int s = 0; s < nu; ++s)  // ends in x: ν sweeps from pre
    block_jacobi_sweep(space, lv.a, omega, b, s % 2 == 0 ? pre : other, s % 2 == 0 ? other : pre, active);
}

}  // namespace mg_detail

// z = M⁻¹ r: one V-cycle from z = 0 (block-Jacobi when the mesh has no hierarchy).
// active (optional): only the rows of these cells (core/cell_params.hpp).
template <class ExecutionSpace, class MemorySpace, class Vector>
void apply_multigrid(const ExecutionSpace& space, const Multigrid<MemorySpace>& mg, const Vector& r,
                     const Vector& z, const CellFlags<MemorySpace>& active = {}) {
  if (!mg.available) {
    block_jacobi_step(space, mg.levels[0].a, 1.0, r, z, active);
    return;
  }
  mg_detail::vcycle(space, mg, 0, r, z, active);
}

}  // namespace dcm
