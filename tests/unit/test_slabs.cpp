// The grid operations of a distributed run on one process: cut into slabs (Slab), the load and the
// sparse rows' products give the whole grid's numbers, slab by slab.
#include <gtest/gtest.h>

#include <cmath>

#include "fictus/grid/load_vector.hpp"
#include "fictus/grid/sparse_rows.hpp"
#include "scattered_rows.hpp"

namespace {

using fictus::GridVector;
using fictus::Slab;

/// Slabs of 3, 3, …, the rest: a cut that divides none of the grids below evenly.
std::vector<Slab> slabs_of(int layers) {
  std::vector<Slab> out;
  for (int first = 0; first < layers; first += 3) out.push_back(Slab{first, std::min(3, layers - first)});
  return out;
}

template <int dim>
void check(const fictus::Grid<dim>& grid) {
  const fictus::SparseRows R = fictus::test_support::scattered_rows(grid, 17);
  GridVector u(grid.n_unknowns());
  for (std::size_t i = 0; i < u.size(); ++i) u[i] = std::sin(0.7 * double(i));
  std::vector<double> whole, sum(17, 0.0), part, lambda(17);
  R.multiply(u, whole);
  for (int r = 0; r < 17; ++r) lambda[std::size_t(r)] = 1.0 + r;
  GridVector transposed(grid.n_unknowns(), 0.0);
  R.add_transposed(lambda, transposed);

  const auto f = [](std::size_t n, const double* x, const double* y, const double* z, double* out) {
    for (std::size_t k = 0; k < n; ++k) out[k] = std::exp(x[k]) * std::cos(2 * y[k]) + (z ? z[k] * z[k] : 0.0);
  };
  GridVector load;
  if constexpr (dim == 2)
    load = fictus::assemble_load(
        grid, [&](std::size_t n, const double* x, const double* y, double* out) { f(n, x, y, nullptr, out); });
  else
    load = fictus::assemble_load(grid, fictus::VectorizedField3(f));

  for (const Slab& s : slabs_of(grid.layers())) {
    const std::size_t offset = grid.slab_offset(s), size = grid.slab_size(s);
    const GridVector local(u.begin() + std::ptrdiff_t(offset), u.begin() + std::ptrdiff_t(offset + size));
    R.multiply(local, offset, part);
    for (int r = 0; r < 17; ++r) sum[std::size_t(r)] += part[std::size_t(r)];
    GridVector local_transposed(size, 0.0);
    R.add_transposed(lambda, local_transposed, offset);
    GridVector local_load;
    if constexpr (dim == 2)
      local_load = fictus::assemble_load(
          grid, [&](std::size_t n, const double* x, const double* y, double* out) { f(n, x, y, nullptr, out); }, 2,
          fictus::Execution{}, s);
    else
      local_load = fictus::assemble_load(grid, fictus::VectorizedField3(f), 2, fictus::Execution{}, s);
    ASSERT_EQ(local_load.size(), size);
    for (std::size_t i = 0; i < size; ++i) {
      EXPECT_EQ(local_transposed[i], transposed[offset + i]);  // the same sums in the same order
      EXPECT_EQ(local_load[i], load[offset + i]);
    }
  }
  for (int r = 0; r < 17; ++r) EXPECT_NEAR(sum[std::size_t(r)], whole[std::size_t(r)], 1e-14 * 17);
}

TEST(Slabs, LoadAndRowsCutIntoSlabsGiveTheWholeGrids) {
  for (auto boundary : {fictus::Boundary::dirichlet, fictus::Boundary::periodic}) {
    check(fictus::Grid2(fictus::Box2{{0, 0}, {1, 1.25}}, 16, boundary));          // 20 (periodic) or 19 layers
    check(fictus::Grid3(fictus::Box3{{0, 0, 0}, {1, 0.75, 1.75}}, 8, boundary));  // 14 or 13 layers
  }
}

}  // namespace
