#pragma once
// Rest-state helpers shared by the constraint terms: a checked copy of a geometric quantity.
#include <Kokkos_Core.hpp>
#include <stdexcept>
#include <string>

namespace dcm {
namespace detail {

// Number of entries of a rank-1 View that are not positive (or NaN): host-side set-up checks.
template <class ExecutionSpace, class V>
int count_not_positive(const ExecutionSpace& space, const V& v) {
  int bad = 0;
  Kokkos::parallel_reduce(
      "dcm::constraints::check_rest",
      Kokkos::RangePolicy<ExecutionSpace>(space, 0, static_cast<int>(v.extent(0))),
      KOKKOS_LAMBDA(const int i, int& n) { n += v(i) > 0 ? 0 : 1; }, bad);
  return bad;
}

// A copy of a rest quantity, checked positive (the constraints divide by it).
template <class ExecutionSpace, class V>
V copy_rest(const ExecutionSpace& space, const V& from, const char* label, const char* what) {
  V to(Kokkos::view_alloc(Kokkos::WithoutInitializing, std::string(label)), from.extent(0));
  Kokkos::deep_copy(space, to, from);
  const int bad = count_not_positive(space, to);
  if (bad > 0)
    throw std::invalid_argument(std::to_string(bad) + " rest " + what +
                                "(s) not positive: a degenerate mesh");
  return to;
}

}  // namespace detail

}  // namespace dcm
