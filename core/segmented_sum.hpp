#pragma once
// Sums whose rounding depends neither on the thread count nor on what else shares the launch (docs/SCANS.md,
// "The batched engine: design", point 2). The elements of each segment [begin[s], begin[s + 1]) (a cell's
// nodes or triangles; one segment for a whole-mesh sum) are cut into chunks of kSumChunk consecutive
// elements; one work item per chunk adds its elements in order, then one work item per segment adds its chunk
// sums in order. A Kokkos::parallel_reduce instead combines per-thread partial sums, so its last bits change
// with OMP_NUM_THREADS; with these sums a run is bitwise the same on 1 and 2 threads (ctest
// app.spread_thread_independent), and a cell's sums do not depend on the other cells of a batch.
// Cost: two launches and a host copy per sum instead of one reduction; on the CPU the same time (bench_step);
// with OpenMP the second launch runs on one thread (core/small_launch.hpp).
// On a GPU a work item per 64 consecutive elements reads uncoalesced; a fixed warp-level tree per chunk would
// keep the order and read coalesced (not done: no GPU to measure it on).
//
//   SumPlan<Mem> plan(host_begin);                       // once per mesh (host offsets, n_segments + 1)
//   segmented_sum<2>("dcm::x::y", space, plan,           // the label names both kernels (label,
//   label::segments)
//                    KOKKOS_LAMBDA(int k, double (&acc)[2]) { acc[0] += ...; acc[1] += ...; },
//                    out);                                // out(s, 0..1) for every segment s
//   double total = fixed_order_sum("dcm::x::y", space, plan, KOKKOS_LAMBDA(int k) { return ...; });  // host
#include <Kokkos_Core.hpp>
#include <string>
#include <vector>

#include "core/kokkos_compat.hpp"
#include "core/small_launch.hpp"

namespace dcm {

constexpr int kSumChunk = 64;
// The per-segment pass (adding each segment's chunk sums) runs on one host thread (core/small_launch.hpp)
// up to this many chunks: it is a few hundred additions per cell.
constexpr int kSumSerialChunks = 1 << 16;
constexpr int kSumMaxComponents = 4;

template <class MemorySpace>
struct SumPlan {
  template <class T>
  using View = Kokkos::View<T, Kokkos::LayoutRight, MemorySpace>;
  int n_segments = 0, n_chunks = 0;
  View<int* [2]> chunk_range;                 // [first, last) element of each chunk
  View<int*> segment_chunks;                  // first chunk of each segment (n_segments + 1)
  View<double* [kSumMaxComponents]> partial;  // chunk sums
  View<double* [kSumMaxComponents]> result;   // segment sums (scratch of segmented_total())
  HostMirrorOf<View<double* [kSumMaxComponents]>> result_host;

  SumPlan() = default;
  explicit SumPlan(const std::vector<int>& begin) {
    n_segments = static_cast<int>(begin.size()) - 1;
    std::vector<int> first(1, 0), lo, hi;
    for (int s = 0; s < n_segments; ++s) {
      for (int k = begin[s]; k < begin[s + 1]; k += kSumChunk) {
        lo.push_back(k);
        hi.push_back(k + kSumChunk < begin[s + 1] ? k + kSumChunk : begin[s + 1]);
      }
      first.push_back(static_cast<int>(lo.size()));
    }
    n_chunks = static_cast<int>(lo.size());
    chunk_range =
        View<int* [2]>(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::sum::chunk_range"), n_chunks);
    segment_chunks = View<int*>(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::sum::segment_chunks"),
                                n_segments + 1);
    auto hr = Kokkos::create_mirror_view(chunk_range);
    for (int q = 0; q < n_chunks; ++q) {
      hr(q, 0) = lo[q];
      hr(q, 1) = hi[q];
    }
    Kokkos::deep_copy(chunk_range, hr);
    auto hs = Kokkos::create_mirror_view(segment_chunks);
    for (int s = 0; s <= n_segments; ++s) hs(s) = first[s];
    Kokkos::deep_copy(segment_chunks, hs);
    partial = View<double* [kSumMaxComponents]>("dcm::sum::partial", n_chunks);
    result = View<double* [kSumMaxComponents]>("dcm::sum::result", n_segments);
    result_host = Kokkos::create_mirror_view(result);
  }
};

namespace sum_detail {

// out(s, c) = the sum of segment s's chunk sums, in order (segmented_sum's second launch).
template <int N, class ExecutionSpace, class MemorySpace, class Out>
void segment_pass(const std::string& label, const ExecutionSpace& space, const SumPlan<MemorySpace>& plan,
                  const Out& out) {
  const auto partial = plan.partial;
  const auto chunks = plan.segment_chunks;
  Kokkos::parallel_for(
      label + "::segments", Kokkos::RangePolicy<ExecutionSpace>(space, 0, plan.n_segments),
      KOKKOS_LAMBDA(const int s) {
        double acc[N];
        for (int c = 0; c < N; ++c) acc[c] = 0;
        for (int q = chunks(s); q < chunks(s + 1); ++q)
          for (int c = 0; c < N; ++c) acc[c] += partial(q, c);
        for (int c = 0; c < N; ++c) out(s, c) = acc[c];
      });
}

// result(s, 0) = the largest of segment s's chunk maxima (segmented_max's second launch).
template <class ExecutionSpace, class MemorySpace>
void segment_max_pass(const std::string& label, const ExecutionSpace& space,
                      const SumPlan<MemorySpace>& plan) {
  const auto partial = plan.partial;
  const auto chunks = plan.segment_chunks;
  const auto result = plan.result;
  Kokkos::parallel_for(
      label + "::segments", Kokkos::RangePolicy<ExecutionSpace>(space, 0, plan.n_segments),
      KOKKOS_LAMBDA(const int s) {
        double m = 0;
        for (int q = chunks(s); q < chunks(s + 1); ++q)
          if (partial(q, 0) > m) m = partial(q, 0);
        result(s, 0) = m;
      });
}

}  // namespace sum_detail

// out(s, c) = Σ over the elements k of segment s of the c-th component term(k, acc) adds, for c < N.
// term may also write per-element results (each element is visited exactly once).
// The kernels are labelled `label` (chunks) and `label`::segments, so profiles keep the caller's name.
template <int N, class ExecutionSpace, class MemorySpace, class Term, class Out>
void segmented_sum(const std::string& label, const ExecutionSpace& space, const SumPlan<MemorySpace>& plan,
                   const Term& term, const Out& out) {
  static_assert(N >= 1 && N <= kSumMaxComponents, "segmented_sum: 1 to 4 components");
  const auto range = plan.chunk_range;
  const auto partial = plan.partial;
  Kokkos::parallel_for(
      label, Kokkos::RangePolicy<ExecutionSpace>(space, 0, plan.n_chunks), KOKKOS_LAMBDA(const int q) {
        double acc[N];
        for (int c = 0; c < N; ++c) acc[c] = 0;
        for (int k = range(q, 0); k < range(q, 1); ++k) term(k, acc);
        for (int c = 0; c < N; ++c) partial(q, c) = acc[c];
      });
  on_small_space(space, plan.n_chunks <= kSumSerialChunks,
                 [&](const auto& s) { sum_detail::segment_pass<N>(label, s, plan, out); });
}

// Two per-segment Views as the `out` of a two-component segmented_sum: out(s, 0) = first(s), out(s, 1) =
// second(s).
template <class MemorySpace>
struct PairOut {
  Kokkos::View<double*, Kokkos::LayoutRight, MemorySpace> first, second;
  KOKKOS_INLINE_FUNCTION double& operator()(int s, int k) const { return k == 0 ? first(s) : second(s); }
};

// The sums over all segments (the segments added in order), on the host.
// per_segment (optional): also each segment's sum of the first component (a cell's own value).
template <int N, class ExecutionSpace, class MemorySpace, class Term>
void segmented_total(const std::string& label, const ExecutionSpace& space, const SumPlan<MemorySpace>& plan,
                     const Term& term, double (&total)[N], std::vector<double>* per_segment = nullptr) {
  segmented_sum<N>(label, space, plan, term, plan.result);
  Kokkos::deep_copy(space, plan.result_host, plan.result);
  space.fence();
  for (int c = 0; c < N; ++c) total[c] = 0;
  for (int s = 0; s < plan.n_segments; ++s)
    for (int c = 0; c < N; ++c) total[c] += plan.result_host(s, c);
  if (per_segment) {
    per_segment->resize(plan.n_segments);
    for (int s = 0; s < plan.n_segments; ++s) (*per_segment)[s] = plan.result_host(s, 0);
  }
}

// out[s] = the largest term(k) over the elements k of segment s (0 for an empty segment; a NaN term is
// skipped). A maximum does not depend on the order, so this only saves one launch per segment.
template <class ExecutionSpace, class MemorySpace, class Term>
void segmented_max(const std::string& label, const ExecutionSpace& space, const SumPlan<MemorySpace>& plan,
                   const Term& term, std::vector<double>& out) {
  const auto range = plan.chunk_range;
  const auto partial = plan.partial;
  Kokkos::parallel_for(
      label, Kokkos::RangePolicy<ExecutionSpace>(space, 0, plan.n_chunks), KOKKOS_LAMBDA(const int q) {
        double m = 0;
        for (int k = range(q, 0); k < range(q, 1); ++k) {
          const double v = term(k);
          if (v > m) m = v;
        }
        partial(q, 0) = m;
      });
  on_small_space(space, plan.n_chunks <= kSumSerialChunks,
                 [&](const auto& s) { sum_detail::segment_max_pass(label, s, plan); });
  Kokkos::deep_copy(space, plan.result_host, plan.result);
  space.fence();
  out.resize(plan.n_segments);
  for (int s = 0; s < plan.n_segments; ++s) out[s] = plan.result_host(s, 0);
}

// One component: Σ term over every element of the plan, in the fixed order.
// per_segment (optional): also each segment's sum.
template <class ExecutionSpace, class MemorySpace, class Term>
double fixed_order_sum(const std::string& label, const ExecutionSpace& space,
                       const SumPlan<MemorySpace>& plan, const Term& term,
                       std::vector<double>* per_segment = nullptr) {
  double total[1];
  segmented_total<1>(
      label, space, plan, KOKKOS_LAMBDA(const int k, double(&acc)[1]) { acc[0] += term(k); }, total,
      per_segment);
  return total[0];
}

}  // namespace dcm
