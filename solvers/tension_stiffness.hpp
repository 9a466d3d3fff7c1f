#pragma once
// Linearly implicit membrane tension. Under the tension σ_t = ∂E/∂A_t of the area terms (eqs. 27–28:
// σ_t = k_a (A_t − A_t*)/A_t* + k_d (A − A*)/A*), moving a node out of a flat patch of membrane costs
// energy σ ∂²A: an out-of-plane stiffness of order σ per node. Where the cortex is curved, the bond dashpots
// (eq. 25) damp that motion through the bonds' normal component, ∝ (edge / radius)²; where it is flat (the
// biconcave cell's inflection circle, a flattened contact), only the Stokes drag 6πηr/N does, and forward
// Euler at the paper's Δt is unstable there: a single node spikes out of the surface until a bond reaches
// d_max (docs/model/time_stepping.md has the measurement). Adding the normal–normal part of the tension
// Hessian,
//   Δt Σ_t max(σ_t, 0) L_t ⊗ n_t n_tᵀ,   L_t,ij = e_i · e_j / (4 A_t),
// (e_i the edge opposite corner i; L_t = EᵀE/(4A_t) is positive semi-definite with the translations in its
// null space) to the friction operator makes the step implicit in exactly these modes, like the implicit
// bending (solvers/bending_stiffness.hpp). Applied matrix-free: a triangle pass s_t = Σ_j ê_j (n_t · v_j)
// with ê = √(Δt σ⁺/(4A)) e, then a gather over each node's triangles, (Γv)_i += (ê_i · s_t) n_t.
#include "core/geometry.hpp"
#include "core/vec3.hpp"
#include "kernels/area_constraints.hpp"

namespace dcm {

template <class MemorySpace>
struct TensionStiffness {
  Kokkos::View<double* [3][3], Kokkos::LayoutRight, MemorySpace> edge;  // ê per triangle corner
  Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace> normal;   // n_t
  Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace> s;        // per triangle scratch
  TensionStiffness() = default;
  explicit TensionStiffness(const MeshBuffers<MemorySpace>& mesh)
      : edge("dcm::tension_stiffness::edge", mesh.n_tris),
        normal("dcm::tension_stiffness::normal", mesh.n_tris),
        s("dcm::tension_stiffness::s", mesh.n_tris) {}
};

// Caches ê and n_t for the current geometry (update_geometry() first) and step dt.
// k_a, k_d: one value each or CellTables (PerCell::table(), core/cell_params.hpp).
template <class ExecutionSpace, class MemorySpace, class KA, class KD, class DT>
void update_tension_stiffness(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                              const GeometryBuffers<MemorySpace>& geo, const AreaRest<MemorySpace>& rest,
                              const KA& k_a, const KD& k_d, const DT& dt_cells,
                              const TensionStiffness<MemorySpace>& ts) {
  const auto x = mesh.x;
  const auto tri = mesh.tri;
  const auto tri_cell = mesh.tri_cell;
  const auto area = geo.tri_area, cell_area = geo.cell_area;
  const auto n_geo = geo.tri_normal;
  const auto rest_tri = rest.tri_area, rest_cell = rest.cell_area;
  const auto edge = ts.edge;
  const auto normal = ts.normal;
  Kokkos::parallel_for(
      "dcm::tension_stiffness::update", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_tris),
      KOKKOS_LAMBDA(const int t) {
        const int c = tri_cell(t);
        const double sigma = cell_value(k_a, c) * (area(t) - rest_tri(t)) / rest_tri(t) +
                             cell_value(k_d, c) * (cell_area(c) - rest_cell(c)) / rest_cell(c);
        const double w =
            (sigma > 0 && area(t) > 0) ? math::sqrt(cell_value(dt_cells, c) * sigma / (4 * area(t))) : 0.0;
        for (int k = 0; k < 3; ++k) {
          const Real3 e = load3(x, tri(t, (k + 2) % 3)) - load3(x, tri(t, (k + 1) % 3));  // opposite corner k
          edge(t, k, 0) = w * e.x;
          edge(t, k, 1) = w * e.y;
          edge(t, k, 2) = w * e.z;
          normal(t, k) = n_geo(t, k);
        }
      });
}

// out += Δt K_tension v.
template <class ExecutionSpace, class MemorySpace, class Vector>
void apply_tension_stiffness(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                             const TensionStiffness<MemorySpace>& ts, const Vector& v, const Vector& out,
                             const CellFlags<MemorySpace>& active = {}) {
  const auto tri = mesh.tri;
  const auto tri_cell = mesh.tri_cell;
  const auto node_cell = mesh.node_cell;
  const auto edge = ts.edge;
  const auto normal = ts.normal;
  const auto s = ts.s;
  Kokkos::parallel_for(
      "dcm::tension_stiffness::triangles", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_tris),
      KOKKOS_LAMBDA(const int t) {
        if (skipped(active, tri_cell(t))) return;
        const Real3 n = load3(normal, t);
        Real3 acc{0, 0, 0};
        for (int k = 0; k < 3; ++k) {
          const double vn = dot(n, load3(v, tri(t, k)));
          acc += vn * Real3{edge(t, k, 0), edge(t, k, 1), edge(t, k, 2)};
        }
        store3(s, t, acc);
      });
  const auto offsets = mesh.node_tri_offsets;
  const auto corners = mesh.node_tri_corners;
  Kokkos::parallel_for(
      "dcm::tension_stiffness::gather", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
      KOKKOS_LAMBDA(const int i) {
        if (skipped(active, node_cell(i))) return;
        Real3 acc{0, 0, 0};
        for (int q = offsets(i); q < offsets(i + 1); ++q) {
          const int t = corners(q) / 3, k = corners(q) % 3;
          const double w = dot(Real3{edge(t, k, 0), edge(t, k, 1), edge(t, k, 2)}, load3(s, t));
          acc += w * load3(normal, t);
        }
        out(i, 0) += acc.x;
        out(i, 1) += acc.y;
        out(i, 2) += acc.z;
      });
}

}  // namespace dcm
