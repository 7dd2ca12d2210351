#include "fictus/grid/grid.hpp"

#include "fictus/grid/q1_element.hpp"

namespace fictus {

const char* to_string(Boundary b) { return b == Boundary::periodic ? "periodic" : "dirichlet"; }

double evaluate_q1(const Grid2& grid, const GridVector& u, Point2 p) {
  const Q1Cell2 cell = q1_cell(grid, p);
  double sum = 0.0;
  for (int k = 0; k < Q1Element<2>::n_nodes; ++k) {
    const int i = cell.ix + Q1Element<2>::offset(k, 0), j = cell.iy + Q1Element<2>::offset(k, 1);
    if (grid.has_unknown(i, j)) sum += u[grid.index(i, j)] * cell.element.value[k];
  }
  return sum;
}

}  // namespace fictus
