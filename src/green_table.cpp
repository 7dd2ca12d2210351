#include "fictus/green_table.hpp"

#include <cmath>
#include <stdexcept>

#include "fftw_plan.hpp"
#include "fictus/fast_solver.hpp"

namespace fictus {

GreenTable::GreenTable(const Grid& grid, double c, int threads)
    : grid_(grid), c_(c), periodic_(grid.periodic()),
      nx_(grid.periodic() ? grid.nx() : 2 * grid.nx()), ny_(grid.periodic() ? grid.ny() : 2 * grid.ny()),
      width_(std::size_t(nx_ / 2 + 1)) {
  if (!(c >= 0.0) || !std::isfinite(c)) throw std::invalid_argument("data.c: must be finite and >= 0");
  const Spectrum1d sx(grid.nx(), grid.h(), grid.boundary()), sy(grid.ny(), grid.h(), grid.boundary());
  const int rows = ny_ / 2 + 1, cols = int(width_);
  table_.assign(std::size_t(rows) * width_, 0.0);
  // Mode (p, q) of the table. Dirichlet: p = 1..nx−1 (spectrum index p−1), zero at p ∈ {0, nx};
  // periodic: p = 0..nx/2 (spectrum index p), the zero mode dropped when λ = 0.
  const double scale = periodic_ ? 1.0 / (double(grid.nx()) * grid.ny()) : 1.0 / (4.0 * grid.nx() * grid.ny());
  const int shift = periodic_ ? 0 : 1;
#pragma omp parallel for num_threads(threads < 1 ? 1 : threads) schedule(static)
  for (int q = 0; q < rows; ++q) {
    const int iq = q - shift;
    if (iq < 0 || iq >= int(sy.mass.size())) continue;
    double* row = table_.data() + std::size_t(q) * width_;
    for (int p = 0; p < cols; ++p) {
      const int ip = p - shift;
      if (ip < 0 || ip >= int(sx.mass.size())) continue;
      const double lambda = sx.stiffness[ip] * sy.mass[iq] + sx.mass[ip] * sy.stiffness[iq] + c * sx.mass[ip] * sy.mass[iq];
      row[p] = lambda > 0 ? scale / lambda : 0.0;
    }
  }
  detail::R2rPlan2d plan(rows, cols, detail::R2rKind::dct1, threads);
  plan.execute(table_.data());
}

}  // namespace fictus
