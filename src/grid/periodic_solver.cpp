#include <stdexcept>

#include "fftw_plan.hpp"
#include "fictus/grid/fast_solver.hpp"

namespace fictus {

template <int dim>
PeriodicSolver<dim>::PeriodicSolver(const Grid<dim>& grid, double c, const Execution& execution)
    : grid_(grid), symbol_(grid, c), threads_(execution.threads()) {
  if (!grid.periodic()) throw std::invalid_argument("PeriodicSolver: needs a periodic box");
  std::vector<int> shape;  // slowest axis first
  for (int d = dim - 1; d >= 0; --d) shape.push_back(grid.n(d));
  dft_ = std::make_unique<detail::RealDft>(shape, threads_);
  spectrum_.resize(grid.n_unknowns() / std::size_t(grid.n(0)) * std::size_t(grid.n(0) / 2 + 1));
}

template <int dim>
PeriodicSolver<dim>::~PeriodicSolver() = default;

template <int dim>
void PeriodicSolver<dim>::transform(GridVector& v, bool inverse) const {
  if (v.size() != grid_.n_unknowns()) throw std::invalid_argument("PeriodicSolver: vector size mismatch");
  dft_->forward(v.data(), spectrum_.data());
  const int row_length = grid_.n(0) / 2 + 1;
  int rows = 1;
  double denominator = 1.0;
  for (int d = 0; d < dim; ++d) denominator *= grid_.n(d);
  for (int d = 1; d < dim; ++d) rows *= grid_.n(d);
  const double norm = 1.0 / denominator, c = symbol_.c();
  const double* k0 = symbol_.axis(0).stiffness.data();
  const double* m0 = symbol_.axis(0).mass.data();
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (int r = 0; r < rows; ++r) {
    std::array<int, dim> slow{};
    for (int d = 1, rest = r; d < dim; ++d) slow[d] = rest % grid_.n(d), rest /= grid_.n(d);
    const typename Q1Symbol<dim>::Row factors = symbol_.row(slow);
    std::complex<double>* row = spectrum_.data() + std::size_t(r) * std::size_t(row_length);
    for (int p = 0; p < row_length; ++p) {
      const double lambda = Q1Symbol<dim>::lambda(k0[p], m0[p], c, factors);
      if (inverse)
        row[p] *= lambda > 0 ? norm / lambda : 0.0;  // λ = 0 only for the constants at c = 0
      else
        row[p] *= norm * lambda;
    }
  }
  dft_->backward(spectrum_.data(), v.data());
}

template <int dim>
void PeriodicSolver<dim>::solve_in_place(GridVector& r) const {
  transform(r, true);
}

template <int dim>
void PeriodicSolver<dim>::apply(const GridVector& x, GridVector& y) const {
  y = x;
  transform(y, false);
}

template class PeriodicSolver<2>;
template class PeriodicSolver<3>;

}  // namespace fictus
