#pragma once
// Exact fast solver for the Q1 matrix A = K + c·M on the grid's interior nodes (homogeneous
// Dirichlet box), by the dim-dimensional sine transform (FFTW RODFT00, see docs/math.md):
//   A⁻¹ r = DST( DST(r) ./ λ ) / (2^dim · Π_d n_d),   λ from Q1Symbol.
// Plans once in the constructor; solve_in_place() is const, allocation-free and reentrant for
// distinct arrays.
#include <memory>
#include <mutex>

#include "fictus/grid/fast_solver.hpp"

namespace fictus {

namespace detail {
class R2rPlan;
}

template <int dim>
class DstSolver final : public FastSolver<dim> {
 public:
  /// c ≥ 0 (c = 0 is fine: the Dirichlet Laplacian is positive definite).
  DstSolver(const Grid<dim>& grid, double c, const Execution& execution = Execution{});
  ~DstSolver() override;
  DstSolver(const DstSolver&) = delete;
  DstSolver& operator=(const DstSolver&) = delete;

  const Grid<dim>& grid() const override { return grid_; }
  double c() const override { return symbol_.c(); }
  void solve_in_place(GridVector& r) const override;
  /// By transforms along the slow axes of the lines that meet the footprints only (the fastest axis's
  /// are all made): solve_in_place's numbers where `wanted` says, up to rounding (1-D passes instead of
  /// FFTW's multi-dimensional plan).
  void solve_in_place_at(GridVector& r, const Footprint& load, const Footprint& wanted) const override;
  void apply(const GridVector& x, GridVector& y) const override;
  /// One in-place DST-I (RODFT00) of a grid vector: the unit of cost benchmarks compare to.
  void transform(GridVector& v) const;

 private:
  void scale_by(GridVector& v, bool inverse) const;
  struct Lines;
  /// The transform of the lines along axis a ≥ 1 in the chunks `mask` names (transform_lines), or
  /// along axis 0 of all of them (a = 0).
  void transform_lines(double* data, int a, const std::vector<char>& mask) const;
  std::vector<char> chunk_mask(const Footprint& f, int a) const;
  Grid<dim> grid_;
  Q1Symbol<dim> symbol_;
  int threads_;
  std::unique_ptr<detail::R2rPlan> plan_;
  mutable std::once_flag lines_planned_;
  mutable std::unique_ptr<Lines> lines_;  // planned by the first solve_in_place_at, on its array
};

}  // namespace fictus
