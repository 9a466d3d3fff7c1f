#pragma once
// Where a conjugate-gradient breakdown comes from (CortexModel::describe_breakdown()): along the search
// direction p whose p·Ap was not positive, each term of A = Γ + Δt K is applied to p alone; for the first
// term whose p·A_term p is not positive, the node of the cell where p_i·(A_term p)_i is first not finite, or
// else lowest, is the one the message names.
#include <cmath>

#include "core/vec3.hpp"

namespace dcm {

// The node of cell `cell` where p_i·(Ap)_i is first not finite, else where it is lowest (the first such);
// -1 if the cell has no node.
template <class ExecutionSpace, class Vector, class NodeCell>
int breakdown_node(const ExecutionSpace& space, const NodeCell& node_cell, int cell, const Vector& p,
                   const Vector& ap, bool& not_finite) {
  const int n = static_cast<int>(p.extent(0));
  int first_bad = n;
  Kokkos::parallel_reduce(
      "dcm::breakdown::non_finite", Kokkos::RangePolicy<ExecutionSpace>(space, 0, n),
      KOKKOS_LAMBDA(const int i, int& m) {
        const double v = p(i, 0) * ap(i, 0) + p(i, 1) * ap(i, 1) + p(i, 2) * ap(i, 2);
        if (node_cell(i) == cell && !math::isfinite(v) && i < m) m = i;
      },
      Kokkos::Min<int>(first_bad));
  not_finite = first_bad < n;
  if (not_finite) return first_bad;
  // The lowest value and its node in one reduction (a second kernel that matched the minimum again could
  // round differently); -1 if the cell has no node.
  using MinLoc = Kokkos::MinLoc<double, int>;
  typename MinLoc::value_type lowest;
  Kokkos::parallel_reduce(
      "dcm::breakdown::lowest", Kokkos::RangePolicy<ExecutionSpace>(space, 0, n),
      KOKKOS_LAMBDA(const int i, typename MinLoc::value_type& low) {
        if (node_cell(i) != cell) return;
        const double v = p(i, 0) * ap(i, 0) + p(i, 1) * ap(i, 1) + p(i, 2) * ap(i, 2);
        if (v < low.val || (v == low.val && i < low.loc)) {
          low.val = v;
          low.loc = i;
        }
      },
      MinLoc(lowest));
  return lowest.loc >= 0 && lowest.loc < n ? lowest.loc : -1;
}

}  // namespace dcm
