#pragma once
// The optical-tweezers geometry shared by stretch and relax: which nodes are pulled, and the diameters.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>
#include <vector>

#include "core/errors.hpp"
#include "core/host_mesh.hpp"
#include "core/scene.hpp"

namespace dcm {

// --pulled-fraction's range (CLI::Range lets NaN through): a one-line error naming the value.
inline void check_pulled_fraction(double fraction) {
  if (!(fraction >= 0.001 && fraction <= 0.25))
    throw SceneError("--pulled-fraction = " + detail::format_real(fraction) +
                     " is out of range: allowed 0.001 .. 0.25");
}

// The optical-tweezers cell floats free: a spreading scene's substrate plane (through the cell's centre)
// would cut it. A one-line error instead of a run that cannot reach equilibrium.
inline void check_no_plane(const char* app, const Scene& scene) {
  if (scene.get_bool("contact.plane"))
    throw SceneError(std::string("contact.plane = true is not allowed in ") + app +
                     ": the optical-tweezers cell has no substrate (the plane would cut it); use a scene "
                     "without it or --set contact.plane=false");
}

// Node indices of the outermost `fraction` of the nodes at the −x and +x ends (at least one each). Nodes
// level with the last one taken (|Δx| within 1e-9 of the cell's length, the mirror images of a symmetric
// mesh) are taken too, so the choice depends on the geometry only, not on how the nodes are numbered, and
// each end gets every node of its outermost rings. The apps check `fraction` with check_pulled_fraction
// before they build a mesh.
inline std::pair<std::vector<int>, std::vector<int>> pulled_nodes(const HostMesh& m, double fraction) {
  std::vector<int> order(m.nodes.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return m.nodes[a][0] < m.nodes[b][0]; });
  const std::size_t n =
      std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(fraction * m.nodes.size())));
  const double tie = 1e-9 * (m.nodes[order.back()][0] - m.nodes[order.front()][0]);
  const double low = m.nodes[order[n - 1]][0], high = m.nodes[order[order.size() - n]][0];
  std::vector<int> left, right;
  for (std::size_t k = 0; k < order.size() && m.nodes[order[k]][0] <= low + tie; ++k)
    left.push_back(order[k]);
  for (std::size_t k = order.size(); k-- > 0 && m.nodes[order[k]][0] >= high - tie;)
    right.push_back(order[k]);
  return {left, right};
}

// Axial (x) and transverse (y) extent of positions [n][3] row major.
inline std::pair<double, double> axial_transverse_diameters(const std::vector<double>& x) {
  double xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300;
  for (std::size_t i = 0; i + 2 < x.size(); i += 3) {
    xmin = std::min(xmin, x[i]);
    xmax = std::max(xmax, x[i]);
    ymin = std::min(ymin, x[i + 1]);
    ymax = std::max(ymax, x[i + 1]);
  }
  return {xmax - xmin, ymax - ymin};
}

// Mean edge length of a mesh (m).
inline double mean_edge_length(const HostMesh& mesh, const Topology& t) {
  double sum = 0;
  for (const auto& e : t.edges) {
    const auto& a = mesh.nodes[e[0]];
    const auto& b = mesh.nodes[e[1]];
    sum += std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                     (a[2] - b[2]) * (a[2] - b[2]));
  }
  return sum / t.edges.size();
}

}  // namespace dcm
