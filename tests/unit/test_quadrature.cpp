// Quadrature over ω and along γ that follows the true curve in cut cells.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "fictus/boundary/curve_grid_intersection.hpp"
#include "fictus/boundary/shapes.hpp"

namespace {

constexpr double pi = std::numbers::pi;

struct Case {
  int N;
  double angle;
};

class DomainQuadrature : public ::testing::TestWithParam<Case> {};

TEST_P(DomainQuadrature, AreaMomentsAndPerimeterOfEllipse) {
  const auto [N, angle] = GetParam();
  const double a = 0.4, b = 0.2, cx = 0.5, cy = 0.47;
  const fictus::Ellipse e({cx, cy}, a, b, angle);
  const fictus::Grid2 grid(fictus::Box2{}, N);
  const fictus::CurveGridIntersection geometry(e, grid);
  const auto moments = fictus::integrate_over_domain<3>(geometry, 4, [&](int, int, double x, double y) {
    return std::array<double, 3>{1.0, x, (x - cx) * (x - cx) + (y - cy) * (y - cy)};
  });
  const double area = pi * a * b;
  EXPECT_NEAR(moments[0] / area, 1.0, 1e-12);
  EXPECT_NEAR(moments[1] / (area * cx), 1.0, 1e-12);
  EXPECT_NEAR(moments[2] / (area * (a * a + b * b) / 4), 1.0, 1e-12);  // polar moment, any rotation

  const auto length = fictus::integrate_along_curve<1>(
      geometry, 6, [](int, int, double, fictus::Point2) { return std::array<double, 1>{1.0}; });
  EXPECT_NEAR(length[0], 4 * a * std::comp_ellint_2(std::sqrt(1 - b * b / (a * a))), 1e-12);
}

INSTANTIATE_TEST_SUITE_P(Grids, DomainQuadrature,
                         ::testing::Values(Case{16, 0.0}, Case{64, 0.0}, Case{128, 0.0}, Case{50, 0.7},
                                           Case{256, 2.1}));

TEST(CurveGridIntersection, KeptCutCellRulesGiveTheRulesMadeAfresh) {
  // row_rule keeps each row's cut-cell rules per q once made (in parallel, 2 threads): later calls, and
  // calls for another q in between, give the points a fresh intersection makes, bit for bit.
  const fictus::Ellipse e({0.5, 0.47}, 0.4, 0.2, 0.7);
  const fictus::Grid2 grid(fictus::Box2{}, 96);
  const fictus::CurveGridIntersection kept(e, grid);
  const fictus::Execution two(2);
  const auto f = [](int, int, double x, double y) { return std::array<double, 2>{1.0, std::sin(3 * x) * y}; };
  const auto first = fictus::integrate_over_domain<2>(kept, 2, f, two);
  const auto other_q = fictus::integrate_over_domain<2>(kept, 3, f, two);
  for (int round = 0; round < 2; ++round) {
    const fictus::CurveGridIntersection fresh(e, grid);
    for (int iy = 0; iy < grid.ny(); ++iy) {
      std::vector<fictus::CellQuadraturePoint> a, b;
      kept.row_rule(iy, round == 0 ? 2 : 3, a);
      fresh.row_rule(iy, round == 0 ? 2 : 3, b);
      ASSERT_EQ(a.size(), b.size()) << iy;
      for (std::size_t k = 0; k < a.size(); ++k) {
        EXPECT_EQ(a[k].ix, b[k].ix);
        EXPECT_EQ(a[k].x, b[k].x);
        EXPECT_EQ(a[k].y, b[k].y);
        EXPECT_EQ(a[k].weight, b[k].weight);
      }
    }
  }
  EXPECT_NEAR(first[0], other_q[0], 1e-12);  // the area, by both rules
  EXPECT_NEAR(first[0], std::numbers::pi * 0.4 * 0.2, 1e-12);
}

TEST(CurveGridIntersection, InsideTestMatchesEllipseEquation) {
  const fictus::Ellipse e({0.5, 0.5}, 0.4, 0.2, 0.4);
  const fictus::Grid2 grid(fictus::Box2{}, 64);
  const fictus::CurveGridIntersection geometry(e, grid);
  int mismatches = 0;
  for (int j = 0; j <= 64; ++j)
    for (int i = 0; i <= 64; ++i) {
      const double X = grid.x(i) - 0.5, Y = grid.y(j) - 0.5;
      const double u = std::cos(0.4) * X + std::sin(0.4) * Y, v = -std::sin(0.4) * X + std::cos(0.4) * Y;
      mismatches += geometry.node_inside(i, j) != (u * u / 0.16 + v * v / 0.04 < 1);
    }
  EXPECT_EQ(mismatches, 0);
}

TEST(CurveGridIntersection, CurveStartingOnAGridLineKeepsTheParityOfThatRow) {
  // The paper's ellipse starts at (0.9, 0.5), on grid row y = ½ for every even N.
  const fictus::Ellipse e({0.5, 0.5}, 0.4, 0.2);
  const fictus::Grid2 grid(fictus::Box2{}, 128);
  const fictus::CurveGridIntersection geometry(e, grid);
  for (int i = 0; i <= 128; ++i) {
    const double x = grid.x(i);
    EXPECT_EQ(geometry.node_inside(i, 64), x > 0.1 && x < 0.9) << "x = " << x;
  }
}

TEST(CurveGridIntersection, CurveThroughAGridNodeKeepsTheCellsBesideIt) {
  // r = 0.3 + 0.05·cos 5t about (½, ½) passes through the node (¼, ½) of every grid with N divisible by 4
  // (t = π), its tangent along the column x = ¼ there: the cells right of that node have three corners
  // inside ω and the fourth on γ, which the crossing parity counts as outside. A rule taking only cells
  // with four corners inside would miss a whole cell beside that node.
  const fictus::StarCurve star({0.5, 0.5}, [](double t) { return 0.3 + 0.05 * std::cos(5 * t); });
  const double area = pi * (0.09 + 0.05 * 0.05 / 2);
  for (int N : {256, 512, 1024}) {
    const fictus::Grid2 grid(fictus::Box2{}, N);
    const fictus::CurveGridIntersection geometry(star, grid);
    const auto moments = fictus::integrate_over_domain<3>(geometry, 2, [](int, int, double x, double y) {
      return std::array<double, 3>{1.0, x, y};
    });
    EXPECT_NEAR(moments[0] / area, 1.0, 1e-12) << "N = " << N;
    EXPECT_NEAR(moments[1] / (0.5 * area), 1.0, 1e-12) << "N = " << N;  // the centroid is the centre
    EXPECT_NEAR(moments[2] / (0.5 * area), 1.0, 1e-12) << "N = " << N;
  }
}

TEST(CurveGridIntersection, PolygonsThroughGridNodesKeepTheirArea) {
  // A triangle whose edge of slope −1 runs through grid nodes (each node on it leaves a cell above and
  // right of it, inside ω and uncut, with its lower-left corner on γ), and an L whose edges lie on grid
  // lines (a concave corner on a node): their areas to round-off.
  const fictus::PolygonCurve triangle({{0.25, 0.5}, {0.5, 0.25}, {0.75, 0.75}});
  const fictus::PolygonCurve l_shape({{0.25, 0.25}, {0.75, 0.25}, {0.75, 0.5}, {0.5, 0.5}, {0.5, 0.75}, {0.25, 0.75}});
  for (int N : {16, 64, 256}) {
    const fictus::Grid2 grid(fictus::Box2{}, N);
    for (const auto& [polygon, area] :
         {std::pair<const fictus::Curve*, double>{&triangle, 0.09375}, {&l_shape, 0.1875}}) {
      const fictus::CurveGridIntersection geometry(*polygon, grid);
      const auto moments = fictus::integrate_over_domain<1>(
          geometry, 2, [](int, int, double, double) { return std::array<double, 1>{1.0}; });
      EXPECT_NEAR(moments[0] / area, 1.0, 1e-12) << "N = " << N << ", area " << area;
    }
  }
}

TEST(CurveGridIntersection, PolygonVerticesInsideCutCellsKeepTheArea) {
  // examples/polygon.toml's pentagon and one with no vertex on a grid line: a vertex inside a cut cell
  // kinks the length of the inside segments, and the rule splits there (without: 1e-7 relative).
  const std::vector<std::vector<fictus::Point2>> pentagons{
      {{0.25, 0.25}, {0.75, 0.3}, {0.8, 0.65}, {0.5, 0.8}, {0.2, 0.6}},
      {{0.21, 0.23}, {0.77, 0.31}, {0.83, 0.67}, {0.49, 0.81}, {0.17, 0.61}}};
  for (const auto& vertices : pentagons) {
    double area = 0;  // the shoelace formula
    for (std::size_t i = 0; i < vertices.size(); ++i) {
      const fictus::Point2 a = vertices[i], b = vertices[(i + 1) % vertices.size()];
      area += 0.5 * (a.x * b.y - b.x * a.y);
    }
    const fictus::PolygonCurve polygon(vertices);
    for (int N : {64, 256, 1024}) {
      const fictus::Grid2 grid(fictus::Box2{}, N);
      const fictus::CurveGridIntersection geometry(polygon, grid);
      const auto moments = fictus::integrate_over_domain<1>(
          geometry, 2, [](int, int, double, double) { return std::array<double, 1>{1.0}; });
      EXPECT_NEAR(moments[0] / area, 1.0, 1e-12) << "N = " << N;
    }
  }
}

TEST(CurveGridIntersection, RejectsCurveLeavingTheBox) {
  const fictus::Ellipse e({0.5, 0.5}, 0.6, 0.2);
  const fictus::Grid2 grid(fictus::Box2{}, 32);
  EXPECT_THROW(fictus::CurveGridIntersection(e, grid), std::invalid_argument);
}

}  // namespace
