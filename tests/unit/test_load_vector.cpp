// The load vector F_k = ∫_Ω f φ_k against exact integrals: with q = 2 Gauss points per direction
// the rule is exact for f of degree ≤ 2 in each variable (f·φ_k has degree ≤ 3).
#include <gtest/gtest.h>

#include <cmath>

#include "fictus/grid/load_vector.hpp"

namespace {

/// ∫ x^a φ(x) dx for the 1-D hat of node c with half-width h, a = 0, 1, 2 (clipped at a Dirichlet
/// box's ends, where the hat is not an unknown anyway).
double hat_moment(int a, double c, double h) {
  if (a == 0) return h;
  if (a == 1) return c * h;
  return h * (c * c + h * h / 6.0);
}

TEST(LoadVector, ExactForQuadraticData) {
  // f = 1 + 2x − 3y² + x²y (degree ≤ 2 per variable), on a box that is not the unit square.
  const fictus::Grid2 grid(fictus::Box2{{-0.5, 0.25}, {1.5, 1.25}}, 16);
  const auto f = [](double x, double y) { return 1 + 2 * x - 3 * y * y + x * x * y; };
  const fictus::GridVector load = fictus::assemble_load(grid, f, 2);
  const double h = grid.h();
  double max_error = 0, max_value = 0;
  for (int j = 1; j < grid.ny(); ++j)
    for (int i = 1; i < grid.nx(); ++i) {
      const double x = grid.x(i), y = grid.y(j);
      auto m = [&](int a, int b) { return hat_moment(a, x, h) * hat_moment(b, y, h); };
      const double exact = m(0, 0) + 2 * m(1, 0) - 3 * m(0, 2) + m(2, 1);
      max_error = std::max(max_error, std::abs(load[grid.index(i, j)] - exact));
      max_value = std::max(max_value, std::abs(exact));
    }
  EXPECT_LE(max_error / max_value, 1e-13);  // exact up to round-off
}

TEST(LoadVector, PeriodicBoxSumsTheIntegral) {
  // Periodic: the hats of a node and its images are one unknown; Σ_k F_k = ∫_Ω f (partition of unity).
  const fictus::Grid2 grid(fictus::Box2{}, 32, fictus::Boundary::periodic);
  const auto f = [](double x, double y) { return 2 + x * y + y * y; };
  const fictus::GridVector load = fictus::assemble_load(grid, f, 2);
  double total = 0;
  for (double v : load) total += v;
  EXPECT_NEAR(total, 2 + 0.25 + 1.0 / 3.0, 1e-13);
}

TEST(LoadVector, HigherOrderRuleIsExactForHigherDegree) {
  // q = 3 is exact for degree ≤ 4 in each variable: f = x⁴ − y³ + 1 needs it (q = 2 is not exact).
  const fictus::Grid2 grid(fictus::Box2{}, 8);
  const auto f = [](double x, double y) { return std::pow(x, 4) - y * y * y + 1; };
  const double h = grid.h();
  auto exact_at = [&](int i, int j) {
    // ∫ x⁴ hat = h(c⁴ + c²h² + h⁴/15), ∫ y³ hat = h(c³ + c h²/2)
    const double x = grid.x(i), y = grid.y(j);
    return h * (x * x * x * x + x * x * h * h + h * h * h * h / 15) * h - h * h * (y * y * y + y * h * h / 2) + h * h;
  };
  double error3 = 0, error2 = 0;
  const fictus::GridVector load3 = fictus::assemble_load(grid, f, 3), load2 = fictus::assemble_load(grid, f, 2);
  for (int j = 1; j < grid.ny(); ++j)
    for (int i = 1; i < grid.nx(); ++i) {
      error3 = std::max(error3, std::abs(load3[grid.index(i, j)] - exact_at(i, j)));
      error2 = std::max(error2, std::abs(load2[grid.index(i, j)] - exact_at(i, j)));
    }
  EXPECT_LE(error3, 1e-15);
  EXPECT_GT(error2, 1e-8);  // the test sees the difference
}

}  // namespace
