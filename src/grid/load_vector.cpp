#include "fictus/grid/load_vector.hpp"

#include <omp.h>

#include <array>
#include <atomic>
#include <stdexcept>
#include <vector>

#include "fictus/grid/q1_element.hpp"
#include "fictus/grid/quadrature.hpp"

namespace fictus {

VectorizedField vectorize(ScalarField f) {
  return [f = std::move(f)](std::size_t n, const double* x, const double* y, double* out) {
    for (std::size_t k = 0; k < n; ++k) out[k] = f(x[k], y[k]);
  };
}

GridVector assemble_load(const Grid2& grid, const ScalarField& f, int q, const Execution& execution) {
  return assemble_load(grid, vectorize(f), q, execution);
}

namespace {
/// Which of the cell layer c's two node layers (c and c + 1 along the slowest axis) carry unknowns the
/// slab holds.
template <int dim>
std::array<bool, 2> held_layers(const Grid<dim>& grid, const Slab& slab, int c) {
  std::array<bool, 2> held{};
  for (int side = 0; side < 2; ++side) {
    const int node = c + side;
    held[std::size_t(side)] = (grid.periodic() || (node > 0 && node < grid.n(dim - 1))) && slab.holds(grid.layer(node));
  }
  return held;
}
}  // namespace

GridVector assemble_load(const Grid2& grid, const VectorizedField& f, int q, const Execution& execution,
                         std::optional<Slab> slab) {
  const GaussRule& rule = gauss_legendre(q);
  const int nx = grid.nx(), ny = grid.ny(), qq = q * q;
  const double h = grid.h(), area = h * h;
  const Slab s = slab.value_or(grid.every_layer());
  const std::size_t offset = grid.slab_offset(s);
  GridVector load(grid.slab_size(s), 0.0);
  std::vector<Q1Element<2>> elements;  // the shape functions at the q×q Gauss points of a cell
  for (int b = 0; b < q; ++b)
    for (int a = 0; a < q; ++a) elements.emplace_back(Point2{rule.nodes[a], rule.nodes[b]}, h);
  // Cell rows of one parity write to disjoint node rows {iy, iy+1}: two parallel sweeps.
  std::atomic<bool> stop = false;  // an interruption seen by thread 0 (the caller's) ends every thread's work
  for (int parity = 0; parity < 2; ++parity) {
#pragma omp parallel num_threads(execution.threads())
    {
      std::vector<double> xs(std::size_t(nx) * qq), ys(xs.size()), values(xs.size());
#pragma omp for schedule(dynamic, 4)
      for (int iy = parity; iy < ny; iy += 2) {
        if (omp_get_thread_num() == 0 && iy % 64 < 2 && execution.interrupt_requested()) stop = true;
        const std::array<bool, 2> held = held_layers(grid, s, iy);
        if (stop || !(held[0] || held[1])) continue;
        for (int ix = 0, k = 0; ix < nx; ++ix)  // the row's quadrature points, cell by cell
          for (int b = 0; b < q; ++b)
            for (int a = 0; a < q; ++a, ++k) {
              xs[k] = grid.x(ix) + rule.nodes[a] * h;
              ys[k] = grid.y(iy) + rule.nodes[b] * h;
            }
        f(xs.size(), xs.data(), ys.data(), values.data());
        for (int ix = 0; ix < nx; ++ix) {
          std::array<double, Q1Element<2>::n_nodes> w{};
          for (int b = 0; b < q; ++b)
            for (int a = 0; a < q; ++a) {
              const Q1Element<2>& element = elements[std::size_t(b) * q + a];
              const double v = values[std::size_t(ix) * qq + b * q + a] * rule.weights[a] * rule.weights[b] * area;
              for (int k = 0; k < Q1Element<2>::n_nodes; ++k) w[k] += v * element.value[k];
            }
          for (int k = 0; k < Q1Element<2>::n_nodes; ++k) {
            const int i = ix + Q1Element<2>::offset(k, 0), j = iy + Q1Element<2>::offset(k, 1);
            if (held[std::size_t(j - iy)] && grid.has_unknown(i, j)) load[grid.index(i, j) - offset] += w[k];
          }
        }
      }
    }
  }
  if (stop) throw Interrupted();
  return load;
}

VectorizedField3 vectorize(ScalarField3 f) {
  return [f = std::move(f)](std::size_t n, const double* x, const double* y, const double* z, double* out) {
    for (std::size_t k = 0; k < n; ++k) out[k] = f(x[k], y[k], z[k]);
  };
}

GridVector assemble_load(const Grid3& grid, const ScalarField3& f, int q, const Execution& execution) {
  return assemble_load(grid, vectorize(f), q, execution);
}

GridVector assemble_load(const Grid3& grid, const VectorizedField3& f, int q, const Execution& execution,
                         std::optional<Slab> slab) {
  const GaussRule& rule = gauss_legendre(q);
  const int nx = grid.nx(), qqq = q * q * q;
  const double h = grid.h(), volume = h * h * h;
  const Slab s = slab.value_or(grid.every_layer());
  const std::size_t offset = grid.slab_offset(s);
  GridVector load(grid.slab_size(s), 0.0);
  std::vector<Q1Element<3>> elements;  // the shape functions at the q×q×q Gauss points of a voxel
  std::vector<double> weights;
  for (int c = 0; c < q; ++c)
    for (int b = 0; b < q; ++b)
      for (int a = 0; a < q; ++a) {
        elements.emplace_back(Point3{rule.nodes[a], rule.nodes[b], rule.nodes[c]}, h);
        weights.push_back(rule.weights[a] * rule.weights[b] * rule.weights[c] * volume);
      }
  // Voxel layers of one parity write to disjoint node layers {iz, iz+1}: two parallel sweeps; f is
  // evaluated one voxel row at a time.
  std::atomic<bool> stop = false;
  for (int parity = 0; parity < 2; ++parity) {
#pragma omp parallel num_threads(execution.threads())
    {
      std::vector<double> xs(std::size_t(nx) * qqq), ys(xs.size()), zs(xs.size()), values(xs.size());
#pragma omp for schedule(dynamic, 1)
      for (int iz = parity; iz < grid.nz(); iz += 2) {
        if (omp_get_thread_num() == 0 && execution.interrupt_requested()) stop = true;
        const std::array<bool, 2> held = held_layers(grid, s, iz);
        if (stop || !(held[0] || held[1])) continue;
        for (int iy = 0; iy < grid.ny(); ++iy) {
          for (int ix = 0, k = 0; ix < nx; ++ix)
            for (int p = 0; p < qqq; ++p, ++k) {
              xs[k] = grid.x(ix) + rule.nodes[p % q] * h;
              ys[k] = grid.y(iy) + rule.nodes[p / q % q] * h;
              zs[k] = grid.z(iz) + rule.nodes[p / (q * q)] * h;
            }
          f(xs.size(), xs.data(), ys.data(), zs.data(), values.data());
          for (int ix = 0; ix < nx; ++ix) {
            std::array<double, Q1Element<3>::n_nodes> w{};
            for (int p = 0; p < qqq; ++p) {
              const double v = values[std::size_t(ix) * qqq + p] * weights[p];
              for (int k = 0; k < Q1Element<3>::n_nodes; ++k) w[k] += v * elements[p].value[k];
            }
            for (int k = 0; k < Q1Element<3>::n_nodes; ++k) {
              const Grid3::Index node{ix + Q1Element<3>::offset(k, 0), iy + Q1Element<3>::offset(k, 1),
                                      iz + Q1Element<3>::offset(k, 2)};
              if (held[std::size_t(node[2] - iz)] && grid.has_unknown(node)) load[grid.index(node) - offset] += w[k];
            }
          }
        }
      }
    }
  }
  if (stop) throw Interrupted();
  return load;
}

}  // namespace fictus
