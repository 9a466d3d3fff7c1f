#pragma once
// Error kinds that cross modules. Each maps to an exit code in apps/common/app_cli.hpp.
#include <stdexcept>

namespace dcm {

// Numerical trouble during a run (a FENE bond at d_max, a non-finite force, a solver that does not
// converge); the message names the term and the node or bond. Exit code 3.
struct NumericalError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A file that cannot be read or written (output folder, HDF5 output, checkpoint); the message names the
// file. Exit code 2.
struct IoError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace dcm
