#pragma once
// Adhesive contact of the rounded triangles with a plane (paper eqs. 15–19, MODEL.md section 4;
// docs/model/contact.md): the kernels over a mesh. What one triangle computes is in
// kernels/plane_contact_triangle.hpp; here the stages run as kernels:
//   dcm::contact::broad       every triangle: its rows cleared, the broad phase (tri_branch);
//   dcm::contact::candidates  the triangles through it, listed (a scan; their count comes to the host);
//   dcm::contact::md_state    the listed rounded triangles: Maugis–Dugdale state (tri_md) and narrow branch;
//   dcm::contact::polar, ::rule, ::disc, ::derjaguin
//                             the listed triangles of that branch: the pressure integrated, distributed to
//                             the nodes (eq. 19), the rows written. Only the branches the parameters can
//                             take are launched.
// Splitting the stages keeps each GPU kernel to its own branch's registers (one kernel for all took 255
// registers and spilled on sm_90: docs/PERFORMANCE.md "Backends") and lets the narrow phase run over the
// contact patch only. The per-triangle results are kept (node loads, β weights for the substrate friction,
// contact area) and gathered per node without atomics through the node → triangle-corner lists.
#include "core/cell_params.hpp"
#include "kernels/plane_contact_triangle.hpp"

namespace dcm {

template <class MemorySpace>
struct ContactBuffers {
  template <class T>
  using View = Kokkos::View<T, Kokkos::LayoutRight, MemorySpace>;
  View<double* [3]> tri_node_load;  // normal force on each corner's node (N), along the plane normal
  View<double* [3]> tri_beta;       // friction weights β of each corner (Σ = 1)
  // Barycentric coordinates of the centroid of the area the substrate friction acts on (Σ = 1, ≥ 0): the
  // "area" friction weights (contact.friction_weights), which follow where the contact is, not where the net
  // load is (β jumps between corners when a triangle's net load passes through zero).
  View<double* [3]> tri_area_weight;
  View<double*> tri_contact_area;   // A^C_t, the part of the triangle inside the contact radius a (m²)
  View<double*> tri_friction_area;  // the area the substrate friction acts on (m²): A^C_t or the zone r < c
  View<double*> tri_load;           // F_t · n (N), repulsive positive
  View<int*> tri_regime;            // ContactRegime
  // In-plane force on each corner's node (N), from contact.law = "derjaguin" only; empty otherwise (the
  // rounded triangles' forces are along the plane normal).
  View<double* [3][3]> tri_node_shear;
  // The stages' scratch (kernels/plane_contact_triangle.hpp): each triangle's ContactBranch (a row
  // is non-zero only where it is not kBranchNone), the Maugis–Dugdale state of the rounded triangles through
  // the broad phase (a, c, δ, P, p0, σ0), and the list of the triangles through the broad phase.
  View<int*> tri_branch;
  View<double* [6]> tri_md;
  View<int*> candidates;

  ContactBuffers() = default;
  ContactBuffers(int n_tris, bool in_plane_forces) : ContactBuffers(n_tris) {
    if (in_plane_forces) tri_node_shear = View<double* [3][3]>("dcm::contact::tri_node_shear", n_tris);
  }
  explicit ContactBuffers(int n_tris)
      : tri_node_load("dcm::contact::tri_node_load", n_tris),
        tri_beta("dcm::contact::tri_beta", n_tris),
        tri_area_weight("dcm::contact::tri_area_weight", n_tris),
        tri_contact_area("dcm::contact::tri_contact_area", n_tris),
        tri_friction_area("dcm::contact::tri_friction_area", n_tris),
        tri_load("dcm::contact::tri_load", n_tris),
        tri_regime("dcm::contact::tri_regime", n_tris),
        tri_branch("dcm::contact::tri_branch", n_tris),
        tri_md("dcm::contact::tri_md", n_tris),
        candidates("dcm::contact::candidates", n_tris) {}
};

namespace contact_detail {
template <class MemorySpace>
KOKKOS_INLINE_FUNCTION void store(const ContactBuffers<MemorySpace>& out, int t, const TriangleContact& c) {
  for (int k = 0; k < 3; ++k) {
    out.tri_node_load(t, k) = c.node_load[k];
    out.tri_beta(t, k) = c.beta[k];
    out.tri_area_weight(t, k) = c.area_weight[k];
  }
  out.tri_contact_area(t) = c.contact_area;
  out.tri_friction_area(t) = c.friction_area;
  out.tri_load(t) = c.load;
  out.tri_regime(t) = c.regime;
  if (out.tri_node_shear.extent(0) > 0)
    for (int k = 0; k < 3; ++k) {
      out.tri_node_shear(t, k, 0) = c.shear[k].x;
      out.tri_node_shear(t, k, 1) = c.shear[k].y;
      out.tri_node_shear(t, k, 2) = c.shear[k].z;
    }
}

// A triangle's MdState in ContactBuffers::tri_md (a, c, δ, P, p0, σ0) and back.
template <class View>
KOKKOS_INLINE_FUNCTION void store_md(const View& md, int t, const MdState& st) {
  md(t, 0) = st.a;
  md(t, 1) = st.c;
  md(t, 2) = st.delta;
  md(t, 3) = st.P;
  md(t, 4) = st.p0;
  md(t, 5) = st.sigma0;
}
template <class View>
KOKKOS_INLINE_FUNCTION MdState load_md(const View& md, int t) {
  MdState st;
  st.a = md(t, 0);
  st.c = md(t, 1);
  st.delta = md(t, 2);
  st.P = md(t, 3);
  st.p0 = md(t, 4);
  st.sigma0 = md(t, 5);
  return st;
}

// Dynamic chunks: the triangles in contact are one patch of the mesh, which a static split hands to one
// thread (2 threads, 2562 nodes pressed 1 µm: 1.8 → 1.3 ms per step; docs/PERFORMANCE.md "Session 11").
// Each triangle's results depend on that triangle only, so the schedule changes no bit.
template <class ExecutionSpace>
using DynamicRange = Kokkos::RangePolicy<ExecutionSpace, Kokkos::Schedule<Kokkos::Dynamic>>;

// The listed triangles (the first `count` of out.candidates) of one narrow-phase branch: f(t) returns the
// triangle's TriangleContact. A functor, not a lambda: CUDA allows no extended lambda in a function
// templated on a lambda's type.
template <class MemorySpace, class F>
struct NarrowPhase {
  ContactBuffers<MemorySpace> out;
  int branch;
  F f;
  KOKKOS_INLINE_FUNCTION void operator()(const int i) const {
    const int t = out.candidates(i);
    if (out.tri_branch(t) == branch) store(out, t, f(t));
  }
};
template <class ExecutionSpace, class MemorySpace, class F>
void narrow_phase(const char* label, const ExecutionSpace& space, const ContactBuffers<MemorySpace>& out,
                  int count, int branch, const F& f) {
  Kokkos::parallel_for(label, DynamicRange<ExecutionSpace>(space, 0, count, Kokkos::ChunkSize(8)),
                       NarrowPhase<MemorySpace, F>{out, branch, f});
}
}  // namespace contact_detail

// Per-triangle contact with the plane (needs update_geometry(): tri_area, tri_normal, the spheres).
// params: one PlaneContactParams or a CellTable of them (PerCell::table(), core/cell_params.hpp).
// branches: the narrow-phase kernels to launch (plane_contact_branches(); the overloads below find them from
// the parameters); a triangle of a branch left out keeps the rows of no contact.
template <class ExecutionSpace, class MemorySpace, class Params>
void compute_plane_contact(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                           const GeometryBuffers<MemorySpace>& geo, const Plane& plane, const Params& params,
                           const ContactBuffers<MemorySpace>& out, int branches) {
  const auto x = mesh.x;
  const auto tri = mesh.tri;
  const auto tri_cell = mesh.tri_cell;
  const auto tri_area = geo.tri_area;
  const auto tri_normal = geo.tri_normal;
  const auto center = geo.tri_sphere_center;
  const auto radius = geo.tri_sphere_radius;
  const auto tri_branch = out.tri_branch;
  const auto md = out.tri_md;
  const auto list = out.candidates;
  const Real3 n = (1.0 / norm(plane.normal)) * plane.normal, p = plane.point;
  // Broad phase; the rows of the last call's contacts cleared (every other row is zero already).
  Kokkos::parallel_for(
      "dcm::contact::broad", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_tris),
      KOKKOS_LAMBDA(const int t) {
        if (tri_branch(t) != kBranchNone) contact_detail::store(out, t, TriangleContact{});
        tri_branch(t) =
            contact_broad_phase(cell_value(params, tri_cell(t)), load3(x, tri(t, 0)), load3(x, tri(t, 1)),
                                load3(x, tri(t, 2)), load3(center, t), radius(t), load3(tri_normal, t), p, n);
      });
  int count = 0;
  Kokkos::parallel_scan(
      "dcm::contact::candidates", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_tris),
      KOKKOS_LAMBDA(const int t, int& offset, const bool final) {
        if (tri_branch(t) == kBranchNone) return;
        if (final) list(offset) = t;
        ++offset;
      },
      count);
  if (count == 0) return;
  if (branches & kMaugisDugdaleBranches)
    Kokkos::parallel_for(
        "dcm::contact::md_state",
        contact_detail::DynamicRange<ExecutionSpace>(space, 0, count, Kokkos::ChunkSize(8)),
        KOKKOS_LAMBDA(const int i) {
          const int t = list(i);
          if (tri_branch(t) != kBranchMaugisDugdale) return;
          const PlaneContactParams prm = cell_value(params, tri_cell(t));
          const MdState st = md_contact_state(prm, load3(center, t), radius(t), p, n);
          contact_detail::store_md(md, t, st);
          tri_branch(t) = md_contact_branch(prm, st, tri_area(t));
        });
  constexpr int lanes = ContactLanes<ExecutionSpace>::value;
  if (branches & branch_bit(kBranchPolar))
    contact_detail::narrow_phase(
        "dcm::contact::polar", space, out, count, kBranchPolar, KOKKOS_LAMBDA(const int t) {
          const PlaneContactParams prm = cell_value(params, tri_cell(t));
          const Real3 x0 = load3(x, tri(t, 0)), x1 = load3(x, tri(t, 1)), x2 = load3(x, tri(t, 2));
          return polar_triangle_contact<lanes>(prm, contact_detail::load_md(md, t), x0, x1, x2,
                                               contact_centre(load3(center, t), p, n), n,
                                               quadrature_area(prm, x0, x1, x2, n, tri_area(t)));
        });
  if (branches & branch_bit(kBranchRule))
    contact_detail::narrow_phase(
        "dcm::contact::rule", space, out, count, kBranchRule, KOKKOS_LAMBDA(const int t) {
          const PlaneContactParams prm = cell_value(params, tri_cell(t));
          const Real3 x0 = load3(x, tri(t, 0)), x1 = load3(x, tri(t, 1)), x2 = load3(x, tri(t, 2));
          return rule_triangle_contact(prm, contact_detail::load_md(md, t), x0, x1, x2,
                                       contact_centre(load3(center, t), p, n), n,
                                       quadrature_area(prm, x0, x1, x2, n, tri_area(t)));
        });
  if (branches & branch_bit(kBranchDisc))
    contact_detail::narrow_phase(
        "dcm::contact::disc", space, out, count, kBranchDisc, KOKKOS_LAMBDA(const int t) {
          return disc_triangle_contact(cell_value(params, tri_cell(t)), contact_detail::load_md(md, t),
                                       load3(x, tri(t, 0)), load3(x, tri(t, 1)), load3(x, tri(t, 2)),
                                       contact_centre(load3(center, t), p, n), n);
        });
  if (branches & branch_bit(kBranchDerjaguin))
    contact_detail::narrow_phase(
        "dcm::contact::derjaguin", space, out, count, kBranchDerjaguin, KOKKOS_LAMBDA(const int t) {
          return derjaguin_triangle_contact(cell_value(params, tri_cell(t)), load3(x, tri(t, 0)),
                                            load3(x, tri(t, 1)), load3(x, tri(t, 2)), p, n);
        });
}

// One set of parameters for every cell.
template <class ExecutionSpace, class MemorySpace>
void compute_plane_contact(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                           const GeometryBuffers<MemorySpace>& geo, const Plane& plane,
                           const PlaneContactParams& params, const ContactBuffers<MemorySpace>& out) {
  compute_plane_contact(space, mesh, geo, plane, params, out, plane_contact_branches(params));
}

// Each cell its own (the branches from the host rows).
template <class ExecutionSpace, class MemorySpace>
void compute_plane_contact(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                           const GeometryBuffers<MemorySpace>& geo, const Plane& plane,
                           const PerCell<PlaneContactParams, MemorySpace>& params,
                           const ContactBuffers<MemorySpace>& out) {
  int branches = 0;
  for (const PlaneContactParams& p : params.host) branches |= plane_contact_branches(p);
  compute_plane_contact(space, mesh, geo, plane, params.table(), out, branches);
}

// A node all of whose triangles lie fully in the contact (the paper's pinned nodes).
template <class Offsets, class Corners, class Regime>
KOKKOS_INLINE_FUNCTION bool node_fully_in_contact(int i, const Offsets& offsets, const Corners& corners,
                                                  const Regime& regime) {
  if (offsets(i + 1) == offsets(i)) return false;
  for (int k = offsets(i); k < offsets(i + 1); ++k)
    if (regime(corners(k) / 3) != kFullContact) return false;
  return true;
}

// Adds the contact forces (along the plane normal, and in the plane with contact.law = "derjaguin") gathered
// from the triangles' corners to force.
template <class ExecutionSpace, class MemorySpace>
void add_plane_contact_forces(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                              const Plane& plane, const ContactBuffers<MemorySpace>& contact,
                              const Kokkos::View<double* [3], Kokkos::LayoutRight, MemorySpace>& force) {
  const auto offsets = mesh.node_tri_offsets;
  const auto corners = mesh.node_tri_corners;
  const auto node_load = contact.tri_node_load;
  const auto shear = contact.tri_node_shear;
  const bool has_shear = shear.extent(0) > 0;
  const Real3 n = (1.0 / norm(plane.normal)) * plane.normal;
  Kokkos::parallel_for(
      "dcm::contact::gather", Kokkos::RangePolicy<ExecutionSpace>(space, 0, mesh.n_nodes),
      KOKKOS_LAMBDA(const int i) {
        double f = 0;
        Real3 s{0, 0, 0};
        for (int k = offsets(i); k < offsets(i + 1); ++k) {
          const int corner = corners(k);
          f += node_load(corner / 3, corner % 3);
          if (has_shear)
            s = s + Real3{shear(corner / 3, corner % 3, 0), shear(corner / 3, corner % 3, 1),
                          shear(corner / 3, corner % 3, 2)};
        }
        if (f != 0 || norm2(s) != 0) {
          const Real3 total = f * n + s;
          force(i, 0) += total.x;
          force(i, 1) += total.y;
          force(i, 2) += total.z;
        }
      });
}

// Σ_t E_t, the Derjaguin adhesion energy of the triangles whose cell uses contact.law = "derjaguin" (J; the
// Maugis–Dugdale pressure of the rounded triangles has no energy and adds 0). per_cell: each cell's.
template <class ExecutionSpace, class MemorySpace, class Params>
double derjaguin_energy(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh, const Plane& plane,
                        const Params& params, std::vector<double>* per_cell = nullptr) {
  const auto x = mesh.x;
  const auto tri = mesh.tri;
  const auto tri_cell = mesh.tri_cell;
  const Real3 n = (1.0 / norm(plane.normal)) * plane.normal, p = plane.point;
  return fixed_order_sum(
      "dcm::contact::derjaguin_energy", space, mesh.tri_sums,
      KOKKOS_LAMBDA(const int t) {
        const PlaneContactParams prm = cell_value(params, tri_cell(t));
        if (!prm.derjaguin) return 0.0;
        const DerjaguinLaw law{prm.material.W, prm.material.h0, prm.material.K};
        return derjaguin_triangle(law, load3(x, tri(t, 0)), load3(x, tri(t, 1)), load3(x, tri(t, 2)), p, n)
            .energy;
      },
      per_cell);
}

// Σ_t A^C_t over the mesh (r_cc = sqrt(A^C / π) of a one-cell mesh); per_cell: each cell's. Fixed summation
// order (mesh.tri_sums).
template <class ExecutionSpace, class MemorySpace>
double total_contact_area(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                          const ContactBuffers<MemorySpace>& contact,
                          std::vector<double>* per_cell = nullptr) {
  const auto v = contact.tri_contact_area;
  return fixed_order_sum(
      "dcm::contact::area", space, mesh.tri_sums, KOKKOS_LAMBDA(const int t) { return v(t); }, per_cell);
}

// Σ_t F_t · n (N).
template <class ExecutionSpace, class MemorySpace>
double total_contact_load(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                          const ContactBuffers<MemorySpace>& contact,
                          std::vector<double>* per_cell = nullptr) {
  const auto v = contact.tri_load;
  return fixed_order_sum(
      "dcm::contact::load", space, mesh.tri_sums, KOKKOS_LAMBDA(const int t) { return v(t); }, per_cell);
}

}  // namespace dcm
