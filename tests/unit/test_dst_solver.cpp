// The fast DST-I solver against a sparse direct solve of the assembled Q1 matrix.
#include <gtest/gtest.h>

#include <Eigen/Sparse>
#include <random>

#include "fictus/grid/dst_solver.hpp"

namespace {

// A = K + cM assembled cell by cell from the Q1 element matrices (independent of the tensor form).
// Dirichlet: boundary nodes dropped; periodic: Grid::index wraps the node indices.
Eigen::SparseMatrix<double> assemble_q1(const fictus::Grid2& grid, double c) {
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
          if (!grid.has_unknown(ia, ja) || !grid.has_unknown(ib, jb)) continue;
          t.emplace_back(int(grid.index(ia, ja)), int(grid.index(ib, jb)), K[a][b] / 6.0 + c * h * h * M[a][b] / 36.0);
        }
  Eigen::SparseMatrix<double> A(grid.n_unknowns(), grid.n_unknowns());
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

class DstSolverTest : public ::testing::TestWithParam<double> {};

TEST_P(DstSolverTest, MatchesSparseDirectSolve) {
  const double c = GetParam();
  const fictus::Grid2 grid(fictus::Box2{{0.0, 0.0}, {1.0, 0.75}}, 16);  // 16 × 12 cells, nx ≠ ny
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
  const fictus::Grid2 grid(fictus::Box2{}, 8);
  EXPECT_THROW(fictus::DstSolver(grid, -1.0), std::invalid_argument);
}

}  // namespace

namespace {

Eigen::Map<const Eigen::VectorXd> view(const fictus::GridVector& v) { return {v.data(), Eigen::Index(v.size())}; }

class PeriodicSolverTest : public ::testing::TestWithParam<double> {};

TEST_P(PeriodicSolverTest, MatchesSparseDirectSolve) {
  const double c = GetParam();
  const fictus::Grid2 grid(fictus::Box2{{0.0, 0.0}, {1.0, 0.75}}, 16, fictus::Boundary::periodic);
  const auto solver = fictus::make_fast_solver(grid, c);
  fictus::GridVector r(grid.n_unknowns());
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> dist(-1.0, 1.0);
  for (double& v : r) v = dist(rng);
  fictus::GridVector u = r;
  solver->solve_in_place(u);
  const Eigen::SparseMatrix<double> A = assemble_q1(grid, c);
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu(A);
  ASSERT_EQ(lu.info(), Eigen::Success);
  const Eigen::VectorXd reference = lu.solve(view(r));
  EXPECT_LE((view(u) - reference).norm() / reference.norm(), 1e-12);
  fictus::GridVector Au;
  solver->apply(u, Au);
  EXPECT_LE((view(Au) - view(r)).norm() / view(r).norm(), 1e-12);
}

INSTANTIATE_TEST_SUITE_P(ReactionCoefficients, PeriodicSolverTest, ::testing::Values(1.0, 100.0));

TEST(PeriodicSolver, SingularCaseIsThePseudoInverse) {
  // c = 0: A is singular with the constants as null space. A·A⁺r = r − mean(r), and A⁺r has zero mean.
  const fictus::Grid2 grid(fictus::Box2{}, 16, fictus::Boundary::periodic);
  const auto solver = fictus::make_fast_solver(grid, 0.0);
  ASSERT_TRUE(solver->singular());
  fictus::GridVector r(grid.n_unknowns());
  for (std::size_t k = 0; k < r.size(); ++k) r[k] = std::sin(0.37 * k) + 0.5;
  fictus::GridVector u = r, Au;
  solver->solve_in_place(u);
  solver->apply(u, Au);
  const double mean = view(r).mean();
  EXPECT_LE((view(Au) - (view(r).array() - mean).matrix()).norm() / view(r).norm(), 1e-12);
  EXPECT_NEAR(view(u).mean(), 0.0, 1e-14);
  const Eigen::SparseMatrix<double> A = assemble_q1(grid, 0.0);
  EXPECT_LE((A * view(u) - view(Au)).norm(), 1e-12);  // the fast apply is the assembled A
}

}  // namespace

namespace {

/// Rows of `count` nodes each, the nodes of a row in one small cluster around a random node: a load
/// or readings near a few points, as the Schur complement's rows are.
template <int dim>
fictus::SparseRows clustered_rows(const fictus::Grid<dim>& grid, int n_rows, std::mt19937& rng) {
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  fictus::SparseRows R;
  for (int r = 0; r < n_rows; ++r) {
    typename fictus::Grid<dim>::Index centre;
    for (int d = 0; d < dim; ++d) centre[d] = 2 + int(rng() % unsigned(grid.n(d) - 4));
    for (int k = 0; k < 3 * dim; ++k) {
      auto node = centre;
      for (int d = 0; d < dim; ++d) node[d] += int(rng() % 3) - 1;
      R.entries.push_back({grid.index(node), node[0], node[1], dim == 3 ? node[dim - 1] : 0, value(rng)});
    }
    R.row_begin.push_back(R.entries.size());
  }
  return R;
}

template <int dim>
void expect_solve_at_matches_full_solve(const fictus::Grid<dim>& grid, double c, int threads) {
  std::mt19937 rng(7);
  const fictus::SparseRows loads = clustered_rows(grid, 9, rng), readings = clustered_rows(grid, 11, rng);
  const fictus::DstSolver<dim> solver(grid, c, fictus::Execution(threads));
  std::vector<double> lambda(9);
  for (double& l : lambda) l = std::uniform_real_distribution<double>(-1.0, 1.0)(rng);
  fictus::GridVector full(grid.n_unknowns(), 0.0);
  loads.add_transposed(lambda, full);
  fictus::GridVector pruned = full;
  solver.solve_in_place(full);
  const fictus::Footprint load = fictus::footprint(grid, {&loads}), wanted = fictus::footprint(grid, {&readings});
  for (int repeat = 0; repeat < 2; ++repeat) {  // the second call runs on the plans of the first
    fictus::GridVector u = pruned;
    solver.solve_in_place_at(u, load, wanted);
    std::vector<double> expected, got;
    readings.multiply(full, expected);
    readings.multiply(u, got);
    double scale = 0;
    for (double v : expected) scale = std::max(scale, std::abs(v));
    ASSERT_GT(scale, 0.0);
    for (std::size_t i = 0; i < got.size(); ++i) EXPECT_NEAR(got[i], expected[i], 1e-13 * scale) << "reading " << i;
  }
  // Footprints of another grid are refused.
  fictus::GridVector u = pruned;
  EXPECT_THROW(solver.solve_in_place_at(u, fictus::Footprint{}, wanted), std::invalid_argument);
}

}  // namespace

// The pruned solve of the Schur complement's products: transforms along the slow axes of the lines that
// meet the load and the readings only, the same readings as the full solve. The fastest axis has 47
// unknowns (chunks of 16, 16 and 15 lines), 32 (two whole chunks) or 11 (one narrow chunk), 2-D and
// 3-D, one and two threads.
TEST(DstSolver, SolveAtFootprintsMatchesTheFullSolve) {
  for (int threads : {1, 2}) {
    expect_solve_at_matches_full_solve(fictus::Grid2(fictus::Box2{{0.0, 0.0}, {1.0, 0.75}}, 48), 1.5, threads);
    expect_solve_at_matches_full_solve(fictus::Grid2(fictus::Box2{{0.0, 0.0}, {1.0, 1.0}}, 33), 0.0, threads);
    expect_solve_at_matches_full_solve(fictus::Grid3(fictus::Box3{{0.0, 0.0, 0.0}, {1.0, 0.75, 0.5}}, 48), 0.0,
                                       threads);
    expect_solve_at_matches_full_solve(fictus::Grid3(fictus::Box3{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}}, 33), 1.0, threads);
    expect_solve_at_matches_full_solve(fictus::Grid3(fictus::Box3{{0.0, 0.0, 0.0}, {1.0, 2.0, 2.0}}, 12), 2.0, threads);
  }
}
