#include "fictus/fast_solver.hpp"

#include <cmath>
#include <stdexcept>

#include "fftw_plan.hpp"

namespace fictus {

PeriodicSolver::PeriodicSolver(const Grid& grid, double c, int threads)
    : grid_(grid), c_(c), threads_(threads < 1 ? 1 : threads), sx_(grid.nx(), grid.h(), Boundary::periodic),
      sy_(grid.ny(), grid.h(), Boundary::periodic) {
  if (!(c >= 0.0) || !std::isfinite(c)) throw std::invalid_argument("data.c: must be finite and >= 0");
  if (!grid.periodic()) throw std::invalid_argument("PeriodicSolver: needs a periodic box");
  dft_ = std::make_unique<detail::RealDft2d>(grid.ny(), grid.nx(), threads_);
  spectrum_.resize(std::size_t(grid.ny()) * std::size_t(grid.nx() / 2 + 1));
}

PeriodicSolver::~PeriodicSolver() = default;

void PeriodicSolver::transform(GridVector& v, bool inverse) const {
  if (v.size() != grid_.n_unknowns()) throw std::invalid_argument("PeriodicSolver: vector size mismatch");
  dft_->forward(v.data(), spectrum_.data());
  const int nq = grid_.ny(), np = grid_.nx() / 2 + 1;
  const double norm = 1.0 / (double(grid_.nx()) * grid_.ny());
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (int q = 0; q < nq; ++q) {
    std::complex<double>* row = spectrum_.data() + std::size_t(q) * np;
    for (int p = 0; p < np; ++p) {
      const double lambda = sx_.stiffness[p] * sy_.mass[q] + sx_.mass[p] * sy_.stiffness[q] + c_ * sx_.mass[p] * sy_.mass[q];
      if (inverse) row[p] *= lambda > 0 ? norm / lambda : 0.0;  // λ = 0 only for the constants at c = 0
      else row[p] *= norm * lambda;
    }
  }
  dft_->backward(spectrum_.data(), v.data());
}

void PeriodicSolver::solve_in_place(GridVector& r) const { transform(r, true); }

void PeriodicSolver::apply(const GridVector& x, GridVector& y) const {
  y = x;
  transform(y, false);
}

}  // namespace fictus
