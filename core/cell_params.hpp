#pragma once
// Constants that may differ from cell to cell (the batched engine: docs/SCANS.md, "The batched engine:
// design", point 1). Kernels read a constant for the cell of the element they work on with
// cell_value(k, cell): k is either one value for every cell (a double or a parameter struct, as a single
// run passes it) or a CellTable, the device-side view of a PerCell (`per_cell.table()`: Views and plain
// data only, so kernels capture nothing of the host). Both give the same arithmetic for a cell, so a cell of
// a batch computes exactly what it computes alone.
#include <Kokkos_Core.hpp>
#include <string>
#include <type_traits>
#include <vector>

#include "core/kokkos_compat.hpp"

namespace dcm {

// What kernels capture: the rows on the device, and whether any row is non-zero (for host-side decisions).
template <class T, class MemorySpace>
struct CellTable {
  Kokkos::View<T*, Kokkos::LayoutRight, MemorySpace> values;
  bool nonzero = true;
};

// A table of one T per cell, owned on the host side.
template <class T, class MemorySpace>
struct PerCell {
  Kokkos::View<T*, Kokkos::LayoutRight, MemorySpace> values;
  std::vector<T> host;  // the same rows, for host-side decisions (is a term on anywhere?)
  HostMirrorOf<Kokkos::View<T*, Kokkos::LayoutRight, MemorySpace>> mirror;  // staging for assign()
  PerCell() = default;
  explicit PerCell(const std::vector<T>& rows, const char* label = "dcm::per_cell")
      : values(Kokkos::view_alloc(Kokkos::WithoutInitializing, std::string(label)), rows.size()),
        host(rows),
        mirror(Kokkos::create_mirror_view(values)) {
    for (std::size_t c = 0; c < rows.size(); ++c) mirror(c) = rows[c];
    Kokkos::deep_copy(values, mirror);
  }
  // New rows of the same count (no allocation: for values that change every step).
  void assign(const std::vector<T>& rows) {
    if (rows.size() != values.extent(0)) {
      *this = PerCell(rows, values.label().c_str());
      return;
    }
    host = rows;
    for (std::size_t c = 0; c < rows.size(); ++c) mirror(c) = rows[c];
    Kokkos::deep_copy(values, mirror);
  }
  CellTable<T, MemorySpace> table() const {
    CellTable<T, MemorySpace> t{values, true};
    if constexpr (std::is_arithmetic<T>::value) {
      t.nonzero = false;
      for (const T& k : host) t.nonzero = t.nonzero || k != 0;
    }
    return t;
  }
};

// The same value for every cell.
template <class T>
KOKKOS_INLINE_FUNCTION const T& cell_value(const T& uniform, int) {
  return uniform;
}
// Cell c's row.
template <class T, class MemorySpace>
KOKKOS_INLINE_FUNCTION T cell_value(const CellTable<T, MemorySpace>& table, int c) {
  return table.values(c);
}

// Which cells a kernel works on: one flag per cell; an empty View means every cell. A batch's CG skips the
// cells that have converged or are not stepping (the operators are block-diagonal per cell, so no other
// cell reads their rows).
template <class MemorySpace>
using CellFlags = Kokkos::View<int*, Kokkos::LayoutRight, MemorySpace>;
template <class Flags>
KOKKOS_INLINE_FUNCTION bool skipped(const Flags& active, int cell) {
  return active.extent(0) > 0 && active(cell) == 0;
}

// Whether a constant is non-zero for some cell (a term with a zero constant everywhere is skipped).
inline bool any_nonzero(double k) { return k != 0; }
template <class MemorySpace>
bool any_nonzero(const CellTable<double, MemorySpace>& table) {
  return table.nonzero;
}

// One member of each cell's parameter struct as a table: member_table(cells, &P::k_b).
template <class MemorySpace, class P, class T>
PerCell<T, MemorySpace> member_table(const std::vector<P>& cells, T P::*member, const char* label) {
  std::vector<T> v;
  v.reserve(cells.size());
  for (const P& p : cells) v.push_back(p.*member);
  return PerCell<T, MemorySpace>(v, label);
}

}  // namespace dcm
