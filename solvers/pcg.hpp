#pragma once
// Preconditioned conjugate gradients for Γ v = F (Γ symmetric positive definite), on [n][3] Views.
// Operator and preconditioner are host-side callables that launch kernels: apply(in, out) and
// precondition(r, z). The iterate x is the warm start on entry and the solution on exit.
// Stops when ||r||₂ ≤ max(abs_tol, rel_tol ||b||₂); the paper's setting is an absolute force residual
// of 1e-14 N. Reaching max_iterations is reported (converged = false), never silently accepted.
//
// Per-cell CG (docs/SCANS.md, "The batched engine: design", point 3): the workspace's segments are the
// cells (CgWorkspace(cell node offsets)); the operator and the preconditioner must then be block-diagonal
// per cell (no coupling term between cells: true of every term dcm has). Each cell has its own α, β, norms,
// tolerance and convergence: a converged cell freezes (its x and r no longer change) while the others
// iterate, and the loop ends when every cell has stopped. Every per-cell number is a fixed-order sum over
// that cell's nodes alone (core/segmented_sum.hpp), so a cell's iterates are bit for bit those of its solve
// alone, whatever shares the launch. One segment over all nodes (CgWorkspace(n)) is plain CG.
#include <vector>

#include "core/kokkos_compat.hpp"
#include "core/segmented_sum.hpp"
#include "core/vec3.hpp"

namespace dcm {

struct CgSettings {
  double abs_tol = 1e-14;  // N
  double rel_tol = 0;
  int max_iterations = 2000;
};

struct CgResult {
  int iterations = 0;
  double residual_norm = 0, rhs_norm = 0;
  bool converged = false;
  // p·Γp ≤ 0 (or not finite) along a search direction: Γ is not positive definite there; the solve stops
  // unconverged at that iteration. `curvature` holds the offending p·Γp.
  bool breakdown = false;
  double curvature = 0;
};

template <class MemorySpace>
struct CgWorkspace {
  using Vector = Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>;
  using Scalars = Kokkos::View<double*, Kokkos::LayoutRight, MemorySpace>;
  Vector r, z, p, q;
  SumPlan<MemorySpace> sums;  // the dot products per segment: thread-count independent
  Kokkos::View<int*, Kokkos::LayoutRight, MemorySpace> node_segment;
  Scalars alpha, beta;  // per segment; 0 freezes a segment
  HostMirrorOf<Scalars> alpha_host, beta_host;
  // 1 for the segments still iterating, kept up to date during a solve: an operator or preconditioner may
  // skip the rows of the others (their results are not used).
  Kokkos::View<int*, Kokkos::LayoutRight, MemorySpace> active;
  HostMirrorOf<Kokkos::View<int*, Kokkos::LayoutRight, MemorySpace>> active_host;
  std::vector<CgResult> segment_results;  // of the last solve, one per segment

  CgWorkspace() = default;
  explicit CgWorkspace(int n) : CgWorkspace(std::vector<int>{0, n}) {}
  // segment_begin: the first node of every segment and the node count (cells: host_cell_node_begin).
  explicit CgWorkspace(const std::vector<int>& segment_begin)
      : r(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::cg::r"), segment_begin.back()),
        z(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::cg::z"), segment_begin.back()),
        p(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::cg::p"), segment_begin.back()),
        q(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::cg::q"), segment_begin.back()),
        sums(segment_begin),
        node_segment("dcm::cg::node_segment", segment_begin.back()),
        alpha("dcm::cg::alpha", segment_begin.size() - 1),
        beta("dcm::cg::beta", segment_begin.size() - 1),
        alpha_host(Kokkos::create_mirror_view(alpha)),
        beta_host(Kokkos::create_mirror_view(beta)),
        active("dcm::cg::active", segment_begin.size() - 1),
        active_host(Kokkos::create_mirror_view(active)),
        segment_results(segment_begin.size() - 1) {
    auto h = Kokkos::create_mirror_view(node_segment);
    for (std::size_t s = 0; s + 1 < segment_begin.size(); ++s)
      for (int i = segment_begin[s]; i < segment_begin[s + 1]; ++i) h(i) = static_cast<int>(s);
    Kokkos::deep_copy(node_segment, h);
  }
  int n_segments() const { return sums.n_segments; }
};

namespace cg_detail {

// a · b summed in the plan's fixed order (core/segmented_sum.hpp): the same bits on any thread count.
template <class ExecutionSpace, class MemorySpace, class Vector>
double dot(const ExecutionSpace& space, const SumPlan<MemorySpace>& plan, const Vector& a, const Vector& b,
           const char* label = "dcm::cg::dot") {
  double sum[1];
  segmented_total<1>(
      label, space, plan,
      KOKKOS_LAMBDA(const int i, double(&acc)[1]) {
        acc[0] += a(i, 0) * b(i, 0) + a(i, 1) * b(i, 1) + a(i, 2) * b(i, 2);
      },
      sum);
  return sum[0];
}

// a · b per segment, into out[s] (host).
template <class ExecutionSpace, class MemorySpace, class Vector>
void segment_dots(const ExecutionSpace& space, const SumPlan<MemorySpace>& plan, const Vector& a,
                  const Vector& b, std::vector<double>& out, const char* label = "dcm::cg::dot") {
  out.resize(plan.n_segments);
  segmented_sum<1>(
      label, space, plan,
      KOKKOS_LAMBDA(const int i, double(&acc)[1]) {
        acc[0] += a(i, 0) * b(i, 0) + a(i, 1) * b(i, 1) + a(i, 2) * b(i, 2);
      },
      plan.result);
  Kokkos::deep_copy(space, plan.result_host, plan.result);
  space.fence();
  for (int s = 0; s < plan.n_segments; ++s) out[s] = plan.result_host(s, 0);
}

// The aggregate of the segments' results: converged if all are; otherwise the first segment that is not
// (a non-finite residual first), so messages name the real failure. Iterations: the most any segment took.
inline CgResult combine(const std::vector<CgResult>& seg) {
  CgResult all = seg.front();
  int worst = -1;
  for (std::size_t s = 0; s < seg.size(); ++s) {
    all.iterations = seg[s].iterations > all.iterations ? seg[s].iterations : all.iterations;
    if (!seg[s].converged && worst < 0) worst = static_cast<int>(s);
    if (!seg[s].converged && !(seg[s].residual_norm < INFINITY)) {
      worst = static_cast<int>(s);
      break;
    }
  }
  if (worst >= 0) {
    const int its = all.iterations;
    all = seg[worst];
    all.iterations = its;
  }
  return all;
}

// The kernels of pcg_solve, outside it: a CUDA extended lambda may not sit in a function whose template
// arguments are types local to another function (the host-side apply and precondition lambdas).
// r = b − q and ||r||² per segment (into plan.result).
template <class ExecutionSpace, class MemorySpace, class Vector>
void residual_and_norms(const ExecutionSpace& space, const SumPlan<MemorySpace>& plan, const Vector& b,
                        const Vector& q, const Vector& r) {
  segmented_sum<1>(
      "dcm::cg::initial_residual", space, plan,
      KOKKOS_LAMBDA(const int i, double(&s)[1]) {
        for (int d = 0; d < 3; ++d) {
          r(i, d) = b(i, d) - q(i, d);
          s[0] += r(i, d) * r(i, d);
        }
      },
      plan.result);
}

// x += α p, r −= α q with each node's segment's α (0: the segment is frozen), and ||r||² per segment.
template <class ExecutionSpace, class MemorySpace, class Vector, class Scalars, class Segments>
void update_iterate(const ExecutionSpace& space, const SumPlan<MemorySpace>& plan, const Segments& seg,
                    const Scalars& alpha, const Vector& p, const Vector& q, const Vector& x,
                    const Vector& r) {
  segmented_sum<1>(
      "dcm::cg::update", space, plan,
      KOKKOS_LAMBDA(const int i, double(&s)[1]) {
        const double a = alpha(seg(i));
        if (a != 0)  // a frozen segment keeps its x and r
          for (int d = 0; d < 3; ++d) {
            x(i, d) += a * p(i, d);
            r(i, d) -= a * q(i, d);
          }
        for (int d = 0; d < 3; ++d) s[0] += r(i, d) * r(i, d);
      },
      plan.result);
}

// p = z + β p with each node's segment's β.
// Segments that stopped (active = 0) keep their p: a segment that broke down keeps the direction along which
// p·Ap was not positive, for the message that names the term (CortexModel::describe_breakdown).
template <class ExecutionSpace, class Segments, class Scalars, class Vector, class Active>
void next_direction(const ExecutionSpace& space, const Segments& seg, const Scalars& beta, const Vector& z,
                    const Vector& p, const Active& active) {
  Kokkos::parallel_for(
      "dcm::cg::direction", Kokkos::RangePolicy<ExecutionSpace>(space, 0, static_cast<int>(p.extent(0))),
      KOKKOS_LAMBDA(const int i) {
        if (!active(seg(i))) return;
        const double bt = beta(seg(i));
        for (int d = 0; d < 3; ++d) p(i, d) = z(i, d) + bt * p(i, d);
      });
}

}  // namespace cg_detail

// frozen (optional, one flag per segment): segments whose x is kept as it is (a batch's cells that are not
// stepping now); their results read converged with 0 iterations.
template <class ExecutionSpace, class Vector, class Apply, class Precondition, class Workspace>
CgResult pcg_solve(const ExecutionSpace& space, Apply&& apply, Precondition&& precondition, const Vector& b,
                   const Vector& x, Workspace& w, const CgSettings& settings,
                   const std::vector<char>* frozen = nullptr) {
  const int n_seg = w.n_segments();
  const auto r = w.r, z = w.z, p = w.p, q = w.q;
  const auto seg = w.node_segment;
  const auto alpha = w.alpha, beta = w.beta;
  const auto& sums = w.sums;
  auto& res = w.segment_results;
  std::vector<double> bb(n_seg), rz(n_seg), pq(n_seg), rz_new(n_seg), tol(n_seg);
  std::vector<char> active(n_seg, 0);
  int n_active = 0;
  const auto publish = [&] {  // w.active = the segments still iterating
    for (int s = 0; s < n_seg; ++s) w.active_host(s) = active[s] != 0 ? 1 : 0;
    Kokkos::deep_copy(space, w.active, w.active_host);
  };
  for (int s = 0; s < n_seg; ++s) active[s] = frozen && (*frozen)[s] ? 0 : 1;
  publish();

  cg_detail::segment_dots(space, sums, b, b, bb);
  apply(x, q);  // r = b - Γ x
  cg_detail::residual_and_norms(space, sums, b, q, r);
  Kokkos::deep_copy(space, sums.result_host, sums.result);
  space.fence();
  n_active = 0;
  for (int s = 0; s < n_seg; ++s) {
    res[s] = CgResult{};
    res[s].rhs_norm = math::sqrt(bb[s]);
    tol[s] = math::max(settings.abs_tol, settings.rel_tol * res[s].rhs_norm);
    res[s].residual_norm = math::sqrt(sums.result_host(s, 0));
    res[s].converged = res[s].residual_norm <= tol[s];
    if (frozen && (*frozen)[s]) {  // not solved: its rows were skipped
      res[s].residual_norm = 0;
      res[s].converged = true;
    }
    active[s] = res[s].converged ? 0 : 1;
    n_active += active[s];
  }
  if (n_active == 0) return cg_detail::combine(res);
  publish();
  precondition(r, z);
  Kokkos::deep_copy(space, p, z);
  cg_detail::segment_dots(space, sums, r, z, rz);
  for (int it = 1; it <= settings.max_iterations; ++it) {
    apply(p, q);
    cg_detail::segment_dots(space, sums, p, q, pq);
    bool stopped = false;
    for (int s = 0; s < n_seg; ++s) {
      if (!active[s] || pq[s] > 0) continue;  // !(p·Γp > 0): also NaN
      res[s].iterations = it;
      res[s].converged = false;
      res[s].breakdown = true;
      res[s].curvature = pq[s];
      active[s] = 0;
      --n_active;
      stopped = true;
    }
    if (n_active == 0) break;
    for (int s = 0; s < n_seg; ++s) w.alpha_host(s) = active[s] ? rz[s] / pq[s] : 0.0;
    Kokkos::deep_copy(space, alpha, w.alpha_host);
    cg_detail::update_iterate(space, sums, seg, alpha, p, q, x, r);
    Kokkos::deep_copy(space, sums.result_host, sums.result);
    space.fence();
    for (int s = 0; s < n_seg; ++s) {
      if (!active[s]) continue;
      res[s].iterations = it;
      res[s].residual_norm = math::sqrt(sums.result_host(s, 0));
      if (!(res[s].residual_norm > tol[s])) {  // also stops on NaN; the caller checks finiteness
        res[s].converged = res[s].residual_norm <= tol[s];
        active[s] = 0;
        --n_active;
        stopped = true;
      }
    }
    if (n_active == 0) break;
    if (stopped) publish();
    precondition(r, z);
    cg_detail::segment_dots(space, sums, r, z, rz_new);
    for (int s = 0; s < n_seg; ++s) {
      w.beta_host(s) = active[s] ? rz_new[s] / rz[s] : 0.0;
      if (active[s]) rz[s] = rz_new[s];
    }
    Kokkos::deep_copy(space, beta, w.beta_host);
    cg_detail::next_direction(space, seg, beta, z, p, w.active);
  }
  return cg_detail::combine(res);
}

}  // namespace dcm
