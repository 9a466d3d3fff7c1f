#pragma once
// Exact-in-r integration of the Maugis–Dugdale pressure over a triangle (dcm's alternative to the paper's
// N_Q-point rule, docs/model/contact.md): the pressure is radial about the contact centre C, so in polar
// coordinates about C
//   F = ∫∫ p dA = Σ_edges ∫ G(ρ(θ)) dθ,            G(ρ) = ∫_0^ρ p(r) r dr   (closed form),
//   M = ∫∫ r × p n dA = Σ_edges ∫ H(ρ(θ)) (ê(θ) × n) dθ,  H(ρ) = ∫_0^ρ p(r) r² dr,
// where each edge (P, Q) of the triangle, projected on the plane, sweeps the sector (C, P, Q) (signed) and
// ρ(θ) is the distance from C to the edge along ê(θ). The step of p at r = c and the square root at r = a
// are integrated exactly in r; the sweep is integrated along the edge (detail::polar_sector) by 8-point
// Gauss–Legendre on pieces split where ρ crosses a and c, so the integrand is smooth on each piece. Same for
// the contact area with G_A(ρ) = min(ρ, a)²/2.
#include "core/vec3.hpp"
#include "kernels/maugis_dugdale.hpp"

namespace dcm {

// The radial integrals of the MD pressure about the contact centre,
//   G(ρ) = ∫_0^ρ p(r) r dr (Pa·m²; the load inside radius ρ is 2π G(ρ)),   H(ρ) = ∫_0^ρ p(r) r² dr (Pa·m³),
// in closed form. Inside the contact radius (ρ < a) with r = a sin φ, u = sqrt(a² − r²) = a cos φ, k = w/a,
// w = sqrt(c² − a²):
//   Hertz (eq. 5):      G = p0/(3a) (a³ − u³),   H = (p0/a) [r (2r² − a²) u + a⁴ φ] / 8;
//   Dugdale (eq. 7), p = −(2σ0/π) atan(w/u):  G −= (2σ0/π) (F(a) − F(u)),  F(v) = ½(v² + w²) atan2(w, v) +
//   ½wv − (π/4)w²,
//     H −= (2σ0/π) a³ [sin³φ/3 · atan2(k, cos φ) − k J(φ)/3],
//     J(φ) = φ/2 + sin 2φ/4 − (2 + k²) φ + (1 + k²)^{3/2}/k · atan(k tan φ / sqrt(1 + k²));
// outside it, −σ0 on a < r < c. MdRadial keeps what depends on the triangle only (w, 1/a, F(a), G(a), H(a)).
// A point costs a square root and three first-quadrant atan2 (φ = atan2(r, u), sin φ = r/a and cos φ = u/a
// exactly, atan2(k, cos φ) = atan2(w, u); math::atan2_first_quadrant, no library call); both forms are
// evaluated and one selected, so that the 8 points of a piece run in SIMD lanes (session 11: the contact
// kernel 2.0 → 1.1 ms per step on one thread, docs/PERFORMANCE.md).
struct MdRadial {
  double a = 0, c = 0, p0 = 0, sigma0 = 0;
  double w = 0, k = 0, q = 0, Fa = 0;  // w = sqrt(c² − a²), k = w/a, q = sqrt(1 + k²), F(a)
  double Ga = 0, Ha = 0;               // G(a), H(a)
  double inv_a = 0;                    // 1/a
  bool dugdale_inside = false;         // σ0 > 0 and c > a: the Dugdale stress reaches inside a
};

namespace detail {
// G(ρ), H(ρ) by the inside form (ρ ≤ a): Hertz and the Dugdale stress reaching inside a. Finite for every
// ρ ≥ 0 (r = min(ρ, a), u = 0 beyond a) and for a = 0 (1/a is stored as 0).
KOKKOS_INLINE_FUNCTION void md_radial_inside(const MdRadial& m, double rho, double& g, double& h) {
  const double a = m.a;
  const double r = math::min(rho, a);
  const double u = math::sqrt(math::max(a * a - r * r, 0.0));
  const double phi = math::atan2_first_quadrant(r, u);  // asin(r/a)
  const double p0_a = m.p0 * m.inv_a;
  g = p0_a / 3.0 * (a * a * a - u * u * u);
  h = p0_a * (r * (2 * r * r - a * a) * u + a * a * a * a * phi) / 8.0;
  const double w = m.w;
  const double t = math::atan2_first_quadrant(w, u);  // = atan2(k, cos φ)
  const double Fu = 0.5 * (u * u + w * w) * t + 0.5 * w * u - 0.25 * kMdPi * w * w;
  const double k = m.k, q = m.q, sn = r * m.inv_a, cs = u * m.inv_a;
  const double kj = k * (phi / 2 + sn * cs / 2 - (2 + k * k) * phi) +
                    q * q * q * math::atan2_first_quadrant(k * sn, q * cs);
  const double d = a * a * a * (sn * sn * sn / 3 * t - kj / 3);
  g = m.dugdale_inside ? g - 2.0 / kMdPi * m.sigma0 * (m.Fa - Fu) : g;
  h = m.dugdale_inside && phi > 0 ? h - 2.0 / kMdPi * m.sigma0 * d : h;
}
}  // namespace detail

KOKKOS_INLINE_FUNCTION MdRadial md_radial(const MdState& st) {
  MdRadial m;
  m.a = st.a;
  m.c = st.c;
  m.p0 = st.p0;
  m.sigma0 = st.sigma0;
  if (!(st.a > 0)) return m;
  m.w = math::sqrt(math::max(st.c * st.c - st.a * st.a, 0.0));
  m.dugdale_inside = st.sigma0 > 0 && m.w > 0;
  m.inv_a = 1.0 / st.a;
  m.k = m.w * m.inv_a;
  m.q = math::sqrt(1 + m.k * m.k);
  m.Fa = 0.5 * (st.a * st.a + m.w * m.w) * math::atan2_first_quadrant(m.w, st.a) + 0.5 * m.w * st.a -
         0.25 * kMdPi * m.w * m.w;
  detail::md_radial_inside(m, st.a, m.Ga, m.Ha);
  return m;
}

// G(ρ) and H(ρ) (see MdRadial). Without branches (the quadrature points of a sector are computed in SIMD
// lanes): the inside and the outside forms are both evaluated and one is selected.
KOKKOS_INLINE_FUNCTION void md_radial_integrals(const MdRadial& m, double rho, double& g, double& h) {
  double gi, hi;
  detail::md_radial_inside(m, rho, gi, hi);
  const double a = m.a, ro = math::min(rho, m.c);
  const bool ring = rho > a && m.c > a;  // −σ0 on a < r < c
  const double go = ring ? m.Ga - 0.5 * m.sigma0 * (ro * ro - a * a) : m.Ga;
  const double ho = ring ? m.Ha - m.sigma0 * (ro * ro * ro - a * a * a) / 3.0 : m.Ha;
  const bool inside = a > 0 && rho < a;
  g = inside ? gi : go;
  h = inside ? hi : ho;
}

// G(ρ) = ∫_0^ρ p(r) r dr (Pa·m²): the load inside radius ρ is 2π G(ρ).
KOKKOS_INLINE_FUNCTION double md_radial_load(const MdState& st, double rho) {
  double g, h;
  md_radial_integrals(md_radial(st), rho, g, h);
  return g;
}

// H(ρ) = ∫_0^ρ p(r) r² dr (Pa·m³).
KOKKOS_INLINE_FUNCTION double md_radial_moment(const MdState& st, double rho) {
  double g, h;
  md_radial_integrals(md_radial(st), rho, g, h);
  return h;
}

struct PolarIntegral {
  double load = 0;          // ∫ p dA (N)
  double m1 = 0, m2 = 0;    // moment about C in the basis (e1, e2) of the plane (N·m)
  double contact_area = 0;  // area of the triangle within r < a (m²)
  double zone_area = 0;     // area of the triangle within r < max(a, c), contact and adhesive zone (m²)
  // First moments about C, in the basis (e1, e2), of those two areas (m³): their centroids are C +
  // (x e1 + y e2) / area.
  double contact_x = 0, contact_y = 0, zone_x = 0, zone_y = 0;
};

namespace detail {
// One signed sector (C = origin, P, Q) in plane coordinates, parametrised by the position s along the edge
// from the foot F of the perpendicular from C: r(s) = F + s d̂, ρ² = h² + s², dθ = κ ds / ρ² with
// κ = F × d̂ (= ±h). The integrands G(ρ) κ/ρ², H(ρ) κ/ρ³ (sin θ, cos θ) stay bounded and smooth even when C
// lies on or near the edge's line (where an angle parametrisation is nearly singular); pieces split where
// ρ = a and ρ = c, 8-point Gauss–Legendre on each, Lanes points at a time (8 on the host: SIMD lanes; 1 on a
// device, where 8 lanes of nine sums would take 144 registers; the sums run in the same order either way).
template <int Lanes>
KOKKOS_INLINE_FUNCTION void polar_sector(const MdRadial& st, double px, double py, double qx, double qy,
                                         PolarIntegral& out) {
  const double dx = qx - px, dy = qy - py, len = math::sqrt(dx * dx + dy * dy);
  if (!(len > 0)) return;
  const double ux = dx / len, uy = dy / len;
  const double sp = px * ux + py * uy, sq = qx * ux + qy * uy;  // positions of P and Q along the edge
  const double fx = px - sp * ux, fy = py - sp * uy;            // foot of the perpendicular from C
  const double kappa = fx * uy - fy * ux;                       // F × d̂, signed distance of the line
  if (kappa == 0) return;                                       // C on the line: a sector of zero area
  const double h2 = kappa * kappa;
  double cuts[6];
  int n_cuts = 0;
  cuts[n_cuts++] = sp;
  const double radii[2] = {st.a, st.c};
  for (int k = 0; k < 2; ++k) {
    if (!(radii[k] * radii[k] > h2)) continue;
    const double sr = math::sqrt(radii[k] * radii[k] - h2);
    for (int sgn = -1; sgn <= 1; sgn += 2) {
      const double sc = sgn * sr;
      if ((sc - sp) * (sc - sq) < 0) cuts[n_cuts++] = sc;
    }
  }
  cuts[n_cuts++] = sq;
  const double dir = sq > sp ? 1.0 : -1.0;
  for (int i = 1; i < n_cuts; ++i)  // insertion sort along the sweep from P to Q
    for (int j = i; j > 0 && dir * (cuts[j] - cuts[j - 1]) < 0; --j) {
      const double tmp = cuts[j];
      cuts[j] = cuts[j - 1];
      cuts[j - 1] = tmp;
    }
  for (int piece = 0; piece + 1 < n_cuts; ++piece) {
    const double s0 = cuts[piece], half = 0.5 * (cuts[piece + 1] - s0);
    if (half == 0) continue;
    // 8-point Gauss–Legendre on [−1, 1] (local arrays: also valid in device code). Lanes points at a time (no
    // branches, so the host compiler vectorises 8 of them), then summed in order.
    constexpr double gx[8] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                              -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                              0.7966664774136267,  0.9602898564975363};
    constexpr double gw[8] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873, 0.3626837833783620,
                              0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};
    static_assert(Lanes == 1 || Lanes == 8, "1 or 8 lanes");
    for (int i0 = 0; i0 < 8; i0 += Lanes) {
      double load[Lanes], m1[Lanes], m2[Lanes], ca[Lanes], za[Lanes], cx[Lanes], cy[Lanes], zx[Lanes],
          zy[Lanes];
      for (int l = 0; l < Lanes; ++l) {
        const int i = i0 + l;
        const double sv = s0 + half * (gx[i] + 1);
        const double rx = fx + sv * ux, ry = fy + sv * uy;
        const double rho2 = h2 + sv * sv, rho = math::sqrt(rho2), inv_rho = 1.0 / rho;
        const double dtheta = gw[i] * half * kappa * inv_rho * inv_rho;
        double g, hr;
        md_radial_integrals(st, rho, g, hr);
        const double hm = hr * inv_rho;
        load[l] = dtheta * g;
        m1[l] = dtheta * hm * ry;  // ê × n = sin θ e1 − cos θ e2
        m2[l] = dtheta * hm * rx;
        const double ra = math::min(rho, st.a);
        ca[l] = dtheta * 0.5 * ra * ra;
        const double rz = math::min(rho, math::max(st.a, st.c));
        za[l] = dtheta * 0.5 * rz * rz;
        const double third = dtheta * inv_rho / 3.0;
        const double ma = third * ra * ra * ra, mz = third * rz * rz * rz;
        cx[l] = ma * rx;  // ∫ r ê(θ) r dr dθ, ê = (rx, ry)/ρ
        cy[l] = ma * ry;
        zx[l] = mz * rx;
        zy[l] = mz * ry;
      }
      for (int l = 0; l < Lanes; ++l) {
        out.load += load[l];
        out.m1 += m1[l];
        out.m2 -= m2[l];
        out.contact_area += ca[l];
        out.zone_area += za[l];
        out.contact_x += cx[l];
        out.contact_y += cy[l];
        out.zone_x += zx[l];
        out.zone_y += zy[l];
      }
    }
  }
}
}  // namespace detail

// ∫ over the triangle (x0, x1, x2) projected on the plane through C with unit normal n, of the radial MD
// pressure about C; (e1, e2) an orthonormal basis of the plane with e1 × e2 = n. Lanes: Gauss points per
// step (detail::polar_sector; ContactLanes picks it per execution space).
template <int Lanes = 8>
KOKKOS_INLINE_FUNCTION PolarIntegral polar_contact_integral(const MdState& st, Real3 x0, Real3 x1, Real3 x2,
                                                            Real3 C, Real3 e1, Real3 e2) {
  const Real3 xs[3] = {x0, x1, x2};
  double qx[3], qy[3];
  for (int k = 0; k < 3; ++k) {
    qx[k] = dot(xs[k] - C, e1);
    qy[k] = dot(xs[k] - C, e2);
  }
  PolarIntegral out;
  const MdRadial m = md_radial(st);
  for (int k = 0; k < 3; ++k)
    detail::polar_sector<Lanes>(m, qx[k], qy[k], qx[(k + 1) % 3], qy[(k + 1) % 3], out);
  const double orientation = (qx[1] - qx[0]) * (qy[2] - qy[0]) - (qy[1] - qy[0]) * (qx[2] - qx[0]);
  if (orientation < 0) {
    out.load = -out.load;
    out.m1 = -out.m1;
    out.m2 = -out.m2;
    out.contact_area = -out.contact_area;
    out.zone_area = -out.zone_area;
    out.contact_x = -out.contact_x;
    out.contact_y = -out.contact_y;
    out.zone_x = -out.zone_x;
    out.zone_y = -out.zone_y;
  }
  return out;
}

}  // namespace dcm
