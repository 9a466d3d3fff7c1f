#pragma once
// Derjaguin adhesion of a flat triangle with a plane (contact.law = "derjaguin"; docs/model/contact_line.md).
// An energy, not a pressure: each triangle that faces the plane stores
//   E_t = A_p · ⟨φ(h)⟩_t,   A_p = the triangle's area projected on the plane (> 0: facing),
// ⟨φ⟩_t the mean over the triangle of the interaction energy per area φ at the local separation h, which is
// linear over a flat triangle (h_k at its corners). φ keeps the paper's two constants, the work of adhesion
// W and the range h0 (Table 1), and the cortex material stiffness K = 4/3 E/(1 − ν²) of eq. 5:
//   h ≥ h0:       φ = 0
//   0 ≤ h < h0:   φ = −W (1 − u²)²,  u = h / h0     (attraction, largest traction 1.54 W/h0 at u = 1/√3)
//   h < 0:        φ = −W + ½ (K / h0) h²             (repulsion; φ and φ' continuous at 0 and h0)
// so a flat bound membrane sits at h = 0 with energy −W per area, the paper's adhesion energy. The forces are
// the exact gradient of E_t: along the plane normal from ∂⟨φ⟩/∂h_k, and in the plane from ∂A_p/∂x_k. The
// in-plane part is the one a pressure law lacks: at the contact line it pulls the line outward with W per
// unit length (Young–Dupré), at any mesh size. ⟨φ⟩ and its derivatives are exact: h over a triangle is
// distributed as a hat between the corners' lowest and highest values, φ is piecewise polynomial in h, and
// each piece is integrated by Gauss–Legendre (exact for these degrees); the derivatives by forward-mode
// differentiation (Dual3) of the same evaluation.
#include "core/vec3.hpp"

namespace dcm {

struct DerjaguinLaw {
  double W = 0;   // work of adhesion (J/m²)
  double h0 = 0;  // range (m)
  double K = 0;   // repulsion: φ'' = K / h0 for h < 0 (Pa/m · m = Pa; K = 4/3 E/(1 − ν²))
};

// The separation below which a triangle's area counts as contact (A^C, r_cc): the separation of the
// largest adhesive traction, h0/√3. A bound membrane sits near h = 0, where the traction itself is zero.
KOKKOS_INLINE_FUNCTION double derjaguin_contact_gap(const DerjaguinLaw& law) {
  return 0.57735026918962576 * law.h0;
}

// A value and its derivatives with respect to the three corner separations.
struct Dual3 {
  double v = 0;
  double d[3] = {0, 0, 0};
};
KOKKOS_INLINE_FUNCTION Dual3 dual_const(double v) {
  Dual3 r;
  r.v = v;
  return r;
}
KOKKOS_INLINE_FUNCTION Dual3 operator+(const Dual3& a, const Dual3& b) {
  Dual3 r;
  r.v = a.v + b.v;
  for (int k = 0; k < 3; ++k) r.d[k] = a.d[k] + b.d[k];
  return r;
}
KOKKOS_INLINE_FUNCTION Dual3 operator-(const Dual3& a, const Dual3& b) {
  Dual3 r;
  r.v = a.v - b.v;
  for (int k = 0; k < 3; ++k) r.d[k] = a.d[k] - b.d[k];
  return r;
}
KOKKOS_INLINE_FUNCTION Dual3 operator*(const Dual3& a, const Dual3& b) {
  Dual3 r;
  r.v = a.v * b.v;
  for (int k = 0; k < 3; ++k) r.d[k] = a.d[k] * b.v + a.v * b.d[k];
  return r;
}
KOKKOS_INLINE_FUNCTION Dual3 operator*(double s, const Dual3& a) {
  Dual3 r;
  r.v = s * a.v;
  for (int k = 0; k < 3; ++k) r.d[k] = s * a.d[k];
  return r;
}
KOKKOS_INLINE_FUNCTION Dual3 operator/(const Dual3& a, const Dual3& b) {
  Dual3 r;
  r.v = a.v / b.v;
  for (int k = 0; k < 3; ++k) r.d[k] = (a.d[k] - r.v * b.d[k]) / b.v;
  return r;
}

// The integrands at separation h: φ, the contact and zone indicators, and the ramps whose derivatives are
// the indicators' first moments (ψ_c = max(h_c − h, 0), ψ_z = max(h0 − h, 0)).
struct DerjaguinIntegrands {
  Dual3 phi, contact, zone, ramp_contact, ramp_zone;
};
KOKKOS_INLINE_FUNCTION void accumulate_integrands(const DerjaguinLaw& law, const Dual3& h, double w,
                                                  DerjaguinIntegrands& acc) {
  const double hc = derjaguin_contact_gap(law);
  if (h.v < 0) {
    acc.phi = acc.phi + w * (dual_const(-law.W) + (0.5 * law.K / law.h0) * (h * h));
  } else if (h.v < law.h0) {
    const Dual3 u = (1.0 / law.h0) * h;
    const Dual3 s = dual_const(1.0) - u * u;
    acc.phi = acc.phi + w * ((-law.W) * (s * s));
  }
  if (h.v < hc) {
    acc.contact.v += w;
    acc.ramp_contact = acc.ramp_contact + w * (dual_const(hc) - h);
  }
  if (h.v < law.h0) {
    acc.zone.v += w;
    acc.ramp_zone = acc.ramp_zone + w * (dual_const(law.h0) - h);
  }
}

// acc += scale · ∫_0^1 f(a + s b) s ds, split where a + s b crosses 0, h_c or h0 (3-point Gauss per piece:
// exact for φ of degree 4 times s).
KOKKOS_INLINE_FUNCTION void integrate_ramp(const DerjaguinLaw& law, const Dual3& a, const Dual3& b,
                                           const Dual3& scale, DerjaguinIntegrands& acc) {
  Dual3 cut[5];
  int n = 0;
  cut[n++] = dual_const(0.0);
  const double levels[3] = {0.0, derjaguin_contact_gap(law), law.h0};
  if (b.v > 1e-12 * law.h0 || b.v < -1e-12 * law.h0)
    for (int l = 0; l < 3; ++l) {
      const Dual3 s = (dual_const(levels[l]) - a) / b;
      if (s.v > 0 && s.v < 1) {
        int i = n++;  // insertion sort by value
        while (i > 1 && cut[i - 1].v > s.v) {
          cut[i] = cut[i - 1];
          --i;
        }
        cut[i] = s;
      }
    }
  cut[n++] = dual_const(1.0);
  const double gx[3] = {0.11270166537925831, 0.5, 0.88729833462074169};
  const double gw[3] = {5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};
  for (int p = 0; p + 1 < n; ++p) {
    const Dual3 len = cut[p + 1] - cut[p];
    for (int q = 0; q < 3; ++q) {
      const Dual3 s = cut[p] + gx[q] * len;
      DerjaguinIntegrands piece;
      accumulate_integrands(law, a + s * b, 1.0, piece);
      const Dual3 w = gw[q] * (len * s) * scale;
      acc.phi = acc.phi + w * piece.phi;
      acc.ramp_contact = acc.ramp_contact + w * piece.ramp_contact;
      acc.ramp_zone = acc.ramp_zone + w * piece.ramp_zone;
      acc.contact.v += w.v * piece.contact.v;
      acc.zone.v += w.v * piece.zone.v;
    }
  }
}

// Means over a flat triangle of the integrands, given its corners' separations h[3].
KOKKOS_INLINE_FUNCTION DerjaguinIntegrands derjaguin_means(const DerjaguinLaw& law, const double h[3]) {
  Dual3 c[3];
  for (int k = 0; k < 3; ++k) {
    c[k].v = h[k];
    c[k].d[k] = 1;
  }
  // sort by value: lo ≤ mid ≤ hi
  if (c[1].v < c[0].v) {
    const Dual3 t = c[0];
    c[0] = c[1];
    c[1] = t;
  }
  if (c[2].v < c[1].v) {
    const Dual3 t = c[1];
    c[1] = c[2];
    c[2] = t;
  }
  if (c[1].v < c[0].v) {
    const Dual3 t = c[0];
    c[0] = c[1];
    c[1] = t;
  }
  DerjaguinIntegrands acc;
  const Dual3 span = c[2] - c[0];
  if (!(span.v > 1e-9 * law.h0)) {  // parallel to the plane: the mean of f(h̄) (error O(span² f''))
    accumulate_integrands(law, (1.0 / 3.0) * (c[0] + c[1] + c[2]), 1.0, acc);
    return acc;
  }
  // h is distributed as a hat on [lo, hi] with its peak at mid:
  //   ⟨f⟩ = 2 r ∫_0^1 f(lo + s (mid − lo)) s ds + 2 (1 − r) ∫_0^1 f(hi − s (hi − mid)) s ds,  r = (mid −
  //   lo)/span
  const Dual3 r = (c[1] - c[0]) / span;
  integrate_ramp(law, c[0], c[1] - c[0], 2.0 * r, acc);
  integrate_ramp(law, c[2], c[1] - c[2], 2.0 * (dual_const(1.0) - r), acc);
  return acc;
}

// One triangle's adhesion: energy, forces on its corners (along the plane normal, and in the plane), the
// contact and zone areas (h < h_c, h < h0) and the barycentric centroids of those areas.
struct DerjaguinTriangle {
  double energy = 0;              // J
  double normal_force[3] = {};    // along the plane normal (N), repulsive positive
  Real3 shear[3] = {};            // in the plane (N)
  double contact_area = 0;        // m², projected
  double zone_area = 0;           // m², projected
  double contact_weight[3] = {};  // barycentric centroid of the contact area (Σ = 1 if contact_area > 0)
  double zone_weight[3] = {};     // the same for the zone
  double highest = 0;             // the largest corner separation (m)
};

// n: the plane's unit normal, pointing to the cell's side; p: a point of the plane. The triangle (x0, x1,
// x2) is ordered with its outward normal (x1 − x0) × (x2 − x0); it faces the plane when that normal has a
// negative component along n. A triangle that does not face the plane has no adhesion (the membrane
// between it and the plane screens it).
KOKKOS_INLINE_FUNCTION DerjaguinTriangle derjaguin_triangle(const DerjaguinLaw& law, Real3 x0, Real3 x1,
                                                            Real3 x2, Real3 p, Real3 n) {
  DerjaguinTriangle out;
  const double h[3] = {dot(x0 - p, n), dot(x1 - p, n), dot(x2 - p, n)};
  out.highest = math::max(math::max(h[0], h[1]), h[2]);
  const double lowest = math::min(math::min(h[0], h[1]), h[2]);
  const double a_p = -0.5 * dot(cross(x1 - x0, x2 - x0), n);  // projected area, > 0 facing
  if (!(lowest < law.h0) || !(a_p > 0)) return out;
  const DerjaguinIntegrands m = derjaguin_means(law, h);
  out.energy = a_p * m.phi.v;
  const Real3 mm = -1.0 * n;  // ∂A_p/∂x_k = ½ m × (x_{k+2} − x_{k+1}), in the plane
  const Real3 g[3] = {0.5 * cross(mm, x2 - x1), 0.5 * cross(mm, x0 - x2), 0.5 * cross(mm, x1 - x0)};
  for (int k = 0; k < 3; ++k) {
    out.normal_force[k] = -a_p * m.phi.d[k];
    out.shear[k] = (-m.phi.v) * g[k];
  }
  out.contact_area = a_p * m.contact.v;
  out.zone_area = a_p * m.zone.v;
  for (int k = 0; k < 3; ++k) {  // ∂⟨ψ⟩/∂h_k = −⟨1[h < level] λ_k⟩
    out.contact_weight[k] = m.contact.v > 0 ? -m.ramp_contact.d[k] / m.contact.v : 0.0;
    out.zone_weight[k] = m.zone.v > 0 ? -m.ramp_zone.d[k] / m.zone.v : 0.0;
  }
  return out;
}

}  // namespace dcm
