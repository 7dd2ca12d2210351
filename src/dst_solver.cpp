#include "fictus/dst_solver.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "fftw_plan.hpp"

namespace fictus {

SineSpectrum1d::SineSpectrum1d(int n_cells, double h) {
  stiffness.resize(n_cells - 1);
  mass.resize(n_cells - 1);
  for (int p = 1; p < n_cells; ++p) {
    const double cp = std::cos(std::numbers::pi * p / n_cells);
    stiffness[p - 1] = (2.0 / h) * (1.0 - cp);
    mass[p - 1] = (h / 3.0) * (2.0 + cp);
  }
}

DstSolver::DstSolver(const Grid& grid, double c, int threads)
    : grid_(grid), c_(c), threads_(threads < 1 ? 1 : threads), sx_(grid.nx(), grid.h()),
      sy_(grid.ny(), grid.h()) {
  if (!(c >= 0.0) || !std::isfinite(c)) throw std::invalid_argument("data.c: must be finite and >= 0");
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

void DstSolver::apply(const GridVector& x, GridVector& y) const {
  y = x;
  plan_->execute(y.data());
  scale_by(y, false);
  plan_->execute(y.data());
}

}  // namespace fictus
