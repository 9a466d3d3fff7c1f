#include "core/host_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace dcm {
namespace {

Vec3 normalized(const Vec3& a) {
  const double n = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  return {a[0] / n, a[1] / n, a[2] / n};
}

HostMesh icosahedron() {
  const double p = (1.0 + std::sqrt(5.0)) / 2.0;
  HostMesh m;
  m.nodes = {{-1, p, 0},  {1, p, 0},  {-1, -p, 0}, {1, -p, 0}, {0, -1, p},  {0, 1, p},
             {0, -1, -p}, {0, 1, -p}, {p, 0, -1},  {p, 0, 1},  {-p, 0, -1}, {-p, 0, 1}};
  // Rotate about x so that vertex 5, (0, 1, p), lies on +z: every subdivision then has a node at each
  // pole, which axisymmetric shapes (Evans-Fung) and axis-aligned experiments rely on.
  const double c = p / std::sqrt(1 + p * p), s = 1 / std::sqrt(1 + p * p);
  for (auto& x : m.nodes) x = normalized({x[0], c * x[1] - s * x[2], s * x[1] + c * x[2]});
  m.triangles = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                 {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  m.parents.assign(m.nodes.size(), {-1, -1});
  return m;
}

// One 1-to-4 split of every triangle of a unit-sphere mesh; midpoints projected onto the sphere.
void subdivide(HostMesh& m) {
  std::map<std::pair<int, int>, int> midpoint;
  auto mid = [&](int a, int b) {
    const auto key = std::minmax(a, b);
    const auto it = midpoint.find(key);
    if (it != midpoint.end()) return it->second;
    const Vec3& p = m.nodes[a];
    const Vec3& q = m.nodes[b];
    m.nodes.push_back(normalized({p[0] + q[0], p[1] + q[1], p[2] + q[2]}));
    m.parents.push_back({key.first, key.second});
    const int id = static_cast<int>(m.nodes.size()) - 1;
    midpoint.emplace(key, id);
    return id;
  };
  std::vector<Tri> next;
  next.reserve(m.triangles.size() * 4);
  for (const Tri& t : m.triangles) {
    const int ab = mid(t[0], t[1]), bc = mid(t[1], t[2]), ca = mid(t[2], t[0]);
    next.push_back({t[0], ab, ca});
    next.push_back({t[1], bc, ab});
    next.push_back({t[2], ca, bc});
    next.push_back({ab, bc, ca});
  }
  m.triangles = std::move(next);
}

// Renumbers the nodes in bands across the x axis: breadth first from the node of largest x, each layer of
// graph distance in the order the previous layer reaches it (neighbours in ascending subdivision order), and
// sorts the triangles by their lowest and highest node. A contiguous range of nodes (one thread's share of a
// kernel) is then a band of the surface, and the nodes it shares bonds with the next range lie in one short,
// contiguous run of indices on each side of the split (within 2% of the nodes at 10242 nodes, for any number
// of threads): on two threads whose cores share no cache, what one thread reads of the other's share is few
// cache lines and they are consecutive, so the hardware fetches them ahead. The bands cross the x axis, so an
// even split of a cell spread on a plane z = const divides its contact patch between the threads. The
// triangle and edge kernels follow the same bands (edges are sorted by their lowest node, build_topology).
// docs/PERFORMANCE.md, "Session 24", has the measurements (against the first-use numbering of session 22).
void renumber_in_bands(HostMesh& m) {
  const int n = static_cast<int>(m.nodes.size());
  std::vector<std::vector<int>> adjacent(n);
  for (const Tri& t : m.triangles)
    for (int c = 0; c < 3; ++c) adjacent[t[c]].push_back(t[(c + 1) % 3]);  // each edge once per direction
  for (auto& a : adjacent) std::sort(a.begin(), a.end());
  int seed = 0;
  for (int i = 1; i < n; ++i)
    if (m.nodes[i][0] > m.nodes[seed][0]) seed = i;
  std::vector<int> id(n, -1), order;
  order.reserve(n);
  id[seed] = 0;
  order.push_back(seed);
  for (std::size_t head = 0; head < order.size(); ++head)
    for (const int w : adjacent[order[head]])
      if (id[w] < 0) {
        id[w] = static_cast<int>(order.size());
        order.push_back(w);
      }
  if (static_cast<int>(order.size()) != n) throw std::logic_error("icosphere: the mesh is not connected");
  std::vector<Vec3> nodes(n);
  std::vector<std::array<int, 2>> parents(m.parents.empty() ? 0 : n, {-1, -1});
  for (int i = 0; i < n; ++i) {
    nodes[id[i]] = m.nodes[i];
    if (!m.parents.empty() && m.parents[i][0] >= 0)
      parents[id[i]] = {id[m.parents[i][0]], id[m.parents[i][1]]};
  }
  for (Tri& t : m.triangles)
    for (int& v : t) v = id[v];
  std::stable_sort(m.triangles.begin(), m.triangles.end(), [](const Tri& a, const Tri& b) {
    const auto key = [](const Tri& t) {
      return std::make_pair(std::min({t[0], t[1], t[2]}), std::max({t[0], t[1], t[2]}));
    };
    return key(a) < key(b);
  });
  m.nodes = std::move(nodes);
  m.parents = std::move(parents);
}

HostMesh unit_icosphere(int subdivisions, const BandRefinement& band) {
  if (subdivisions < 0 || subdivisions > 8)
    throw std::invalid_argument("icosphere subdivisions = " + std::to_string(subdivisions) +
                                " is out of range: allowed 0 .. 8");
  HostMesh m = icosahedron();
  for (int k = 0; k < subdivisions; ++k) subdivide(m);
  if (band.levels > 0) refine_band(m, band);
  renumber_in_bands(m);
  return m;
}

}  // namespace

long long icosphere_node_count(int subdivisions) { return 10LL * (1LL << (2 * subdivisions)) + 2; }

HostMesh make_icosphere(int subdivisions, double radius, const BandRefinement& band) {
  if (!(radius > 0)) throw std::invalid_argument("icosphere radius must be positive");
  HostMesh m = unit_icosphere(subdivisions, band);
  for (auto& x : m.nodes)
    for (double& c : x) c *= radius;
  return m;
}

double EvansFungShape::half_thickness(double rho) const {
  const double s = rho / diameter;
  const double root = std::sqrt(std::max(0.0, 1.0 - 4.0 * s * s));
  return diameter * root * (a0 + a1 * s * s + a2 * s * s * s * s);
}

HostMesh make_evans_fung(int subdivisions, const EvansFungShape& shape, const BandRefinement& band) {
  if (!(shape.diameter > 0)) throw std::invalid_argument("Evans-Fung diameter must be positive");
  HostMesh m = unit_icosphere(subdivisions, band);
  const double D = shape.diameter;
  for (auto& x : m.nodes) {
    const double r2 = x[0] * x[0] + x[1] * x[1];
    const double profile = shape.a0 + shape.a1 * r2 / 4.0 + shape.a2 * r2 * r2 / 16.0;
    x = {0.5 * D * x[0], 0.5 * D * x[1], D * x[2] * profile};  // x[2] = sign(z) |z|
  }
  return m;
}

void translate(HostMesh& mesh, const Vec3& offset) {
  for (auto& x : mesh.nodes)
    for (int c = 0; c < 3; ++c) x[c] += offset[c];
}

namespace {

std::vector<int> offsets_from_counts(const std::vector<int>& counts) {
  std::vector<int> off(counts.size() + 1, 0);
  for (std::size_t i = 0; i < counts.size(); ++i) off[i + 1] = off[i] + counts[i];
  return off;
}

// Orders each node's neighbours counter-clockwise (seen from outside): in triangle (i, a, b) oriented
// outward, b follows a around i. Walk that successor map once around.
void build_rings(const HostMesh& m, Topology& t) {
  const int n = static_cast<int>(m.nodes.size());
  t.ring_offsets = t.node_tri_offsets;  // a closed manifold: one neighbour per incident triangle
  t.ring.assign(t.ring_offsets[n], -1);
  for (int i = 0; i < n; ++i) {
    const int begin = t.node_tri_offsets[i], end = t.node_tri_offsets[i + 1];
    std::map<int, int> next;
    for (int s = begin; s < end; ++s) {
      const int tri = t.node_tri_corners[s] / 3, corner = t.node_tri_corners[s] % 3;
      const Tri& tr = m.triangles[tri];
      next[tr[(corner + 1) % 3]] = tr[(corner + 2) % 3];
    }
    int cur = next.begin()->first;
    for (int s = begin; s < end; ++s) {
      t.ring[s] = cur;
      cur = next.at(cur);
    }
    if (cur != t.ring[begin])
      throw std::runtime_error("mesh: the triangles around node " + std::to_string(i) +
                               " do not form a single closed fan");
  }
}

}  // namespace

Topology build_topology(const HostMesh& m) {
  const int n = static_cast<int>(m.nodes.size());
  const int nt = static_cast<int>(m.triangles.size());
  Topology t;
  // Directed half-edges: (a, b) -> triangle. Each undirected edge must appear once in each direction.
  std::map<std::pair<int, int>, int> half;
  for (int f = 0; f < nt; ++f) {
    for (int c = 0; c < 3; ++c) {
      const int a = m.triangles[f][c], b = m.triangles[f][(c + 1) % 3];
      if (a < 0 || a >= n || b < 0 || b >= n || a == b)
        throw std::runtime_error("mesh: triangle " + std::to_string(f) + " has an invalid node index");
      if (!half.emplace(std::make_pair(a, b), f).second)
        throw std::runtime_error("mesh: edge " + std::to_string(a) + "-" + std::to_string(b) +
                                 " is used twice in the same direction (inconsistent orientation)");
    }
  }
  for (const auto& [ab, f] : half) {
    const auto [a, b] = ab;
    const auto twin = half.find({b, a});
    if (twin == half.end())
      throw std::runtime_error("mesh: edge " + std::to_string(a) + "-" + std::to_string(b) +
                               " has only one triangle (the surface is not closed)");
    if (a > b) continue;
    const int g = twin->second;
    const Tri& tf = m.triangles[f];
    const Tri& tg = m.triangles[g];
    const int k = tf[0] + tf[1] + tf[2] - a - b;
    const int l = tg[0] + tg[1] + tg[2] - a - b;
    t.edges.push_back({a, b});
    t.edge_triangles.push_back({f, g});
    t.hinges.push_back({a, b, k, l});
  }
  // Edges (and their hinges) in the order of their lowest node of all four, then (a, b): a kernel over the
  // nodes that gathers from the hinges (bending forces, the implicit bending) then meets each hinge first
  // in the order the hinges are stored, so its first touches stream through memory instead of jumping back
  // a band (session 30: 12-15% off the 40962-node step on one thread, docs/PERFORMANCE.md).
  {
    const int ne = static_cast<int>(t.edges.size());
    std::vector<int> order(ne);
    for (int e = 0; e < ne; ++e) order[e] = e;
    const auto key = [&](int e) {
      const auto& h = t.hinges[e];
      return std::make_tuple(std::min({h[0], h[1], h[2], h[3]}), h[0], h[1]);
    };
    std::sort(order.begin(), order.end(), [&](int x, int y) { return key(x) < key(y); });
    Topology s;
    for (const int e : order) {
      s.edges.push_back(t.edges[e]);
      s.edge_triangles.push_back(t.edge_triangles[e]);
      s.hinges.push_back(t.hinges[e]);
    }
    t.edges = std::move(s.edges);
    t.edge_triangles = std::move(s.edge_triangles);
    t.hinges = std::move(s.hinges);
  }
  std::vector<int> tri_count(n, 0), edge_count(n, 0);
  for (const Tri& tr : m.triangles)
    for (int v : tr) ++tri_count[v];
  for (const auto& e : t.edges) {
    ++edge_count[e[0]];
    ++edge_count[e[1]];
  }
  t.node_tri_offsets = offsets_from_counts(tri_count);
  t.node_edge_offsets = offsets_from_counts(edge_count);
  t.node_tri_corners.assign(t.node_tri_offsets[n], 0);
  t.node_edges.assign(t.node_edge_offsets[n], 0);
  std::vector<int> fill(n, 0);
  for (int f = 0; f < nt; ++f)
    for (int c = 0; c < 3; ++c) {
      const int v = m.triangles[f][c];
      t.node_tri_corners[t.node_tri_offsets[v] + fill[v]++] = 3 * f + c;
    }
  std::fill(fill.begin(), fill.end(), 0);
  for (int e = 0; e < static_cast<int>(t.edges.size()); ++e)
    for (int v : t.edges[e]) t.node_edges[t.node_edge_offsets[v] + fill[v]++] = e;
  std::vector<int> hinge_count(n, 0);
  for (const auto& h : t.hinges)
    for (int v : h) ++hinge_count[v];
  t.node_hinge_offsets = offsets_from_counts(hinge_count);
  t.node_hinge_roles.assign(t.node_hinge_offsets[n], 0);
  std::fill(fill.begin(), fill.end(), 0);
  for (int h = 0; h < static_cast<int>(t.hinges.size()); ++h)
    for (int r = 0; r < 4; ++r) {
      const int v = t.hinges[h][r];
      t.node_hinge_roles[t.node_hinge_offsets[v] + fill[v]++] = 4 * h + r;
    }
  for (int v = 0; v < n; ++v)
    if (tri_count[v] < 3)
      throw std::runtime_error("mesh: node " + std::to_string(v) + " belongs to fewer than 3 triangles");
  build_rings(m, t);
  t.euler_characteristic = n - static_cast<int>(t.edges.size()) + nt;
  return t;
}

}  // namespace dcm
