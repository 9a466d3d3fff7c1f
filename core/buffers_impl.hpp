#pragma once
// Implementation of upload_cells(): fill host mirrors, then one deep_copy per View.
#include <string>

namespace dcm {
namespace detail {

template <class V>
V alloc_view(const std::string& label, std::size_t n) {
  return V(Kokkos::view_alloc(Kokkos::WithoutInitializing, "dcm::mesh::" + label), n);
}

// Host-filled copy of a device View: fill(host_view) then deep_copy.
template <class V, class Fill>
V upload(const std::string& label, std::size_t n, Fill&& fill) {
  V v = alloc_view<V>(label, n);
  auto h = Kokkos::create_mirror_view(v);
  fill(h);
  Kokkos::deep_copy(v, h);
  return v;
}

}  // namespace detail

template <class MemorySpace>
MeshBuffers<MemorySpace> upload_cells(const std::vector<HostCell>& cells) {
  using B = MeshBuffers<MemorySpace>;
  using IV = typename B::template View<int*>;
  B b;
  b.n_cells = static_cast<int>(cells.size());
  std::vector<int> nb(1, 0), tb(1, 0), bb(1, 0), hb(1, 0);
  for (const HostCell& c : cells) {
    nb.push_back(nb.back() + static_cast<int>(c.mesh.nodes.size()));
    tb.push_back(tb.back() + static_cast<int>(c.mesh.triangles.size()));
    bb.push_back(bb.back() + static_cast<int>(c.topology.edges.size()));
    hb.push_back(hb.back() + static_cast<int>(c.topology.hinges.size()));
  }
  b.n_nodes = nb.back();
  b.n_tris = tb.back();
  b.n_bonds = bb.back();
  b.n_hinges = hb.back();

  auto vec_view = [](const std::string& label, const std::vector<int>& v) {
    return detail::upload<IV>(label, v.size(), [&](auto& h) {
      for (std::size_t i = 0; i < v.size(); ++i) h(i) = v[i];
    });
  };
  b.host_cell_node_begin = nb;
  b.host_cell_tri_begin = tb;
  b.cell_node_begin = vec_view("cell_node_begin", nb);
  b.cell_tri_begin = vec_view("cell_tri_begin", tb);
  b.cell_bond_begin = vec_view("cell_bond_begin", bb);
  b.cell_hinge_begin = vec_view("cell_hinge_begin", hb);
  b.node_sums = SumPlan<MemorySpace>(nb);
  b.tri_sums = SumPlan<MemorySpace>(tb);
  b.bond_sums = SumPlan<MemorySpace>(bb);
  b.hinge_sums = SumPlan<MemorySpace>(hb);
  std::vector<int> cb(b.n_cells + 1);  // one segment per cell: per-cell values of per-cell terms
  for (int c = 0; c <= b.n_cells; ++c) cb[c] = c;
  b.cell_sums = SumPlan<MemorySpace>(cb);

  // Per-element arrays: walk cells, offset node indices by the cell's first node.
  auto per_cell = [&](auto&& body) {
    for (int c = 0; c < b.n_cells; ++c) body(c, cells[c], nb[c]);
  };
  b.x = detail::upload<typename B::template View<double* [3]>>("x", b.n_nodes, [&](auto& h) {
    per_cell([&](int, const HostCell& cell, int n0) {
      for (std::size_t i = 0; i < cell.mesh.nodes.size(); ++i)
        for (int d = 0; d < 3; ++d) h(n0 + i, d) = cell.mesh.nodes[i][d];
    });
  });
  auto cell_index = [&](const std::string& label, const std::vector<int>& begin) {
    return detail::upload<IV>(label, begin.back(), [&](auto& h) {
      for (int c = 0; c < b.n_cells; ++c)
        for (int i = begin[c]; i < begin[c + 1]; ++i) h(i) = c;
    });
  };
  b.node_cell = cell_index("node_cell", nb);
  b.tri_cell = cell_index("tri_cell", tb);
  b.bond_cell = cell_index("bond_cell", bb);
  b.hinge_cell = cell_index("hinge_cell", hb);

  b.tri = detail::upload<typename B::template View<int* [3]>>("tri", b.n_tris, [&](auto& h) {
    per_cell([&](int c, const HostCell& cell, int n0) {
      for (std::size_t t = 0; t < cell.mesh.triangles.size(); ++t)
        for (int d = 0; d < 3; ++d) h(tb[c] + t, d) = n0 + cell.mesh.triangles[t][d];
    });
  });
  b.bond = detail::upload<typename B::template View<int* [2]>>("bond", b.n_bonds, [&](auto& h) {
    per_cell([&](int c, const HostCell& cell, int n0) {
      for (std::size_t e = 0; e < cell.topology.edges.size(); ++e)
        for (int d = 0; d < 2; ++d) h(bb[c] + e, d) = n0 + cell.topology.edges[e][d];
    });
  });
  b.hinge = detail::upload<typename B::template View<int* [4]>>("hinge", b.n_hinges, [&](auto& h) {
    per_cell([&](int c, const HostCell& cell, int n0) {
      for (std::size_t e = 0; e < cell.topology.hinges.size(); ++e)
        for (int d = 0; d < 4; ++d) h(hb[c] + e, d) = n0 + cell.topology.hinges[e][d];
    });
  });

  // CSR arrays: offsets shifted by the cell's first entry, entries shifted by the cell's first
  // node / triangle / bond / hinge.
  auto csr = [&](const std::string& name, auto offsets_of, auto entries_of, auto shift_entry,
                 typename B::template View<int*>& off_view, typename B::template View<int*>& ent_view) {
    std::vector<int> off(1, 0), ent;
    per_cell([&](int c, const HostCell& cell, int) {
      const std::vector<int>& o = offsets_of(cell);
      const std::vector<int>& e = entries_of(cell);
      const int base = off.back();
      for (std::size_t i = 1; i < o.size(); ++i) off.push_back(base + o[i]);
      for (int v : e) ent.push_back(shift_entry(c, v));
    });
    off_view = vec_view(name + "_offsets", off);
    ent_view = vec_view(name, ent);
  };
  csr(
      "node_tri_corners",
      [](const HostCell& c) -> const std::vector<int>& { return c.topology.node_tri_offsets; },
      [](const HostCell& c) -> const std::vector<int>& { return c.topology.node_tri_corners; },
      [&](int c, int v) { return v + 3 * tb[c]; }, b.node_tri_offsets, b.node_tri_corners);
  csr(
      "node_bonds", [](const HostCell& c) -> const std::vector<int>& { return c.topology.node_edge_offsets; },
      [](const HostCell& c) -> const std::vector<int>& { return c.topology.node_edges; },
      [&](int c, int v) { return v + bb[c]; }, b.node_bond_offsets, b.node_bonds);
  csr(
      "node_hinge_roles",
      [](const HostCell& c) -> const std::vector<int>& { return c.topology.node_hinge_offsets; },
      [](const HostCell& c) -> const std::vector<int>& { return c.topology.node_hinge_roles; },
      [&](int c, int v) { return v + 4 * hb[c]; }, b.node_hinge_offsets, b.node_hinge_roles);
  csr(
      "ring", [](const HostCell& c) -> const std::vector<int>& { return c.topology.ring_offsets; },
      [](const HostCell& c) -> const std::vector<int>& { return c.topology.ring; },
      [&](int c, int v) { return v + nb[c]; }, b.ring_offsets, b.ring);
  return b;
}

}  // namespace dcm
