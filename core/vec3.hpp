#pragma once
// Small 3-vector arithmetic for kernels (device-callable, no std::).
#include "core/kokkos_compat.hpp"

namespace dcm {

struct Real3 {
  double x, y, z;
};

KOKKOS_INLINE_FUNCTION Real3 operator+(Real3 a, Real3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
KOKKOS_INLINE_FUNCTION Real3 operator-(Real3 a, Real3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
KOKKOS_INLINE_FUNCTION Real3 operator-(Real3 a) { return {-a.x, -a.y, -a.z}; }
KOKKOS_INLINE_FUNCTION Real3 operator*(double s, Real3 a) { return {s * a.x, s * a.y, s * a.z}; }
KOKKOS_INLINE_FUNCTION Real3& operator+=(Real3& a, Real3 b) {
  a.x += b.x;
  a.y += b.y;
  a.z += b.z;
  return a;
}
KOKKOS_INLINE_FUNCTION double dot(Real3 a, Real3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
KOKKOS_INLINE_FUNCTION Real3 cross(Real3 a, Real3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
KOKKOS_INLINE_FUNCTION double norm2(Real3 a) { return dot(a, a); }
KOKKOS_INLINE_FUNCTION double norm(Real3 a) { return math::sqrt(dot(a, a)); }

// Row i of a [n][3] View as a Real3, and the reverse.
template <class View>
KOKKOS_INLINE_FUNCTION Real3 load3(const View& v, int i) {
  return {v(i, 0), v(i, 1), v(i, 2)};
}
template <class View>
KOKKOS_INLINE_FUNCTION void store3(const View& v, int i, Real3 a) {
  v(i, 0) = a.x;
  v(i, 1) = a.y;
  v(i, 2) = a.z;
}

}  // namespace dcm
