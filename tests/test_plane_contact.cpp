// Rounded triangles against a plane (kernels/plane_contact.hpp): the paper's central claim, mesh
// independence: a rigid triangulated sphere pressed into the plane gives the continuum Maugis–Dugdale load
// of a perfect sphere at the same contact radius; node forces add up to the triangle loads; the contact
// area gives r_cc ≈ a.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "core/host_copy.hpp"
#include "core/update_geometry.hpp"
#include "kernels/plane_contact.hpp"

namespace dcm {
namespace {

using Exec = Kokkos::DefaultExecutionSpace;
using Mem = Exec::memory_space;
constexpr double kPi = 3.14159265358979323846;
constexpr double kR = 3.25e-6, kE = 800e3, kNu = 0.4, kW = 1e-3;

// h0 giving the wanted λ for a sphere of radius kR (λ ∝ 1/h0).
MdMaterial material_for_lambda(double lambda) {
  MdMaterial m = md_material(kE, kNu, kW, 20e-9);
  m.h0 *= md_lambda(m, kR) / lambda;
  return m;
}

struct SphereContact {
  double load = 0, node_load = 0, area = 0, edge = 0;
};

// An icosphere of radius kR (k subdivisions), rotated by `tilt` about x, its lowest point δ below the plane.
SphereContact press_sphere(int k, double a, const PlaneContactParams& prm, double tilt = 0) {
  HostMesh m = make_icosphere(k, kR);
  double zmin = 1;
  for (auto& x : m.nodes) {
    const double y = x[1] * std::cos(tilt) - x[2] * std::sin(tilt),
                 z = x[1] * std::sin(tilt) + x[2] * std::cos(tilt);
    x[1] = y;
    x[2] = z;
    zmin = std::fmin(zmin, z);
  }
  const double delta = kR - std::sqrt(kR * kR - a * a);  // geometric overlap of the perfect sphere
  for (auto& x : m.nodes) x[2] += kR - delta;
  const Exec space;
  const MeshBuffers<Mem> mesh = upload_cells<Mem>({HostCell(m)});
  const GeometryBuffers<Mem> geo(mesh);
  update_geometry(space, mesh, geo, 1e4);
  ContactBuffers<Mem> contact(mesh.n_tris);
  compute_plane_contact(space, mesh, geo, Plane{}, prm, contact);
  Kokkos::View<double* [3], Kokkos::LayoutRight, Mem> force("force", mesh.n_nodes);
  add_plane_contact_forces(space, mesh, Plane{}, contact, force);
  SphereContact r;
  r.load = total_contact_load(space, contact);
  r.area = total_contact_area(space, contact);
  const auto f = to_host_vector(force);
  for (std::size_t i = 2; i < f.size(); i += 3) r.node_load += f[i];
  const auto tri = to_host_vector(mesh.tri);
  double sum = 0;
  for (std::size_t t = 0; t < tri.size(); t += 3)
    for (int e = 0; e < 3; ++e) {
      const auto& p = m.nodes[tri[t + e]];
      const auto& q = m.nodes[tri[t + (e + 1) % 3]];
      sum += std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                       (p[2] - q[2]) * (p[2] - q[2]));
    }
  r.edge = sum / static_cast<double>(tri.size());
  return r;
}

TEST(PlaneContact, RigidSphereMatchesTheContinuumLaw) {
  for (int k : {3, 4}) {
    for (double lambda : {0.1, 1.0, 10.0}) {
      for (int nq : {1, 3, 7, 16}) {
        PlaneContactParams prm;
        prm.material = material_for_lambda(lambda);
        prm.quadrature_points = nq;
        double worst = 0;
        const double edge = press_sphere(k, 0.3e-6, prm).edge;
        for (double a_over_R : {0.0, 0.1, 0.2, 0.3, 0.4, 0.5}) {
          const double a = a_over_R == 0 ? edge : a_over_R * kR;
          if (a < edge) continue;
          for (double tilt : {0.0, 0.3}) {
            const SphereContact s = press_sphere(k, a, prm, tilt);
            const MdState exact = md_state_from_radius(a, kR, prm.material);
            const double err = std::fabs(s.load - exact.P) / std::fabs(exact.P);
            worst = std::fmax(worst, err);
            if (nq == 16)
              std::printf(
                  "k=%d lambda=%g nq=%d a/R=%.3f tilt=%.1f  P=%.4e exact=%.4e err=%.2e  nodeΣ-Σ=%.1e  "
                  "r_cc/a=%.3f\n",
                  k, lambda, nq, a / kR, tilt, s.load, exact.P, err,
                  std::fabs(s.node_load - s.load) / std::fabs(s.load), std::sqrt(s.area / kPi) / a);
          }
        }
        std::printf("nodes=%d lambda=%g nq=%d worst=%.3e\n", 10 * (1 << (2 * k)) + 2, lambda, nq, worst);
      }
    }
  }
}

}  // namespace
}  // namespace dcm
