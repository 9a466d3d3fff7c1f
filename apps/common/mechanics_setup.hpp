#pragma once
// From a scene to the cells and the mechanical constants of a run (shared by the mechanics apps).
#include <cmath>
#include <string>
#include <vector>

#include "core/host_mesh.hpp"
#include "core/scene.hpp"
#include "solvers/cortex_model.hpp"
#include "solvers/time_stepper.hpp"

namespace dcm {

// Table 1 constants as the energies of docs/model/ use them (docs/MODEL.md section 3 says why):
// k_s (N/m), x_max, k_b (J) as given; c (N·s/m) the membrane's shear viscosity, each bond's dashpot
// 4c/√3 (or c itself with cortex.c_reading = bond); cortex.k_a, cortex.k_d (N/m) and cortex.k_v (Pa) are the
// constants of E = k (X − X*)² / (2 X*) for the triangle areas, the cell area and the cell volume.
inline MechanicsParams mechanics_from_scene(const Scene& scene) {
  MechanicsParams p;
  p.bonds.k_s = scene.get_real("cortex.k_s_N_per_m");
  p.bonds.x_max = scene.get_real("cortex.x_max");
  p.bond_prestretch = scene.get_real("cortex.bond_prestretch");
  if (!(p.bond_prestretch < p.bonds.x_max))
    throw SceneError("cortex.bond_prestretch = " + detail::format_real(p.bond_prestretch) +
                     " is not below cortex.x_max = " + detail::format_real(p.bonds.x_max) +
                     ": the initial bonds would be at or past d_max");
  p.k_b = scene.get_real("cortex.k_b_J");
  p.k_area_local = scene.get_real("cortex.k_a");
  p.k_area_global = scene.get_real("cortex.k_d");
  p.k_volume = scene.get_real("cortex.k_v");
  const bool relative = scene.get_string("cortex.dashpot") == "relative";
  const double c = scene.get_real("cortex.c_N_s_per_m");
  p.dashpot = scene.get_string("cortex.c_reading") == "surface_viscosity"
                  ? bond_dashpot_of_surface_viscosity(c, relative)
                  : c;
  p.dashpot_transverse = relative ? p.dashpot : 0.0;
  p.viscosity = scene.get_real("fluid.eta_Pa_s");
  p.h_min = scene.get_real("geometry.h_min_per_m");
  p.multigrid = scene.get_string("solver.preconditioner") == "multigrid";
  p.mg.sweeps = static_cast<int>(scene.get_int("solver.mg_sweeps"));
  p.mg.damping = scene.get_real("solver.mg_damping");
  p.mg.serial_rows = static_cast<int>(scene.get_int("solver.mg_serial_rows"));
  const std::string mg_bending = scene.get_string("solver.mg_bending");
  using Bending = MultigridSettings::Bending;
  p.mg.bending = mg_bending == "on" ? Bending::on : mg_bending == "off" ? Bending::off : Bending::automatic;
  p.implicit_bending = scene.get_bool("solver.implicit_bending");
  p.implicit_bonds = scene.get_bool("solver.implicit_bonds");
  p.implicit_tension = scene.get_bool("solver.implicit_tension");
  p.precondition_volume = scene.get_bool("solver.precondition_volume");
  p.gravity = scene.get_real("body.gravity_m_per_s2");
  p.density_excess = scene.get_real("body.density_excess_kg_per_m3");
  p.has_plane = scene.get_bool("contact.plane");
  if (p.has_plane) {
    p.plane.point = {0, 0, scene.get_real("contact.plane_z_m")};
    p.contact.material = md_material(scene.get_real("cortex.E_Pa"), scene.get_real("cortex.nu"),
                                     scene.get_real("contact.W_J_per_m2"), scene.get_real("contact.h0_m"));
    p.contact.quadrature_points = static_cast<int>(scene.get_int("contact.quadrature_points"));
    p.contact.projected_area = scene.get_string("contact.quadrature_area") == "projected";
    p.contact.friction_on_adhesive_zone = scene.get_string("contact.friction_zone") == "adhesive";
    p.contact.derjaguin = scene.get_string("contact.law") == "derjaguin";
    p.gamma_n = scene.get_real("contact.gamma_n_N_s_per_m3");
    p.gamma_t = scene.get_real("contact.gamma_t_N_s_per_m3");
    p.pin_friction = scene.get_real("contact.pin_friction_N_s_per_m");
    p.crease_radius = scene.get_real("contact.crease_radius_m");
    p.guard_depth = scene.get_real("contact.guard_depth_m");
    p.guard_stiffness = scene.get_real("contact.guard_stiffness_Pa_per_m");
    p.lumped_friction = scene.get_string("contact.friction_weights") != "consistent";
    p.area_friction_weights = scene.get_string("contact.friction_weights") == "area";
  }
  return p;
}

// The cell's start shape (mesh.shape).
inline HostMesh cell_mesh_from_scene(const Scene& scene) {
  const int k = static_cast<int>(scene.get_int("mesh.subdivisions"));
  BandRefinement band;
  band.levels = static_cast<int>(scene.get_int("mesh.refine_levels"));
  band.from_deg = scene.get_real("mesh.refine_from_deg");
  band.to_deg = scene.get_real("mesh.refine_to_deg");
  if (scene.get_string("mesh.shape") == "evans_fung") {
    EvansFungShape ef;
    ef.diameter = scene.get_real("mesh.diameter_m");
    return make_evans_fung(k, ef, band);
  }
  return make_icosphere(k, scene.get_real("mesh.radius_m"), band);
}

// The time-step settings (time.*). dt_min ≤ dt ≤ dt_max is checked here (one line naming the keys).
inline TimeStepSettings steps_from_scene(const Scene& scene) {
  TimeStepSettings s;
  s.dt = scene.get_real("time.dt_s");
  s.adaptive = scene.get_bool("time.adaptive");
  s.error_tol_m = scene.get_real("time.error_tol_m");
  s.dt_min = scene.get_real("time.dt_min_s");
  s.dt_max = scene.get_real("time.dt_max_s");
  s.contact_change = scene.get_real("time.contact_change");
  if (s.adaptive && !(s.dt_min <= s.dt_max))
    throw SceneError("time.dt_min_s = " + detail::format_real(s.dt_min) +
                     " is not allowed with time.adaptive = true: it must not exceed time.dt_max_s = " +
                     detail::format_real(s.dt_max));
  if (s.adaptive && !(s.dt_min <= s.dt && s.dt <= s.dt_max))
    throw SceneError("time.dt_s = " + detail::format_real(s.dt) +
                     " is not allowed with time.adaptive = true: it must "
                     "lie in [time.dt_min_s, time.dt_max_s] = [" +
                     detail::format_real(s.dt_min) + ", " + detail::format_real(s.dt_max) + "]");
  return s;
}

inline CgSettings cg_settings_from_scene(const Scene& scene) {
  CgSettings s;
  s.abs_tol = scene.get_real("solver.cg_abs_tol_N");
  s.rel_tol = scene.get_real("solver.cg_rel_tol");
  s.max_iterations = static_cast<int>(scene.get_int("solver.cg_max_iterations"));
  if (!(s.abs_tol > 0) && !(s.rel_tol > 0))
    throw SceneError(
        "solver.cg_abs_tol_N = 0 with solver.cg_rel_tol = 0 is not allowed: CG could stop only at an exactly "
        "zero residual; set one of them > 0");
  return s;
}

}  // namespace dcm
