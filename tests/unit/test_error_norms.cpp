// The error norms against exact integrals of polynomials on a disc: with u_h = 0 the "errors" are the
// norms of the polynomial itself, ∫_ω p², ∫_ω |∇p|², ∫_γ p², known in closed form.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <numbers>

#include "fictus/boundary/curve.hpp"
#include "fictus/boundary/curve_grid_intersection.hpp"
#include "fictus/grid/q1_element.hpp"
#include "fictus/solve/error_norms.hpp"

namespace {

constexpr double pi = std::numbers::pi;
const fictus::Point2 center{0.47, 0.52};  // off the grid's symmetry
constexpr double R = 0.3;

struct Case {
  const char* name;
  fictus::ScalarField p;
  fictus::GradientField grad;
  double l2_omega2, h1semi2, l2_gamma2;  // ∫_ω p², ∫_ω |∇p|², ∫_γ p²
};

TEST(ErrorNorms, MatchExactIntegralsOfPolynomialsOnADisc) {
  const fictus::Grid2 grid(fictus::Box2{}, 64);
  const fictus::Ellipse circle(center, R, R);
  const fictus::CurveGridIntersection geometry(circle, grid);
  const fictus::GridVector zero(grid.n_unknowns(), 0.0);
  const double cx = center.x, cy = center.y;
  const Case cases[] = {
      {"1", [](double, double) { return 1.0; },
       [](double, double) {
         return fictus::Point2{0, 0};
       },
       pi * R * R, 0.0, 2 * pi * R},
      {"x - cx", [=](double x, double) { return x - cx; },
       [](double, double) {
         return fictus::Point2{1, 0};
       },
       pi * std::pow(R, 4) / 4, pi * R * R, pi * std::pow(R, 3)},
      {"r^2", [=](double x, double y) { return (x - cx) * (x - cx) + (y - cy) * (y - cy); },
       [=](double x, double y) {
         return fictus::Point2{2 * (x - cx), 2 * (y - cy)};
       },
       pi * std::pow(R, 6) / 3, 2 * pi * std::pow(R, 4), 2 * pi * std::pow(R, 5)},
      {"(x-cx)(y-cy)", [=](double x, double y) { return (x - cx) * (y - cy); },
       [=](double x, double y) {
         return fictus::Point2{y - cy, x - cx};
       },
       pi * std::pow(R, 6) / 24, pi * std::pow(R, 4) / 2, pi * std::pow(R, 5) / 4},
  };
  for (const Case& c : cases) {
    const fictus::ErrorNorms e = fictus::compute_errors(zero, geometry, c.p, c.grad, 3);
    // The cut-cell rule is exact in the inner coordinate and Gauss with ≥ 8 points in the outer one
    // across a circular arc: 1e-10 relative is far below any discretization error it measures.
    EXPECT_NEAR(e.l2_omega * e.l2_omega, c.l2_omega2, 1e-10 * c.l2_omega2 + 1e-16) << c.name;
    EXPECT_NEAR(e.h1semi_omega * e.h1semi_omega, c.h1semi2, 1e-10 * c.h1semi2 + 1e-16) << c.name;
    EXPECT_NEAR(e.l2_gamma * e.l2_gamma, c.l2_gamma2, 1e-10 * c.l2_gamma2) << c.name;
  }
}

TEST(ErrorNorms, ZeroForTheInterpolantOfABilinearFunction) {
  // u = 1 + x + 2y − xy is Q1: its nodal interpolant is exact, so every error vanishes.
  const fictus::Grid2 grid(fictus::Box2{}, 32, fictus::Boundary::periodic);  // every node carries a value
  const fictus::Ellipse circle(center, R, R);
  const fictus::CurveGridIntersection geometry(circle, grid);
  const auto u = [](double x, double y) { return 1 + x + 2 * y - x * y; };
  fictus::GridVector u_h(grid.n_unknowns());
  for (int j = 0; j < grid.ny(); ++j)
    for (int i = 0; i < grid.nx(); ++i) u_h[grid.index(i, j)] = u(grid.x(i), grid.y(j));
  const fictus::ErrorNorms e = fictus::compute_errors(
      u_h, geometry, u,
      [](double x, double y) {
        return fictus::Point2{1 - y, 2 - x};
      },
      3);
  EXPECT_LE(e.rel_l2_omega, 1e-14);
  EXPECT_LE(e.rel_h1_omega, 1e-13);
  EXPECT_LE(e.rel_l2_gamma, 1e-14);
}

}  // namespace

TEST(Q1Element, FactorizedTrilinearSampleMatchesTheShapeFunctions) {
  // The 3-D error integrals sample û by nested linear interpolation: the same value and gradient as
  // Σ_k u_k φ_k and Σ_k u_k ∇φ_k, at corners, on faces and inside.
  const std::array<double, 8> u{0.3, -1.2, 2.5, 0.7, -0.4, 1.9, 3.1, -2.2};
  const double h = 0.125;
  for (const fictus::Point3 xi : {fictus::Point3{0, 0, 0}, fictus::Point3{1, 1, 1}, fictus::Point3{0.25, 0.5, 0.75},
                                  fictus::Point3{0.9, 0.1, 0.0}, fictus::Point3{0.33, 1.0, 0.61}}) {
    const fictus::Q1Element<3> element(xi, h);
    double value = 0;
    fictus::Point3 gradient{};
    for (int k = 0; k < 8; ++k) {
      value += u[std::size_t(k)] * element.value[std::size_t(k)];
      gradient = gradient + u[std::size_t(k)] * element.gradient(k);
    }
    const auto sample = fictus::Q1Element<3>::interpolate(u, xi, h);
    EXPECT_NEAR(sample.value, value, 1e-14);
    for (int d = 0; d < 3; ++d) EXPECT_NEAR(sample.gradient[d], gradient[d], 1e-13) << "axis " << d;
  }
}
