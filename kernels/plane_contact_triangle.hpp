#pragma once
// One rounded triangle's adhesive contact with a plane (paper eqs. 15–19, MODEL.md section 4;
// docs/model/contact.md), in the stages the kernels of kernels/plane_contact.hpp run one after the other:
//   broad phase (contact_broad_phase): the sphere within h0, facing the plane, the triangle near the plane;
//   state (md_contact_state, md_contact_branch): the Maugis–Dugdale state for the overlap δ = R_t − dist and
//     which integration the triangle takes;
//   one narrow-phase function per branch: exact polar integral, the paper's point rules (eq. 18 regime 1,
//     eqs. 16–17), the small disc (regime 2), or flat triangles with the Derjaguin energy (contact.law =
//     "derjaguin", kernels/derjaguin_adhesion.hpp); the first three end with the 3×3 distribution of eq. 19.
// Each stage is a function of the triangle alone, so a kernel per stage (and per branch) computes what one
// call of triangle_contact() below computes; on a GPU each kernel keeps the registers of its own branch only
// (docs/PERFORMANCE.md, "Session 26").
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

// Which stage a triangle is at and which narrow-phase kernel computes it (ContactBuffers::tri_branch).
// kBranchMaugisDugdale: through the broad phase, its Maugis–Dugdale state not computed yet.
enum ContactBranch : int {
  kBranchNone = 0,
  kBranchMaugisDugdale = 1,
  kBranchPolar = 2,
  kBranchRule = 3,
  kBranchDisc = 4,
  kBranchDerjaguin = 5
};
// Bit masks of branches (which narrow-phase kernels a set of parameters can need).
constexpr int branch_bit(int branch) { return 1 << branch; }
// The branches that need a Maugis–Dugdale state (the md_state kernel).
constexpr int kMaugisDugdaleBranches =
    branch_bit(kBranchPolar) | branch_bit(kBranchRule) | branch_bit(kBranchDisc);
inline int plane_contact_branches(const PlaneContactParams& p) {
  if (p.derjaguin) return branch_bit(kBranchDerjaguin);
  if (p.quadrature_points == 0) return branch_bit(kBranchPolar);
  return branch_bit(kBranchRule) | branch_bit(kBranchDisc);
}

// One triangle's results: the rows of ContactBuffers.
struct TriangleContact {
  double node_load[3] = {};    // N, along the plane normal, repulsive positive
  double beta[3] = {};         // friction weights of eq. 19 (Σ = 1 in contact)
  double area_weight[3] = {};  // barycentric centroid of the friction area
  Real3 shear[3] = {};         // in-plane node forces (contact.law = "derjaguin" only)
  double contact_area = 0, friction_area = 0, load = 0;
  int regime = kNoContact;
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

// Broad phase. Rounded triangles take part when the sphere (O, R) comes within h0 of the plane (p, unit n),
// the triangle faces the plane (outward normal tri_n against n), and the triangle itself is within h0 plus
// its size of the plane (a flat triangle far above has a huge sphere too). Derjaguin triangles take part
// when their lowest corner is within h0 and they face the plane (derjaguin_triangle's own test).
KOKKOS_INLINE_FUNCTION int contact_broad_phase(const PlaneContactParams& prm, Real3 x0, Real3 x1, Real3 x2,
                                               Real3 O, double R, Real3 tri_n, Real3 p, Real3 n) {
  const double lowest = math::min(math::min(dot(x0 - p, n), dot(x1 - p, n)), dot(x2 - p, n));
  if (prm.derjaguin) {
    const double a_p = -0.5 * dot(cross(x1 - x0, x2 - x0), n);
    return lowest < prm.material.h0 && a_p > 0 ? kBranchDerjaguin : kBranchNone;
  }
  const double delta = R - dot(O - p, n);
  if (!(delta > -prm.material.h0) || !(dot(tri_n, n) < 0)) return kBranchNone;
  const double span = math::max(math::max(norm(x1 - x0), norm(x2 - x1)), norm(x0 - x2));
  return lowest < prm.material.h0 + span ? kBranchMaugisDugdale : kBranchNone;
}

// The Maugis–Dugdale state of a triangle through the broad phase (its sphere (O, R)).
KOKKOS_INLINE_FUNCTION MdState md_contact_state(const PlaneContactParams& prm, Real3 O, double R, Real3 p,
                                                Real3 n) {
  return md_state_from_overlap(R - dot(O - p, n), R, prm.material);
}

// The contact centre C: the foot of the sphere's centre O on the plane (p, unit n).
KOKKOS_INLINE_FUNCTION Real3 contact_centre(Real3 O, Real3 p, Real3 n) { return O - dot(O - p, n) * n; }

// The narrow phase a triangle with state st takes: none without interaction (max(a, c) = 0), the polar
// integral (quadrature_points = 0), else eq. 18's choice between the point rule (π c² ≥ 2 A_t / N_Q) and
// the small disc.
KOKKOS_INLINE_FUNCTION int md_contact_branch(const PlaneContactParams& prm, const MdState& st,
                                             double area_t) {
  const double outer = math::max(st.a, st.c);
  if (!(outer > 0)) return kBranchNone;
  if (prm.quadrature_points == 0) return kBranchPolar;
  return kMdPi * outer * outer * prm.quadrature_points >= 2.0 * area_t ? kBranchRule : kBranchDisc;
}

// The projected area the quadrature weights multiply (PlaneContactParams::projected_area).
KOKKOS_INLINE_FUNCTION double quadrature_area(const PlaneContactParams& prm, Real3 x0, Real3 x1, Real3 x2,
                                              Real3 n, double area_t) {
  return prm.projected_area ? 0.5 * math::fabs(dot(cross(x1 - x0, x2 - x0), n)) : area_t;
}

namespace contact_detail {
// The rounded triangles' common end: the net load Fn and moment M about C_apply distributed to the nodes
// (eq. 19), the friction area's centroid lam (lam[0] < 0: none, the corners equally), the areas.
KOKKOS_INLINE_FUNCTION void finish(const PlaneContactParams& prm, Real3 x0, Real3 x1, Real3 x2, Real3 C_apply,
                                   Real3 n, double Fn, Real3 M, double a_contact, double a_zone,
                                   const double lam[3], TriangleContact& out) {
  const NodeLoads nl = distribute_normal_load(x0, x1, x2, C_apply, n, Fn, M);  // eq. 19
  for (int k = 0; k < 3; ++k) {
    out.node_load[k] = nl.f[k];
    out.beta[k] = nl.beta[k];
    out.area_weight[k] = lam[0] >= 0 ? lam[k] : 1.0 / 3.0;
  }
  out.load = Fn;
  out.contact_area = math::max(a_contact, 0.0);  // the exact integral of an empty overlap can round to -1e-28
  out.friction_area = prm.friction_on_adhesive_zone ? a_zone : a_contact;
  const double projected = 0.5 * math::fabs(dot(cross(x1 - x0, x2 - x0), n));
  if (a_contact >= (1 - 1e-9) * projected && projected > 0) out.regime = kFullContact;
}
}  // namespace contact_detail

// Gauss points per step of the polar integral (kernels/polar_contact_integral.hpp): 8 SIMD lanes where the
// execution space runs on the host, 1 on a device (CUDA, HIP, SYCL), as MembraneLanes.
template <class ExecutionSpace>
struct ContactLanes {
  static constexpr int value =
      Kokkos::SpaceAccessibility<ExecutionSpace, Kokkos::HostSpace>::accessible ? 8 : 1;
};

// Exact in r, Gauss in θ (kernels/polar_contact_integral.hpp); eqs. 16–17 without regimes. C: the contact
// centre (the foot of the sphere's centre on the plane). Lanes: ContactLanes.
template <int Lanes = 8>
KOKKOS_INLINE_FUNCTION TriangleContact polar_triangle_contact(const PlaneContactParams& prm,
                                                              const MdState& st, Real3 x0, Real3 x1, Real3 x2,
                                                              Real3 C, Real3 n, double area_q) {
  TriangleContact out;
  const Real3 ref = math::fabs(n.x) < 0.9 ? Real3{1, 0, 0} : Real3{0, 1, 0};
  Real3 e1 = cross(ref, n);
  e1 = (1.0 / norm(e1)) * e1;
  const Real3 e2 = cross(n, e1);
  const PolarIntegral pi = polar_contact_integral<Lanes>(st, x0, x1, x2, C, e1, e2);
  double lam[3] = {-1, 0, 0};
  const double fa = prm.friction_on_adhesive_zone ? pi.zone_area : pi.contact_area;
  if (fa > 1e-9 * area_q) {  // (a sliver's moments are rounding noise; its friction is negligible)
    const double mx = prm.friction_on_adhesive_zone ? pi.zone_x : pi.contact_x,
                 my = prm.friction_on_adhesive_zone ? pi.zone_y : pi.contact_y;
    projected_barycentric(x0, x1, x2, C + (mx / fa) * e1 + (my / fa) * e2, n, lam);
  }
  out.regime = st.a > 0 ? kQuadrature : kGap;
  contact_detail::finish(prm, x0, x1, x2, C, n, pi.load, pi.m1 * e1 + pi.m2 * e2, pi.contact_area,
                         pi.zone_area, lam, out);
  return out;
}

// Eq. 18 regime 1: the paper's N_Q-point rule over the projected triangle (eqs. 16–17).
KOKKOS_INLINE_FUNCTION TriangleContact rule_triangle_contact(const PlaneContactParams& prm, const MdState& st,
                                                             Real3 x0, Real3 x1, Real3 x2, Real3 C, Real3 n,
                                                             double area_q) {
  TriangleContact out;
  const int nq = prm.quadrature_points;
  const double outer = math::max(st.a, st.c);
  double Fn = 0;
  Real3 M{0, 0, 0};
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
  double lam[3] = {-1, 0, 0};
  const double fw = prm.friction_on_adhesive_zone ? in_zone : inside;
  if (fw > 1e-9)
    for (int k = 0; k < 3; ++k) lam[k] = moment[k] / fw;
  out.regime = st.a > 0 ? kQuadrature : kGap;
  contact_detail::finish(prm, x0, x1, x2, C, n, Fn, M, inside * area_q, in_zone * area_q, lam, out);
  return out;
}

// Eq. 18 regime 2, a small disc: the disc's share of the net load, at C or the triangle's nearest point.
KOKKOS_INLINE_FUNCTION TriangleContact disc_triangle_contact(const PlaneContactParams& prm, const MdState& st,
                                                             Real3 x0, Real3 x1, Real3 x2, Real3 C, Real3 n) {
  TriangleContact out;
  const double outer = math::max(st.a, st.c);
  const Real3 q0 = x0 - dot(x0 - C, n) * n, q1 = x1 - dot(x1 - C, n) * n, q2 = x2 - dot(x2 - C, n) * n;
  const double fraction = disc_fraction_in_triangle(q0, q1, q2, C, n, outer);
  const Real3 C_apply = nearest_point_in_triangle(q0, q1, q2, C, n);
  double lam[3];
  projected_barycentric(x0, x1, x2, C_apply, n, lam);
  out.regime = st.a > 0 ? kSmallDisc : kGap;
  contact_detail::finish(prm, x0, x1, x2, C_apply, n, fraction * st.P, Real3{0, 0, 0},
                         fraction * kMdPi * st.a * st.a, fraction * kMdPi * outer * outer, lam, out);
  return out;
}

// contact.law = "derjaguin": a flat triangle with the Derjaguin energy's exact gradient.
KOKKOS_INLINE_FUNCTION TriangleContact derjaguin_triangle_contact(const PlaneContactParams& prm, Real3 x0,
                                                                  Real3 x1, Real3 x2, Real3 p, Real3 n) {
  TriangleContact out;
  const DerjaguinLaw law{prm.material.W, prm.material.h0, prm.material.K};
  const DerjaguinTriangle dt = derjaguin_triangle(law, x0, x1, x2, p, n);
  const double fa = prm.friction_on_adhesive_zone ? dt.zone_area : dt.contact_area;
  const double* w = prm.friction_on_adhesive_zone ? dt.zone_weight : dt.contact_weight;
  for (int k = 0; k < 3; ++k) {
    out.node_load[k] = dt.normal_force[k];
    out.load += dt.normal_force[k];
    out.beta[k] = out.area_weight[k] = fa > 0 ? w[k] : 1.0 / 3.0;
    out.shear[k] = dt.shear[k];
  }
  out.contact_area = dt.contact_area;
  out.friction_area = fa;
  if (dt.contact_area > 0)
    out.regime = dt.highest < derjaguin_contact_gap(law) ? kFullContact : kQuadrature;
  else if (dt.zone_area > 0)
    out.regime = kGap;
  return out;
}

// Every stage for one triangle in one call (the reference the kernels are tested against).
// branch: the narrow phase it took (kBranchNone without contact).
KOKKOS_INLINE_FUNCTION TriangleContact triangle_contact(const PlaneContactParams& prm, Real3 x0, Real3 x1,
                                                        Real3 x2, Real3 O, double R, Real3 tri_n,
                                                        double area_t, Real3 p, Real3 n, int& branch) {
  branch = contact_broad_phase(prm, x0, x1, x2, O, R, tri_n, p, n);
  if (branch == kBranchNone) return TriangleContact{};
  if (branch == kBranchDerjaguin) return derjaguin_triangle_contact(prm, x0, x1, x2, p, n);
  const MdState st = md_contact_state(prm, O, R, p, n);
  branch = md_contact_branch(prm, st, area_t);
  const Real3 C = contact_centre(O, p, n);
  if (branch == kBranchPolar)
    return polar_triangle_contact(prm, st, x0, x1, x2, C, n, quadrature_area(prm, x0, x1, x2, n, area_t));
  if (branch == kBranchRule)
    return rule_triangle_contact(prm, st, x0, x1, x2, C, n, quadrature_area(prm, x0, x1, x2, n, area_t));
  if (branch == kBranchDisc) return disc_triangle_contact(prm, st, x0, x1, x2, C, n);
  return TriangleContact{};
}

}  // namespace dcm
