// G from the Green's table against columns of A⁻¹ computed with the DST solver.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "fictus/grid/distribution.hpp"
#include "fictus/grid/dst_solver.hpp"
#include "fictus/grid/green_table.hpp"

namespace {

struct Case {
  fictus::Boundary boundary;
  double c;
};

class GreenTableTest : public ::testing::TestWithParam<Case> {};

TEST_P(GreenTableTest, MatchesColumnsOfInverse) {
  const auto [boundary, c] = GetParam();
  const fictus::Grid2 grid(fictus::Box2{{0.0, 0.0}, {1.0, 0.75}}, 16, boundary);
  const auto solver = fictus::make_fast_solver(grid, c);
  const fictus::GreenTable<2> green(grid, c);
  const int columns[][2] = {{1, 1}, {8, 6}, {15, 11}, {3, 10}, {12, 2}};
  for (const auto& col : columns) {
    fictus::GridVector e(grid.n_unknowns(), 0.0);
    e[grid.index(col[0], col[1])] = 1.0;
    solver->solve_in_place(e);  // for c = 0 periodic: the pseudo-inverse column A⁺e
    double max_abs = 0.0, max_diff = 0.0;
    for (int j = 0; j <= grid.ny(); ++j)
      for (int i = 0; i <= grid.nx(); ++i) {
        if (!grid.has_unknown(i, j)) continue;
        const double ref = e[grid.index(i, j)];
        max_abs = std::max(max_abs, std::abs(ref));
        max_diff = std::max(max_diff, std::abs(green.G({i, j}, {col[0], col[1]}) - ref));
      }
    EXPECT_LE(max_diff / max_abs, 1e-12) << "column (" << col[0] << ", " << col[1] << ")";
  }
}

INSTANTIATE_TEST_SUITE_P(BoundariesAndReactions, GreenTableTest,
                         ::testing::Values(Case{fictus::Boundary::dirichlet, 0.0},
                                           Case{fictus::Boundary::dirichlet, 1.0},
                                           Case{fictus::Boundary::dirichlet, 100.0},
                                           Case{fictus::Boundary::periodic, 0.0}, Case{fictus::Boundary::periodic, 1.0},
                                           Case{fictus::Boundary::periodic, 100.0}));

/// G node by node in the order of the Schur assembly's sums: G(a, b) in 2-D; in 3-D the reflections
/// grouped by z (a + b and a − b folded by T).
double node_by_node(const fictus::GreenTable<2>& green, const fictus::Grid2::Index& a, const fictus::Grid2::Index& b) {
  return green.G(a, b);
}
double node_by_node(const fictus::GreenTable<3>& green, const fictus::Grid3::Index& a, const fictus::Grid3::Index& b) {
  if (green.grid().periodic()) return green.G(a, b);
  const auto T = [&](int sx, int sy, int sz) {
    return green.T({a[0] + sx * b[0], a[1] + sy * b[1], a[2] + sz * b[2]});
  };
  return (T(-1, -1, -1) - T(1, -1, -1) - T(-1, 1, -1) + T(1, 1, -1)) -
         (T(-1, -1, 1) - T(1, -1, 1) - T(-1, 1, 1) + T(1, 1, 1));
}

/// The batch forms of the Schur assembly against G node by node, to the last bit: the tensor form
/// (far blocks' cores) and the weighted sums (near blocks), on both boxes, in 2-D and 3-D, with nodes
/// on the box's faces (a + b = 2n, and |a − b| = n in a periodic box).
template <int dim>
void expect_batch_forms_match(fictus::Boundary boundary) {
  using Index = typename fictus::Grid<dim>::Index;
  fictus::Box<dim> box;
  for (int d = 0; d < dim; ++d) box.lower[d] = 0.0, box.upper[d] = 1.0 + 0.5 * d;  // 12, 18, 24 cells
  const fictus::Grid<dim> grid(box, 12, boundary);
  const fictus::GreenTable<dim> green(grid, 1.0);
  std::array<std::vector<int>, dim> a, b;
  for (int d = 0; d < dim; ++d) {
    a[std::size_t(d)] = {0, 3, 4, grid.n(d)};
    b[std::size_t(d)] = {1, 7 + d, grid.n(d) - 1, grid.n(d)};
  }
  std::size_t na = 1, nb = 1;
  for (int d = 0; d < dim; ++d) na *= a[std::size_t(d)].size(), nb *= b[std::size_t(d)].size();
  const auto node = [](const std::array<std::vector<int>, dim>& axes, std::size_t flat) {
    Index x;
    for (int d = 0; d < dim; ++d) {
      const std::size_t p = axes[std::size_t(d)].size();
      x[d] = axes[std::size_t(d)][flat % p], flat /= p;
    }
    return x;
  };
  const std::size_t ld = na + 2;
  std::vector<double> core(ld * nb, 0.0);
  green.G(a, b, core.data(), ld);
  int nonzero = 0;
  for (std::size_t q = 0; q < nb; ++q)
    for (std::size_t p = 0; p < na; ++p) {
      const double expected = node_by_node(green, node(a, p), node(b, q));
      nonzero += expected != 0.0;
      EXPECT_EQ(core[p + ld * q], expected) << "p " << p << ", q " << q;
    }
  EXPECT_GT(nonzero, int(na * nb / 16));  // the nodes on a Dirichlet face give 0

  std::vector<Index> rows, cols;
  std::vector<double> w;
  for (std::size_t p = 0; p < na; ++p) rows.push_back(node(a, p));
  for (std::size_t q = 0; q < nb; ++q) cols.push_back(node(b, q)), w.push_back(1.0 + 0.5 * double(q % 3) - 0.2 * q);
  std::vector<double> sums(na, -1.0);
  green.G(rows.data(), rows.size(), cols.data(), w.data(), cols.size(), sums.data());
  for (std::size_t p = 0; p < na; ++p) {
    double expected = 0.0;
    for (std::size_t q = 0; q < nb; ++q) expected += node_by_node(green, rows[p], cols[q]) * w[q];
    EXPECT_EQ(sums[p], expected) << "row " << p;
  }
}

TEST(GreenTableBatch, TensorAndWeightedFormsEqualNodeByNode2d) {
  expect_batch_forms_match<2>(fictus::Boundary::dirichlet);
  expect_batch_forms_match<2>(fictus::Boundary::periodic);
}

TEST(GreenTableBatch, TensorAndWeightedFormsEqualNodeByNode3d) {
  expect_batch_forms_match<3>(fictus::Boundary::dirichlet);
  expect_batch_forms_match<3>(fictus::Boundary::periodic);
}

/// A table of some planes (the near blocks' whole planes in a distributed assembly): with the planes
/// mark_planes gives for the nodes' ranges along the slowest axis, its weighted sums are the table's to
/// the last bit; a sum that reads a plane not copied is refused, never a silent zero.
template <int dim>
void expect_copied_planes_suffice(fictus::Boundary boundary) {
  using Index = typename fictus::Grid<dim>::Index;
  fictus::Box<dim> box;
  for (int d = 0; d < dim; ++d) box.lower[d] = 0.0, box.upper[d] = 1.0;
  const fictus::Grid<dim> grid(box, 16, boundary);
  const fictus::GreenTable<dim> green(grid, 1.0);
  const int z = dim - 1, lo = boundary == fictus::Boundary::dirichlet ? 1 : 0;
  std::vector<Index> rows, cols;
  std::vector<double> w;
  for (int k = 0; k < 6; ++k) {
    Index a, b;
    for (int d = 0; d < dim; ++d) a[d] = lo + (3 * k + d) % 14, b[d] = lo + (5 * k + 2 * d) % 14;
    a[z] = 9 + k % 3, b[z] = 4 + k % 2;  // a_z in [9, 11], b_z in [4, 5]
    rows.push_back(a), cols.push_back(b), w.push_back(1.0 - 0.3 * k);
  }
  std::vector<char> wanted;
  green.mark_planes(9, 11, 4, 5, wanted);
  ASSERT_EQ(int(wanted.size()), green.planes());
  const int marked = int(std::count(wanted.begin(), wanted.end(), 1));
  EXPECT_LT(2 * marked, green.planes() + 1);  // minus [4, 7]; plus [13, 16] in a Dirichlet box
  const fictus::GreenTable<dim> some(green, wanted, fictus::Distribution{});
  std::vector<double> want(rows.size()), got(rows.size());
  green.G(rows.data(), rows.size(), cols.data(), w.data(), cols.size(), want.data());
  some.G(rows.data(), rows.size(), cols.data(), w.data(), cols.size(), got.data());
  for (std::size_t p = 0; p < rows.size(); ++p) EXPECT_EQ(got[p], want[p]) << "row " << p;
  EXPECT_EQ(some.memory_bytes(), std::size_t(marked + 1) * green.plane_size() * sizeof(double));  // and a zero plane
  rows[2][z] = 5;  // the plane of |5 − 4| = 1 was not marked
  EXPECT_THROW(some.G(rows.data(), rows.size(), cols.data(), w.data(), cols.size(), got.data()), std::logic_error);
}

TEST(GreenTablePlanes, CopiedPlanesGiveTheTablesSums) {
  expect_copied_planes_suffice<2>(fictus::Boundary::dirichlet);
  expect_copied_planes_suffice<2>(fictus::Boundary::periodic);
  expect_copied_planes_suffice<3>(fictus::Boundary::dirichlet);
  expect_copied_planes_suffice<3>(fictus::Boundary::periodic);
}

}  // namespace
