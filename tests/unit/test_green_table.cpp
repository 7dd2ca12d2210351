// G from the Green's table against columns of A⁻¹ computed with the DST solver.
#include <gtest/gtest.h>

#include "fictus/dst_solver.hpp"
#include "fictus/green_table.hpp"

namespace {

class GreenTableTest : public ::testing::TestWithParam<double> {};

TEST_P(GreenTableTest, MatchesColumnsOfInverse) {
  const double c = GetParam();
  const fictus::Grid grid(fictus::Box{0.0, 1.0, 0.0, 0.75}, 16);
  const fictus::DstSolver solver(grid, c);
  const fictus::GreenTable green(grid, c);
  const int columns[][2] = {{1, 1}, {8, 6}, {15, 11}, {3, 10}, {12, 2}};
  for (const auto& col : columns) {
    fictus::GridVector e(grid.n_unknowns(), 0.0);
    e[grid.index(col[0], col[1])] = 1.0;
    solver.solve_in_place(e);
    double max_abs = 0.0, max_diff = 0.0;
    for (int j = 1; j < grid.ny(); ++j)
      for (int i = 1; i < grid.nx(); ++i) {
        const double ref = e[grid.index(i, j)];
        max_abs = std::max(max_abs, std::abs(ref));
        max_diff = std::max(max_diff, std::abs(green.G(i, j, col[0], col[1]) - ref));
      }
    EXPECT_LE(max_diff / max_abs, 1e-12) << "column (" << col[0] << ", " << col[1] << ")";
  }
}

INSTANTIATE_TEST_SUITE_P(ReactionCoefficients, GreenTableTest, ::testing::Values(0.0, 1.0, 100.0));

}  // namespace
