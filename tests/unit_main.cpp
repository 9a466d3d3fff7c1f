// GoogleTest main for dcm tests: Kokkos lives for the whole test program.
#include <gtest/gtest.h>

#include "core/kokkos_compat.hpp"

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  dcm::KokkosSession kokkos;
  return RUN_ALL_TESTS();
}
