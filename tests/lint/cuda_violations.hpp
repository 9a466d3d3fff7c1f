// Not compiled: input of the ctest lint.cuda_lint_catches, which expects scripts/cuda_lint.py to report each
// of the six rules below once (and nothing in the comments or strings: "std::string KOKKOS_LAMBDA { this }").
#include <Kokkos_Core.hpp>
#include <cmath>

template <bool Flag, class View>
void kernel_with_everything(const View& v) {
  Kokkos::parallel_for(
      "bad", 10, KOKKOS_LAMBDA(const int i) {
        double x = std::sqrt(2.0);      // device-std
        if constexpr (Flag) x += v(i);  // lambda-constexpr-if
        if (x < 0) throw 1;             // device-throw
        v(i) = x + this->offset;        // lambda-this
      });
}

KOKKOS_INLINE_FUNCTION double h() {
  struct L {
    virtual ~L() = default;  // device-virtual
  };
  return 0;
}

TEST(Lint, LambdaInTestBody) {
  Kokkos::parallel_for("t", 1, KOKKOS_LAMBDA(const int){});  // lambda-in-test
}
