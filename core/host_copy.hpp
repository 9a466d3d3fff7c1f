#pragma once
// Copy a rank-1 or rank-2 View to the host as a flat row-major std::vector (reports, output, tests).
#include <Kokkos_Core.hpp>
#include <vector>

namespace dcm {

template <class View>
std::vector<typename View::non_const_value_type> to_host_vector(const View& v) {
  static_assert(View::rank == 1 || View::rank == 2, "rank 1 or 2");
  auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), v);
  std::vector<typename View::non_const_value_type> out;
  const std::size_t n0 = h.extent(0), n1 = View::rank == 2 ? h.extent(1) : 1;
  out.reserve(n0 * n1);
  for (std::size_t i = 0; i < n0; ++i)
    for (std::size_t j = 0; j < n1; ++j) {
      if constexpr (View::rank == 2)
        out.push_back(h(i, j));
      else
        out.push_back(h(i));
    }
  return out;
}

}  // namespace dcm
