// The fast DST-I solver against a sparse direct solve of the assembled Q1 matrix.
#include <gtest/gtest.h>

#include <Eigen/Sparse>
#include <random>

#include "fictus/dst_solver.hpp"

namespace {

// A = K + cM assembled cell by cell from the Q1 element matrices (independent of the tensor form).
Eigen::SparseMatrix<double> assemble_q1(const fictus::Grid& grid, double c) {
  const double h = grid.h();
  const int ci[4] = {0, 1, 1, 0}, cj[4] = {0, 0, 1, 1};  // corners counter-clockwise
  const double K[4][4] = {{4, -1, -2, -1}, {-1, 4, -1, -2}, {-2, -1, 4, -1}, {-1, -2, -1, 4}};
  const double M[4][4] = {{4, 2, 1, 2}, {2, 4, 2, 1}, {1, 2, 4, 2}, {2, 1, 2, 4}};
  std::vector<Eigen::Triplet<double>> t;
  for (int iy = 0; iy < grid.ny(); ++iy)
    for (int ix = 0; ix < grid.nx(); ++ix)
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) {
          const int ia = ix + ci[a], ja = iy + cj[a], ib = ix + ci[b], jb = iy + cj[b];
          if (!grid.is_interior(ia, ja) || !grid.is_interior(ib, jb)) continue;
          t.emplace_back(int(grid.index(ia, ja)), int(grid.index(ib, jb)), K[a][b] / 6.0 + c * h * h * M[a][b] / 36.0);
        }
  Eigen::SparseMatrix<double> A(grid.n_unknowns(), grid.n_unknowns());
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

class DstSolverTest : public ::testing::TestWithParam<double> {};

TEST_P(DstSolverTest, MatchesSparseDirectSolve) {
  const double c = GetParam();
  const fictus::Grid grid(fictus::Box{0.0, 1.0, 0.0, 0.75}, 16);  // 16 × 12 cells, nx ≠ ny
  const fictus::DstSolver solver(grid, c);
  const Eigen::SparseMatrix<double> A = assemble_q1(grid, c);
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu(A);
  ASSERT_EQ(lu.info(), Eigen::Success);

  std::mt19937 rng(7);
  std::uniform_real_distribution<double> dist(-1.0, 1.0);
  fictus::GridVector r(grid.n_unknowns());
  for (double& v : r) v = dist(rng);
  Eigen::VectorXd reference = lu.solve(Eigen::Map<const Eigen::VectorXd>(r.data(), r.size()));

  fictus::GridVector u = r;
  solver.solve_in_place(u);
  const double diff = (Eigen::Map<const Eigen::VectorXd>(u.data(), u.size()) - reference).norm();
  EXPECT_LE(diff / reference.norm(), 1e-12);  // round-off of two transforms and one LU

  fictus::GridVector Au(grid.n_unknowns());
  solver.apply(u, Au);  // solve(apply(x)) == x
  const Eigen::VectorXd back = Eigen::Map<const Eigen::VectorXd>(Au.data(), Au.size());
  EXPECT_LE((back - Eigen::Map<const Eigen::VectorXd>(r.data(), r.size())).norm() / back.norm(), 1e-12);
}

INSTANTIATE_TEST_SUITE_P(ReactionCoefficients, DstSolverTest, ::testing::Values(0.0, 1.0, 100.0));

TEST(DstSolver, RejectsNegativeReaction) {
  const fictus::Grid grid(fictus::Box{}, 8);
  EXPECT_THROW(fictus::DstSolver(grid, -1.0), std::invalid_argument);
}

}  // namespace
