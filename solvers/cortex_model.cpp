// CortexModel compiled once, for Kokkos' default execution space (solvers/cortex_model.hpp declares the
// instantiation extern; docs/ARCHITECTURE.md, "Compile once").
#include "solvers/cortex_model_impl.hpp"

namespace dcm {
template class CortexModel<Kokkos::DefaultExecutionSpace>;
}  // namespace dcm
