#pragma once
// The one place that knows Kokkos versions differ (3.4.1 is what CI sees; 4.x and 5.x must also work).
//  - math: Kokkos::Experimental::sqrt & co. in 3.4-3.6, Kokkos::sqrt from 3.7 on;
//  - initialisation: InitArguments (3.x) versus InitializationSettings (>= 3.7);
//  - a view's host mirror type: View::HostMirror, deprecated in 5.0 for View::host_mirror_type (which 3.4.1
//    lacks); HostMirrorOf<V> below is the type create_mirror_view returns, in every version.
// Everything else in dcm uses the subset of the API that all of them share.
#include <Kokkos_Core.hpp>
#include <utility>

namespace dcm {

template <class ViewType>
using HostMirrorOf = decltype(Kokkos::create_mirror_view(std::declval<const ViewType&>()));

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

// atan2(y, x) for y, x >= 0 (the first quadrant; atan2(0, 0) = 0), without the library call: the contact
// integrals (kernels/polar_contact_integral.hpp) evaluate three per quadrature point, and the library's
// atan2 was 13% of a spreading run (perf, session 11). Cephes' atan: the argument reduced to [0, 1] by
// swapping y and x, above 0.66 to (t - 1)/(t + 1) about pi/4, then t + t z P(z)/Q(z), z = t^2; relative
// error <= 2.3e-16 against std::atan2 (tests/test_maugis_dugdale.cpp).
KOKKOS_INLINE_FUNCTION double atan2_first_quadrant(double y, double x) {
  constexpr double kPiOver4 = 0.78539816339744830962, kPiOver2 = 1.57079632679489661923;
  constexpr double kMoreBits = 6.123233995736765886130e-17;  // pi/2 - kPiOver2
  const bool swap = y > x;
  const double num = swap ? x : y, den = swap ? y : x;  // num / den in [0, 1]
  const bool shift = num > 0.66 * den;                  // then (t - 1)/(t + 1) = (num - den)/(num + den)
  const double top = shift ? num - den : num, bottom = shift ? num + den : den;
  const double t = bottom > 0 ? top / bottom : 0.0 * num;  // one division (NaN stays NaN)
  const double z = t * t;
  const double p =
      (((-8.750608600031904122785e-1 * z - 1.615753718733365076637e1) * z - 7.500855792314704667340e1) * z -
       1.228866684490136173410e2) *
          z -
      6.485021904942025371773e1;
  const double q =
      ((((z + 2.485846490142306297962e1) * z + 1.650270098316988542046e2) * z + 4.328810604912902668951e2) *
           z +
       4.853903996359136964868e2) *
          z +
      1.945506571482613964425e2;
  const double r = (shift ? kPiOver4 + 0.5 * kMoreBits : 0.0) + (t + t * z * p / q);
  return swap ? (kPiOver2 - r) + kMoreBits : r;
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
