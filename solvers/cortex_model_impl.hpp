#pragma once
// The member functions of CortexModel (solvers/cortex_model.hpp) that run kernels, defined outside the class
// so that only the translation units that include this file compile them: solvers/cortex_model.cpp for
// Kokkos' default execution space (the explicit instantiation every app and test links), and code that
// runs the model on another execution space (perf/bench_step.cpp: Serial beside OpenMP).
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "solvers/cortex_model.hpp"

namespace dcm {

template <class ExecutionSpace>
CortexModel<ExecutionSpace>::CortexModel(const ExecutionSpace& space, const std::vector<HostCell>& cells,
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
      guard_area_ = Kokkos::View<double*, Kokkos::LayoutRight, Mem>("dcm::model::guard_area", mesh_.n_nodes);
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

template <class ExecutionSpace>
void CortexModel<ExecutionSpace>::refresh_curvature() const {
  if (rounded_geometry_) return;
  compute_node_curvature(space_, mesh_, geo_);
  compute_triangle_curvature(space_, mesh_, geo_, params_.h_min);
  compute_rounded_triangles(space_, mesh_, geo_);
}

template <class ExecutionSpace>
void CortexModel<ExecutionSpace>::node_fields(const NodeFields<Mem>& out) const {
  if (!bonds_) throw std::logic_error("node_fields() needs the FENE+POW bond term");
  refresh_curvature();
  compute_node_fields(space_, mesh_, geo_, *bonds_, bond_params_.table(), force_, out);
}

template <class ExecutionSpace>
std::vector<double> CortexModel<ExecutionSpace>::cell_slice(const Vector& v, int cell) const {
  const auto all = to_host_vector(v);
  const int b = mesh_.host_cell_node_begin.at(cell), e = mesh_.host_cell_node_begin.at(cell + 1);
  return std::vector<double>(all.begin() + 3 * b, all.begin() + 3 * e);
}

template <class ExecutionSpace>
void CortexModel<ExecutionSpace>::set_cell_slice(const Vector& v, int cell,
                                                 const std::vector<double>& values) const {
  auto all = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), v);
  const int b = mesh_.host_cell_node_begin.at(cell), e = mesh_.host_cell_node_begin.at(cell + 1);
  if (values.size() != 3 * static_cast<std::size_t>(e - b))
    throw std::invalid_argument("set_cell_slice: " + std::to_string(values.size() / 3) +
                                " nodes for a cell of " + std::to_string(e - b));
  for (int i = b; i < e; ++i)
    for (int d = 0; d < 3; ++d) all(i, d) = values[3 * (i - b) + d];
  Kokkos::deep_copy(v, all);
}

template <class ExecutionSpace>
void CortexModel<ExecutionSpace>::restore_cell_state(const Checkpoint& c, int cell) {
  set_cell_slice(mesh_.x, cell, c.array("model.x"));
  set_cell_slice(velocity_, cell, c.array("model.v"));
  update_geometry(space_, mesh_, geo_, params_.h_min, rounded_geometry_);
}

template <class ExecutionSpace>
void CortexModel<ExecutionSpace>::scale_rest_volume(double factor) {
  if (!volume_) return;
  const auto v = volume_->cell_volume;
  Kokkos::parallel_for(
      "dcm::model::scale_rest_volume", Kokkos::RangePolicy<ExecutionSpace>(space_, 0, v.extent(0)),
      KOKKOS_LAMBDA(const int c) { v(c) *= factor; });
  space_.fence();
}

template <class ExecutionSpace>
void CortexModel<ExecutionSpace>::set_flat_bending_rest() {
  if (hinges_) set_hinge_rest_angles(*hinges_, {0.0});
}

template <class ExecutionSpace>
std::vector<double> CortexModel<ExecutionSpace>::cell_max_bond_extension() const {
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

template <class ExecutionSpace>
std::string CortexModel<ExecutionSpace>::describe_most_extended_bond(int cell) const {
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

template <class ExecutionSpace>
double CortexModel<ExecutionSpace>::contact_power(std::vector<double>* per_cell) const {
  if (per_cell) per_cell->assign(mesh_.n_cells, 0.0);
  return contact_ ? dcm::contact_power(space_, mesh_, params_.plane, *contact_, velocity_, per_cell) : 0.0;
}

template <class ExecutionSpace>
double CortexModel<ExecutionSpace>::adhesion_energy(std::vector<double>* per_cell) const {
  if (per_cell) per_cell->assign(mesh_.n_cells, 0.0);
  return contact_ ? derjaguin_energy(space_, mesh_, params_.plane, contact_params_.table(), per_cell) : 0.0;
}

template <class ExecutionSpace>
double CortexModel<ExecutionSpace>::contact_area(std::vector<double>* per_cell) const {  // Σ A^C_t
  if (per_cell) per_cell->assign(mesh_.n_cells, 0.0);
  return contact_ ? total_contact_area(space_, mesh_, *contact_, per_cell) : 0.0;
}

template <class ExecutionSpace>
double CortexModel<ExecutionSpace>::contact_load(std::vector<double>* per_cell) const {  // N
  if (per_cell) per_cell->assign(mesh_.n_cells, 0.0);
  return contact_ ? total_contact_load(space_, mesh_, *contact_, per_cell) : 0.0;
}

template <class ExecutionSpace>
void CortexModel<ExecutionSpace>::compute_forces() {
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

template <class ExecutionSpace>
void CortexModel<ExecutionSpace>::update_contact() {
  if (!contact_) return;
  update_geometry(space_, mesh_, geo_, params_.h_min, rounded_geometry_);
  compute_plane_contact(space_, mesh_, geo_, params_.plane, contact_params_, *contact_);
}

template <class ExecutionSpace>
double CortexModel<ExecutionSpace>::energy(std::vector<double>* per_cell) {
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

template <class ExecutionSpace>
CgResult CortexModel<ExecutionSpace>::solve_velocity(const CgSettings& settings,
                                                     const std::vector<double>& dt_cells,
                                                     const std::vector<char>* frozen,
                                                     bool throw_if_unconverged) {
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
          if (implicit_tension) apply_tension_stiffness(space_, mesh_, *tension_stiffness_, in, out, active);
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

template <class ExecutionSpace>
double CortexModel<ExecutionSpace>::power() {
  return cg_detail::dot(space_, cg_.sums, force_, velocity_, "dcm::model::power");
}

template <class ExecutionSpace>
int CortexModel<ExecutionSpace>::largest_force_node() const {
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

template <class ExecutionSpace>
std::string CortexModel<ExecutionSpace>::describe_breakdown(int cell) {
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

template <class ExecutionSpace>
void CortexModel<ExecutionSpace>::advance(double dt) {
  const auto x = mesh_.x;
  const auto v = velocity_;
  Kokkos::parallel_for(
      "dcm::integrator::euler", Kokkos::RangePolicy<ExecutionSpace>(space_, 0, mesh_.n_nodes),
      KOKKOS_LAMBDA(const int i) {
        for (int d = 0; d < 3; ++d) x(i, d) += dt * v(i, d);
      });
}

template <class ExecutionSpace>
double CortexModel<ExecutionSpace>::dissipation(std::vector<double>* per_cell) {
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

template <class ExecutionSpace>
auto CortexModel<ExecutionSpace>::node_weights(const std::vector<HostCell>& cells) -> Vector {
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

template <class ExecutionSpace>
std::vector<double> CortexModel<ExecutionSpace>::bending_scales(const std::vector<HostCell>& cells) const {
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

template <class ExecutionSpace>
auto CortexModel<ExecutionSpace>::node_drag(const std::vector<HostCell>& cells)
    -> Kokkos::View<double*, Kokkos::LayoutRight, Mem> {
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

template <class ExecutionSpace>
template <class Visit>
void CortexModel<ExecutionSpace>::for_each_force_term(Visit&& visit) {
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
  if (hinges_ && term("bending", [&] { add_bending_forces(space_, mesh_, *hinges_, k_b_.table(), scratch); }))
    return;
  if (area_ && term("area constraints", [&] {
        add_area_forces(space_, mesh_, geo_, *area_, k_area_local_.table(), k_area_global_.table(), scratch);
      }))
    return;
  if (volume_ && term("volume constraint",
                      [&] { add_volume_forces(space_, mesh_, geo_, *volume_, k_volume_.table(), scratch); }))
    return;
  if (contact_ && term("plane contact",
                       [&] { add_plane_contact_forces(space_, mesh_, params_.plane, *contact_, scratch); }))
    return;
  if (crease_ && term("contact crease", [&] { add_crease_forces(space_, mesh_, crease_->table(), scratch); }))
    return;
  if (guard_ && term("substrate guard", [&] {
        add_substrate_guard_forces(space_, mesh_, guard_->table(), guard_area_, scratch, guard_k_);
      }))
    return;
}

template <class ExecutionSpace>
std::string CortexModel<ExecutionSpace>::term_with_non_finite_force(int node) {
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

template <class ExecutionSpace>
std::string CortexModel<ExecutionSpace>::describe_largest_force() {
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

template <class ExecutionSpace>
std::string CortexModel<ExecutionSpace>::describe_overstretch(int bond) const {
  auto b = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh_.bond);
  auto cell = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), mesh_.bond_cell);
  char x_max[32];
  std::snprintf(x_max, sizeof x_max, "%g", cell_params_.at(cell(bond)).bonds.x_max);
  return "FENE bond " + std::to_string(bond) + " (nodes " + std::to_string(b(bond, 0)) + "-" +
         std::to_string(b(bond, 1)) + (mesh_.n_cells > 1 ? ", cell " + std::to_string(cell(bond)) : "") +
         ") reached its maximum length d_max = x_max d* (x_max = " + x_max +
         "); reduce the load (and, in a run that steps in time, the time step)";
}

template <class ExecutionSpace>
void CortexModel<ExecutionSpace>::make_cell_tables() {
  bond_params_ = member_table<Mem>(cell_params_, &MechanicsParams::bonds, "dcm::model::bond_params");
  k_b_ = member_table<Mem>(cell_params_, &MechanicsParams::k_b, "dcm::model::k_b");
  k_area_local_ = member_table<Mem>(cell_params_, &MechanicsParams::k_area_local, "dcm::model::k_a");
  k_area_global_ = member_table<Mem>(cell_params_, &MechanicsParams::k_area_global, "dcm::model::k_d");
  k_volume_ = member_table<Mem>(cell_params_, &MechanicsParams::k_volume, "dcm::model::k_v");
  contact_params_ = member_table<Mem>(cell_params_, &MechanicsParams::contact, "dcm::model::contact");
}

}  // namespace dcm
