// Local refinement of a band of a unit-sphere mesh (BandRefinement, core/host_mesh.hpp): red-green splits.
//
// Level L = 1 .. levels splits 1-to-4 ("red") every triangle whose polar angles (from (0, 0, -1)) reach the
// band widened by margin_L = 3 (e_L + ... + e_{levels-1}), e_j the edge angle after j levels; so level
// `levels` covers the band itself and each coarser level reaches three of its own children's edges further
// on each side. A triangle with two or more split edges is made red as well (repeated until none is left);
// one with a single split edge is bisected from the opposite node ("green", two triangles of 30-60-90° from
// an equilateral one). The margins keep every green pair outside the next level's red region, so no green
// triangle is split again (checked: a std::logic_error if it were). New nodes are edge midpoints projected
// onto the unit sphere, shared by the two triangles of the edge; HostMesh::parents records the edge's two
// nodes as the new node's parents, which extends the icosphere's subdivision hierarchy into the band, so
// the multigrid (solvers/multigrid_setup.hpp) coarsens the band first and the icosphere after it.
#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/host_mesh.hpp"

namespace dcm {
namespace {

constexpr double kPi = 3.14159265358979323846;

double polar_angle(const Vec3& x) { return std::acos(std::clamp(-x[2], -1.0, 1.0)); }  // from (0, 0, -1)

double edge_angle(const Vec3& a, const Vec3& b) {
  return std::acos(std::clamp(a[0] * b[0] + a[1] * b[1] + a[2] * b[2], -1.0, 1.0));
}

std::pair<int, int> edge_key(int a, int b) { return std::minmax(a, b); }

// One level: splits the triangles in [lo, hi] (polar angle, radians) red, closes the border green.
void refine_level(HostMesh& m, std::vector<char>& green, double lo, double hi) {
  const int nt = static_cast<int>(m.triangles.size());
  std::map<std::pair<int, int>, std::array<int, 2>> edge_tris;
  for (int f = 0; f < nt; ++f)
    for (int c = 0; c < 3; ++c) {
      auto& slot = edge_tris
                       .try_emplace(edge_key(m.triangles[f][c], m.triangles[f][(c + 1) % 3]),
                                    std::array<int, 2>{-1, -1})
                       .first->second;
      slot[slot[0] < 0 ? 0 : 1] = f;
    }
  std::vector<char> red(nt, 0);
  for (int f = 0; f < nt; ++f) {
    double tmin = kPi, tmax = 0;
    for (const int v : m.triangles[f]) {
      const double t = polar_angle(m.nodes[v]);
      tmin = std::min(tmin, t);
      tmax = std::max(tmax, t);
    }
    red[f] = tmax >= lo && tmin <= hi;
  }
  const auto other = [&](int f, int c) {
    const auto& two = edge_tris.at(edge_key(m.triangles[f][c], m.triangles[f][(c + 1) % 3]));
    return two[0] == f ? two[1] : two[0];
  };
  for (bool changed = true; changed;) {  // red closure: two split edges make a triangle red
    changed = false;
    for (int f = 0; f < nt; ++f) {
      if (red[f]) continue;
      int split = 0;
      for (int c = 0; c < 3; ++c) split += red[other(f, c)];
      if (split >= 2) red[f] = changed = true;
    }
  }
  std::map<std::pair<int, int>, int> midpoint;
  const auto mid = [&](int a, int b) {
    const auto key = edge_key(a, b);
    const auto it = midpoint.find(key);
    if (it != midpoint.end()) return it->second;
    const Vec3& p = m.nodes[a];
    const Vec3& q = m.nodes[b];
    const Vec3 s{p[0] + q[0], p[1] + q[1], p[2] + q[2]};
    const double n = std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    m.nodes.push_back({s[0] / n, s[1] / n, s[2] / n});
    if (!m.parents.empty()) m.parents.push_back({key.first, key.second});
    const int id = static_cast<int>(m.nodes.size()) - 1;
    midpoint.emplace(key, id);
    return id;
  };
  std::vector<Tri> next;
  std::vector<char> next_green;
  for (int f = 0; f < nt; ++f) {
    const Tri t = m.triangles[f];
    int split_edge = -1, split = 0;
    for (int c = 0; c < 3; ++c)
      if (!red[f] && red[other(f, c)]) {
        split_edge = c;
        ++split;
      }
    if ((red[f] || split > 0) && green[f])
      throw std::logic_error("band refinement: a closure triangle would be split again (triangle " +
                             std::to_string(f) + ")");
    if (red[f]) {
      const int ab = mid(t[0], t[1]), bc = mid(t[1], t[2]), ca = mid(t[2], t[0]);
      for (const Tri& c : {Tri{t[0], ab, ca}, Tri{t[1], bc, ab}, Tri{t[2], ca, bc}, Tri{ab, bc, ca}}) {
        next.push_back(c);
        next_green.push_back(0);
      }
    } else if (split == 1) {
      const int a = t[split_edge], b = t[(split_edge + 1) % 3], c = t[(split_edge + 2) % 3];
      const int ab = mid(a, b);
      for (const Tri& g : {Tri{a, ab, c}, Tri{ab, b, c}}) {
        next.push_back(g);
        next_green.push_back(1);
      }
    } else {
      next.push_back(t);
      next_green.push_back(green[f]);
    }
  }
  m.triangles = std::move(next);
  green = std::move(next_green);
}

}  // namespace

void refine_band(HostMesh& m, const BandRefinement& band) {
  if (band.levels < 0 || band.levels > 6)
    throw std::invalid_argument("band refinement levels = " + std::to_string(band.levels) +
                                " is out of range: allowed 0 .. 6");
  if (!(0 <= band.from_deg && band.from_deg < band.to_deg && band.to_deg <= 180))
    throw std::invalid_argument("band refinement: polar angles " + std::to_string(band.from_deg) + " .. " +
                                std::to_string(band.to_deg) + " deg must satisfy 0 <= from < to <= 180");
  double e0 = 0;  // the longest edge (angle on the unit sphere)
  for (const Tri& t : m.triangles)
    for (int c = 0; c < 3; ++c) e0 = std::max(e0, edge_angle(m.nodes[t[c]], m.nodes[t[(c + 1) % 3]]));
  const double from = band.from_deg * kPi / 180, to = band.to_deg * kPi / 180;
  std::vector<char> green(m.triangles.size(), 0);
  for (int level = 1; level <= band.levels; ++level) {
    double margin = 0;
    for (int j = level; j < band.levels; ++j) margin += 3 * e0 / std::ldexp(1.0, j);
    refine_level(m, green, from - margin, to + margin);
  }
}

double smallest_angle_deg(const HostMesh& m) {
  double smallest = 180;
  for (const Tri& t : m.triangles)
    for (int c = 0; c < 3; ++c) {
      const Vec3& p = m.nodes[t[c]];
      const Vec3& a = m.nodes[t[(c + 1) % 3]];
      const Vec3& b = m.nodes[t[(c + 2) % 3]];
      const Vec3 u{a[0] - p[0], a[1] - p[1], a[2] - p[2]}, v{b[0] - p[0], b[1] - p[1], b[2] - p[2]};
      const double dot = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
      const double nu = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
      const double nv = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      smallest = std::min(smallest, std::acos(std::clamp(dot / (nu * nv), -1.0, 1.0)) * 180 / kPi);
    }
  return smallest;
}

}  // namespace dcm
