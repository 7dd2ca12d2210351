// B_γ, C_γ and B_Γ reproduce what they must; the kink correction undoes a kink of known strength.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <set>

#include "fictus/boundary/collocation.hpp"
#include "fictus/boundary/kink_correction.hpp"
#include "fictus/boundary/shapes.hpp"
#include "fictus/boundary/trace_operators.hpp"

namespace {

constexpr double pi = std::numbers::pi;

struct EllipseFixture {
  fictus::Grid2 grid{fictus::Box2{}, 64};
  std::shared_ptr<fictus::Ellipse> gamma = std::make_shared<fictus::Ellipse>(fictus::Point2{0.5, 0.5}, 0.4, 0.2, 0.2);
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

/// Largest error of rows R applied to u against the exact n·∇u at the points.
double max_normal_derivative_error(const EllipseFixture& s, const fictus::SparseRows& C,
                                   const std::function<double(double, double)>& u,
                                   const std::function<fictus::Point2(double, double)>& grad) {
  std::vector<double> values;
  C.multiply(s.sample(u), values);
  double error = 0.0;
  for (int i = 0; i < s.points.m; ++i) {
    const fictus::Point2 p = s.points.point[i], g = grad(p.x, p.y);
    error = std::max(error, std::abs(values[i] - fictus::dot(s.points.normal[i], g)));
  }
  return error;
}

TEST(TraceOperators, CenteredRowsReproducePolynomialsOfTheirDegree) {
  const EllipseFixture s;
  // Biquadratic rows are exact on x²y², bicubic rows on x³y³ (tensor-product interpolation).
  auto quadratic = [](double x, double y) { return 1 + x - 2 * y + 3 * x * x * y * y - x * y; };
  auto quadratic_grad = [](double x, double y) {
    return fictus::Point2{1 + 6 * x * y * y - y, -2 + 6 * x * x * y - x};
  };
  auto cubic = [](double x, double y) { return x * x * x * y * y * y - 2 * x * x * y; };
  auto cubic_grad = [](double x, double y) {
    return fictus::Point2{3 * x * x * y * y * y - 4 * x * y, 3 * x * x * x * y * y - 2 * x * x};
  };
  const auto C2 = fictus::normal_derivative_rows_centered(s.grid, s.points.point, s.points.normal, 2);
  const auto C3 = fictus::normal_derivative_rows_centered(s.grid, s.points.point, s.points.normal, 3);
  EXPECT_LT(max_normal_derivative_error(s, C2, quadratic, quadratic_grad), 1e-11);
  EXPECT_LT(max_normal_derivative_error(s, C3, cubic, cubic_grad), 1e-11);
  for (std::size_t r = 0; r < 4; ++r) EXPECT_EQ(C2.row_begin[r + 1] - C2.row_begin[r], 9u);
}

TEST(TraceOperators, CenteredRowsAreSecondOrderWhereTheShiftedOnesAreNot) {
  auto u = [](double x, double y) { return std::sin(2 * x + 1) * std::cos(3 * y) + x * x * y; };
  auto grad = [](double x, double y) {
    return fictus::Point2{2 * std::cos(2 * x + 1) * std::cos(3 * y) + 2 * x * y,
                          -3 * std::sin(2 * x + 1) * std::sin(3 * y) + x * x};
  };
  double centered[2], shifted[2];
  for (int k = 0; k < 2; ++k) {
    EllipseFixture s;
    s.grid = fictus::Grid2(fictus::Box2{}, 128 << k);
    centered[k] = max_normal_derivative_error(
        s, fictus::normal_derivative_rows_centered(s.grid, s.points.point, s.points.normal, 2), u, grad);
    shifted[k] = max_normal_derivative_error(
        s, fictus::normal_derivative_rows(s.grid, s.points.point, s.points.normal, s.grid.h()), u, grad);
  }
  EXPECT_NEAR(std::log2(centered[0] / centered[1]), 2.0, 0.3);  // O(h²)
  EXPECT_NEAR(std::log2(shifted[0] / shifted[1]), 1.0, 0.3);    // O(h): ∂u/∂n one cell inside
}

TEST(TraceOperators, OneSidedRowsUseNodesOfOmegaOnlyAndReproduceQuadratics) {
  const EllipseFixture s;
  const fictus::CurveGridIntersection geometry(*s.gamma, s.grid);
  const auto D =
      fictus::one_sided_rows(geometry, s.points.point, s.points.normal, fictus::OneSidedTrace::normal_derivative, 2);
  const auto V = fictus::one_sided_rows(geometry, s.points.point, s.points.normal, fictus::OneSidedTrace::value, 2);
  for (const auto& e : D.entries) EXPECT_TRUE(geometry.node_inside(e.i, e.j));
  // Outside ω the values are arbitrary (here: a kink); inside they are a quadratic.
  auto q = [](double x, double y) { return 1 + x - 2 * y + 3 * x * x - x * y + 0.5 * y * y; };
  fictus::GridVector u = s.sample(q);
  for (int j = 1; j < s.grid.ny(); ++j)
    for (int i = 1; i < s.grid.nx(); ++i)
      if (!geometry.node_inside(i, j)) u[s.grid.index(i, j)] += 7.0;
  std::vector<double> derivative, value;
  D.multiply(u, derivative);
  V.multiply(u, value);
  for (int i = 0; i < s.points.m; ++i) {
    const fictus::Point2 p = s.points.point[i], n = s.points.normal[i];
    EXPECT_NEAR(value[i], q(p.x, p.y), 1e-10);
    EXPECT_NEAR(derivative[i], n.x * (1 + 6 * p.x - p.y) + n.y * (-2 - p.x + p.y), 1e-9);
  }
  // The independent check's cubic fit reproduces cubics.
  const auto D3 =
      fictus::one_sided_rows(geometry, s.points.point, s.points.normal, fictus::OneSidedTrace::normal_derivative,
                             fictus::check_fit_degree, fictus::check_fit_radius);
  for (const auto& e : D3.entries) EXPECT_TRUE(geometry.node_inside(e.i, e.j));
  auto c = [](double x, double y) { return 1 + x - 2 * y + 3 * x * x * x - 2 * x * x * y + 0.5 * y * y * y; };
  fictus::GridVector v = s.sample(c);
  for (int j = 1; j < s.grid.ny(); ++j)
    for (int i = 1; i < s.grid.nx(); ++i)
      if (!geometry.node_inside(i, j)) v[s.grid.index(i, j)] -= 5.0;
  D3.multiply(v, derivative);
  for (int i = 0; i < s.points.m; ++i) {
    const fictus::Point2 p = s.points.point[i], n = s.points.normal[i];
    EXPECT_NEAR(derivative[i], n.x * (1 + 9 * p.x * p.x - 4 * p.x * p.y) + n.y * (-2 - 2 * p.x * p.x + 1.5 * p.y * p.y),
                1e-8);
  }
}

TEST(KinkCorrection, TracesOfAKinkedFieldAreThoseOfItsSmoothPart) {
  // û = w − λψ with ψ = q(d)⁺ the kink of strength λ on γ (λ the same on every arc): the corrected
  // rows R û + Dλ give the traces of the smooth w, to the order of R.
  EllipseFixture s;
  s.grid = fictus::Grid2(fictus::Box2{}, 256);
  const fictus::CurveGridIntersection geometry(*s.gamma, s.grid);
  const fictus::KinkCorrection kink(geometry, s.points, 1.0);
  auto w = [](double x, double y) { return std::cos(3 * x - y) + x * y; };
  auto grad_w = [](double x, double y) {
    return fictus::Point2{-3 * std::sin(3 * x - y) + y, std::sin(3 * x - y) + x};
  };
  const double lambda = 2.5;
  std::vector<double> lambdas(s.points.m, lambda);
  // I_h(w − λψ): start from I_h w, subtract λψ at the nodes of the band (add_kinks adds +λψ).
  fictus::GridVector kinked = s.sample(w), zero(kinked.size(), 0.0);
  kink.add_kinks(lambdas, zero);
  for (std::size_t k = 0; k < kinked.size(); ++k) kinked[k] -= zero[k];
  const auto B = fictus::point_value_rows(s.grid, s.points.point);
  const auto C = fictus::normal_derivative_rows_centered(s.grid, s.points.point, s.points.normal, 2);
  const Eigen::VectorXd l = Eigen::VectorXd::Constant(s.points.m, lambda);
  const Eigen::VectorXd dB = kink.direct(B) * l, dC = kink.direct(C) * l;
  std::vector<double> trace, derivative, raw;
  B.multiply(kinked, trace);
  C.multiply(kinked, derivative);
  double raw_error = 0.0;
  for (int i = 0; i < s.points.m; ++i) {
    const fictus::Point2 p = s.points.point[i];
    EXPECT_NEAR(trace[i] + dB(i), w(p.x, p.y), 2e-5);  // O(h²) of the bilinear interpolant
    EXPECT_NEAR(derivative[i] + dC(i), fictus::dot(s.points.normal[i], grad_w(p.x, p.y)), 2e-3);
    raw_error = std::max(raw_error, std::abs(derivative[i] - fictus::dot(s.points.normal[i], grad_w(p.x, p.y))));
  }
  EXPECT_GT(raw_error, 0.1);  // without D the centered stencil straddles the kink
}

TEST(KinkCorrection, GalerkinRowsLiveOnTheCutCellsAndCarryNoMassWhenCIsZero) {
  // r_j = a(ψ_j − I_hψ_j, φ): with c = 0 the constant test function gives Σ_k r_j,k = 0.
  const EllipseFixture s;
  const fictus::CurveGridIntersection geometry(*s.gamma, s.grid);
  const fictus::KinkCorrection kink(geometry, s.points, 0.0);
  const fictus::SparseRows& R = kink.galerkin();
  ASSERT_EQ(R.n_rows(), s.points.m);
  double scale = 0.0;
  for (const auto& e : R.entries) scale = std::max(scale, std::abs(e.value));
  EXPECT_GT(scale, 1e-4);
  for (int r = 0; r < R.n_rows(); ++r) {
    double sum = 0.0;
    for (std::size_t k = R.row_begin[r]; k < R.row_begin[r + 1]; ++k) sum += R.entries[k].value;
    EXPECT_NEAR(sum, 0.0, 1e-12 * scale * 64) << "arc " << r;
  }
  // Every node of R belongs to a cut cell.
  std::set<std::pair<int, int>> cut_nodes;
  for (const auto& cell : geometry.cut_cells())
    for (int k = 0; k < 4; ++k) cut_nodes.insert({cell.ix + (k & 1), cell.iy + (k >> 1)});
  for (const auto& e : R.entries) EXPECT_TRUE(cut_nodes.count({e.i, e.j}));
}

TEST(KinkCorrection, KinkValuesOfAPolygonFollowTheDistanceToEdgesAndCorners) {
  // ψ = q(d)⁺ with q(d) = d on straight edges: outside a convex corner d is the distance to the
  // vertex, beside an edge the distance to its line (the projection must not flip between edges).
  const fictus::Grid2 grid(fictus::Box2{}, 64);
  const auto square = std::make_shared<fictus::PolygonCurve>(
      std::vector<fictus::Point2>{{0.3, 0.3}, {0.7, 0.32}, {0.68, 0.7}, {0.31, 0.69}});
  const fictus::ArcLengthTable arc(*square);
  const fictus::Collocation points =
      fictus::make_collocation(*square, arc, 24, fictus::phase_off_corners(*square, arc, 24));
  const fictus::CurveGridIntersection geometry(*square, grid);
  const fictus::KinkCorrection kink(geometry, points, 1.0);
  fictus::GridVector psi(grid.n_unknowns(), 0.0);
  kink.add_kinks(std::vector<double>(points.m, 1.0), psi);
  const auto& v = square->vertices();
  auto segment_distance = [](fictus::Point2 p, fictus::Point2 a, fictus::Point2 b) {
    const fictus::Point2 e = b - a;
    const double t = std::clamp(fictus::dot(p - a, e) / fictus::dot(e, e), 0.0, 1.0);
    return fictus::norm(p - (a + t * e));
  };
  int checked = 0;
  for (int j = 1; j < grid.ny(); ++j)
    for (int i = 1; i < grid.nx(); ++i) {
      const fictus::Point2 x{grid.x(i), grid.y(j)};
      if (geometry.node_inside(i, j)) {
        EXPECT_EQ(psi[grid.index(i, j)], 0.0);
        continue;
      }
      double d = 1e300;
      for (std::size_t k = 0; k < v.size(); ++k) d = std::min(d, segment_distance(x, v[k], v[(k + 1) % v.size()]));
      if (d > 2.5 * grid.h()) continue;  // outside the band
      EXPECT_NEAR(psi[grid.index(i, j)], d, 1e-12) << "node (" << i << ", " << j << ")";
      ++checked;
    }
  EXPECT_GT(checked, 100);
}

}  // namespace
