#include "fictus/dst_solver.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "fftw_plan.hpp"

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

std::unique_ptr<FastSolver> make_fast_solver(const Grid& grid, double c, int threads) {
  if (grid.periodic()) return std::make_unique<PeriodicSolver>(grid, c, threads);
  return std::make_unique<DstSolver>(grid, c, threads);
}

DstSolver::DstSolver(const Grid& grid, double c, int threads)
    : grid_(grid), c_(c), threads_(threads < 1 ? 1 : threads), sx_(grid.nx(), grid.h(), Boundary::dirichlet),
      sy_(grid.ny(), grid.h(), Boundary::dirichlet) {
  if (!(c >= 0.0) || !std::isfinite(c)) throw std::invalid_argument("data.c: must be finite and >= 0");
  if (grid.periodic()) throw std::invalid_argument("DstSolver: needs a Dirichlet box");
  plan_ = std::make_unique<detail::R2rPlan2d>(grid.ny() - 1, grid.nx() - 1, detail::R2rKind::dst1,
                                              threads_);
}

DstSolver::~DstSolver() = default;

void DstSolver::scale_by(GridVector& v, bool inverse) const {
  const int nx = grid_.nx() - 1, ny = grid_.ny() - 1;
  const double norm = 1.0 / (4.0 * grid_.nx() * grid_.ny());
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (int q = 0; q < ny; ++q) {
    double* row = v.data() + std::size_t(q) * nx;
    const double kq = sy_.stiffness[q], mq = sy_.mass[q];
    for (int p = 0; p < nx; ++p) {
      const double lambda = sx_.stiffness[p] * mq + sx_.mass[p] * kq + c_ * sx_.mass[p] * mq;
      row[p] *= inverse ? norm / lambda : norm * lambda;
    }
  }
}

void DstSolver::solve_in_place(GridVector& r) const {
  if (r.size() != grid_.n_unknowns()) throw std::invalid_argument("DstSolver: vector size mismatch");
  plan_->execute(r.data());
  scale_by(r, true);
  plan_->execute(r.data());
}

void DstSolver::transform(GridVector& v) const { plan_->execute(v.data()); }

void DstSolver::apply(const GridVector& x, GridVector& y) const {
  y = x;
  plan_->execute(y.data());
  scale_by(y, false);
  plan_->execute(y.data());
}

}  // namespace fictus
