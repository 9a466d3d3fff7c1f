#pragma once
// Preconditioned conjugate gradients for Γ v = F (Γ symmetric positive definite), on [n][3] Views.
// Operator and preconditioner are host-side callables that launch kernels: apply(in, out) and
// precondition(r, z). The iterate x is the warm start on entry and the solution on exit.
// Stops when ||r||₂ ≤ max(abs_tol, rel_tol ||b||₂); the paper's setting is an absolute force residual
// of 1e-14 N. Reaching max_iterations is reported (converged = false), never silently accepted.
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
};

template <class MemorySpace>
struct CgWorkspace {
  using Vector = Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>;
  Vector r, z, p, q;
  SumPlan<MemorySpace> sums;  // the dot products: thread-count independent (core/segmented_sum.hpp)
  CgWorkspace() = default;
  explicit CgWorkspace(int n)
      : r(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::cg::r"), n),
        z(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::cg::z"), n),
        p(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::cg::p"), n),
        q(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::cg::q"), n),
        sums(std::vector<int>{0, n}) {}
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

}  // namespace cg_detail

template <class ExecutionSpace, class Vector, class Apply, class Precondition, class Workspace>
CgResult pcg_solve(const ExecutionSpace& space, Apply&& apply, Precondition&& precondition, const Vector& b,
                   const Vector& x, Workspace& w, const CgSettings& settings) {
  using Policy = Kokkos::RangePolicy<ExecutionSpace>;
  const int n = static_cast<int>(b.extent(0));
  const auto r = w.r, z = w.z, p = w.p, q = w.q;
  CgResult result;
  const auto& sums = w.sums;
  result.rhs_norm = math::sqrt(cg_detail::dot(space, sums, b, b));
  const double tol = math::max(settings.abs_tol, settings.rel_tol * result.rhs_norm);

  apply(x, q);  // r = b - Γ x
  double rr[1];
  segmented_total<1>(
      "dcm::cg::initial_residual", space, sums,
      KOKKOS_LAMBDA(const int i, double(&s)[1]) {
        for (int d = 0; d < 3; ++d) {
          r(i, d) = b(i, d) - q(i, d);
          s[0] += r(i, d) * r(i, d);
        }
      },
      rr);
  result.residual_norm = math::sqrt(rr[0]);
  if (result.residual_norm <= tol) {
    result.converged = true;
    return result;
  }
  precondition(r, z);
  Kokkos::deep_copy(space, p, z);
  double rz = cg_detail::dot(space, sums, r, z);
  for (int it = 1; it <= settings.max_iterations; ++it) {
    apply(p, q);
    const double alpha = rz / cg_detail::dot(space, sums, p, q);
    segmented_total<1>(
        "dcm::cg::update", space, sums,
        KOKKOS_LAMBDA(const int i, double(&s)[1]) {
          for (int d = 0; d < 3; ++d) {
            x(i, d) += alpha * p(i, d);
            r(i, d) -= alpha * q(i, d);
            s[0] += r(i, d) * r(i, d);
          }
        },
        rr);
    result.iterations = it;
    result.residual_norm = math::sqrt(rr[0]);
    if (!(result.residual_norm > tol)) {  // also stops on NaN; the caller checks finiteness
      result.converged = result.residual_norm <= tol;
      return result;
    }
    precondition(r, z);
    const double rz_new = cg_detail::dot(space, sums, r, z);
    const double beta = rz_new / rz;
    rz = rz_new;
    Kokkos::parallel_for(
        "dcm::cg::direction", Policy(space, 0, n), KOKKOS_LAMBDA(const int i) {
          for (int d = 0; d < 3; ++d) p(i, d) = z(i, d) + beta * p(i, d);
        });
  }
  return result;
}

}  // namespace dcm
