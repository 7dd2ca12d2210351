#include "fictus/green_table.hpp"

#include "fftw_plan.hpp"
#include "fictus/q1_symbol.hpp"

namespace fictus {

template <int dim>
GreenTable<dim>::GreenTable(const Grid<dim>& grid, double c, const Execution& execution)
    : grid_(grid), c_(c), periodic_(grid.periodic()) {
  const Q1Symbol<dim> symbol(grid, c);
  std::size_t entries = 1;
  for (int d = 0; d < dim; ++d) {
    period_[d] = periodic_ ? grid.n(d) : 2 * grid.n(d);
    size_[d] = std::size_t(period_[d] / 2 + 1);
    entries *= size_[d];
  }
  table_.assign(entries, 0.0);
  // Table entry p holds 1/λ of mode p. Dirichlet: p_d = 1..n_d−1 (spectrum index p_d − 1), zero at
  // p_d ∈ {0, n_d}; periodic: p_d = 0..n_d/2 (spectrum index p_d), the zero mode dropped when λ = 0.
  double denominator = periodic_ ? 1.0 : double(1 << dim);
  for (int d = 0; d < dim; ++d) denominator *= grid.n(d);
  const double scale = 1.0 / denominator;
  const int shift = periodic_ ? 0 : 1, rows = int(entries / size_[0]), row_length = int(size_[0]);
  const double* k0 = symbol.axis(0).stiffness.data();
  const double* m0 = symbol.axis(0).mass.data();
#pragma omp parallel for num_threads(execution.threads()) schedule(static)
  for (int r = 0; r < rows; ++r) {
    std::array<int, dim> slow{};
    bool inside = true;
    for (int d = 1, rest = r; d < dim; ++d) {
      slow[d] = rest % int(size_[d]) - shift, rest /= int(size_[d]);
      inside = inside && slow[d] >= 0 && slow[d] < symbol.axis(d).size();
    }
    if (!inside) continue;
    const typename Q1Symbol<dim>::Row factors = symbol.row(slow);
    double* row = table_.data() + std::size_t(r) * size_[0];
    for (int p = 0; p < row_length; ++p) {
      const int ip = p - shift;
      if (ip < 0 || ip >= symbol.axis(0).size()) continue;
      const double lambda = Q1Symbol<dim>::lambda(k0[ip], m0[ip], c, factors);
      row[p] = lambda > 0 ? scale / lambda : 0.0;
    }
  }
  std::vector<int> shape;  // slowest axis first
  for (int d = dim - 1; d >= 0; --d) shape.push_back(int(size_[d]));
  detail::R2rPlan plan(shape, detail::R2rKind::dct1, execution.threads());
  plan.execute(table_.data());
}

template class GreenTable<2>;
template class GreenTable<3>;

}  // namespace fictus
