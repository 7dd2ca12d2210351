#include "fictus/grid/dst_solver.hpp"

#include <stdexcept>

#include "fftw_plan.hpp"

namespace fictus {

template <int dim>
std::unique_ptr<FastSolver<dim>> make_fast_solver(const Grid<dim>& grid, double c, const Execution& execution) {
  if (grid.periodic()) return std::make_unique<PeriodicSolver<dim>>(grid, c, execution);
  return std::make_unique<DstSolver<dim>>(grid, c, execution);
}

template <int dim>
DstSolver<dim>::DstSolver(const Grid<dim>& grid, double c, const Execution& execution)
    : grid_(grid), symbol_(grid, c), threads_(execution.threads()) {
  if (grid.periodic()) throw std::invalid_argument("DstSolver: needs a Dirichlet box");
  std::vector<int> shape;  // slowest axis first
  for (int d = dim - 1; d >= 0; --d) shape.push_back(grid.n(d) - 1);
  plan_ = std::make_unique<detail::R2rPlan>(shape, detail::R2rKind::dst1, threads_);
}

template <int dim>
DstSolver<dim>::~DstSolver() = default;

template <int dim>
void DstSolver<dim>::scale_by(GridVector& v, bool inverse) const {
  const int row_length = grid_.n(0) - 1;
  int rows = 1;
  double denominator = double(1 << dim);
  for (int d = 0; d < dim; ++d) denominator *= grid_.n(d);
  for (int d = 1; d < dim; ++d) rows *= grid_.n(d) - 1;
  const double norm = 1.0 / denominator, c = symbol_.c();
  const double* k0 = symbol_.axis(0).stiffness.data();
  const double* m0 = symbol_.axis(0).mass.data();
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (int r = 0; r < rows; ++r) {
    std::array<int, dim> slow{};
    for (int d = 1, rest = r; d < dim; ++d) slow[d] = rest % (grid_.n(d) - 1), rest /= grid_.n(d) - 1;
    const typename Q1Symbol<dim>::Row factors = symbol_.row(slow);
    double* row = v.data() + std::size_t(r) * std::size_t(row_length);
    for (int p = 0; p < row_length; ++p) {
      const double lambda = Q1Symbol<dim>::lambda(k0[p], m0[p], c, factors);
      row[p] *= inverse ? norm / lambda : norm * lambda;
    }
  }
}

template <int dim>
void DstSolver<dim>::solve_in_place(GridVector& r) const {
  if (r.size() != grid_.n_unknowns()) throw std::invalid_argument("DstSolver: vector size mismatch");
  plan_->execute(r.data());
  scale_by(r, true);
  plan_->execute(r.data());
}

template <int dim>
void DstSolver<dim>::transform(GridVector& v) const {
  plan_->execute(v.data());
}

template <int dim>
void DstSolver<dim>::apply(const GridVector& x, GridVector& y) const {
  y = x;
  plan_->execute(y.data());
  scale_by(y, false);
  plan_->execute(y.data());
}

template class DstSolver<2>;
template class DstSolver<3>;
template std::unique_ptr<FastSolver<2>> make_fast_solver(const Grid<2>&, double, const Execution&);
template std::unique_ptr<FastSolver<3>> make_fast_solver(const Grid<3>&, double, const Execution&);

}  // namespace fictus
