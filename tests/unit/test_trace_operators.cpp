// B_γ, C_γ and B_Γ reproduce what they must.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "fictus/collocation.hpp"
#include "fictus/trace_operators.hpp"

namespace {

constexpr double pi = std::numbers::pi;

struct EllipseFixture {
  fictus::Grid grid{fictus::Box{}, 64};
  std::shared_ptr<fictus::Ellipse> gamma = std::make_shared<fictus::Ellipse>(fictus::Point{0.5, 0.5}, 0.4, 0.2, 0.2);
  fictus::ArcLengthTable arc{*gamma};
  fictus::Collocation points = fictus::make_collocation(*gamma, arc, 40);

  fictus::GridVector sample(const std::function<double(double, double)>& u) const {
    fictus::GridVector v(grid.n_unknowns());
    for (int j = 1; j < grid.ny(); ++j)
      for (int i = 1; i < grid.nx(); ++i) v[grid.index(i, j)] = u(grid.x(i), grid.y(j));
    return v;
  }
};

TEST(TraceOperators, PointRowsReproduceBilinearFunctions) {
  const EllipseFixture s;
  auto u = [](double x, double y) { return 1.0 + 2.0 * x - 3.0 * y + 4.0 * x * y; };
  const fictus::SparseRows B = fictus::point_value_rows(s.grid, s.points.point);
  std::vector<double> values;
  B.multiply(s.sample(u), values);
  for (int i = 0; i < s.points.m; ++i) EXPECT_NEAR(values[i], u(s.points.point[i].x, s.points.point[i].y), 1e-13);
}

TEST(TraceOperators, NormalDerivativeRowsReproduceLinearFunctions) {
  const EllipseFixture s;
  auto u = [](double x, double y) { return 0.3 + 2.0 * x - 3.0 * y; };
  for (double shift : {0.0, 1.0, 1.5}) {
    const fictus::SparseRows C =
        fictus::normal_derivative_rows(s.grid, s.points.point, s.points.normal, shift * s.grid.h());
    std::vector<double> values;
    C.multiply(s.sample(u), values);
    for (int i = 0; i < s.points.m; ++i)
      EXPECT_NEAR(values[i], 2.0 * s.points.normal[i].x - 3.0 * s.points.normal[i].y, 1e-11);
  }
}

TEST(TraceOperators, ArcRowsSumToArcLength) {
  const EllipseFixture s;
  const fictus::CurveGridIntersection geometry(*s.gamma, s.grid);
  const fictus::SparseRows B = fictus::arc_integral_rows(geometry, s.points.arc_begin, s.points.arc_end);
  std::vector<double> sums;
  B.multiply(s.sample([](double, double) { return 1.0; }), sums);
  for (int i = 0; i < s.points.m; ++i) EXPECT_NEAR(sums[i], s.points.spacing, 1e-13);

  // Offset curve: arcs are images of γ's arcs; their lengths add up to L + 2πδ.
  const double delta = s.points.spacing;
  const fictus::OffsetCurve Gamma(s.gamma, delta);
  const fictus::CurveGridIntersection offset(Gamma, s.grid);
  const fictus::SparseRows BG = fictus::arc_integral_rows(offset, s.points.arc_begin, s.points.arc_end);
  BG.multiply(s.sample([](double, double) { return 1.0; }), sums);
  double total = 0.0;
  for (double v : sums) total += v;
  EXPECT_NEAR(total, s.points.length + 2 * pi * delta, 1e-12);
}

TEST(TraceOperators, ArcRowsIntegrateQ1FunctionsExactly) {
  // Against a brute-force reference: 20000-panel Gauss along each arc of the Q1 interpolant.
  const EllipseFixture s;
  const fictus::CurveGridIntersection geometry(*s.gamma, s.grid);
  const fictus::SparseRows B = fictus::arc_integral_rows(geometry, s.points.arc_begin, s.points.arc_end);
  const fictus::GridVector u = s.sample([](double x, double y) { return std::sin(5 * x) * std::cos(3 * y); });
  std::vector<double> values;
  B.multiply(u, values);
  for (int i : {0, 7, 21}) {
    const double t0 = s.points.arc_begin[i], t1 = s.points.arc_end[i];
    const int panels = 20000;
    double ref = 0.0;
    for (int k = 0; k < panels; ++k) {
      const double t = t0 + (k + 0.5) * (t1 - t0) / panels;  // midpoint rule, error O(panels⁻²)
      ref += fictus::evaluate_q1(s.grid, u, s.gamma->position(t)) * s.gamma->speed(t) * (t1 - t0) / panels;
    }
    EXPECT_NEAR(values[i], ref, 1e-8);
  }
}

}  // namespace
