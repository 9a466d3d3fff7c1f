#pragma once
// The paper's Table 1 cortex as dcm reads it (docs/MODEL.md), for tests that build a CortexModel.
#include "solvers/cortex_model.hpp"

namespace dcm::test_params {

inline MechanicsParams table1_cortex() {
  MechanicsParams p;
  p.bonds = {3.2e-6, 2.05};  // k_s (N/m), x_max
  p.k_b = 240e-21;           // J
  p.k_area_local = 6e-3;     // N/m
  p.k_area_global = 6e-3;    // N/m
  p.k_volume = 1e4;          // Pa
  p.dashpot = 1.5e-6;        // N·s/m
  p.viscosity = 0.8e-3;      // Pa·s
  return p;
}

}  // namespace dcm::test_params
