#include "core/kokkos_compat.hpp"

#include <cstdlib>
#include <sstream>
#include <string>

namespace dcm {

void initialize_kokkos(int num_threads) {
  setenv("OMP_PROC_BIND", "false", /*overwrite=*/0);
#if KOKKOS_VERSION >= 30700
  Kokkos::InitializationSettings settings;
  if (num_threads > 0) settings.set_num_threads(num_threads);
  Kokkos::initialize(settings);
#else
  Kokkos::InitArguments args;
  if (num_threads > 0) args.num_threads = num_threads;
  Kokkos::initialize(args);
#endif
}

std::string kokkos_description() {
  std::ostringstream s;
  s << "Kokkos " << KOKKOS_VERSION / 10000 << '.' << (KOKKOS_VERSION / 100) % 100 << '.'
    << KOKKOS_VERSION % 100 << ", execution space " << Kokkos::DefaultExecutionSpace::name();
  if (Kokkos::SpaceAccessibility<Kokkos::DefaultExecutionSpace, Kokkos::HostSpace>::accessible)
    s << " (" << Kokkos::DefaultExecutionSpace().concurrency() << " threads)";
  else  // a device: its concurrency counts GPU threads, not what --threads sets
    s << " (a device; host " << Kokkos::DefaultHostExecutionSpace::name() << " with "
      << Kokkos::DefaultHostExecutionSpace().concurrency() << " threads)";
  return s.str();
}

}  // namespace dcm
