#include "fictus/green_table.hpp"

#include <cmath>
#include <stdexcept>

#include "fftw_plan.hpp"
#include "fictus/dst_solver.hpp"

namespace fictus {

GreenTable::GreenTable(const Grid& grid, double c, int threads) : grid_(grid) {
  if (!(c >= 0.0) || !std::isfinite(c)) throw std::invalid_argument("data.c: must be finite and >= 0");
  const int nx = grid.nx(), ny = grid.ny();
  const SineSpectrum1d sx(nx, grid.h()), sy(ny, grid.h());
  table_.assign(std::size_t(nx + 1) * std::size_t(ny + 1), 0.0);
  const double scale = 1.0 / (4.0 * nx * ny);
#pragma omp parallel for num_threads(threads < 1 ? 1 : threads) schedule(static)
  for (int q = 1; q < ny; ++q) {
    double* row = table_.data() + std::size_t(q) * std::size_t(nx + 1);
    for (int p = 1; p < nx; ++p) {
      const double lambda = sx.stiffness[p - 1] * sy.mass[q - 1] + sx.mass[p - 1] * sy.stiffness[q - 1] +
                            c * sx.mass[p - 1] * sy.mass[q - 1];
      row[p] = scale / lambda;
    }
  }
  detail::R2rPlan2d plan(ny + 1, nx + 1, detail::R2rKind::dct1, threads);
  plan.execute(table_.data());
}

}  // namespace fictus
