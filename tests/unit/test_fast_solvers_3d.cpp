// The same fast solvers and Green's table instantiated in 3-D: against a sparse direct solve of the
// trilinear Q1 matrix assembled cell by cell, and G against columns of A⁻¹ (2-D: test_dst_solver.cpp,
// test_green_table.cpp).
#include <gtest/gtest.h>

#include <Eigen/Sparse>
#include <random>

#include "fictus/grid/dst_solver.hpp"
#include "fictus/grid/green_table.hpp"

namespace {

using Index3 = fictus::Grid3::Index;

/// A = K + cM from the element matrices of the trilinear element on a cube of side h: the
/// products of the 1-D element matrices k = (1/h)[1 −1; −1 1], m = (h/6)[2 1; 1 2].
Eigen::SparseMatrix<double> assemble_q1(const fictus::Grid3& grid, double c) {
  const double h = grid.h();
  const double k1[2][2] = {{1 / h, -1 / h}, {-1 / h, 1 / h}}, m1[2][2] = {{h / 3, h / 6}, {h / 6, h / 3}};
  std::vector<Eigen::Triplet<double>> t;
  for (int iz = 0; iz < grid.nz(); ++iz)
    for (int iy = 0; iy < grid.ny(); ++iy)
      for (int ix = 0; ix < grid.nx(); ++ix)
        for (int a = 0; a < 8; ++a)
          for (int b = 0; b < 8; ++b) {
            const int ax = a & 1, ay = (a >> 1) & 1, az = a >> 2, bx = b & 1, by = (b >> 1) & 1, bz = b >> 2;
            const Index3 na{ix + ax, iy + ay, iz + az}, nb{ix + bx, iy + by, iz + bz};
            if (!grid.has_unknown(na) || !grid.has_unknown(nb)) continue;
            const double value = k1[ax][bx] * m1[ay][by] * m1[az][bz] + m1[ax][bx] * k1[ay][by] * m1[az][bz] +
                                 m1[ax][bx] * m1[ay][by] * k1[az][bz] + c * m1[ax][bx] * m1[ay][by] * m1[az][bz];
            t.emplace_back(int(grid.index(na)), int(grid.index(nb)), value);
          }
  Eigen::SparseMatrix<double> A(grid.n_unknowns(), grid.n_unknowns());
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

Eigen::Map<const Eigen::VectorXd> view(const fictus::GridVector& v) { return {v.data(), Eigen::Index(v.size())}; }

const fictus::Box3 box{{0.0, 0.0, 0.0}, {1.0, 0.75, 0.5}};  // 8 × 6 × 4 cells at N = 8: no symmetry

struct Case {
  fictus::Boundary boundary;
  double c;
};

class FastSolver3d : public ::testing::TestWithParam<Case> {};

TEST_P(FastSolver3d, MatchesSparseDirectSolve) {
  const auto [boundary, c] = GetParam();
  const fictus::Grid3 grid(box, 8, boundary);
  const auto solver = fictus::make_fast_solver(grid, c);
  fictus::GridVector r(grid.n_unknowns());
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> dist(-1.0, 1.0);
  for (double& v : r) v = dist(rng);
  fictus::GridVector u = r, Au;
  solver->solve_in_place(u);
  solver->apply(u, Au);
  const Eigen::SparseMatrix<double> A = assemble_q1(grid, c);
  if (solver->singular()) {  // A⁺: A·A⁺r = r − mean(r), zero mean
    const double mean = view(r).mean();
    EXPECT_LE((A * view(u) - (view(r).array() - mean).matrix()).norm() / view(r).norm(), 1e-12);
    EXPECT_NEAR(view(u).mean(), 0.0, 1e-13);
    return;
  }
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu(A);
  ASSERT_EQ(lu.info(), Eigen::Success);
  const Eigen::VectorXd reference = lu.solve(view(r));
  EXPECT_LE((view(u) - reference).norm() / reference.norm(), 1e-12);  // round-off of transforms and LU
  EXPECT_LE((view(Au) - view(r)).norm() / view(r).norm(), 1e-12);     // solve(apply(x)) == x
}

TEST_P(FastSolver3d, GreenTableMatchesColumnsOfInverse) {
  const auto [boundary, c] = GetParam();
  const fictus::Grid3 grid(box, 8, boundary);
  const auto solver = fictus::make_fast_solver(grid, c);
  const fictus::GreenTable<3> green(grid, c);
  for (const Index3& column : {Index3{1, 1, 1}, Index3{4, 3, 2}, Index3{7, 5, 3}, Index3{2, 5, 1}}) {
    fictus::GridVector e(grid.n_unknowns(), 0.0);
    e[grid.index(column)] = 1.0;
    solver->solve_in_place(e);
    double max_abs = 0.0, max_diff = 0.0;
    for (int k = 0; k <= grid.nz(); ++k)
      for (int j = 0; j <= grid.ny(); ++j)
        for (int i = 0; i <= grid.nx(); ++i) {
          const Index3 node{i, j, k};
          if (!grid.has_unknown(node)) continue;
          const double reference = e[grid.index(node)];
          max_abs = std::max(max_abs, std::abs(reference));
          max_diff = std::max(max_diff, std::abs(green.G(node, column) - reference));
        }
    EXPECT_LE(max_diff / max_abs, 1e-12) << "column (" << column[0] << ", " << column[1] << ", " << column[2] << ")";
  }
}

INSTANTIATE_TEST_SUITE_P(BoundariesAndReactions, FastSolver3d,
                         ::testing::Values(Case{fictus::Boundary::dirichlet, 0.0},
                                           Case{fictus::Boundary::dirichlet, 1.0},
                                           Case{fictus::Boundary::dirichlet, 100.0},
                                           Case{fictus::Boundary::periodic, 0.0}, Case{fictus::Boundary::periodic, 1.0},
                                           Case{fictus::Boundary::periodic, 100.0}));

}  // namespace
