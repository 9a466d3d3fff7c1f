#pragma once
// Local and global surface-area constraints (paper eqs. 27 and 28), as exact gradients of energies.
//
//   E_local  = sum_t k_a (A_t - A_t*)^2 / (2 A_t*)       per triangle t, A_t* its rest area
//   E_global = sum_c k_d (A_c - A_c*)^2 / (2 A_c*)       per cell c, A_c = sum_{t in c} A_t, A_c* its rest
//   area k_a, k_d in N/m (energy per area). The paper gives force magnitudes k_a (A_t - A_t*) and k_d (A -
//   A*) with Table 1 values "6e3 N/m^2"; how those numbers map onto these constants is decided with the
//   stretching calibration (docs/model/constraints.md lists the candidate readings). Fedosov et al. 2010 use
//   exactly these two energies but name them the other way round (their k_a is global, k_d local).
//
// Forces, F_i = -dE/dx_i, with dA_t/dx_i = (1/2) n_t x (x_k - x_j) for triangle (i, j, k) (in the
// triangle's plane, perpendicular to the opposite edge, pointing away from it: the paper's "from the
// barycenter"):
//   F_i = - sum_{t containing i} [ k_a (A_t - A_t*) / A_t* + k_d (A_c - A_c*) / A_c* ] dA_t/dx_i
// A gather per node over its triangle corners (no atomics). Every triangle's three gradients sum to zero
// and A_t is rotation invariant, so the forces have zero net force and zero net torque.
//
// Needs the current geometry of mesh.x: compute_triangle_geometry() (tri_area, tri_normal) and
// compute_cell_measures() (cell_area), i.e. update_geometry().
// Expectations (tests/test_constraints.cpp): forces = -grad E by central differences (relative error
// < 1e-6) for each term; zero at the rest shape; zero net force and torque; cells independent.
#include "core/cell_params.hpp"
#include "core/geometry.hpp"
#include "core/vec3.hpp"
#include "kernels/rest_state.hpp"

namespace dcm {

// Rest areas: A_t* per triangle, A_c* per cell (m^2).
template <class MemorySpace>
struct AreaRest {
  template <class T>
  using View = Kokkos::View<T, Kokkos::LayoutRight, MemorySpace>;
  View<double*> tri_area;
  View<double*> cell_area;
};

// The rest state is the current geometry (update_geometry() first). Throws std::invalid_argument when a
// rest area is not positive (a degenerate triangle would divide by zero).
template <class ExecutionSpace, class MemorySpace>
AreaRest<MemorySpace> make_area_rest(const ExecutionSpace& space, const MeshBuffers<MemorySpace>&,
                                     const GeometryBuffers<MemorySpace>& geo) {
  AreaRest<MemorySpace> rest;
  rest.tri_area = detail::copy_rest(space, geo.tri_area, "dcm::area::rest_tri_area", "triangle area");
  rest.cell_area = detail::copy_rest(space, geo.cell_area, "dcm::area::rest_cell_area", "cell area");
  return rest;
}

namespace detail {

// Local and/or global term, chosen at compile time so a zero constant costs nothing.
template <bool Local, bool Global, class ExecutionSpace, class MemorySpace, class KA, class KD>
void add_area_forces_impl(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                          const GeometryBuffers<MemorySpace>& geo, const AreaRest<MemorySpace>& rest,
                          const KA& k_a_cells, const KD& k_d_cells,
                          const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& force) {
  const auto x = mesh.x;
  const auto tri = mesh.tri;
  const auto node_cell = mesh.node_cell;
  const auto offsets = mesh.node_tri_offsets;
  const auto corners = mesh.node_tri_corners;
  const auto area = geo.tri_area;
  const auto normal = geo.tri_normal;
  const auto cell_area = geo.cell_area;
  const auto rest_area = rest.tri_area;
  const auto rest_cell_area = rest.cell_area;
  Kokkos::parallel_for(
      "dcm::area::forces", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
      KOKKOS_LAMBDA(const int i) {
        const int cell = node_cell(i);
        double global = 0;  // eq. 28: k_d (A_c - A_c*) / A_c*, the same for every triangle of the cell
        if (Global)         // (not if constexpr: CUDA lambdas may not first-capture inside one)
          global =
              cell_value(k_d_cells, cell) * (cell_area(cell) - rest_cell_area(cell)) / rest_cell_area(cell);
        Real3 f{0, 0, 0};
        for (int s = offsets(i); s < offsets(i + 1); ++s) {
          const int t = corners(s) / 3, c = corners(s) % 3;
          double coef = global;
          if (Local) coef += cell_value(k_a_cells, cell) * (area(t) - rest_area(t)) / rest_area(t);  // eq. 27
          const Real3 edge = load3(x, tri(t, (c + 2) % 3)) - load3(x, tri(t, (c + 1) % 3));  // x_k - x_j
          f += (-0.5 * coef) * cross(load3(normal, t), edge);  // -coef dA_t/dx_i
        }
        force(i, 0) += f.x;
        force(i, 1) += f.y;
        force(i, 2) += f.z;
      });
}

}  // namespace detail

// Adds the area-constraint forces (N) into force (n_nodes x 3). Either constant may be 0; both 0 is a
// no-op. Needs update_geometry() (tri_area, tri_normal, cell_area) on the current mesh.x.
// k_a, k_d: one value each (N/m) or CellTables (PerCell::table(), core/cell_params.hpp).
template <class ExecutionSpace, class MemorySpace, class KA, class KD>
void add_area_forces(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                     const GeometryBuffers<MemorySpace>& geo, const AreaRest<MemorySpace>& rest,
                     const KA& k_a, const KD& k_d,
                     const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& force) {
  const bool local = any_nonzero(k_a), global = any_nonzero(k_d);
  if (local && global)
    detail::add_area_forces_impl<true, true>(space, mesh, geo, rest, k_a, k_d, force);
  else if (local)
    detail::add_area_forces_impl<true, false>(space, mesh, geo, rest, k_a, k_d, force);
  else if (global)
    detail::add_area_forces_impl<false, true>(space, mesh, geo, rest, k_a, k_d, force);
}

// E_local + E_global (J), summed over all cells. Same geometry requirement as add_area_forces().
template <class ExecutionSpace, class MemorySpace, class KA, class KD>
double area_energy(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                   const GeometryBuffers<MemorySpace>& geo, const AreaRest<MemorySpace>& rest, const KA& k_a,
                   const KD& k_d, std::vector<double>* per_cell = nullptr) {
  const auto area = geo.tri_area;
  const auto tri_cell = mesh.tri_cell;
  const auto cell_area = geo.cell_area;
  const auto rest_area = rest.tri_area;
  const auto rest_cell_area = rest.cell_area;
  double local = 0, global = 0;
  std::vector<double> local_cell(mesh.n_cells, 0.0), global_cell(mesh.n_cells, 0.0);
  if (any_nonzero(k_a))
    local = fixed_order_sum(
        "dcm::area::energy_local", space, mesh.tri_sums,
        KOKKOS_LAMBDA(const int t) {
          const double d = area(t) - rest_area(t);
          return 0.5 * cell_value(k_a, tri_cell(t)) * d * d / rest_area(t);
        },
        &local_cell);
  if (any_nonzero(k_d))
    global = fixed_order_sum(
        "dcm::area::energy_global", space, mesh.cell_sums,
        KOKKOS_LAMBDA(const int c) {
          const double d = cell_area(c) - rest_cell_area(c);
          return 0.5 * cell_value(k_d, c) * d * d / rest_cell_area(c);
        },
        &global_cell);
  if (per_cell) {
    per_cell->resize(mesh.n_cells);
    for (int c = 0; c < mesh.n_cells; ++c) (*per_cell)[c] = local_cell[c] + global_cell[c];
  }
  return local + global;
}

}  // namespace dcm
