#include "fictus/q1_symbol.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "fictus/options.hpp"

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
  checked(*find_option("c"), c);  // the rule of data.c, written once in options.cpp
  for (int d = 0; d < dim; ++d) axes_.emplace_back(grid.n(d), grid.h(), grid.boundary());
}

template class Q1Symbol<2>;
template class Q1Symbol<3>;

}  // namespace fictus
