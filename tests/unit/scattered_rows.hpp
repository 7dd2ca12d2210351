#pragma once
// Sparse rows over a grid without structure, for the tests of the slab operations (unit and mpirun).
#include "fictus/grid/sparse_rows.hpp"

namespace fictus::test_support {

/// Rows of 5 nodes each, spread over the whole grid without structure (a deterministic sequence).
template <int dim>
SparseRows scattered_rows(const Grid<dim>& grid, int rows) {
  SparseRows R;
  unsigned state = 12345;
  auto next = [&state](int n) { return int((state = state * 1103515245u + 12345u) / 65536u % unsigned(n)); };
  for (int r = 0; r < rows; ++r) {
    for (int e = 0; e < 5; ++e) {
      typename Grid<dim>::Index node{};
      for (int d = 0; d < dim; ++d) node[d] = grid.periodic() ? next(grid.n(d)) : 1 + next(grid.n(d) - 1);
      R.entries.push_back({grid.index(node), node[0], node[1], dim == 3 ? node[dim - 1] : 0, 0.5 + 0.1 * e - 0.03 * r});
    }
    R.row_begin.push_back(R.entries.size());
  }
  return R;
}

}  // namespace fictus::test_support
