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
              const std::vector<MechanicsParams>& cell_params)
      : space_(space),
        params_(checked_batch(cells, cell_params)),
        cell_params_(cell_params),
        mesh_(upload_cells<Mem>(cells)),
        geo_(mesh_),
        force_(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::model::force"), mesh_.n_nodes),
        velocity_("dcm::model::velocity", mesh_.n_nodes),
        external_("dcm::model::external_force", mesh_.n_nodes),
        overstretched_("dcm::model::overstretched"),
        cg_(mesh_.host_cell_node_begin) {
    const MechanicsParams& p = params_;
    make_cell_tables();
    update_geometry(space_, mesh_, geo_, p.h_min);
    if (p.bonds.k_s > 0) {
      std::vector<double> prestretch;
      for (const MechanicsParams& q : cell_params_) prestretch.push_back(q.bond_prestretch);
      bonds_ = make_bond_rest(space_, mesh_, prestretch);
    }
    if (p.k_b > 0) hinges_ = make_hinge_rest(space_, mesh_);
    if (p.k_b > 0 && p.implicit_bending) bending_stiffness_ = BendingStiffness<Mem>(mesh_);
    if (p.k_area_local > 0 || p.k_area_global > 0) area_ = make_area_rest(space_, mesh_, geo_);
    if (area_ && p.implicit_tension) tension_stiffness_ = TensionStiffness<Mem>(mesh_);
    if (p.k_volume > 0) volume_ = make_volume_rest(space_, mesh_, geo_);
    if (p.fused_membrane && bonds_ && hinges_ && area_ && volume_ && bonds_match_hinges(mesh_))
      membrane_ = MembraneScratch<Mem>(mesh_);
    if (p.k_area_global > 0 || p.k_volume > 0)
      global_ = GlobalStiffness<Mem>(mesh_, p.k_area_global > 0, p.k_volume > 0);
    if (global_ && global_->volume && p.precondition_volume) woodbury_ = GlobalWoodbury<Mem>(mesh_);
    if (p.gravity != 0 && p.density_excess != 0) gravity_ = node_weights(cells);
    friction_ = FrictionOperator<Mem>(mesh_, node_drag(cells), p.dashpot, p.dashpot_transverse);
    rounded_geometry_ = p.has_plane && !p.contact.derjaguin;
    if (p.has_plane) {
      contact_ = ContactBuffers<Mem>(mesh_.n_tris, p.contact.derjaguin);
      if (p.gamma_n > 0 || p.gamma_t > 0 || p.pin_friction > 0)
        enable_substrate_friction(friction_, *contact_, p.gamma_n, p.gamma_t, p.plane.normal, p.pin_friction,
                                  p.lumped_friction, p.area_friction_weights);
      if (p.crease_radius > 0) {  // each cell's own W, h0 and fillet radius (on in every cell or in none)
        std::vector<CreaseLaw> laws;
        for (const MechanicsParams& q : cell_params_)
          laws.push_back(CreaseLaw{q.contact.material.W, q.contact.material.h0, q.crease_radius, p.plane});
        crease_ = PerCell<CreaseLaw, Mem>(laws, "dcm::model::crease");
      }
      if (p.guard_stiffness > 0) {  // each cell's own depth and stiffness (on in every cell or in none)
        std::vector<SubstrateGuard> guards;
        for (const MechanicsParams& q : cell_params_)
          guards.push_back(SubstrateGuard{q.guard_depth, q.guard_stiffness, p.plane});
        guard_ = PerCell<SubstrateGuard, Mem>(guards, "dcm::model::guard");
        // Each node's area in the start shape: fixed, so that the guard's force is its energy's gradient.
        guard_area_ =
            Kokkos::View<double*, Kokkos::LayoutRight, Mem>("dcm::model::guard_area", mesh_.n_nodes);
        Kokkos::deep_copy(space_, guard_area_, geo_.node_area);
        guard_k_ = Kokkos::View<double*, Kokkos::LayoutRight, Mem>("dcm::model::guard_k", mesh_.n_nodes);
        guard_dt_ = Kokkos::View<double*, Kokkos::LayoutRight, Mem>("dcm::model::guard_k_dt", mesh_.n_nodes);
        friction_.substrate_normal = (1.0 / norm(p.plane.normal)) * p.plane.normal;
      }
    }
    for (const MechanicsParams& q : cell_params_)
      friction_.cell_rows.push_back({q.dashpot, q.dashpot_transverse, q.gamma_n, q.gamma_t, q.pin_friction});
    if (p.multigrid && (p.dashpot > 0 || p.dashpot_transverse > 0)) {
      MultigridSettings mg = p.mg;  // no recipe for a bending that never enters the solve
      if (p.k_b == 0 || !p.implicit_bending) mg.bending = MultigridSettings::Bending::off;
      multigrid_ = make_multigrid(cells, mesh_, mg);
      if (!multigrid_->available) multigrid_.reset();  // no hierarchy: block-Jacobi
      if (multigrid_) cell_bending_scale_ = bending_scales(cells);
    }
  }

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
  void refresh_curvature() const {
    if (rounded_geometry_) return;
    compute_node_curvature(space_, mesh_, geo_);
    compute_triangle_curvature(space_, mesh_, geo_, params_.h_min);
    compute_rounded_triangles(space_, mesh_, geo_);
  }
  // Per-triangle contact results of the last compute_forces() (empty without a plane).
  const std::optional<ContactBuffers<Mem>>& contact() const { return contact_; }
  // Per-node tension (eq. 1), stretch, normal force and pressure of the current state (compute_forces()
  // first); needs the bond term.
  void node_fields(const NodeFields<Mem>& out) const {
    if (!bonds_) throw std::logic_error("node_fields() needs the FENE+POW bond term");
    refresh_curvature();
    compute_node_fields(space_, mesh_, geo_, *bonds_, bond_params_.table(), force_, out);
  }
  // The state a step of a cell starts from: its positions and last velocity (the warm start of the next
  // solve). The rest states, parameters and external forces are not saved: they come from the scene. A
  // batch member's checkpoint is the checkpoint of its one-cell run.
  void save_cell_state(Checkpoint& c, int cell) const {
    c.put("model.x", cell_slice(mesh_.x, cell));
    c.put("model.v", cell_slice(velocity_, cell));
  }
  // Flat [n][3] values of a cell's nodes.
  std::vector<double> cell_slice(const Vector& v, int cell) const {
    const auto all = to_host_vector(v);
    const int b = mesh_.host_cell_node_begin.at(cell), e = mesh_.host_cell_node_begin.at(cell + 1);
    return std::vector<double>(all.begin() + 3 * b, all.begin() + 3 * e);
  }
  // Writes flat [n][3] values into a cell's nodes.
  void set_cell_slice(const Vector& v, int cell, const std::vector<double>& values) const {
    auto all = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), v);
    const int b = mesh_.host_cell_node_begin.at(cell), e = mesh_.host_cell_node_begin.at(cell + 1);
    if (values.size() != 3 * static_cast<std::size_t>(e - b))
      throw std::invalid_argument("set_cell_slice: " + std::to_string(values.size() / 3) +
                                  " nodes for a cell of " + std::to_string(e - b));
    for (int i = b; i < e; ++i)
      for (int d = 0; d < 3; ++d) all(i, d) = values[3 * (i - b) + d];
    Kokkos::deep_copy(v, all);
  }
  // One cell's state from a checkpoint of it (save_cell_state()).
  void restore_cell_state(const Checkpoint& c, int cell) {
    set_cell_slice(mesh_.x, cell, c.array("model.x"));
    set_cell_slice(velocity_, cell, c.array("model.v"));
    update_geometry(space_, mesh_, geo_, params_.h_min, rounded_geometry_);
  }
  // Rest-state edits for shape finding (apps/deflate): every cell's target volume times `factor` (no-op
  // without a volume term), and flat hinges (θ* = 0: no spontaneous curvature; no-op without bending).
  void scale_rest_volume(double factor) {
    if (!volume_) return;
    const auto v = volume_->cell_volume;
    Kokkos::parallel_for(
        "dcm::model::scale_rest_volume", Kokkos::RangePolicy<ExecutionSpace>(space_, 0, v.extent(0)),
        KOKKOS_LAMBDA(const int c) { v(c) *= factor; });
    space_.fence();
  }
  void set_flat_bending_rest() {
    if (hinges_) set_hinge_rest_angles(*hinges_, {0.0});
  }
  // Largest d / d_max over each cell's bonds at the current positions (a batch's cells step on their own; a
  // non-finite length counts as infinitely long; 0 without bonds).
  std::vector<double> cell_max_bond_extension() const {
    std::vector<double> m(mesh_.n_cells, 0.0);
    if (!bonds_) return m;
    const auto x = mesh_.x;
    const auto bond = mesh_.bond;
    const auto rest = bonds_->rest_length;
    const auto bond_cell = mesh_.bond_cell;
    const auto table = bond_params_.table();
    segmented_max(
        "dcm::model::cell_max_bond_extension", space_, mesh_.bond_sums,
        KOKKOS_LAMBDA(const int b) {
          const double x_max = cell_value(table, bond_cell(b)).x_max;
          const double e = norm(load3(x, bond(b, 1)) - load3(x, bond(b, 0))) / (x_max * rest(b));
          return e <= 1e300 ? e : 1e308;
        },
        m);
    return m;
  }

  // For a message (host, on the failure path only): the bond of `cell` nearest its maximum length, as
  // describe_overstretch() names it with its stretch d / d_max appended; "" without bonds.
  std::string describe_most_extended_bond(int cell) const {
    if (!bonds_) return "";
    const auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh_.x);
    const auto b = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh_.bond);
    const auto rest = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), bonds_->rest_length);
    const auto bond_cell = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh_.bond_cell);
    const double x_max = cell_params_.at(cell).bonds.x_max;
    int best = -1;
    double worst = -1;
    for (int k = 0; k < static_cast<int>(b.extent(0)); ++k) {
      if (bond_cell(k) != cell) continue;
      double d2 = 0;
      for (int dim = 0; dim < 3; ++dim) d2 += std::pow(x(b(k, 1), dim) - x(b(k, 0), dim), 2);
      const double e = std::sqrt(d2) / (x_max * rest(k));
      if (!(e <= worst)) {  // (a non-finite length wins)
        worst = e;
        best = k;
      }
    }
    if (best < 0) return "";
    char stretch[48];
    std::snprintf(stretch, sizeof stretch, "%.6f", worst);
    return "FENE bond " + std::to_string(best) + ", nodes " + std::to_string(b(best, 0)) + "-" +
           std::to_string(b(best, 1)) + ", at " + stretch + " of d_max";
  }

  // Power of the contact forces at the current velocity (W); 0 without a plane.
  // per_cell (optional): each cell's value, for these and the contact area and load below.
  double contact_power(std::vector<double>* per_cell = nullptr) const {
    if (per_cell) per_cell->assign(mesh_.n_cells, 0.0);
    return contact_ ? dcm::contact_power(space_, mesh_, params_.plane, *contact_, velocity_, per_cell) : 0.0;
  }
  // The adhesion energy of contact.law = "derjaguin" (J; 0 for the paper's Maugis–Dugdale pressure, which is
  // not the gradient of an energy). energy() leaves it out: spread balances it as the contact power.
  double adhesion_energy(std::vector<double>* per_cell = nullptr) const {
    if (per_cell) per_cell->assign(mesh_.n_cells, 0.0);
    return contact_ ? derjaguin_energy(space_, mesh_, params_.plane, contact_params_.table(), per_cell) : 0.0;
  }
  double contact_area(std::vector<double>* per_cell = nullptr) const {  // Σ A^C_t
    if (per_cell) per_cell->assign(mesh_.n_cells, 0.0);
    return contact_ ? total_contact_area(space_, mesh_, *contact_, per_cell) : 0.0;
  }
  double contact_load(std::vector<double>* per_cell = nullptr) const {  // N
    if (per_cell) per_cell->assign(mesh_.n_cells, 0.0);
    return contact_ ? total_contact_load(space_, mesh_, *contact_, per_cell) : 0.0;
  }

  // Geometry, then the total force on every node.
  void compute_forces() {
    update_geometry(space_, mesh_, geo_, params_.h_min, rounded_geometry_);
    Kokkos::deep_copy(space_, force_, 0.0);
    if (membrane_) {  // all four membrane terms in three passes (kernels/membrane_forces.hpp)
      Kokkos::deep_copy(space_, overstretched_, -1);
      add_membrane_forces(space_, mesh_, geo_, *bonds_, bond_params_.table(), *hinges_, k_b_.table(), *area_,
                          k_area_local_.table(), k_area_global_.table(), *volume_, k_volume_.table(),
                          *membrane_, force_, overstretched_);
      int bad = -1;
      space_.fence();  // the scalar deep_copy below does not wait for space_'s kernels in Kokkos 3.x
      Kokkos::deep_copy(bad, overstretched_);
      if (bad >= 0) throw NumericalError(describe_overstretch(bad));
    } else {
      if (bonds_) {
        Kokkos::deep_copy(space_, overstretched_, -1);
        add_fene_pow_forces(space_, mesh_, *bonds_, bond_params_.table(), force_, overstretched_);
        int bad = -1;
        space_.fence();
        Kokkos::deep_copy(bad, overstretched_);
        if (bad >= 0) throw NumericalError(describe_overstretch(bad));
      }
      if (hinges_) add_bending_forces(space_, mesh_, *hinges_, k_b_.table(), force_);
      if (area_)
        add_area_forces(space_, mesh_, geo_, *area_, k_area_local_.table(), k_area_global_.table(), force_);
      if (volume_) add_volume_forces(space_, mesh_, geo_, *volume_, k_volume_.table(), force_);
    }
    add_external_forces(space_, external_, force_);
    if (gravity_) add_external_forces(space_, *gravity_, force_);
    if (contact_) {
      compute_plane_contact(space_, mesh_, geo_, params_.plane, contact_params_, *contact_);
      add_plane_contact_forces(space_, mesh_, params_.plane, *contact_, force_);
    }
    if (crease_) add_crease_forces(space_, mesh_, crease_->table(), force_);
    if (guard_) add_substrate_guard_forces(space_, mesh_, guard_->table(), guard_area_, force_, guard_k_);
    const int bad_node = first_non_finite_node(space_, force_);
    if (bad_node >= 0)
      throw NumericalError("non-finite force at node " + std::to_string(bad_node) +
                           " (term: " + term_with_non_finite_force(bad_node) + ")");
  }

  // The contact of the current positions (the geometry and the contact stage of compute_forces(), no forces):
  // what contact_area(), contact_load() and contact() report after a step has moved the nodes. The contact
  // kernels keep no state between calls, so the next compute_forces() at these positions computes the same.
  void update_contact() {
    if (!contact_) return;
    update_geometry(space_, mesh_, geo_, params_.h_min, rounded_geometry_);
    compute_plane_contact(space_, mesh_, geo_, params_.plane, contact_params_, *contact_);
  }

  // Total energy for the current positions (calls update_geometry()).
  // per_cell (optional): each cell's energy, the same terms added in the same order (a batch's cell gets
  // the bits it gets alone).
  double energy(std::vector<double>* per_cell = nullptr) {
    update_geometry(space_, mesh_, geo_, params_.h_min, rounded_geometry_);
    std::vector<double> term;
    std::vector<double>* out = per_cell ? &term : nullptr;
    const auto add = [&](double total, double& e) {
      e += total;
      if (per_cell)
        for (int c = 0; c < mesh_.n_cells; ++c) (*per_cell)[c] += term[c];
    };
    if (per_cell) per_cell->assign(mesh_.n_cells, 0.0);
    double e = external_energy(space_, mesh_.node_sums, external_, mesh_.x, per_cell);
    if (gravity_) add(external_energy(space_, mesh_.node_sums, *gravity_, mesh_.x, out), e);
    if (bonds_) add(fene_pow_energy(space_, mesh_, *bonds_, bond_params_.table(), out), e);
    if (hinges_) add(bending_energy(space_, mesh_, *hinges_, k_b_.table(), out), e);
    if (area_)
      add(area_energy(space_, mesh_, geo_, *area_, k_area_local_.table(), k_area_global_.table(), out), e);
    if (volume_) add(volume_energy(space_, mesh_, geo_, *volume_, k_volume_.table(), out), e);
    // the contact line's crease, counted with the cortex
    if (crease_) add(crease_energy(space_, mesh_, crease_->table(), out), e);
    if (guard_) add(substrate_guard_energy(space_, mesh_, guard_->table(), guard_area_, out), e);
    return e;
  }

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
                          const std::vector<char>* frozen, bool throw_if_unconverged = true) {
    if (static_cast<int>(dt_cells.size()) != mesh_.n_cells)
      throw std::invalid_argument("solve_velocity: one step per cell expected");
    const bool with_dt = dt_cells[0] > 0;
    for (const double h : dt_cells)
      if ((h > 0) != with_dt)
        throw std::invalid_argument("solve_velocity: steps must be all positive or all 0");
    dt_.assign(dt_cells);
    last_solve_implicit_ = with_dt;
    const double dt = with_dt ? 1.0 : 0.0;  // only its sign is used below
    const bool implicit_bonds = dt > 0 && params_.implicit_bonds && bonds_.has_value();
    if (implicit_bonds) {
      if (friction_.bond_stiffness_dt.extent(0) == 0)
        friction_.bond_stiffness_dt =
            Kokkos::View<double*, Kokkos::LayoutRight, Mem>("dcm::model::bond_k_dt", mesh_.n_bonds);
      const auto x = mesh_.x;
      const auto bond = mesh_.bond;
      const auto rest = bonds_->rest_length;
      const auto k_dt = friction_.bond_stiffness_dt;
      const auto bond_cell = mesh_.bond_cell;
      const auto table = bond_params_.table();
      const auto step = dt_.table();
      Kokkos::parallel_for(
          "dcm::model::implicit_bonds", Kokkos::RangePolicy<ExecutionSpace>(space_, 0, mesh_.n_bonds),
          KOKKOS_LAMBDA(const int b) {
            const FenePowParams pr = cell_value(table, bond_cell(b));
            const double k_s = pr.k_s, x_max = pr.x_max;
            const double d = norm(load3(x, bond(b, 1)) - load3(x, bond(b, 0)));
            k_dt(b) = cell_value(step, bond_cell(b)) * fene_pow_implicit_stiffness(d, rest(b), k_s, x_max);
          });
    } else {
      friction_.bond_stiffness_dt = Kokkos::View<double*, Kokkos::LayoutRight, Mem>();
    }
    if (guard_ && dt > 0) {  // the substrate guard linearly implicit: Δt k_g A_i n̂n̂ᵀ where it acts
      const auto k = guard_k_;
      const auto k_dt = guard_dt_;
      const auto node_cell = mesh_.node_cell;
      const auto step = dt_.table();
      Kokkos::parallel_for(
          "dcm::model::implicit_guard", Kokkos::RangePolicy<ExecutionSpace>(space_, 0, mesh_.n_nodes),
          KOKKOS_LAMBDA(const int i) { k_dt(i) = cell_value(step, node_cell(i)) * k(i); });
      friction_.node_guard = guard_dt_;
    } else {
      friction_.node_guard = Kokkos::View<double*, Kokkos::LayoutRight, Mem>();
    }
    update_friction(space_, mesh_, friction_, !multigrid_.has_value());  // the multigrid inverts its own
    const bool implicit_tension = dt > 0 && tension_stiffness_.has_value();
    const bool implicit_bending = dt > 0 && bending_stiffness_.has_value();
    if (implicit_bending)
      update_bending_stiffness(k_b_.host, dt_cells, *bending_stiffness_);  // ∇θ from compute_forces()
    if (implicit_tension)
      update_tension_stiffness(space_, mesh_, geo_, *area_, k_area_local_.table(), k_area_global_.table(),
                               dt_.table(), *tension_stiffness_);
    // The multigrid's fine level holds Γ, the implicit bonds and the implicit tension (same sparsity), and
    // for the cells whose bending is strong (select_bending_cells()) an approximation of the implicit bending
    // for the preconditioner only (fine_operator()).
    if (multigrid_) {
      if (implicit_bending)
        select_bending_cells(dt_cells);
      else
        last_bending_ratio_ = 0;
      update_multigrid_operator(space_, mesh_, friction_, *multigrid_,
                                implicit_tension ? &*tension_stiffness_ : nullptr,
                                implicit_bending ? &*hinges_ : nullptr,
                                implicit_bending ? &*bending_stiffness_ : nullptr, &bending_cells_);
    }
    const bool implicit = dt > 0 && global_.has_value();
    if (implicit)
      update_global_stiffness(space_, mesh_, geo_, area_ ? area_->cell_area : volume_->cell_volume,
                              volume_ ? volume_->cell_volume : area_->cell_area, k_area_global_.table(),
                              k_volume_.table(), dt_.table(), *global_);
    const auto precondition_without_volume = [&](const Vector& in, const Vector& out,
                                                 const CellFlags<Mem>& rows) {
      if (multigrid_)
        apply_multigrid(space_, *multigrid_, in, out, rows);
      else
        apply_block_jacobi(space_, friction_, in, out);
    };
    // What only the preconditioner needs (the multigrid's hierarchy, the Woodbury correction) is built on its
    // first application: a solve whose warm start already meets the tolerance applies none (session 37: about
    // 6% of the paper-Δt spreading step, whose solves average 0.61 iterations). The same kernels in the same
    // order, so the same bits.
    const bool woodbury = implicit && woodbury_.has_value();
    bool preconditioner_ready = false;
    const auto prepare_preconditioner = [&]() {
      if (preconditioner_ready) return;
      preconditioner_ready = true;
      ++preconditioner_builds_;
      if (multigrid_) {
        try {
          update_multigrid_hierarchy(space_, mesh_, *multigrid_, implicit_bending ? &*hinges_ : nullptr);
        } catch (const NumericalError& e) {
          // the coarse level knows the cell; the force shows where it starts
          throw NumericalError(std::string(e.what()) + "; the largest force is at node " +
                               std::to_string(largest_force_node()));
        }
      }
      if (woodbury)
        update_global_woodbury(space_, mesh_, *global_, *woodbury_, [&](const Vector& in, const Vector& out) {
          precondition_without_volume(in, out, CellFlags<Mem>());
        });
    };
    if (params_.dashpot == 0 && params_.dashpot_transverse == 0 && !friction_.substrate && !implicit &&
        !implicit_bending && !implicit_bonds && !implicit_tension) {
      apply_block_jacobi(space_, friction_, force_, velocity_);  // exact: Γ is block-diagonal (a frozen
      CgResult r;                                                // cell gets the same v again)
      r.converged = true;
      cg_.segment_results.assign(mesh_.n_cells, r);
      return r;
    }
    const CellFlags<Mem> active = mesh_.n_cells > 1 ? cg_.active : CellFlags<Mem>();
    const CgResult r = pcg_solve(
        space_,
        // Only the cells still iterating (a batch: the others have converged or are not stepping; one cell:
        // no mask, no per-row check).
        [&](const Vector& in, const Vector& out) {
          if (multigrid_) {  // Γ, the implicit bonds and tension as one block product
            block_csr_multiply(space_, multigrid_->fine_operator(), in, out, active);
          } else {
            apply_friction(space_, mesh_, friction_, in, out, active);
            if (implicit_tension)
              apply_tension_stiffness(space_, mesh_, *tension_stiffness_, in, out, active);
          }
          if (implicit) apply_global_stiffness(space_, mesh_, *global_, in, out, active);
          if (implicit_bending)
            apply_bending_stiffness(space_, mesh_, *hinges_, *bending_stiffness_, in, out, active);
        },
        [&](const Vector& in, const Vector& out) {
          prepare_preconditioner();
          precondition_without_volume(in, out, active);
          if (woodbury) apply_global_woodbury(space_, mesh_, *woodbury_, in, out, active);
        },
        force_, velocity_, cg_, settings, frozen);
    if (!r.converged && !(r.residual_norm < INFINITY)) {
      const int bad_v = first_non_finite_node(space_, velocity_);
      throw NumericalError(std::string("conjugate gradients diverged: the residual is not finite") +
                           (bad_v >= 0 ? " (the velocity of node " + std::to_string(bad_v) + " first)" : "") +
                           "; the largest force is at node " + std::to_string(largest_force_node()));
    }
    if (!r.converged && throw_if_unconverged) {
      std::string why = unconverged_message(r, settings);
      for (int c = 0; c < mesh_.n_cells; ++c)
        if (cg_.segment_results[c].breakdown) {
          why += describe_breakdown(c);
          break;
        }
      throw NumericalError(why);
    }
    const int bad = first_non_finite_node(space_, velocity_);
    if (bad >= 0)
      throw NumericalError("non-finite velocity at node " + std::to_string(bad) + " after the solve");
    return r;
  }

  // F · v: the rate at which the forces do work on the current velocity (W); with the explicit step it
  // equals the dissipation vᵀΓv, with the implicit global terms it is vᵀ(Γ + dt K)v.
  double power() { return cg_detail::dot(space_, cg_.sums, force_, velocity_, "dcm::model::power"); }

  // The node with the largest total force (the first, if several); for messages.
  int largest_force_node() const {
    const auto f = force_;
    double m = 0;
    Kokkos::parallel_reduce(
        "dcm::model::largest_force", Kokkos::RangePolicy<ExecutionSpace>(space_, 0, mesh_.n_nodes),
        KOKKOS_LAMBDA(const int i, double& a) {
          const double s = f(i, 0) * f(i, 0) + f(i, 1) * f(i, 1) + f(i, 2) * f(i, 2);
          if (s > a) a = s;
        },
        Kokkos::Max<double>(m));
    int first = mesh_.n_nodes;
    Kokkos::parallel_reduce(
        "dcm::model::largest_force_node", Kokkos::RangePolicy<ExecutionSpace>(space_, 0, mesh_.n_nodes),
        KOKKOS_LAMBDA(const int i, int& a) {
          const double s = f(i, 0) * f(i, 0) + f(i, 1) * f(i, 1) + f(i, 2) * f(i, 2);
          if (s >= m && i < a) a = i;
        },
        Kokkos::Min<int>(first));
    return first < mesh_.n_nodes ? first : 0;
  }

  // After a solve that broke down (CgResult::breakdown) the workspace still holds the search direction p
  // along which p·(Γ + Δt K)p was not positive. Each term of the operator is applied to p alone; the text
  // gives, for cell `cell`, every term's p·A_term p (W) and names the first that is not positive, with the
  // node where p_i·(A_term p)_i is lowest (or first not finite). For the messages of a failed step.
  std::string describe_breakdown(int cell) {
    const auto p = cg_.p, q = cg_.q, z = cg_.z;
    const auto node_cell = mesh_.node_cell;
    std::string text = "; p.A p per term along that direction:";
    bool named = false, first = true;
    std::vector<double> dots;
    const auto term = [&](const char* name, const Vector& aq) {
      cg_detail::segment_dots(space_, cg_.sums, p, aq, dots, "dcm::model::breakdown_term");
      const double c = dots[cell];
      char buf[96];
      std::snprintf(buf, sizeof buf, "%s %s %.3g W", first ? "" : ",", name, c);
      text += buf;
      first = false;
      if (named || c > 0) return;  // !(c > 0): also NaN
      named = true;
      bool not_finite = false;
      const int node = breakdown_node(space_, node_cell, cell, p, aq, not_finite);
      text += std::string(" (the term at fault: ") +
              (not_finite ? "not finite first at node " : "lowest at node ") + std::to_string(node) + ")";
    };
    FrictionOperator<Mem> gamma = friction_;  // Γ alone, without the implicit bond and guard stiffness
    gamma.bond_stiffness_dt = Kokkos::View<double*, Kokkos::LayoutRight, Mem>();
    gamma.node_guard = Kokkos::View<double*, Kokkos::LayoutRight, Mem>();
    apply_friction(space_, mesh_, gamma, p, q);
    term("friction (drag, dashpots, substrate)", q);
    double guard_max = 0;  // a guard that acts nowhere adds exactly 0 W: not a term at fault
    if (last_solve_implicit_ && friction_.node_guard.extent(0) > 0) {
      const auto g = friction_.node_guard;
      Kokkos::parallel_reduce(
          "dcm::model::breakdown_guard_max", Kokkos::RangePolicy<ExecutionSpace>(space_, 0, mesh_.n_nodes),
          KOKKOS_LAMBDA(const int i, double& m) { m = g(i) > m ? g(i) : m; }, Kokkos::Max<double>(guard_max));
    }
    // An implicit part of the friction operator alone: (Γ + the part) p − Γ p.
    const auto friction_part = [&](const char* name, const FrictionOperator<Mem>& with_part) {
      apply_friction(space_, mesh_, with_part, p, z);
      Kokkos::parallel_for(
          "dcm::model::breakdown_part", Kokkos::RangePolicy<ExecutionSpace>(space_, 0, mesh_.n_nodes),
          KOKKOS_LAMBDA(const int i) {
            for (int d = 0; d < 3; ++d) z(i, d) -= q(i, d);
          });
      term(name, z);
    };
    if (guard_max > 0) {
      FrictionOperator<Mem> guarded = gamma;
      guarded.node_guard = friction_.node_guard;
      friction_part("implicit substrate guard", guarded);
    }
    if (last_solve_implicit_ && friction_.bond_stiffness_dt.extent(0) > 0) {
      FrictionOperator<Mem> bonded = gamma;
      bonded.bond_stiffness_dt = friction_.bond_stiffness_dt;
      friction_part("implicit bonds", bonded);
    }
    const auto fresh = [&]() {
      Kokkos::deep_copy(space_, q, 0.0);
      return q;
    };
    if (last_solve_implicit_ && tension_stiffness_) {
      apply_tension_stiffness(space_, mesh_, *tension_stiffness_, p, fresh());
      term("implicit tension", q);
    }
    if (last_solve_implicit_ && global_) {
      apply_global_stiffness(space_, mesh_, *global_, p, fresh());
      term("global area and volume", q);
    }
    if (last_solve_implicit_ && bending_stiffness_) {
      apply_bending_stiffness(space_, mesh_, *hinges_, *bending_stiffness_, p, fresh());
      term("implicit bending", q);
    }
    if (!named) text += " (each positive: the sum lost its sign to round-off)";
    return text;
  }

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
  void advance(double dt) {
    const auto x = mesh_.x;
    const auto v = velocity_;
    Kokkos::parallel_for(
        "dcm::integrator::euler", Kokkos::RangePolicy<ExecutionSpace>(space_, 0, mesh_.n_nodes),
        KOKKOS_LAMBDA(const int i) {
          for (int d = 0; d < 3; ++d) x(i, d) += dt * v(i, d);
        });
  }

  // vᵀ Γ v: the power dissipated by the friction (W), for the energy balance.
  double dissipation(std::vector<double>* per_cell = nullptr) {
    FrictionOperator<Mem> gamma = friction_;  // Γ alone, without the implicit bond and guard stiffness
    gamma.bond_stiffness_dt = Kokkos::View<double*, Kokkos::LayoutRight, Mem>();
    gamma.node_guard = Kokkos::View<double*, Kokkos::LayoutRight, Mem>();
    apply_friction(space_, mesh_, gamma, velocity_, cg_.q);
    if (!per_cell) return cg_detail::dot(space_, cg_.sums, velocity_, cg_.q, "dcm::model::dissipation");
    cg_detail::segment_dots(space_, cg_.sums, velocity_, cg_.q, *per_cell, "dcm::model::dissipation");
    double total = 0;  // the cells' sums in order: what dot() returns
    for (const double d : *per_cell) total += d;
    return total;
  }

 private:
  // ζ_i = 6 π η r / N per cell, r the radius of the sphere with the cell's rest area.
  // Gravity: each cell's buoyant weight Δρ V* g (V* its volume at construction), shared equally by its
  // nodes, along −z. A constant field, so its energy is −Σ F_i · x_i like the external forces.
  Vector node_weights(const std::vector<HostCell>& cells) {
    Vector w("dcm::model::gravity_force", mesh_.n_nodes);
    auto h = Kokkos::create_mirror_view(w);
    Kokkos::deep_copy(h, 0.0);  // only z is written below
    const auto volume = to_host_vector(geo_.cell_volume);
    int i = 0;
    for (std::size_t c = 0; c < cells.size(); ++c) {
      const int n = static_cast<int>(cells[c].mesh.nodes.size());
      const double per_node = cell_params_[c].density_excess * volume[c] * cell_params_[c].gravity / n;
      for (int k = 0; k < n; ++k, ++i) h(i, 2) = -per_node;
    }
    Kokkos::deep_copy(w, h);
    return w;
  }

  // Per cell, bending_ratio() for Δt k_b = 1 J·s (solvers/multigrid.hpp): h the mean rest bond length, R the
  // radius of the sphere of the rest area.
  std::vector<double> bending_scales(const std::vector<HostCell>& cells) const {
    const auto area = to_host_vector(geo_.cell_area);
    constexpr double pi = 3.14159265358979323846;
    std::vector<double> scale(cells.size(), 0.0);
    for (std::size_t c = 0; c < cells.size(); ++c) {
      const auto& x = cells[c].mesh.nodes;
      const auto& edges = cells[c].topology.edges;
      if (edges.empty()) continue;
      double sum = 0;
      for (const auto& e : edges)
        sum += std::sqrt((x[e[1]][0] - x[e[0]][0]) * (x[e[1]][0] - x[e[0]][0]) +
                         (x[e[1]][1] - x[e[0]][1]) * (x[e[1]][1] - x[e[0]][1]) +
                         (x[e[1]][2] - x[e[0]][2]) * (x[e[1]][2] - x[e[0]][2]));
      const double h = sum / static_cast<double>(edges.size()), r = std::sqrt(area[c] / (4 * pi));
      scale[c] = bending_ratio(1.0, h, r, cell_params_[c].dashpot, cell_params_[c].dashpot_transverse);
    }
    return scale;
  }

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

  Kokkos::View<double*, Kokkos::LayoutRight, Mem> node_drag(const std::vector<HostCell>& cells) {
    Kokkos::View<double*, Kokkos::LayoutRight, Mem> drag("dcm::model::node_drag", mesh_.n_nodes);
    auto h = Kokkos::create_mirror_view(drag);
    const auto area = to_host_vector(geo_.cell_area);
    constexpr double pi = 3.14159265358979323846;
    int i = 0;
    for (std::size_t c = 0; c < cells.size(); ++c) {
      const int n = static_cast<int>(cells[c].mesh.nodes.size());
      const double r = std::sqrt(area[c] / (4 * pi));
      for (int k = 0; k < n; ++k) h(i++) = 6 * pi * cell_params_[c].viscosity * r / n;
    }
    Kokkos::deep_copy(drag, h);
    return drag;
  }

  // Failure path only: each force term evaluated alone into a scratch vector, visit(name, scratch) after each
  // (in the order of compute_forces()); visit returns true to stop.
  template <class Visit>
  void for_each_force_term(Visit&& visit) {
    Vector scratch("dcm::model::scratch", mesh_.n_nodes);
    const auto term = [&](const char* name, auto&& add) {
      Kokkos::deep_copy(scratch, 0.0);
      add();
      return visit(name, scratch);
    };
    if (bonds_ && term("FENE+POW bonds", [&] {
          add_fene_pow_forces(space_, mesh_, *bonds_, bond_params_.table(), scratch, overstretched_);
        }))
      return;
    if (hinges_ &&
        term("bending", [&] { add_bending_forces(space_, mesh_, *hinges_, k_b_.table(), scratch); }))
      return;
    if (area_ && term("area constraints", [&] {
          add_area_forces(space_, mesh_, geo_, *area_, k_area_local_.table(), k_area_global_.table(),
                          scratch);
        }))
      return;
    if (volume_ && term("volume constraint", [&] {
          add_volume_forces(space_, mesh_, geo_, *volume_, k_volume_.table(), scratch);
        }))
      return;
    if (contact_ && term("plane contact",
                         [&] { add_plane_contact_forces(space_, mesh_, params_.plane, *contact_, scratch); }))
      return;
    if (crease_ &&
        term("contact crease", [&] { add_crease_forces(space_, mesh_, crease_->table(), scratch); }))
      return;
    if (guard_ && term("substrate guard", [&] {
          add_substrate_guard_forces(space_, mesh_, guard_->table(), guard_area_, scratch, guard_k_);
        }))
      return;
  }

  // Failure path only: the term that produced the non-finite force at `node`.
  std::string term_with_non_finite_force(int node) {
    std::string found = "external force or positions";
    for_each_force_term([&](const char* name, const Vector& f) {
      auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), f);
      for (int d = 0; d < 3; ++d)
        if (!std::isfinite(h(node, d))) {
          found = name;
          return true;
        }
      return false;
    });
    return found;
  }

 public:
  // For the messages of an equilibrium that was not reached: "node N (|F| = X N; largest term there: T, Y N)"
  // for the node with the largest total force (compute_forces() first), external forces included in |F|.
  std::string describe_largest_force() {
    const int node = largest_force_node();
    auto total = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), force_);
    const double f_node = std::sqrt(total(node, 0) * total(node, 0) + total(node, 1) * total(node, 1) +
                                    total(node, 2) * total(node, 2));
    std::string largest;
    double f_largest = -1, rest[3] = {total(node, 0), total(node, 1), total(node, 2)};
    for_each_force_term([&](const char* name, const Vector& f) {
      auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), f);
      const double m = std::sqrt(h(node, 0) * h(node, 0) + h(node, 1) * h(node, 1) + h(node, 2) * h(node, 2));
      for (int d = 0; d < 3; ++d) rest[d] -= h(node, d);
      if (m > f_largest) {
        f_largest = m;
        largest = name;
      }
      return false;
    });
    // What the terms leave of the total: the external forces and gravity (stretch's pull, a spread's weight).
    const double m_rest = std::sqrt(rest[0] * rest[0] + rest[1] * rest[1] + rest[2] * rest[2]);
    if (m_rest > f_largest) {
      f_largest = m_rest;
      largest = "external force and gravity";
    }
    char buf[200];
    std::snprintf(buf, sizeof buf, "node %d (|F| = %.3g N; largest term there: %s, %.3g N)", node, f_node,
                  largest.c_str(), f_largest);
    return buf;
  }

 private:
  std::string describe_overstretch(int bond) const {
    auto b = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh_.bond);
    auto cell = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh_.bond_cell);
    char x_max[32];
    std::snprintf(x_max, sizeof x_max, "%g", cell_params_.at(cell(bond)).bonds.x_max);
    return "FENE bond " + std::to_string(bond) + " (nodes " + std::to_string(b(bond, 0)) + "-" +
           std::to_string(b(bond, 1)) + (mesh_.n_cells > 1 ? ", cell " + std::to_string(cell(bond)) : "") +
           ") reached its maximum length d_max = x_max d* (x_max = " + x_max +
           "); reduce the load (and, in a run that steps in time, the time step)";
  }

  // The per-cell constant tables the kernels read (core/cell_params.hpp).
  void make_cell_tables() {
    bond_params_ = member_table<Mem>(cell_params_, &MechanicsParams::bonds, "dcm::model::bond_params");
    k_b_ = member_table<Mem>(cell_params_, &MechanicsParams::k_b, "dcm::model::k_b");
    k_area_local_ = member_table<Mem>(cell_params_, &MechanicsParams::k_area_local, "dcm::model::k_a");
    k_area_global_ = member_table<Mem>(cell_params_, &MechanicsParams::k_area_global, "dcm::model::k_d");
    k_volume_ = member_table<Mem>(cell_params_, &MechanicsParams::k_volume, "dcm::model::k_v");
    contact_params_ = member_table<Mem>(cell_params_, &MechanicsParams::contact, "dcm::model::contact");
  }

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

}  // namespace dcm
