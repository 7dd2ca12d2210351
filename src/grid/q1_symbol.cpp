#include "fictus/grid/q1_symbol.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace fictus {

Spectrum1d::Spectrum1d(int n_cells, double h, Boundary boundary) {
  const bool periodic = boundary == Boundary::periodic;
  const int count = periodic ? n_cells : n_cells - 1;
  stiffness.resize(count);
  mass.resize(count);
  for (int k = 0; k < count; ++k) {
    const double angle = periodic ? 2.0 * std::numbers::pi * k / n_cells : std::numbers::pi * (k + 1) / n_cells;
    const double cp = std::cos(angle);
    stiffness[k] = (2.0 / h) * (1.0 - cp);
    mass[k] = (h / 3.0) * (2.0 + cp);
  }
}

template <int dim>
Q1Symbol<dim>::Q1Symbol(const Grid<dim>& grid, double c) : c_(c) {
  if (!(c >= 0 && c <= largest_reaction))  // data.c's rule (options.cpp reads the same bound)
    throw std::invalid_argument("data.c: must be in [0.0, 1e12], got " + std::to_string(c));
  for (int d = 0; d < dim; ++d) axes_.emplace_back(grid.n(d), grid.h(), grid.boundary());
}

template class Q1Symbol<2>;
template class Q1Symbol<3>;

}  // namespace fictus
