#include "fictus/grid.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace fictus {

const char* to_string(Boundary b) { return b == Boundary::periodic ? "periodic" : "dirichlet"; }

Grid::Grid(const Box& box, int nx, Boundary boundary) : box_(box), boundary_(boundary), nx_(nx) {
  if (!(box.x1 > box.x0) || !(box.y1 > box.y0))
    throw std::invalid_argument("domain.box: need x0 < x1 and y0 < y1");
  if (nx < 2) throw std::invalid_argument("domain.N: need at least 2 cells, got " + std::to_string(nx));
  h_ = (box.x1 - box.x0) / nx;
  const double cells_y = (box.y1 - box.y0) / h_;
  ny_ = int(std::lround(cells_y));
  if (std::abs(cells_y - ny_) > 1e-9 * std::max(1.0, cells_y) || ny_ < 2)
    throw std::invalid_argument("domain.box: the height (y1 - y0) must be a whole number of cells of side "
                                "h = (x1 - x0)/N");
  if (periodic() && (nx_ % 2 != 0 || ny_ % 2 != 0))
    throw std::invalid_argument("domain.N: a periodic box needs an even number of cells in x and y");
}

int Grid::cell_x(double x) const {
  return std::clamp(int(std::floor((x - box_.x0) / h_)), 0, nx_ - 1);
}

int Grid::cell_y(double y) const {
  return std::clamp(int(std::floor((y - box_.y0) / h_)), 0, ny_ - 1);
}

double evaluate_q1(const Grid& grid, const GridVector& u, Point p) {
  const int ix = grid.cell_x(p.x), iy = grid.cell_y(p.y);
  const double xi = (p.x - grid.x(ix)) / grid.h(), eta = (p.y - grid.y(iy)) / grid.h();
  auto value = [&](int i, int j) { return grid.has_unknown(i, j) ? u[grid.index(i, j)] : 0.0; };
  return value(ix, iy) * (1 - xi) * (1 - eta) + value(ix + 1, iy) * xi * (1 - eta) +
         value(ix, iy + 1) * (1 - xi) * eta + value(ix + 1, iy + 1) * xi * eta;
}

}  // namespace fictus
