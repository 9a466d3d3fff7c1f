#pragma once
// Host-side (symbolic) set-up of the geometric multigrid hierarchy on the icosphere subdivision levels,
// done once per mesh: prolongation P, restriction R = Pᵀ, the block-sparse pattern of every level and the
// recipe of the Galerkin products A_{l+1} = Pᵀ A_l P (which fine slots, with which weights, sum into each
// coarse slot). The numeric part, rebuilt every step, is in solvers/multigrid.hpp.
//
// Levels: 0 is the mesh; level l holds, for each cell of depth k_c (its deepest subdivision level), its nodes
// of subdivision level ≤ max(k_c − l, 0) (HostMesh::parents records the hierarchy; subdivision_levels()
// derives each node's level), in the order of their mesh indices, so a coarse level keeps the mesh's
// locality. On an icosphere of subdivision k_c those are 10·4^max(k_c−l,0)+2 nodes; on a band-refined one
// (core/band_refinement.cpp) the first levels thin the band only, then the icosphere's follow.
// Cells are concatenated in the order of the buffers. Every
// cell reaches the 12 icosahedron nodes on the coarsest level, where a cell already there is carried
// down unchanged (P = I for it). P sets a midpoint node to the mean of its two parents, per component;
// the fine node i takes ½(x_c[p(i,0)] + x_c[p(i,1)]), with p(i,0) = p(i,1) for a node that survives.
#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include "core/buffers.hpp"
#include "core/host_mesh.hpp"

namespace dcm {

struct HostSparsePattern {
  std::vector<int> offsets, cols;  // CSR, sorted columns, diagonal included
  int rows() const { return static_cast<int>(offsets.size()) - 1; }
  int slot(int i, int j) const {
    const auto b = cols.begin() + offsets[i], e = cols.begin() + offsets[i + 1];
    return static_cast<int>(std::lower_bound(b, e, j) - cols.begin());
  }
};

struct HostTransfer {                                // from level l (fine) to level l + 1 (coarse)
  std::vector<std::array<int, 2>> prolong;           // per fine node: the two coarse nodes it averages
  std::vector<int> restrict_offsets, restrict_fine;  // per coarse node: the fine nodes of its Pᵀ row
  std::vector<double> restrict_weight;
  HostSparsePattern coarse;                            // pattern of Pᵀ A P
  std::vector<int> galerkin_offsets, galerkin_source;  // per coarse slot: fine slots and weights
  std::vector<double> galerkin_weight;
};

struct HostHierarchy {
  bool available = false;
  std::string note;                     // why not, when not
  HostSparsePattern fine;               // level 0: the bond graph plus the diagonal
  std::vector<int> fine_slot_bond;      // per level-0 slot: its bond, −1 on the diagonal
  std::vector<HostTransfer> transfers;  // levels − 1 of them
  int n_cells = 0;
};

// The diagonal plus every bond (global node indices, as in MeshBuffers::bond).
inline HostSparsePattern bond_pattern(int n_nodes, const std::vector<int>& bond_pairs,
                                      std::vector<int>& slot_bond) {
  std::vector<std::vector<std::array<int, 2>>> rows(n_nodes);  // (col, bond)
  for (int i = 0; i < n_nodes; ++i) rows[i].push_back({i, -1});
  for (std::size_t b = 0; b < bond_pairs.size() / 2; ++b) {
    const int i = bond_pairs[2 * b], j = bond_pairs[2 * b + 1];
    rows[i].push_back({j, static_cast<int>(b)});
    rows[j].push_back({i, static_cast<int>(b)});
  }
  HostSparsePattern p;
  p.offsets.assign(1, 0);
  slot_bond.clear();
  for (auto& r : rows) {
    std::sort(r.begin(), r.end());
    for (const auto& e : r) {
      p.cols.push_back(e[0]);
      slot_bond.push_back(e[1]);
    }
    p.offsets.push_back(static_cast<int>(p.cols.size()));
  }
  return p;
}

// One coarsening: P, Pᵀ and the Galerkin recipe for the pattern `fine`.
inline HostTransfer make_transfer(const HostSparsePattern& fine, std::vector<std::array<int, 2>> prolong,
                                  int n_coarse) {
  HostTransfer t;
  t.prolong = std::move(prolong);
  const int nf = fine.rows();
  // Rows of P: (coarse node, weight).
  auto prow = [&](int i, std::array<std::array<double, 2>, 2>& out) {
    const auto p = t.prolong[i];
    if (p[0] == p[1]) {
      out[0] = {static_cast<double>(p[0]), 1.0};
      return 1;
    }
    out[0] = {static_cast<double>(p[0]), 0.5};
    out[1] = {static_cast<double>(p[1]), 0.5};
    return 2;
  };
  std::vector<std::vector<std::array<double, 2>>> rrows(n_coarse);
  std::vector<std::vector<int>> pattern(n_coarse);
  struct Contribution {
    int coarse_row, coarse_col, fine_slot;
    double weight;
  };
  std::vector<Contribution> contributions;
  std::array<std::array<double, 2>, 2> pi{}, pj{};
  for (int i = 0; i < nf; ++i) {
    const int ni = prow(i, pi);
    for (int a = 0; a < ni; ++a)
      rrows[static_cast<int>(pi[a][0])].push_back({static_cast<double>(i), pi[a][1]});
    for (int s = fine.offsets[i]; s < fine.offsets[i + 1]; ++s) {
      const int nj = prow(fine.cols[s], pj);
      for (int a = 0; a < ni; ++a)
        for (int b = 0; b < nj; ++b) {
          const int I = static_cast<int>(pi[a][0]), J = static_cast<int>(pj[b][0]);
          pattern[I].push_back(J);
          contributions.push_back({I, J, s, pi[a][1] * pj[b][1]});
        }
    }
  }
  t.restrict_offsets.assign(1, 0);
  for (const auto& r : rrows) {
    for (const auto& e : r) {
      t.restrict_fine.push_back(static_cast<int>(e[0]));
      t.restrict_weight.push_back(e[1]);
    }
    t.restrict_offsets.push_back(static_cast<int>(t.restrict_fine.size()));
  }
  t.coarse.offsets.assign(1, 0);
  for (auto& r : pattern) {
    std::sort(r.begin(), r.end());
    r.erase(std::unique(r.begin(), r.end()), r.end());
    t.coarse.cols.insert(t.coarse.cols.end(), r.begin(), r.end());
    t.coarse.offsets.push_back(static_cast<int>(t.coarse.cols.size()));
  }
  // Group the contributions by coarse slot (counting sort keeps the fine order: deterministic sums).
  const int nnz = static_cast<int>(t.coarse.cols.size());
  std::vector<int> slot_of(contributions.size()), count(nnz + 1, 0);
  for (std::size_t k = 0; k < contributions.size(); ++k) {
    slot_of[k] = t.coarse.slot(contributions[k].coarse_row, contributions[k].coarse_col);
    ++count[slot_of[k] + 1];
  }
  for (int s = 0; s < nnz; ++s) count[s + 1] += count[s];
  t.galerkin_offsets = count;
  t.galerkin_source.resize(contributions.size());
  t.galerkin_weight.resize(contributions.size());
  for (std::size_t k = 0; k < contributions.size(); ++k) {
    const int at = count[slot_of[k]]++;
    t.galerkin_source[at] = contributions[k].fine_slot;
    t.galerkin_weight[at] = contributions[k].weight;
  }
  return t;
}

// Each node's subdivision level (0: an icosahedron node, else 1 + the larger of its parents' levels) from
// HostMesh::parents, or an empty vector when they do not describe a subdivision hierarchy of the icosahedron:
// a cycle of parents, a node with one parent, other than 12 nodes on level 0, or more nodes of level <= j
// than the icosphere of subdivision j has. A band-refined icosphere (core/band_refinement.cpp) has fewer
// on its finest levels; the coarsening needs only that every node's parents lie on the coarser levels.
inline std::vector<int> subdivision_levels(const HostMesh& m) {
  const int n = static_cast<int>(m.nodes.size());
  if (n == 0 || static_cast<int>(m.parents.size()) != n) return {};
  std::vector<int> level(n, -1);
  for (bool changed = true; changed;) {  // parents may be numbered after their children
    changed = false;
    for (int i = 0; i < n; ++i) {
      if (level[i] >= 0) continue;
      const auto p = m.parents[i];
      if (p[0] < 0 && p[1] < 0) {
        level[i] = 0;
      } else if (p[0] < 0 || p[1] < 0 || p[0] >= n || p[1] >= n) {
        return {};
      } else if (level[p[0]] >= 0 && level[p[1]] >= 0) {
        level[i] = 1 + std::max(level[p[0]], level[p[1]]);
      } else {
        continue;
      }
      changed = true;
    }
  }
  int depth = 0;
  for (const int l : level) {
    if (l < 0 || l > 16) return {};  // a cycle of parents, or deeper than any mesh dcm makes
    depth = std::max(depth, l);
  }
  std::vector<long long> count(depth + 1, 0);
  for (const int l : level) ++count[l];
  if (count[0] != 12) return {};
  long long total = 0;
  for (int j = 0; j <= depth; ++j)
    if ((total += count[j]) > icosphere_node_count(j)) return {};
  return level;
}

// The hierarchy of cells concatenated in this order; bond_pairs are MeshBuffers::bond on the host.
inline HostHierarchy make_hierarchy(const std::vector<HostCell>& cells, int n_nodes,
                                    const std::vector<int>& bond_pairs) {
  HostHierarchy h;
  h.n_cells = static_cast<int>(cells.size());
  h.fine = bond_pattern(n_nodes, bond_pairs, h.fine_slot_bond);
  std::vector<int> depth_of(cells.size());
  std::vector<std::vector<int>> node_level(cells.size());
  int depth = 0;
  for (std::size_t c = 0; c < cells.size(); ++c) {
    const HostMesh& m = cells[c].mesh;
    node_level[c] = subdivision_levels(m);
    if (node_level[c].empty()) {
      h.note = "cell " + std::to_string(c) + " (" + std::to_string(m.nodes.size()) +
               " nodes) has no icosphere subdivision hierarchy (HostMesh::parents): multigrid falls back to "
               "block-Jacobi";
      return h;
    }
    const int k = *std::max_element(node_level[c].begin(), node_level[c].end());
    depth_of[c] = k;
    depth = std::max(depth, k);
  }
  // rank[c][i]: node i's index within cell c's part of the current level (−1: not on it).
  std::vector<std::vector<int>> rank(cells.size());
  for (std::size_t c = 0; c < cells.size(); ++c) {
    rank[c].resize(node_level[c].size());
    for (std::size_t i = 0; i < rank[c].size(); ++i) rank[c][i] = static_cast<int>(i);
  }
  const HostSparsePattern* fine = &h.fine;
  h.transfers.reserve(depth);
  for (int l = 0; l < depth; ++l) {
    std::vector<std::array<int, 2>> prolong;
    int coarse_begin = 0;
    for (std::size_t c = 0; c < cells.size(); ++c) {
      const std::vector<int>& lev = node_level[c];
      const int keep = std::max(depth_of[c] - l - 1, 0);  // the coarse level's subdivision
      std::vector<int> coarse_rank(lev.size(), -1);
      int nc = 0;
      for (std::size_t i = 0; i < lev.size(); ++i)
        if (rank[c][i] >= 0 && lev[i] <= keep) coarse_rank[i] = nc++;
      for (std::size_t i = 0; i < lev.size(); ++i) {  // the fine level's nodes, in their order
        if (rank[c][i] < 0) continue;
        if (coarse_rank[i] >= 0) {
          prolong.push_back({coarse_begin + coarse_rank[i], coarse_begin + coarse_rank[i]});
        } else {
          const auto p = cells[c].mesh.parents[i];
          prolong.push_back({coarse_begin + coarse_rank[p[0]], coarse_begin + coarse_rank[p[1]]});
        }
      }
      rank[c] = std::move(coarse_rank);
      coarse_begin += nc;
    }
    h.transfers.push_back(make_transfer(*fine, std::move(prolong), coarse_begin));
    fine = &h.transfers.back().coarse;
  }
  h.available = true;
  return h;
}

}  // namespace dcm
