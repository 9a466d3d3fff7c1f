#pragma once
// The paper's Table 1 cortex as dcm read it until session 29 (docs/MODEL.md; the dashpot per bond), for tests
// that build a CortexModel.
#include <cmath>

#include "solvers/cortex_model.hpp"

namespace dcm::test_params {

inline MechanicsParams table1_cortex() {
  MechanicsParams p;
  p.bonds = {3.2e-6, 2.05};  // k_s (N/m), x_max
  p.k_b = 240e-21;           // J
  p.k_area_local = 6e-3;     // N/m
  p.k_area_global = 6e-3;    // N/m
  p.k_volume = 1e4;          // Pa
  p.dashpot = 1.5e-6;    // N·s/m per bond: Table 1's c per bond (cortex.c_reading = bond; the apps: 4c/√3)
  p.viscosity = 0.8e-3;  // Pa·s
  return p;
}

// Table 1 on a plane the sphere of radius r just overlaps (contact radius a), with the spreading scene's
// solver options (multigrid, implicit bending and tension) and substrate friction (Hategan's W = 1 mJ/m²,
// h0 = 20 nm, γ_n = 8e9, γ_t = 6e9 N·s/m³).
inline MechanicsParams spreading_on_plane(double r, double a) {
  MechanicsParams p = table1_cortex();
  p.multigrid = true;
  p.implicit_bending = true;
  p.implicit_tension = true;
  p.has_plane = true;
  p.plane.point = {0, 0, -r + (r - std::sqrt(r * r - a * a))};
  p.contact.material = md_material(800e3, 0.4, 1e-3, 20e-9);
  p.gamma_n = 8e9;
  p.gamma_t = 6e9;
  return p;
}

}  // namespace dcm::test_params
