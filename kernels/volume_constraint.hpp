#pragma once
// Volume constraint (paper eq. 29), as the exact gradient of an energy.
//
//   E_vol = sum_c k_v (V_c - V_c*)^2 / (2 V_c*)     per cell c, V_c* its rest volume
//   k_v in Pa (J/m^3). Table 1 gives "k_V = 10e3 N/m^3" for a force magnitude k_V (V - V*); the mapping
//   onto k_v is decided with the stretching calibration (docs/model/constraints.md).
//
// Forces: V = sum_t x_i . (x_j x x_k) / 6, so dV/dx_i = sum_{t containing i} (x_j x x_k) / 6 for
// triangle (i, j, k); on a closed surface this equals sum_t (x_j - x_i) x (x_k - x_i) / 6 =
// sum_t (A_t / 3) n_t, the area-weighted normal, which is what is evaluated here (translation invariant
// term by term, so no cancellation for cells far from the origin):
//   F_i = - k_v (V_c - V_c*) / V_c* * sum_{t containing i} (A_t / 3) n_t
// A gather per node (no atomics). sum_i dV/dx_i = sum_t A_t n_t = 0 and sum_i x_i x dV/dx_i =
// sum_t A_t b_t x n_t = 0 (b_t the barycentre) on a closed surface: zero net force and torque.
//
// The paper applies F_volume along the Laplace-Beltrami normal of eq. 14 (the direction of K_i). That is
// not the gradient of any energy of V alone; the exact gradient is the area-weighted normal above, and
// only the exact gradient conserves energy (the work done by the forces equals -dE), which the
// finite-difference tests check. The two directions agree on smooth, evenly meshed regions.
//
// Needs the current geometry of mesh.x: compute_triangle_geometry() (tri_area, tri_normal) and
// compute_cell_measures() (cell_volume), i.e. update_geometry().
// Expectations (tests/test_constraints.cpp): forces = -grad E by central differences (relative error
// < 1e-6); zero at the rest shape; zero net force and torque; a uniformly scaled icosphere gets
// restoring radial forces, sum_i x_i . F_i = -3 k_v (V - V*) V / V* (V is homogeneous of degree 3).
#include "core/cell_params.hpp"
#include "core/geometry.hpp"
#include "core/vec3.hpp"
#include "kernels/rest_state.hpp"

namespace dcm {

// Rest volume V_c* per cell (m^3).
template <class MemorySpace>
struct VolumeRest {
  template <class T>
  using View = Kokkos::View<T, Kokkos::LayoutRight, MemorySpace>;
  View<double*> cell_volume;
};

// The rest state is the current geometry (update_geometry() first). Throws std::invalid_argument when a
// rest volume is not positive (an inside-out or flat cell).
template <class ExecutionSpace, class MemorySpace>
VolumeRest<MemorySpace> make_volume_rest(const ExecutionSpace& space, const MeshBuffers<MemorySpace>&,
                                         const GeometryBuffers<MemorySpace>& geo) {
  VolumeRest<MemorySpace> rest;
  rest.cell_volume =
      detail::copy_rest(space, geo.cell_volume, "dcm::volume::rest_cell_volume", "cell volume");
  return rest;
}

// Adds the volume-constraint forces (N) into force (n_nodes x 3); k_v = 0 is a no-op. Needs
// update_geometry() (tri_area, tri_normal, cell_volume) on the current mesh.x.
// k_v: one value (Pa) or a CellTable (PerCell::table(), core/cell_params.hpp).
template <class ExecutionSpace, class MemorySpace, class KV>
void add_volume_forces(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                       const GeometryBuffers<MemorySpace>& geo, const VolumeRest<MemorySpace>& rest,
                       const KV& k_v_cells,
                       const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& force) {
  if (!any_nonzero(k_v_cells)) return;
  const auto node_cell = mesh.node_cell;
  const auto offsets = mesh.node_tri_offsets;
  const auto corners = mesh.node_tri_corners;
  const auto area = geo.tri_area;
  const auto normal = geo.tri_normal;
  const auto volume = geo.cell_volume;
  const auto rest_volume = rest.cell_volume;
  Kokkos::parallel_for(
      "dcm::volume::forces", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
      KOKKOS_LAMBDA(const int i) {
        const int c = node_cell(i);
        // eq. 29 as a gradient: -k_v (V - V*) / V* dV/dx_i
        const double coef = -cell_value(k_v_cells, c) * (volume(c) - rest_volume(c)) / rest_volume(c) / 3.0;
        Real3 an{0, 0, 0};  // sum_t A_t n_t
        for (int s = offsets(i); s < offsets(i + 1); ++s) {
          const int t = corners(s) / 3;
          an += area(t) * load3(normal, t);
        }
        force(i, 0) += coef * an.x;
        force(i, 1) += coef * an.y;
        force(i, 2) += coef * an.z;
      });
}

// E_vol (J), summed over all cells. Same geometry requirement as add_volume_forces().
template <class ExecutionSpace, class MemorySpace, class KV>
double volume_energy(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                     const GeometryBuffers<MemorySpace>& geo, const VolumeRest<MemorySpace>& rest,
                     const KV& k_v, std::vector<double>* per_cell = nullptr) {
  const auto volume = geo.cell_volume;
  const auto rest_volume = rest.cell_volume;
  return fixed_order_sum(
      "dcm::volume::energy", space, mesh.cell_sums,
      KOKKOS_LAMBDA(const int c) {
        const double d = volume(c) - rest_volume(c);
        return 0.5 * cell_value(k_v, c) * d * d / rest_volume(c);
      },
      per_cell);
}

}  // namespace dcm
