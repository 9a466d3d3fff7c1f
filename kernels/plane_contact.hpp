#pragma once
// Adhesive contact of the rounded triangles with a plane (paper eqs. 15–19, MODEL.md section 4;
// docs/model/contact.md). Per triangle t whose encompassing sphere (centre O_t, radius R_t;
// kernels/rounded_triangle.hpp) comes within h0 of the plane and that faces the plane:
//   overlap δ = R_t − dist(O_t, plane); Maugis–Dugdale state for (δ, R_t) (kernels/maugis_dugdale.hpp);
//   contact centre C = the foot of O_t on the plane;
//   regime 1, π c² ≥ 2 A_t / N_Q (eq. 18): the pressure p(r) integrated over the triangle by the N_Q-point
//     rule, force F_t (eq. 16) and moment M_t about C (eq. 17);
//   regime 2, a small disc: the net MD load times the fraction of the disc inside the triangle's
//     projection, applied at C (or the nearest point of the triangle);
//   distribution to the three nodes by the 3×3 solve of eq. 19 (kernels/contact_distribution.hpp).
// The per-triangle results are kept (node loads, β weights for the substrate friction, contact area) and
// gathered per node without atomics through the node → triangle-corner lists.
// A cell with contact.law = "derjaguin" takes another branch per triangle: flat triangles with the exact
// gradient of the Derjaguin energy (kernels/derjaguin_adhesion.hpp, docs/model/contact_line.md), which adds
// in-plane node forces (tri_node_shear).
#include "core/cell_params.hpp"
#include "core/geometry.hpp"
#include "core/vec3.hpp"
#include "kernels/contact_distribution.hpp"
#include "kernels/derjaguin_adhesion.hpp"
#include "kernels/maugis_dugdale.hpp"
#include "kernels/polar_contact_integral.hpp"
#include "kernels/quadrature_rules.hpp"

namespace dcm {

// The plane {x : (x − point)·normal = 0}; the cells live on the side the unit normal points to.
struct Plane {
  Real3 point{0, 0, 0};
  Real3 normal{0, 0, 1};
};

struct PlaneContactParams {
  MdMaterial material{};       // K = 4/3 E/(1 − ν²), W, h0
  int quadrature_points = 0;   // 0: exact polar integration (dcm); 1, 3, 7 or 16: the paper's rules (eq. 18)
  bool projected_area = true;  // quadrature weights × the triangle's area projected on the plane (else A_t)
  // Substrate friction acts on the triangle's area within r < max(a, c) (contact and adhesive zone; dcm's
  // default, docs/model/contact.md) or, as the paper writes, within the contact radius a only.
  bool friction_on_adhesive_zone = true;
  // contact.law = "derjaguin": flat triangles with the Derjaguin energy of kernels/derjaguin_adhesion.hpp
  // (forces in and out of the plane) instead of the rounded triangles' Maugis–Dugdale pressure.
  bool derjaguin = false;
};

// What a triangle's contact is doing (tri_regime).
// kFullContact: the whole (projected) triangle lies within the contact radius a.
enum ContactRegime : int { kNoContact = 0, kGap = 1, kQuadrature = 2, kSmallDisc = 3, kFullContact = 4 };

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
        tri_regime("dcm::contact::tri_regime", n_tris) {}
};

// Fraction of a disc of radius c centred at C inside the triangle (p0, p1, p2), all in the plane: the
// product of the fractions on the inner side of each edge's line (exact for a disc that crosses one
// edge; shared discs near a vertex are split approximately).
KOKKOS_INLINE_FUNCTION double disc_fraction_in_triangle(Real3 p0, Real3 p1, Real3 p2, Real3 C, Real3 n,
                                                        double c) {
  const Real3 p[3] = {p0, p1, p2};
  const double orient = dot(cross(p1 - p0, p2 - p0), n) >= 0 ? 1.0 : -1.0;
  double fraction = 1;
  for (int e = 0; e < 3; ++e) {
    const Real3 a = p[e], b = p[(e + 1) % 3];
    const Real3 inward = orient * cross(n, b - a);  // in the plane, towards the triangle's inside
    const double len = norm(inward);
    if (!(len > 0)) continue;
    const double s = math::min(math::max(dot(C - a, inward) / (len * c), -1.0), 1.0);
    fraction *= 1.0 - (math::acos(s) - s * math::sqrt(1.0 - s * s)) / kMdPi;
  }
  return fraction;
}

// The point of triangle (p0, p1, p2) nearest to C, all in one plane (C itself when inside).
KOKKOS_INLINE_FUNCTION Real3 nearest_point_in_triangle(Real3 p0, Real3 p1, Real3 p2, Real3 C, Real3 n) {
  const Real3 p[3] = {p0, p1, p2};
  const double orient = dot(cross(p1 - p0, p2 - p0), n) >= 0 ? 1.0 : -1.0;
  bool inside = true;
  for (int e = 0; e < 3; ++e)
    if (orient * dot(cross(p[(e + 1) % 3] - p[e], C - p[e]), n) < 0) inside = false;
  if (inside) return C;
  Real3 best = p0;
  double best_d2 = norm2(C - p0);
  for (int e = 0; e < 3; ++e) {
    const Real3 a = p[e], d = p[(e + 1) % 3] - a;
    const double dd = norm2(d);
    const double t = dd > 0 ? math::min(math::max(dot(C - a, d) / dd, 0.0), 1.0) : 0.0;
    const Real3 q = a + t * d;
    if (norm2(C - q) < best_d2) {
      best_d2 = norm2(C - q);
      best = q;
    }
  }
  return best;
}

// Per-triangle contact with the plane (needs update_geometry(): tri_area, tri_normal, the spheres).
// params: one PlaneContactParams or a CellTable of them (PerCell::table(), core/cell_params.hpp).
template <class ExecutionSpace, class MemorySpace, class Params>
void compute_plane_contact(const ExecutionSpace& space, const MeshBuffers<MemorySpace>& mesh,
                           const GeometryBuffers<MemorySpace>& geo, const Plane& plane, const Params& params,
                           const ContactBuffers<MemorySpace>& out) {
  const auto x = mesh.x;
  const auto tri = mesh.tri;
  const auto tri_area = geo.tri_area;
  const auto tri_normal = geo.tri_normal;
  const auto center = geo.tri_sphere_center;
  const auto radius = geo.tri_sphere_radius;
  const auto node_load = out.tri_node_load;
  const auto beta = out.tri_beta;
  const auto area_weight = out.tri_area_weight;
  const auto contact_area = out.tri_contact_area;
  const auto friction_area = out.tri_friction_area;
  const auto load = out.tri_load;
  const auto regime = out.tri_regime;
  const auto shear = out.tri_node_shear;
  const bool has_shear = shear.extent(0) > 0;
  const double len = norm(plane.normal);
  const Real3 n = (1.0 / len) * plane.normal, p_plane = plane.point;
  const auto tri_cell = mesh.tri_cell;
  // Dynamic chunks: the triangles in contact are one patch of the mesh, which a static split hands to one
  // thread (2 threads, 2562 nodes pressed 1 µm: 1.8 → 1.3 ms per step; docs/PERFORMANCE.md "Session 11").
  // Each triangle's results depend on that triangle only, so the schedule changes no bit.
  Kokkos::parallel_for(
      "dcm::contact::plane",
      Kokkos::RangePolicy<ExecutionSpace, Kokkos::Schedule<Kokkos::Dynamic>>(space, 0, mesh.n_tris,
                                                                             Kokkos::ChunkSize(32)),
      KOKKOS_LAMBDA(const int t) {
        for (int k = 0; k < 3; ++k) {
          node_load(t, k) = 0;
          beta(t, k) = 0;
          area_weight(t, k) = 0;
        }
        contact_area(t) = 0;
        friction_area(t) = 0;
        load(t) = 0;
        regime(t) = kNoContact;
        if (has_shear)
          for (int k = 0; k < 3; ++k)
            for (int d = 0; d < 3; ++d) shear(t, k, d) = 0;
        const PlaneContactParams prm = cell_value(params, tri_cell(t));
        const Real3 x0 = load3(x, tri(t, 0)), x1 = load3(x, tri(t, 1)), x2 = load3(x, tri(t, 2));
        if (prm.derjaguin) {  // flat triangles, the Derjaguin energy's exact gradient
          const DerjaguinLaw law{prm.material.W, prm.material.h0, prm.material.K};
          const DerjaguinTriangle dt = derjaguin_triangle(law, x0, x1, x2, p_plane, n);
          const double fa = prm.friction_on_adhesive_zone ? dt.zone_area : dt.contact_area;
          const double* w = prm.friction_on_adhesive_zone ? dt.zone_weight : dt.contact_weight;
          double total = 0;
          for (int k = 0; k < 3; ++k) {
            node_load(t, k) = dt.normal_force[k];
            total += dt.normal_force[k];
            beta(t, k) = fa > 0 ? w[k] : 1.0 / 3.0;
            area_weight(t, k) = beta(t, k);
            if (has_shear) {
              shear(t, k, 0) = dt.shear[k].x;
              shear(t, k, 1) = dt.shear[k].y;
              shear(t, k, 2) = dt.shear[k].z;
            }
          }
          load(t) = total;
          contact_area(t) = dt.contact_area;
          friction_area(t) = fa;
          if (dt.contact_area > 0)
            regime(t) = dt.highest < derjaguin_contact_gap(law) ? kFullContact : kQuadrature;
          else if (dt.zone_area > 0)
            regime(t) = kGap;
          return;
        }
        const double R = radius(t);
        const Real3 O = load3(center, t);
        const double height = dot(O - p_plane, n);  // of the sphere centre
        const double delta = R - height;
        // Broad phase: the sphere within h0, the triangle facing the plane, and the triangle itself
        // within h0 plus its size of the plane (a flat triangle far above has a huge sphere too).
        if (!(delta > -prm.material.h0) || !(dot(load3(tri_normal, t), n) < 0)) return;
        const double span = math::max(math::max(norm(x1 - x0), norm(x2 - x1)), norm(x0 - x2));
        const double lowest =
            math::min(math::min(dot(x0 - p_plane, n), dot(x1 - p_plane, n)), dot(x2 - p_plane, n));
        if (!(lowest < prm.material.h0 + span)) return;
        const MdState st = md_state_from_overlap(delta, R, prm.material);
        const double outer = math::max(st.a, st.c);
        if (!(outer > 0)) return;
        const Real3 C = O - height * n;
        const double area_t = tri_area(t);
        const double area_q = prm.projected_area ? 0.5 * math::fabs(dot(cross(x1 - x0, x2 - x0), n)) : area_t;
        double Fn = 0, a_contact = 0, a_zone = 0;
        double lam_friction[3] = {-1, 0, 0};  // the friction area's centroid in barycentric coordinates
        Real3 M{0, 0, 0}, C_apply = C;
        const int nq = prm.quadrature_points;
        if (nq == 0) {  // exact in r, Gauss in θ (kernels/polar_contact_integral.hpp); no regimes needed
          const Real3 ref = math::fabs(n.x) < 0.9 ? Real3{1, 0, 0} : Real3{0, 1, 0};
          Real3 e1 = cross(ref, n);
          e1 = (1.0 / norm(e1)) * e1;
          const Real3 e2 = cross(n, e1);
          const PolarIntegral pi = polar_contact_integral(st, x0, x1, x2, C, e1, e2);
          Fn = pi.load;
          M = pi.m1 * e1 + pi.m2 * e2;
          a_contact = pi.contact_area;
          a_zone = pi.zone_area;
          const double fa = prm.friction_on_adhesive_zone ? a_zone : a_contact;
          if (fa > 1e-9 * area_q) {  // (a sliver's moments are rounding noise; its friction is negligible)
            const double mx = prm.friction_on_adhesive_zone ? pi.zone_x : pi.contact_x,
                         my = prm.friction_on_adhesive_zone ? pi.zone_y : pi.contact_y;
            projected_barycentric(x0, x1, x2, C + (mx / fa) * e1 + (my / fa) * e2, n, lam_friction);
          }
          regime(t) = st.a > 0 ? kQuadrature : kGap;
        } else if (kMdPi * outer * outer * nq >= 2.0 * area_t) {  // eq. 18, regime 1: quadrature (eqs. 16–17)
          integrate_pressure(
              x0, x1, x2, C, n, area_q, nq, [&](Real3 r) { return md_pressure(st, norm(r)); }, Fn, M);
          double inside = 0, in_zone = 0, moment[3] = {0, 0, 0};
          for (int q = 0; q < nq; ++q) {
            double l1, l2, l3, w;
            quadrature_point(nq, q, l1, l2, l3, w);
            const Real3 rel = l1 * x0 + l2 * x1 + l3 * x2 - C;
            const Real3 r = rel - dot(rel, n) * n;
            const bool in_a = norm2(r) < st.a * st.a, in_c = norm2(r) < outer * outer;
            if (in_a) inside += w;
            if (in_c) in_zone += w;
            if (prm.friction_on_adhesive_zone ? in_c : in_a) {
              moment[0] += w * l1;
              moment[1] += w * l2;
              moment[2] += w * l3;
            }
          }
          a_contact = inside * area_q;
          a_zone = in_zone * area_q;
          const double fw = prm.friction_on_adhesive_zone ? in_zone : inside;
          if (fw > 1e-9)
            for (int k = 0; k < 3; ++k) lam_friction[k] = moment[k] / fw;
          regime(t) = st.a > 0 ? kQuadrature : kGap;
        } else {  // regime 2: the disc's share of the net load, at C or the triangle's nearest point
          const Real3 q0 = x0 - dot(x0 - C, n) * n, q1 = x1 - dot(x1 - C, n) * n,
                      q2 = x2 - dot(x2 - C, n) * n;
          const double fraction = disc_fraction_in_triangle(q0, q1, q2, C, n, outer);
          Fn = fraction * st.P;
          a_contact = fraction * kMdPi * st.a * st.a;
          a_zone = fraction * kMdPi * outer * outer;
          C_apply = nearest_point_in_triangle(q0, q1, q2, C, n);
          projected_barycentric(x0, x1, x2, C_apply, n, lam_friction);
          regime(t) = st.a > 0 ? kSmallDisc : kGap;
        }
        const NodeLoads nl = distribute_normal_load(x0, x1, x2, C_apply, n, Fn, M);  // eq. 19
        for (int k = 0; k < 3; ++k) {
          node_load(t, k) = nl.f[k];
          beta(t, k) = nl.beta[k];
          area_weight(t, k) = lam_friction[0] >= 0 ? lam_friction[k] : 1.0 / 3.0;
        }
        load(t) = Fn;
        contact_area(t) =
            math::max(a_contact, 0.0);  // the exact integral of an empty overlap can round to -1e-28
        friction_area(t) = prm.friction_on_adhesive_zone ? a_zone : a_contact;
        const double projected = 0.5 * math::fabs(dot(cross(x1 - x0, x2 - x0), n));
        if (a_contact >= (1 - 1e-9) * projected && projected > 0) regime(t) = kFullContact;
      });
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
