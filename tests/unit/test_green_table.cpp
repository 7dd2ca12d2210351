// G from the Green's table against columns of A⁻¹ computed with the DST solver.
#include <gtest/gtest.h>

#include "fictus/dst_solver.hpp"
#include "fictus/green_table.hpp"

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
        max_diff = std::max(max_diff, std::abs(green.G(i, j, col[0], col[1]) - ref));
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

}  // namespace
