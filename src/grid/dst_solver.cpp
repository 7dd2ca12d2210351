#include "fictus/grid/dst_solver.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>

#include "fftw_plan.hpp"
#include "fictus/grid/distribution.hpp"

namespace fictus {

template <int dim>
std::unique_ptr<FastSolver<dim>> make_fast_solver(const Grid<dim>& grid, double c, const Execution& execution) {
  return execution.distribution().fast_solver(grid, c, execution);
}

template <int dim>
Footprint footprint(const Grid<dim>& grid, std::initializer_list<const SparseRows*> rows) {
  const std::size_t columns = grid.layer_size(), row = std::size_t(grid.periodic() ? grid.n(0) : grid.n(0) - 1);
  Footprint f;
  f.columns.assign(columns, 0);
  f.lines.assign(grid.n_unknowns() / row, 0);
  for (const SparseRows* R : rows)
    for (const SparseRows::Entry& e : R->entries) f.columns[e.index % columns] = 1, f.lines[e.index / row] = 1;
  return f;
}

namespace {
constexpr int chunk = detail::line_chunk;
constexpr int rows_per_task = detail::rows_per_task;
}  // namespace

/// Plans for the lines of the grid: per axis a ≥ 1, `chunk` adjacent lines and the last, narrower chunk
/// of each row; along axis 0, `rows_per_task` rows and the rest.
template <int dim>
struct DstSolver<dim>::Lines {
  std::array<std::unique_ptr<detail::R2rLines>, dim> wide, narrow;
  std::unique_ptr<detail::R2rLines> rows, last_rows;
};

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
std::vector<char> DstSolver<dim>::chunk_mask(const Footprint& f, int a) const {
  const int L0 = grid_.n(0) - 1, chunks = (L0 + chunk - 1) / chunk;
  std::size_t inner = 1;  // the coordinates of axes 1 … a−1
  for (int d = 1; d < a; ++d) inner *= std::size_t(grid_.n(d) - 1);
  std::vector<char> mask(inner * std::size_t(chunks), 0);
  for (std::size_t col = 0; col < f.columns.size(); ++col)
    if (f.columns[col]) {
      const std::size_t x = col % std::size_t(L0), rest = col / std::size_t(L0);
      mask[(rest % inner) * std::size_t(chunks) + x / chunk] = 1;
    }
  return mask;
}

template <int dim>
void DstSolver<dim>::transform_lines(double* data, int a, const std::vector<char>& mask) const {
  std::array<std::size_t, dim + 1> stride{1};
  for (int d = 0; d < dim; ++d) stride[d + 1] = stride[d] * std::size_t(grid_.n(d) - 1);
  const int L0 = grid_.n(0) - 1;
  if (a == 0) {
    const std::size_t rows = stride[dim] / stride[1], tasks = (rows + rows_per_task - 1) / rows_per_task;
#pragma omp parallel for num_threads(threads_) schedule(dynamic, 1)
    for (std::size_t t = 0; t < tasks; ++t) {
      double* first = data + t * rows_per_task * std::size_t(L0);
      (t + 1 < tasks ? lines_->rows : lines_->last_rows)->execute(first);
    }
    return;
  }
  const int chunks = (L0 + chunk - 1) / chunk;
  const std::size_t inner = stride[a] / stride[1], outer = stride[dim] / stride[a + 1];
  const std::size_t tasks = inner * outer * std::size_t(chunks);  // one chunk each (2-D: only chunks)
#pragma omp parallel for num_threads(threads_) schedule(dynamic, 16)
  for (std::size_t t = 0; t < tasks; ++t) {
    const std::size_t c = t % std::size_t(chunks), line = t / std::size_t(chunks), i = line % inner, o = line / inner;
    if (!mask[i * std::size_t(chunks) + c]) continue;
    double* first = data + o * stride[a + 1] + i * std::size_t(L0) + c * chunk;
    ((c + 1) * chunk <= std::size_t(L0) ? lines_->wide : lines_->narrow)[std::size_t(a)]->execute(first);
  }
}

template <int dim>
void DstSolver<dim>::solve_in_place_at(GridVector& r, const Footprint& load, const Footprint& wanted) const {
  const std::size_t columns = grid_.layer_size();
  if (r.size() != grid_.n_unknowns() || load.columns.size() != columns || wanted.columns.size() != columns)
    throw std::invalid_argument("DstSolver: vector or footprint size mismatch");
  std::call_once(lines_planned_, [&] {
    auto lines = std::make_unique<Lines>();
    const int L0 = grid_.n(0) - 1;
    std::ptrdiff_t stride = 1;
    for (int a = 0; a < dim; ++a) {
      const int n = grid_.n(a) - 1;
      if (a > 0) {
        if (L0 >= chunk)
          lines->wide[std::size_t(a)] =
              std::make_unique<detail::R2rLines>(n, stride, chunk, 1, detail::R2rKind::dst1, r.data());
        if (L0 % chunk != 0)
          lines->narrow[std::size_t(a)] =
              std::make_unique<detail::R2rLines>(n, stride, L0 % chunk, 1, detail::R2rKind::dst1, r.data());
      }
      stride *= n;
    }
    const int rows = int(grid_.n_unknowns() / std::size_t(L0)),
              last = rows - (rows - 1) / rows_per_task * rows_per_task;
    lines->rows =
        std::make_unique<detail::R2rLines>(L0, 1, std::min(rows, rows_per_task), L0, detail::R2rKind::dst1, r.data());
    lines->last_rows = std::make_unique<detail::R2rLines>(L0, 1, last, L0, detail::R2rKind::dst1, r.data());
    lines_ = std::move(lines);
  });
  for (int a = dim - 1; a >= 1; --a) transform_lines(r.data(), a, chunk_mask(load, a));
  transform_lines(r.data(), 0, {});
  scale_by(r, true);
  transform_lines(r.data(), 0, {});
  for (int a = 1; a < dim; ++a) transform_lines(r.data(), a, chunk_mask(wanted, a));
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

template Footprint footprint(const Grid<2>&, std::initializer_list<const SparseRows*>);
template Footprint footprint(const Grid<3>&, std::initializer_list<const SparseRows*>);
template class DstSolver<2>;
template class DstSolver<3>;
template std::unique_ptr<FastSolver<2>> make_fast_solver(const Grid<2>&, double, const Execution&);
template std::unique_ptr<FastSolver<3>> make_fast_solver(const Grid<3>&, double, const Execution&);

}  // namespace fictus
