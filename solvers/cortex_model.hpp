#pragma once
// The cortex of one or more cells as a mechanical system: positions, the enabled force terms with their
// rest states, external node forces, and the friction operator. Host-side composition: a term the
// parameters switch off (constant 0) is not constructed and costs nothing.
//
//   compute_forces(): geometry, then F = Σ enabled terms + external (paper eq. 32, left-hand side)
//   energy():         Σ term energies − Σ F_ext · x (a Lyapunov function of the overdamped flow)
//   solve_velocity(): Γ v = F by PCG, warm-started from the previous v
//
// Numerical trouble (a FENE bond at d_max, a non-finite force or velocity) throws NumericalError naming
// the term and the node or bond; callers add the step.
//
// The kernels' member functions: solvers/cortex_model_impl.hpp (compiled once, solvers/cortex_model.cpp).
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/checkpoint.hpp"
#include "core/errors.hpp"
#include "core/host_copy.hpp"
#include "core/update_geometry.hpp"
#include "kernels/area_constraints.hpp"
#include "kernels/bending.hpp"
#include "kernels/contact_crease.hpp"
#include "kernels/cortex_diagnostics.hpp"
#include "kernels/external_forces.hpp"
#include "kernels/fene_pow_bonds.hpp"
#include "kernels/membrane_forces.hpp"
#include "kernels/plane_contact.hpp"
#include "kernels/substrate_guard.hpp"
#include "kernels/volume_constraint.hpp"
#include "solvers/bending_stiffness.hpp"
#include "solvers/breakdown_diagnosis.hpp"
#include "solvers/friction_operator.hpp"
#include "solvers/global_stiffness.hpp"
#include "solvers/global_woodbury.hpp"
#include "solvers/multigrid.hpp"
#include "solvers/pcg.hpp"
#include "solvers/tension_stiffness.hpp"

namespace dcm {

// Constants in the units of the energies of docs/model/ (SI). See mechanics_from_scene() for how the
// paper's Table 1 numbers map onto them.
struct MechanicsParams {
  FenePowParams bonds;            // k_s (N/m), x_max
  double bond_prestretch = 1;     // initial bond length / d* (kernels/fene_pow_bonds.hpp, make_bond_rest)
  double k_b = 0;                 // J, bending
  double k_area_local = 0;        // N/m, E = Σ k (A_t − A_t*)² / (2 A_t*)
  double k_area_global = 0;       // N/m, E = k (A − A*)² / (2 A*)
  double k_volume = 0;            // Pa,  E = k (V − V*)² / (2 V*)
  double dashpot = 0;             // c (N·s/m), along each bond (eq. 25)
  double dashpot_transverse = 0;  // c_t (N·s/m), across each bond (c_t = c: eq. 32's c (v_i − v_j))
  double viscosity = 0.8e-3;      // η (Pa·s), Stokes drag 6πηr/N per node
  double h_min = 1e4;             // 1/m, triangle curvature clamp
  bool multigrid = false;         // V-cycle preconditioner (where the mesh has an icosphere hierarchy)
  MultigridSettings mg;           // its smoother: sweeps and damping
  bool implicit_bonds = false;    // the bonds' axial stiffness Δt k'(d) in the solve (stiff FENE near d_max)
  bool implicit_bending =
      false;  // bending's Gauss-Newton stiffness in the solve (solvers/bending_stiffness.hpp)
  bool implicit_tension = false;  // the area terms' tension stiffness in the solve (tension_stiffness.hpp)
  // The implicit volume stiffness also in the preconditioner (solvers/global_woodbury.hpp).
  bool precondition_volume = false;
  double gravity = 0;         // m/s², along −z (paper eq. 32's F_gravity); 0: no gravity term
  double density_excess = 0;  // kg/m³, cell minus medium (buoyant weight Δρ V* g per cell)
  // A substrate plane with Maugis–Dugdale adhesion (kernels/plane_contact.hpp) and substrate friction
  // γ_n, γ_t (N·s/m³); no plane: no contact kernel runs.
  bool has_plane = false;
  Plane plane;
  PlaneContactParams contact;
  double gamma_n = 0, gamma_t = 0;
  double pin_friction = 0;   // N·s/m on nodes fully in contact (the paper's pinning); 0: off
  double crease_radius = 0;  // m, the fillet at the contact line (kernels/contact_crease.hpp); 0: off
  // The substrate guard (kernels/substrate_guard.hpp): nodes deeper than guard_depth below the plane are
  // pushed back with guard_stiffness (Pa/m) per metre past it; guard_stiffness = 0: off.
  double guard_depth = 0, guard_stiffness = 0;
  bool lumped_friction =
      true;  // substrate friction w_i Γ_t per node (false: β_i β_j Γ_t), friction_operator.hpp
  bool area_friction_weights = true;  // lumped: w_i from the friction area's centroid (false: the load's)
  // With bonds, bending, area and volume terms: the fused membrane pass (kernels/membrane_forces.hpp;
  // false: one kernel per term). The same forces to rounding.
  bool fused_membrane = true;
};

// Why cells with parameters a and b cannot share the buffers of one batch ("" if they can): what decides
// which terms, kernels and solver options exist must agree; the constants themselves may differ.
inline std::string batch_mismatch(const MechanicsParams& a, const MechanicsParams& b) {
  auto on = [](double k) { return k != 0; };
  struct Switch {
    const char* name;
    bool differs;
  };
  const Switch checks[] = {
      {"bonds on/off (k_s = 0)", on(a.bonds.k_s) != on(b.bonds.k_s)},
      {"bending on/off (k_b = 0)", on(a.k_b) != on(b.k_b)},
      {"local area term on/off", on(a.k_area_local) != on(b.k_area_local)},
      {"global area term on/off", on(a.k_area_global) != on(b.k_area_global)},
      {"volume term on/off", on(a.k_volume) != on(b.k_volume)},
      {"dashpots on/off",
       on(a.dashpot) != on(b.dashpot) || on(a.dashpot_transverse) != on(b.dashpot_transverse)},
      {"the curvature clamp h_min", a.h_min != b.h_min},
      {"the preconditioner (multigrid, its sweeps and damping)",
       a.multigrid != b.multigrid || a.mg.sweeps != b.mg.sweeps || a.mg.damping != b.mg.damping ||
           a.mg.serial_rows != b.mg.serial_rows || a.mg.bending != b.mg.bending ||
           a.precondition_volume != b.precondition_volume},
      {"the implicit terms", a.implicit_bonds != b.implicit_bonds ||
                                 a.implicit_bending != b.implicit_bending ||
                                 a.implicit_tension != b.implicit_tension},
      {"gravity on/off", on(a.gravity * a.density_excess) != on(b.gravity * b.density_excess)},
      {"the plane",
       a.has_plane != b.has_plane ||
           (a.has_plane && (a.plane.point.x != b.plane.point.x || a.plane.point.y != b.plane.point.y ||
                            a.plane.point.z != b.plane.point.z || a.plane.normal.x != b.plane.normal.x ||
                            a.plane.normal.y != b.plane.normal.y || a.plane.normal.z != b.plane.normal.z))},
      {"the contact law or its integration (quadrature points, projected area, friction zone)",
       a.contact.derjaguin != b.contact.derjaguin ||
           a.contact.quadrature_points != b.contact.quadrature_points ||
           a.contact.projected_area != b.contact.projected_area ||
           a.contact.friction_on_adhesive_zone != b.contact.friction_on_adhesive_zone},
      {"substrate friction on/off", on(a.gamma_n) != on(b.gamma_n) || on(a.gamma_t) != on(b.gamma_t) ||
                                        on(a.pin_friction) != on(b.pin_friction)},
      {"the crease at the contact line on/off", on(a.crease_radius) != on(b.crease_radius)},
      {"the substrate guard on/off", on(a.guard_stiffness) != on(b.guard_stiffness)},
      {"the membrane pass (fused or per term)", a.fused_membrane != b.fused_membrane},
      {"lumped substrate friction",
       a.lumped_friction != b.lumped_friction || a.area_friction_weights != b.area_friction_weights},
  };
  for (const Switch& s : checks)
    if (s.differs) return std::string("they differ in ") + s.name;
  return "";
}

// Index of the first node with a non-finite component, or -1.
template <class ExecutionSpace, class Vector>
int first_non_finite_node(const ExecutionSpace& space, const Vector& v) {
  const int n = static_cast<int>(v.extent(0));
  int first = n;
  Kokkos::parallel_reduce(
      "dcm::model::check_finite", Kokkos::RangePolicy<ExecutionSpace>(space, 0, n),
      KOKKOS_LAMBDA(const int i, int& m) {
        const bool ok = math::isfinite(v(i, 0)) && math::isfinite(v(i, 1)) && math::isfinite(v(i, 2));
        if (!ok && i < m) m = i;
      },
      Kokkos::Min<int>(first));
  return first < n ? first : -1;
}

template <class ExecutionSpace>
class CortexModel {
 public:
  using Mem = typename ExecutionSpace::memory_space;
  using Vector = Kokkos::View<double* [3], Kokkos::LayoutRight, Mem>;

  // The rest state of every term is the shape the cells are given in.
  CortexModel(const ExecutionSpace& space, const std::vector<HostCell>& cells, const MechanicsParams& p)
      : CortexModel(space, cells, std::vector<MechanicsParams>(cells.size(), p)) {}
  // A batch: cell c with the constants cell_params[c] (the batched engine, docs/SCANS.md). The constants may
  // differ from cell to cell; what decides which terms and kernels exist must not (batch_mismatch()).
  // Each cell then computes exactly what it computes alone.
  CortexModel(const ExecutionSpace& space, const std::vector<HostCell>& cells,
              const std::vector<MechanicsParams>& cell_params);

  // The last solve's bending_ratio() (largest over the cells; 0 without the multigrid) and whether the
  // multigrid's level 0 held the bending of some cell (MultigridSettings::Bending).
  double last_bending_ratio() const { return last_bending_ratio_; }
  bool last_bending_preconditioned() const { return multigrid_ && multigrid_->bending_in_level0; }
  // How many solves have built what only the preconditioner needs (solve_velocity builds it on the first
  // application; a solve whose warm start meets the tolerance builds none).
  long long preconditioner_builds() const { return preconditioner_builds_; }
  const MeshBuffers<Mem>& mesh() const { return mesh_; }
  const GeometryBuffers<Mem>& geometry() const { return geo_; }
  const MechanicsParams& params() const { return params_; }  // cell 0's (structure: the same for all)
  const MechanicsParams& cell_params(int c) const { return cell_params_.at(c); }
  int n_cells() const { return mesh_.n_cells; }
  const Vector& positions() const { return mesh_.x; }
  const Vector& force() const { return force_; }
  const Vector& velocity() const { return velocity_; }
  const Vector& external_force() const { return external_; }  // set by the caller; zero at start
  const ExecutionSpace& space() const { return space_; }
  const FrictionOperator<Mem>& friction() const { return friction_; }
  // Each cell's part of the last velocity solve (iterations, residual, convergence): the CG is per cell.
  const std::vector<CgResult>& cell_solves() const { return cg_.segment_results; }
  // The node normals, areas and curvatures and the rounded triangles' spheres of the current positions,
  // which compute_forces() leaves out unless the paper's contact law needs them (a no-op then).
  void refresh_curvature() const;
  // Per-triangle contact results of the last compute_forces() (empty without a plane).
  const std::optional<ContactBuffers<Mem>>& contact() const { return contact_; }
  // Per-node tension (eq. 1), stretch, normal force and pressure of the current state (compute_forces()
  // first); needs the bond term.
  void node_fields(const NodeFields<Mem>& out) const;
  // The state a step of a cell starts from: its positions and last velocity (the warm start of the next
  // solve). The rest states, parameters and external forces are not saved: they come from the scene. A
  // batch member's checkpoint is the checkpoint of its one-cell run.
  void save_cell_state(Checkpoint& c, int cell) const {
    c.put("model.x", cell_slice(mesh_.x, cell));
    c.put("model.v", cell_slice(velocity_, cell));
  }
  // Flat [n][3] values of a cell's nodes.
  std::vector<double> cell_slice(const Vector& v, int cell) const;
  // Writes flat [n][3] values into a cell's nodes.
  void set_cell_slice(const Vector& v, int cell, const std::vector<double>& values) const;
  // One cell's state from a checkpoint of it (save_cell_state()).
  void restore_cell_state(const Checkpoint& c, int cell);
  // Rest-state edits for shape finding (apps/deflate): every cell's target volume times `factor` (no-op
  // without a volume term), and flat hinges (θ* = 0: no spontaneous curvature; no-op without bending).
  void scale_rest_volume(double factor);
  void set_flat_bending_rest();
  // Largest d / d_max over each cell's bonds at the current positions (a batch's cells step on their own; a
  // non-finite length counts as infinitely long; 0 without bonds).
  std::vector<double> cell_max_bond_extension() const;

  // For a message (host, on the failure path only): the bond of `cell` nearest its maximum length, as
  // describe_overstretch() names it with its stretch d / d_max appended; "" without bonds.
  std::string describe_most_extended_bond(int cell) const;

  // Power of the contact forces at the current velocity (W); 0 without a plane.
  // per_cell (optional): each cell's value, for these and the contact area and load below.
  double contact_power(std::vector<double>* per_cell = nullptr) const;
  // The adhesion energy of contact.law = "derjaguin" (J; 0 for the paper's Maugis–Dugdale pressure, which is
  // not the gradient of an energy). energy() leaves it out: spread balances it as the contact power.
  double adhesion_energy(std::vector<double>* per_cell = nullptr) const;
  double contact_area(std::vector<double>* per_cell = nullptr) const;
  double contact_load(std::vector<double>* per_cell = nullptr) const;

  // Geometry, then the total force on every node.
  void compute_forces();

  // The contact of the current positions (the geometry and the contact stage of compute_forces(), no forces):
  // what contact_area(), contact_load() and contact() report after a step has moved the nodes. The contact
  // kernels keep no state between calls, so the next compute_forces() at these positions computes the same.
  void update_contact();

  // Total energy for the current positions (calls update_geometry()).
  // per_cell (optional): each cell's energy, the same terms added in the same order (a batch's cell gets
  // the bits it gets alone).
  double energy(std::vector<double>* per_cell = nullptr);

  // Γ v = F for the current positions and forces (compute_forces() first), warm-started from the last v.
  // With dt > 0 the global area and volume constraints (and bending, if params().implicit_bending) are taken
  // linearly implicit, (Γ + dt K) v = F (solvers/global_stiffness.hpp, bending_stiffness.hpp); dt = 0 solves
  // Γ v = F. Without dashpots and implicit terms Γ is
  // diagonal and the solve is one multiplication per node.
  // With params().implicit_bonds, the bonds' axial stiffness too (Δt k n̂n̂ᵀ per bond, k the larger of the
  // tangent and the secant to half-way to d_max, kernels/fene_pow_bonds.hpp; added to the dashpot
  // coefficient in the friction operator): a FENE bond close to d_max does not overshoot it.
  // With throw_if_unconverged = false a solve that reaches the iteration cap returns converged = false
  // (the time stepper then retries with a shorter step; unconverged_message() says what happened).
  CgResult solve_velocity(const CgSettings& settings, double dt = 0, bool throw_if_unconverged = true) {
    return solve_velocity(settings, std::vector<double>(mesh_.n_cells, dt), nullptr, throw_if_unconverged);
  }
  // A batch: cell c's implicit terms for its own step dt_cells[c] (all > 0, or all 0); cells flagged in
  // `frozen` keep their velocity (they are not stepping now). cell_solves() has each cell's result.
  CgResult solve_velocity(const CgSettings& settings, const std::vector<double>& dt_cells,
                          const std::vector<char>* frozen, bool throw_if_unconverged = true);

  // F · v: the rate at which the forces do work on the current velocity (W); with the explicit step it
  // equals the dissipation vᵀΓv, with the implicit global terms it is vᵀ(Γ + dt K)v.
  double power();

  // The node with the largest total force (the first, if several); for messages.
  int largest_force_node() const;

  // After a solve that broke down (CgResult::breakdown) the workspace still holds the search direction p
  // along which p·(Γ + Δt K)p was not positive. Each term of the operator is applied to p alone; the text
  // gives, for cell `cell`, every term's p·A_term p (W) and names the first that is not positive, with the
  // node where p_i·(A_term p)_i is lowest (or first not finite). For the messages of a failed step.
  std::string describe_breakdown(int cell);

  static std::string unconverged_message(const CgResult& r, const CgSettings& settings) {
    char msg[300];
    if (r.breakdown) {
      std::snprintf(msg, sizeof msg,
                    "conjugate gradients broke down at iteration %d: p.A p = %.3g W is not positive "
                    "(the operator Gamma + dt K is not positive definite along a search direction)",
                    r.iterations, r.curvature);
      return msg;
    }
    std::snprintf(
        msg, sizeof msg,
        "conjugate gradients did not converge in %d iterations (residual %.3g N, tolerance %.3g N, "
        "|F| = %.3g N); raise solver.cg_max_iterations or solver.cg_rel_tol",
        r.iterations, r.residual_norm,
        settings.abs_tol > settings.rel_tol * r.rhs_norm ? settings.abs_tol : settings.rel_tol * r.rhs_norm,
        r.rhs_norm);
    return msg;
  }

  // x += dt v (forward Euler, paper eq. 32 integrated explicitly).
  void advance(double dt);

  // vᵀ Γ v: the power dissipated by the friction (W), for the energy balance.
  double dissipation(std::vector<double>* per_cell = nullptr);

 private:
  // ζ_i = 6 π η r / N per cell, r the radius of the sphere with the cell's rest area.
  // Gravity: each cell's buoyant weight Δρ V* g (V* its volume at construction), shared equally by its
  // nodes, along −z. A constant field, so its energy is −Σ F_i · x_i like the external forces.
  Vector node_weights(const std::vector<HostCell>& cells);

  // Per cell, bending_ratio() for Δt k_b = 1 J·s (solvers/multigrid.hpp): h the mean rest bond length, R the
  // radius of the sphere of the rest area.
  std::vector<double> bending_scales(const std::vector<HostCell>& cells) const;

  // The cells whose bending goes into the multigrid's level 0 this step (MultigridSettings::Bending), each
  // decided from its own Δt and constants: a cell's preconditioner does not depend on its batch.
  void select_bending_cells(const std::vector<double>& dt_cells) {
    using B = MultigridSettings::Bending;
    last_bending_ratio_ = 0;
    bending_cells_.assign(cell_bending_scale_.size(), 0);
    for (std::size_t c = 0; c < cell_bending_scale_.size(); ++c) {
      const double ratio = dt_cells[c] * k_b_.host[c] * cell_bending_scale_[c];
      last_bending_ratio_ = std::max(last_bending_ratio_, ratio);
      bending_cells_[c] = params_.mg.bending == B::on ||
                          (params_.mg.bending == B::automatic && ratio >= MultigridSettings::kAutoRatio);
    }
  }

  Kokkos::View<double*, Kokkos::LayoutRight, Mem> node_drag(const std::vector<HostCell>& cells);

  // Failure path only: each force term evaluated alone into a scratch vector, visit(name, scratch) after each
  // (in the order of compute_forces()); visit returns true to stop.
  template <class Visit>
  void for_each_force_term(Visit&& visit);

  // Failure path only: the term that produced the non-finite force at `node`.
  std::string term_with_non_finite_force(int node);

 public:
  // For the messages of an equilibrium that was not reached: "node N (|F| = X N; largest term there: T, Y N)"
  // for the node with the largest total force (compute_forces() first), external forces included in |F|.
  std::string describe_largest_force();

 private:
  std::string describe_overstretch(int bond) const;

  // The per-cell constant tables the kernels read (core/cell_params.hpp).
  void make_cell_tables();

  // Cell 0's parameters, after checking that every cell has the same structure (batch_mismatch()).
  static MechanicsParams checked_batch(const std::vector<HostCell>& cells,
                                       const std::vector<MechanicsParams>& p) {
    if (p.empty() || p.size() != cells.size())
      throw std::invalid_argument("CortexModel: " + std::to_string(p.size()) + " parameter sets for " +
                                  std::to_string(cells.size()) + " cells");
    for (std::size_t c = 1; c < p.size(); ++c) {
      const std::string what = batch_mismatch(p[0], p[c]);
      if (!what.empty())
        throw std::invalid_argument("cells 0 and " + std::to_string(c) + " cannot share a batch: " + what);
    }
    return p[0];
  }

  ExecutionSpace space_;
  MechanicsParams params_;                    // cell 0's
  std::vector<MechanicsParams> cell_params_;  // every cell's
  PerCell<FenePowParams, Mem> bond_params_;
  PerCell<double, Mem> k_b_, k_area_local_, k_area_global_, k_volume_;
  PerCell<PlaneContactParams, Mem> contact_params_;
  PerCell<double, Mem> dt_{std::vector<double>{}, "dcm::model::dt"};  // each cell's step in the last solve
  MeshBuffers<Mem> mesh_;
  GeometryBuffers<Mem> geo_;
  Vector force_, velocity_, external_;
  Kokkos::View<int, Mem> overstretched_;
  std::optional<BondRest<Mem>> bonds_;
  std::optional<HingeRest<Mem>> hinges_;
  std::optional<AreaRest<Mem>> area_;
  std::optional<VolumeRest<Mem>> volume_;
  std::optional<MembraneScratch<Mem>> membrane_;  // set: the fused membrane pass
  std::optional<GlobalStiffness<Mem>> global_;
  std::optional<GlobalWoodbury<Mem>> woodbury_;  // set: the volume term in the preconditioner
  std::optional<Multigrid<Mem>> multigrid_;
  std::vector<double>
      cell_bending_scale_;               // per cell, bending_ratio() per J·s of Δt k_b (with the multigrid)
  long long preconditioner_builds_ = 0;  // preconditioner_builds()
  double last_bending_ratio_ = 0;        // the largest cell's bending_ratio() of the last solve
  std::vector<char> bending_cells_;      // per cell: its bending in the multigrid's level 0 (last solve)
  std::optional<BendingStiffness<Mem>> bending_stiffness_;
  std::optional<TensionStiffness<Mem>> tension_stiffness_;
  std::optional<Vector> gravity_;
  std::optional<ContactBuffers<Mem>> contact_;
  std::optional<PerCell<CreaseLaw, Mem>> crease_;      // per cell; empty: off
  std::optional<PerCell<SubstrateGuard, Mem>> guard_;  // per cell; empty: off
  // The guard's fixed node areas A_i, its k_g A_i where it acts (compute_forces()) and Δt k_g A_i (the
  // solve).
  Kokkos::View<double*, Kokkos::LayoutRight, Mem> guard_area_, guard_k_, guard_dt_;
  // The curvature and the rounded triangles' spheres are updated each step only for the paper's contact law
  // (core/update_geometry.hpp); refresh_curvature() brings them up to date for output.
  bool rounded_geometry_ = true;
  FrictionOperator<Mem> friction_;
  CgWorkspace<Mem> cg_;
  bool last_solve_implicit_ = false;  // the last solve_velocity() had Δt > 0 (describe_breakdown())
};

// The member functions that run kernels are defined in solvers/cortex_model_impl.hpp and compiled once, for
// Kokkos' default execution space, in solvers/cortex_model.cpp (the dcm_model library): the apps and tests
// that use the model do not each compile its kernels again (docs/ARCHITECTURE.md, "Compile once"). Code that
// needs the model on another execution space includes solvers/cortex_model_impl.hpp.
extern template class CortexModel<Kokkos::DefaultExecutionSpace>;

}  // namespace dcm
