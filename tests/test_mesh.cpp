// Mesh generation and topology: counts, closedness, orientation, rings.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>
#include <vector>

#include "apps/common/stretch_setup.hpp"
#include "core/host_mesh.hpp"

namespace dcm {
namespace {

Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 cross3(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot3(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

class IcosphereLevels : public ::testing::TestWithParam<int> {};

TEST_P(IcosphereLevels, CountsEulerAndManifold) {
  const int k = GetParam();
  const HostMesh m = make_icosphere(k, 2.0);
  const long long p = 1LL << (2 * k);
  EXPECT_EQ(static_cast<long long>(m.nodes.size()), 10 * p + 2);
  EXPECT_EQ(icosphere_node_count(k), 10 * p + 2);
  EXPECT_EQ(static_cast<long long>(m.triangles.size()), 20 * p);
  const Topology t = build_topology(m);
  EXPECT_EQ(static_cast<long long>(t.edges.size()), 30 * p);
  EXPECT_EQ(static_cast<long long>(t.hinges.size()), 30 * p);
  EXPECT_EQ(t.euler_characteristic, 2);

  // Independent check: every directed edge appears once, and its reverse once.
  std::map<std::pair<int, int>, int> directed;
  for (const Tri& tr : m.triangles)
    for (int c = 0; c < 3; ++c) ++directed[{tr[c], tr[(c + 1) % 3]}];
  for (const auto& [e, count] : directed) {
    EXPECT_EQ(count, 1);
    EXPECT_EQ(directed.count({e.second, e.first}), 1u);
  }
}

TEST_P(IcosphereLevels, OutwardOrientationAndRadius) {
  const int k = GetParam();
  const double r = 3.25e-6;
  const HostMesh m = make_icosphere(k, r);
  for (const Vec3& x : m.nodes) EXPECT_NEAR(std::sqrt(dot3(x, x)), r, 1e-15 * r);
  for (const Tri& tr : m.triangles) {
    const Vec3 n = cross3(sub(m.nodes[tr[1]], m.nodes[tr[0]]), sub(m.nodes[tr[2]], m.nodes[tr[0]]));
    EXPECT_GT(dot3(n, m.nodes[tr[0]]), 0.0);  // normal points away from the centre
  }
}

INSTANTIATE_TEST_SUITE_P(Levels0to6, IcosphereLevels, ::testing::Range(0, 7));

// The optical tweezers' pulled nodes (apps/common/stretch_setup.hpp) depend on the geometry only: the same
// positions under a reversed numbering, every mirror image of a node taken with it (the icosphere's rings at
// the ends hold nodes level in x, which a count alone would split by their numbering), at least the fraction.
TEST(StretchSetup, PulledNodesDoNotDependOnTheNumbering) {
  for (const HostMesh& m : {make_icosphere(4, 1.0), make_evans_fung(3)}) {
    HostMesh reversed = m;
    std::reverse(reversed.nodes.begin(), reversed.nodes.end());
    const auto positions = [](const HostMesh& mesh, const std::vector<int>& ids) {
      std::vector<Vec3> p;
      for (int i : ids) p.push_back(mesh.nodes[i]);
      std::sort(p.begin(), p.end());
      return p;
    };
    for (const double fraction : {0.025, 0.05}) {
      const auto [left, right] = pulled_nodes(m, fraction);
      const auto [left_r, right_r] = pulled_nodes(reversed, fraction);
      EXPECT_EQ(positions(m, left), positions(reversed, left_r)) << fraction;
      EXPECT_EQ(positions(m, right), positions(reversed, right_r)) << fraction;
      EXPECT_GE(left.size(), std::lround(fraction * m.nodes.size()));
      EXPECT_EQ(left.size(), right.size());  // both meshes are symmetric under x -> -x
      double x_taken = -1e300;               // every node left out lies further in than every node taken
      for (int i : left) x_taken = std::max(x_taken, m.nodes[i][0]);
      for (std::size_t i = 0; i < m.nodes.size(); ++i)
        if (std::find(left.begin(), left.end(), static_cast<int>(i)) == left.end()) {
          EXPECT_GT(m.nodes[i][0], x_taken);
        }
    }
  }
}

TEST(Topology, HingesAreTheTwoTrianglesOfEachEdge) {
  const HostMesh m = make_icosphere(2, 1.0);
  const Topology t = build_topology(m);
  std::set<std::array<int, 3>> oriented;
  for (const Tri& tr : m.triangles)
    for (int c = 0; c < 3; ++c) oriented.insert({tr[c], tr[(c + 1) % 3], tr[(c + 2) % 3]});
  for (const auto& h : t.hinges) {
    EXPECT_TRUE(oriented.count({h[0], h[1], h[2]})) << "(i, j, k) is a mesh triangle";
    EXPECT_TRUE(oriented.count({h[1], h[0], h[3]})) << "(j, i, l) is a mesh triangle";
    EXPECT_NE(h[2], h[3]);
  }
}

// The hinges (and edges) are stored in the order of their lowest node of all four (session 30): a node gather
// then meets every hinge first in storage order. Checked as that invariant and as its consequence: walking
// the nodes in order, the first touch of each hinge never goes back in storage.
TEST(Topology, HingesAreStoredInTheOrderTheNodeGathersFirstMeetThem) {
  const HostMesh m = make_icosphere(4, 1.0);
  const Topology t = build_topology(m);
  const auto lowest = [&](int e) {
    const auto& h = t.hinges[e];
    return std::min({h[0], h[1], h[2], h[3]});
  };
  for (std::size_t e = 1; e < t.hinges.size(); ++e)
    ASSERT_LE(lowest(static_cast<int>(e) - 1), lowest(static_cast<int>(e))) << "hinge " << e;
  for (std::size_t e = 0; e < t.hinges.size(); ++e) {
    EXPECT_EQ(t.edges[e][0], t.hinges[e][0]) << "edge " << e << " and its hinge share the storage index";
    EXPECT_EQ(t.edges[e][1], t.hinges[e][1]);
  }
  std::vector<char> seen(t.hinges.size(), 0);
  int last_first_touch = -1;
  const int n = static_cast<int>(m.nodes.size());
  for (int i = 0; i < n; ++i)
    for (int k = t.node_hinge_offsets[i]; k < t.node_hinge_offsets[i + 1]; ++k) {
      const int h = t.node_hinge_roles[k] >> 2;
      if (seen[h]) continue;
      seen[h] = 1;
      EXPECT_GT(h, last_first_touch) << "node " << i << " meets hinge " << h << " first, after hinge "
                                     << last_first_touch;
      last_first_touch = h;
    }
}

TEST(Topology, RingsAreOrderedCounterClockwiseFromOutside) {
  const HostMesh m = make_icosphere(3, 1.0);
  const Topology t = build_topology(m);
  std::set<std::array<int, 3>> oriented;
  for (const Tri& tr : m.triangles)
    for (int c = 0; c < 3; ++c) oriented.insert({tr[c], tr[(c + 1) % 3], tr[(c + 2) % 3]});
  int valence5 = 0;
  for (int i = 0; i < static_cast<int>(m.nodes.size()); ++i) {
    const int b = t.ring_offsets[i], e = t.ring_offsets[i + 1];
    const int valence = e - b;
    EXPECT_TRUE(valence == 5 || valence == 6);
    valence5 += valence == 5;
    EXPECT_EQ(t.node_edge_offsets[i + 1] - t.node_edge_offsets[i], valence);
    std::set<int> distinct(t.ring.begin() + b, t.ring.begin() + e);
    EXPECT_EQ(static_cast<int>(distinct.size()), valence);
    for (int s = b; s < e; ++s) {
      const int a = t.ring[s], c = t.ring[s + 1 < e ? s + 1 : b];
      EXPECT_TRUE(oriented.count({i, a, c})) << "node " << i;
    }
  }
  EXPECT_EQ(valence5, 12);  // the icosahedron's vertices
}

TEST(Topology, CsrListsAreComplete) {
  const HostMesh m = make_icosphere(2, 1.0);
  const Topology t = build_topology(m);
  for (int i = 0; i < static_cast<int>(m.nodes.size()); ++i) {
    for (int s = t.node_tri_offsets[i]; s < t.node_tri_offsets[i + 1]; ++s)
      EXPECT_EQ(m.triangles[t.node_tri_corners[s] / 3][t.node_tri_corners[s] % 3], i);
    for (int s = t.node_edge_offsets[i]; s < t.node_edge_offsets[i + 1]; ++s) {
      const auto& e = t.edges[t.node_edges[s]];
      EXPECT_TRUE(e[0] == i || e[1] == i);
    }
    // Node i is an edge end of each incident edge and the tip of each incident triangle's far hinge.
    const int valence = t.node_edge_offsets[i + 1] - t.node_edge_offsets[i];
    EXPECT_EQ(t.node_hinge_offsets[i + 1] - t.node_hinge_offsets[i], 2 * valence);
    for (int s = t.node_hinge_offsets[i]; s < t.node_hinge_offsets[i + 1]; ++s)
      EXPECT_EQ(t.hinges[t.node_hinge_roles[s] / 4][t.node_hinge_roles[s] % 4], i);
  }
  EXPECT_EQ(t.node_tri_offsets.back(), 3 * static_cast<int>(m.triangles.size()));
  EXPECT_EQ(t.node_edge_offsets.back(), 2 * static_cast<int>(t.edges.size()));
  EXPECT_EQ(t.node_hinge_offsets.back(), 4 * static_cast<int>(t.hinges.size()));
}

TEST(Topology, RejectsOpenAndMisorientedSurfaces) {
  HostMesh open = make_icosphere(1, 1.0);
  open.triangles.pop_back();
  EXPECT_THROW(build_topology(open), std::runtime_error);
  HostMesh flipped = make_icosphere(1, 1.0);
  std::swap(flipped.triangles[3][1], flipped.triangles[3][2]);
  EXPECT_THROW(build_topology(flipped), std::runtime_error);
}

TEST(Icosphere, HasANodeAtEachPole) {
  const HostMesh m = make_icosphere(4, 1.0);
  int poles = 0;
  for (const Vec3& x : m.nodes) poles += std::hypot(x[0], x[1]) < 1e-14;
  EXPECT_EQ(poles, 2);
}

TEST(EvansFung, ProfileMatchesPublishedDimensions) {
  const EvansFungShape s{};  // D = 7.82 um
  EXPECT_NEAR(2 * s.half_thickness(0), 0.810e-6, 0.001e-6);
  // Maximum thickness 2.566 um at rho = 2.738 um: scan the profile.
  double best = 0, best_rho = 0;
  for (int i = 0; i <= 39100; ++i) {
    const double rho = i * 1e-10;
    if (s.half_thickness(rho) > best) best = s.half_thickness(rho), best_rho = rho;
  }
  EXPECT_NEAR(2 * best, 2.566e-6, 0.001e-6);
  EXPECT_NEAR(best_rho, 2.738e-6, 0.005e-6);
  EXPECT_DOUBLE_EQ(s.half_thickness(s.diameter / 2), 0.0);
}

TEST(EvansFung, NodesLieOnTheProfile) {
  const EvansFungShape s{};
  const HostMesh m = make_evans_fung(4, s);
  EXPECT_EQ(m.nodes.size(), 2562u);
  for (const Vec3& x : m.nodes) {
    const double rho = std::hypot(x[0], x[1]);
    EXPECT_LE(rho, s.diameter / 2 * (1 + 1e-15));
    // At the rim sqrt(1 - 4 rho^2 / D^2) amplifies round-off in rho: ~1e-8 D there, 1e-16 D elsewhere.
    EXPECT_NEAR(std::fabs(x[2]), s.half_thickness(rho), 1e-7 * s.diameter);
  }
  EXPECT_NO_THROW(build_topology(m));
}

TEST(Icosphere, RejectsBadArguments) {
  EXPECT_THROW(make_icosphere(-1, 1.0), std::invalid_argument);
  EXPECT_THROW(make_icosphere(9, 1.0), std::invalid_argument);
  EXPECT_THROW(make_icosphere(2, -1.0), std::invalid_argument);
}

}  // namespace
}  // namespace dcm
