#pragma once
// The paper's biconcave start (its Methods, "Initial cell shape"; MODEL.md section 1): deflate the
// sphere to a fraction of its volume and let the cortex relax. The sphere is the rest state of every term
// (bonds, bending angles, triangle and cell areas); the volume term's target V* is lowered in steps and
// the equilibrium is found after each by the Newton method of solvers/newton_equilibrium.hpp. A small
// oblate squash of the start selects the oblate (discocyte) branch over the prolate one.
// docs/model/deflation.md compares the result with the Evans–Fung shape.
#include <stdexcept>
#include <string>
#include <vector>

#include "core/host_copy.hpp"
#include "core/host_mesh.hpp"
#include "solvers/newton_equilibrium.hpp"

namespace dcm {

struct DeflationSettings {
  double volume_fraction = 0.6;  // V_end / V_sphere
  int ramp_steps = 8;            // equilibria on the way down
  double oblate_seed = 0.8;      // z of the start scaled by this
  double length_scale = 0;       // Newton's step scale (m); 0: 1% of the radius
  double force_tol = 1e-15;      // N, Newton's convergence per ramp step
  double spring_scale = 0.001;   // bonds' k_s × this during deflation (soft shear: bending shapes the cell)
  bool local_area = false;       // keep the per-triangle area term (off: triangles may change area)
  bool flat_bending = true;      // bending rest angles 0 (no spontaneous curvature) instead of the sphere's
};

struct DeflationResult {
  HostMesh mesh;
  int newton_steps = 0;
  double max_force = 0;  // N, residual at the end
};

template <class ExecutionSpace>
DeflationResult deflate_sphere(const ExecutionSpace& space, const HostMesh& sphere, MechanicsParams p,
                               const DeflationSettings& s) {
  if (!(p.k_volume > 0))
    throw std::invalid_argument("deflation needs a volume term (cortex.k_v > 0), got k_v = " +
                                std::to_string(p.k_volume));
  p.gravity = 0;
  if (!s.local_area) p.k_area_local = 0;
  p.bonds.k_s *= s.spring_scale;
  CortexModel<ExecutionSpace> model(space, {HostCell(sphere)}, p);
  if (s.flat_bending) model.flatten_bending_rest();
  {
    auto x = Kokkos::create_mirror_view(model.positions());
    for (std::size_t i = 0; i < sphere.nodes.size(); ++i)
      for (int d = 0; d < 3; ++d) x(i, d) = sphere.nodes[i][d] * (d == 2 ? s.oblate_seed : 1.0);
    Kokkos::deep_copy(model.positions(), x);
  }
  double radius = 0;
  for (const auto& x : sphere.nodes) radius += std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
  radius /= static_cast<double>(sphere.nodes.size());
  const double scale = s.length_scale > 0 ? s.length_scale : 0.01 * radius;

  DeflationResult result;
  double fraction = 1.0;
  for (int k = 1; k <= s.ramp_steps; ++k) {
    const double target = 1.0 + (s.volume_fraction - 1.0) * k / s.ramp_steps;
    model.scale_rest_volume(target / fraction);
    fraction = target;
    NewtonSettings ns;
    ns.force_tol = s.force_tol;
    const NewtonResult r = newton_equilibrium(model, ns, scale);
    result.newton_steps += r.newton_steps;
    result.max_force = r.max_force;
  }
  result.mesh = sphere;
  const auto x = to_host_vector(model.positions());
  for (std::size_t i = 0; i < result.mesh.nodes.size(); ++i)
    for (int d = 0; d < 3; ++d) result.mesh.nodes[i][d] = x[3 * i + d];
  return result;
}

}  // namespace dcm
