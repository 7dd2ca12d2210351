#include "fictus/load_vector.hpp"

#include <stdexcept>
#include <vector>

#include "fictus/quadrature.hpp"

namespace fictus {

GridVector assemble_load(const Grid& grid, const ScalarField& f, int q, int threads) {
  const GaussRule& rule = gauss_legendre(q);
  const int nx = grid.nx(), ny = grid.ny();
  const double h = grid.h(), area = h * h;
  GridVector load(grid.n_unknowns(), 0.0);
  // Cell rows of one parity write to disjoint node rows {iy, iy+1}: two parallel sweeps.
  for (int parity = 0; parity < 2; ++parity) {
#pragma omp parallel for num_threads(threads < 1 ? 1 : threads) schedule(dynamic, 4)
    for (int iy = parity; iy < ny; iy += 2) {
      for (int ix = 0; ix < nx; ++ix) {
        double w00 = 0, w10 = 0, w01 = 0, w11 = 0;
        for (int b = 0; b < q; ++b) {
          const double eta = rule.nodes[b];
          for (int a = 0; a < q; ++a) {
            const double xi = rule.nodes[a];
            const double v = f(grid.x(ix) + xi * h, grid.y(iy) + eta * h) * rule.weights[a] *
                             rule.weights[b] * area;
            w00 += v * (1 - xi) * (1 - eta);
            w10 += v * xi * (1 - eta);
            w01 += v * (1 - xi) * eta;
            w11 += v * xi * eta;
          }
        }
        auto add = [&](int i, int j, double w) {
          if (grid.has_unknown(i, j)) load[grid.index(i, j)] += w;
        };
        add(ix, iy, w00);
        add(ix + 1, iy, w10);
        add(ix, iy + 1, w01);
        add(ix + 1, iy + 1, w11);
      }
    }
  }
  return load;
}

}  // namespace fictus
