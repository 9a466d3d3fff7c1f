#pragma once
// Host-side triangulated surfaces: generation (icosphere, Evans-Fung biconcave RBC) and topology.
// Built once on the host, then uploaded into the SoA device buffers (core/buffers.hpp).
#include <array>
#include <string>
#include <vector>

namespace dcm {

using Vec3 = std::array<double, 3>;
using Tri = std::array<int, 3>;

struct HostMesh {
  std::vector<Vec3> nodes;     // m
  std::vector<Tri> triangles;  // counter-clockwise seen from outside: normals point outward
  // Subdivision hierarchy (icosphere and Evans-Fung meshes): the two parent nodes of every node created
  // as an edge midpoint, {-1, -1} for the 12 icosahedron nodes. A node's subdivision level follows from
  // them (0 for the icosahedron, else 1 + the larger of its parents' levels); the nodes of level <= j are
  // the mesh of subdivision j (of a band-refined icosphere: those of level <= j, fewer than 10·4^j+2 above
  // the icosphere's own subdivision). The nodes are numbered for locality (in bands across the x axis,
  // breadth first from the node of largest x; the triangles sorted by their nodes), not by level. Empty for
  // meshes without such a hierarchy (the multigrid then falls back).
  std::vector<std::array<int, 2>> parents;
};

// A band of the surface refined beyond the icosphere's subdivisions (core/band_refinement.cpp): the
// triangles that reach polar angles from_deg .. to_deg, measured on the unit sphere from its lowest point
// (0, 0, -1), are split 1-to-4 `levels` more times (new nodes on the sphere), each coarser level over a
// wider band so that the edge length halves in steps; the triangles at a level's border are bisected
// (red-green closure). levels = 0: no refinement. Every new node is an edge midpoint and records the edge's
// nodes as its parents, so the refined mesh keeps a subdivision hierarchy (its band's levels go deeper).
struct BandRefinement {
  int levels = 0;
  double from_deg = 0, to_deg = 180;
};

// Node count of an icosphere with k subdivisions: 10*4^k + 2.
long long icosphere_node_count(int subdivisions);

// Icosahedron subdivided k times (each triangle into four, new nodes projected onto the sphere),
// radius R, centred at the origin. V = 10*4^k+2, E = 30*4^k, F = 20*4^k. k in 0..8.
HostMesh make_icosphere(int subdivisions, double radius, const BandRefinement& band = {});

// Evans-Fung biconcave red blood cell (MODEL.md section 1): the icosphere of the same k mapped by
//   (x, y, z) on the unit sphere -> (D/2 x, D/2 y, sign(z) D |z| (a0 + a1 r^2/4 + a2 r^4/16)),
// r^2 = x^2 + y^2, which is z(rho) = D sqrt(1 - 4 rho^2/D^2) (a0 + a1 rho^2/D^2 + a2 rho^4/D^4)
// at rho = D r / 2 (|z| = sqrt(1 - r^2) on the unit sphere). Axis of symmetry: z.
struct EvansFungShape {
  double diameter = 7.82e-6;  // D (m)
  double a0 = 0.0518, a1 = 2.0026, a2 = -4.491;
  // Half-thickness z(rho) for 0 <= rho <= D/2.
  double half_thickness(double rho) const;
};
HostMesh make_evans_fung(int subdivisions, const EvansFungShape& shape = {}, const BandRefinement& band = {});

// Splits the triangles of a unit-sphere mesh that reach the band (BandRefinement);
// called by make_icosphere and make_evans_fung before they scale or map the sphere.
void refine_band(HostMesh& m, const BandRefinement& band);

// The smallest interior angle of any triangle (degrees): the mesh's worst shape.
double smallest_angle_deg(const HostMesh& m);

// Adds a constant offset to every node.
void translate(HostMesh& mesh, const Vec3& offset);

// Connectivity derived from the triangles. Throws std::runtime_error when the surface is not a closed,
// consistently oriented 2-manifold (an edge not in exactly two triangles with opposite directions).
struct Topology {
  std::vector<std::array<int, 2>> edges;  // bonds, i < j
  // Hinges: one per edge, (i, j, k, l): the edge i-j, triangle (i, j, k) and triangle (j, i, l), both
  // as oriented in the mesh; k and l are the opposite nodes.
  std::vector<std::array<int, 4>> hinges;
  std::vector<std::array<int, 2>> edge_triangles;  // the two triangles of each edge
  // CSR: node -> incident triangle corners, packed as 3*triangle + corner.
  std::vector<int> node_tri_offsets, node_tri_corners;
  // CSR: node -> incident edges.
  std::vector<int> node_edge_offsets, node_edges;
  // CSR: node -> the hinges it belongs to, packed as 4*hinge + role, role its slot in (i, j, k, l).
  std::vector<int> node_hinge_offsets, node_hinge_roles;
  // CSR: node -> neighbours in cyclic order, counter-clockwise seen from outside (the one-ring).
  std::vector<int> ring_offsets, ring;
  int euler_characteristic = 0;  // V - E + F
};
Topology build_topology(const HostMesh& mesh);

}  // namespace dcm
