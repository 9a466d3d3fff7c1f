#pragma once
// The one place that knows Kokkos versions differ (3.4.1 is what CI sees; 4.x and 5.x must also work).
//  - math: Kokkos::Experimental::sqrt & co. in 3.4-3.6, Kokkos::sqrt from 3.7 on;
//  - initialisation: InitArguments (3.x) versus InitializationSettings (>= 3.7).
// Everything else in dcm uses the subset of the API that all of them share.
#include <Kokkos_Core.hpp>

namespace dcm {
namespace math {

#if KOKKOS_VERSION >= 30700
using Kokkos::acos;
using Kokkos::asin;
using Kokkos::atan;
using Kokkos::atan2;
using Kokkos::cbrt;
using Kokkos::cos;
using Kokkos::exp;
using Kokkos::fabs;
using Kokkos::isfinite;
using Kokkos::log;
using Kokkos::pow;
using Kokkos::sin;
using Kokkos::sqrt;
#else
using Kokkos::Experimental::acos;
using Kokkos::Experimental::asin;
using Kokkos::Experimental::atan;
using Kokkos::Experimental::atan2;
using Kokkos::Experimental::cbrt;
using Kokkos::Experimental::cos;
using Kokkos::Experimental::exp;
using Kokkos::Experimental::fabs;
using Kokkos::Experimental::isfinite;
using Kokkos::Experimental::log;
using Kokkos::Experimental::pow;
using Kokkos::Experimental::sin;
using Kokkos::Experimental::sqrt;
#endif

KOKKOS_INLINE_FUNCTION constexpr double min(double a, double b) { return a < b ? a : b; }
KOKKOS_INLINE_FUNCTION constexpr double max(double a, double b) { return a > b ? a : b; }
KOKKOS_INLINE_FUNCTION constexpr double clamp(double x, double lo, double hi) {
  return x < lo ? lo : (x > hi ? hi : x);
}

}  // namespace math

// Start Kokkos with a thread count (0: Kokkos' own default, i.e. OMP_NUM_THREADS or all cores).
// OMP_PROC_BIND is set to "false" when the user has not set it, which silences Kokkos' start-up
// warning and keeps several dcm processes on one machine from pinning to the same cores.
void initialize_kokkos(int num_threads);

// A scope that starts Kokkos and finalises it on exit (also on an exception).
class KokkosSession {
 public:
  explicit KokkosSession(int num_threads = 0) { initialize_kokkos(num_threads); }
  ~KokkosSession() { Kokkos::finalize(); }
  KokkosSession(const KokkosSession&) = delete;
  KokkosSession& operator=(const KokkosSession&) = delete;
};

// "Kokkos 3.4.1, execution space OpenMP (2 threads)"-style description for reports.
std::string kokkos_description();

}  // namespace dcm
