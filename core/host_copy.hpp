#pragma once
// Copy a rank-1, 2 or 3 View to the host as a flat row-major std::vector (reports, output, tests), and
// back (checkpoints).
#include <Kokkos_Core.hpp>
#include <stdexcept>
#include <vector>

namespace dcm {

template <class View>
std::vector<typename View::non_const_value_type> to_host_vector(const View& v) {
  static_assert(View::rank >= 1 && View::rank <= 3, "rank 1, 2 or 3");
  auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), v);
  std::vector<typename View::non_const_value_type> out;
  const std::size_t n0 = h.extent(0), n1 = View::rank >= 2 ? h.extent(1) : 1,
                    n2 = View::rank == 3 ? h.extent(2) : 1;
  out.reserve(n0 * n1 * n2);
  for (std::size_t i = 0; i < n0; ++i)
    for (std::size_t j = 0; j < n1; ++j)
      for (std::size_t k = 0; k < n2; ++k) {
        if constexpr (View::rank == 3)
          out.push_back(h(i, j, k));
        else if constexpr (View::rank == 2)
          out.push_back(h(i, j));
        else
          out.push_back(h(i));
      }
  return out;
}

// The inverse of to_host_vector(): fills v (rank 2) from a flat row-major vector of the same size.
template <class View>
void from_host_vector(const View& v, const std::vector<typename View::non_const_value_type>& values) {
  static_assert(View::rank == 2, "rank 2");
  auto h = Kokkos::create_mirror_view(v);
  const std::size_t n0 = h.extent(0), n1 = h.extent(1);
  if (values.size() != n0 * n1) throw std::invalid_argument("from_host_vector: size mismatch");
  for (std::size_t i = 0; i < n0; ++i)
    for (std::size_t j = 0; j < n1; ++j) h(i, j) = values[i * n1 + j];
  Kokkos::deep_copy(v, h);
}

}  // namespace dcm
