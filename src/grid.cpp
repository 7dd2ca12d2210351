#include "fictus/grid.hpp"

namespace fictus {

const char* to_string(Boundary b) { return b == Boundary::periodic ? "periodic" : "dirichlet"; }

double evaluate_q1(const Grid2& grid, const GridVector& u, Point2 p) {
  const int ix = grid.cell_x(p.x), iy = grid.cell_y(p.y);
  const double xi = (p.x - grid.x(ix)) / grid.h(), eta = (p.y - grid.y(iy)) / grid.h();
  auto value = [&](int i, int j) { return grid.has_unknown(i, j) ? u[grid.index(i, j)] : 0.0; };
  return value(ix, iy) * (1 - xi) * (1 - eta) + value(ix + 1, iy) * xi * (1 - eta) +
         value(ix, iy + 1) * (1 - xi) * eta + value(ix + 1, iy + 1) * xi * eta;
}

}  // namespace fictus
