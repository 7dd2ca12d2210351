// Shapes and their checks: simple polygons of every kind pass check_simple, curves that meet
// themselves do not.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "fictus/boundary/shapes.hpp"

namespace {

using fictus::Point2;
constexpr double pi = std::numbers::pi;

std::vector<Point2> regular_polygon(int n, Point2 center, double radius, double angle) {
  std::vector<Point2> v;
  for (int k = 0; k < n; ++k) {
    const double t = angle + 2 * pi * k / n;
    v.push_back({center.x + radius * std::cos(t), center.y + radius * std::sin(t)});
  }
  return v;
}

std::vector<Point2> rectangle(double x0, double y0, double x1, double y1) {
  return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
}

/// check_simple of the polygon, of its TransformedCurve and of its reversal; the message if one throws.
std::string refusal(const std::vector<Point2>& vertices) {
  try {
    auto polygon = std::make_shared<fictus::PolygonCurve>(vertices);
    fictus::check_simple(*polygon, "geometry.vertices");
    fictus::check_simple(fictus::TransformedCurve(polygon, 0.3, {0.01, -0.02}), "geometry.vertices");
    fictus::check_simple(fictus::ReversedCurve(polygon), "geometry.vertices");
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

// Regular n-gons for every n = 3 … 1000 (a corner at every arc-length fraction j/n, among them
// the fractions j/4096 of the samples the old check merged with the corners), at two sizes and turns.
TEST(CheckSimple, EveryRegularPolygonFrom3To1000Passes) {
  for (int n = 3; n <= 1000; ++n)
    for (const auto& [radius, angle] : {std::pair{0.2, 0.0}, std::pair{0.37, 0.1234}}) {
      const std::string why = refusal(regular_polygon(n, {0.5, 0.5}, radius, angle));
      ASSERT_EQ(why, "") << "n = " << n << ", radius " << radius << ", angle " << angle;
    }
}

TEST(CheckSimple, SquaresAndRectanglesAtManyPositionsAndSizesPass) {
  int checked = 0;
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 20; ++j)
      for (double width : {0.1, 0.2, 0.3, 0.4, 0.41, 0.5}) {
        const double x0 = 0.02 + 0.023 * i, y0 = 0.03 + 0.021 * j;
        ASSERT_EQ(refusal(rectangle(x0, y0, x0 + width, y0 + width)), "") << x0 << " " << y0 << " " << width;
        ASSERT_EQ(refusal(rectangle(x0, y0, x0 + width, y0 + 0.37 * width)), "") << x0 << " " << y0 << " " << width;
        checked += 2;
      }
  EXPECT_EQ(checked, 4800);
  // The squares a new user tries first.
  for (double a : {0.1, 0.2, 0.25, 0.3, 0.35, 0.4}) EXPECT_EQ(refusal(rectangle(a, a, 1 - a, 1 - a)), "") << a;
}

TEST(CheckSimple, NonConvexOutlinesPass) {
  const std::vector<std::vector<Point2>> shapes = {
      // a C
      {{0.2, 0.2}, {0.8, 0.2}, {0.8, 0.35}, {0.35, 0.35}, {0.35, 0.65}, {0.8, 0.65}, {0.8, 0.8}, {0.2, 0.8}},
      // a 12-vertex cross
      {{0.4, 0.2},
       {0.6, 0.2},
       {0.6, 0.4},
       {0.8, 0.4},
       {0.8, 0.6},
       {0.6, 0.6},
       {0.6, 0.8},
       {0.4, 0.8},
       {0.4, 0.6},
       {0.2, 0.6},
       {0.2, 0.4},
       {0.4, 0.4}},
      // a square with mid-edge vertices (collinear neighbours)
      {{0.3, 0.3}, {0.5, 0.3}, {0.7, 0.3}, {0.7, 0.5}, {0.7, 0.7}, {0.5, 0.7}, {0.3, 0.7}, {0.3, 0.5}},
      // a comb with narrow slots
      {{0.1, 0.1},
       {0.9, 0.1},
       {0.9, 0.9},
       {0.8, 0.9},
       {0.8, 0.3},
       {0.7, 0.3},
       {0.7, 0.9},
       {0.6, 0.9},
       {0.6, 0.3},
       {0.5, 0.3},
       {0.5, 0.9},
       {0.1, 0.9}},
  };
  for (std::size_t k = 0; k < shapes.size(); ++k) EXPECT_EQ(refusal(shapes[k]), "") << "shape " << k;
  // A 5-pointed star (non-convex, simple) and a sampled outline of 4096 points (an ellipse).
  std::vector<Point2> star;
  for (int k = 0; k < 10; ++k) {
    const double r = k % 2 ? 0.12 : 0.3, t = pi / 2 + pi * k / 5;
    star.push_back({0.5 + r * std::cos(t), 0.5 + r * std::sin(t)});
  }
  EXPECT_EQ(refusal(star), "");
  std::vector<Point2> outline;
  for (int k = 0; k < 4096; ++k)
    outline.push_back({0.5 + 0.35 * std::cos(2 * pi * k / 4096), 0.5 + 0.15 * std::sin(2 * pi * k / 4096)});
  EXPECT_EQ(refusal(outline), "");
}

TEST(CheckSimple, PolygonsThatMeetThemselvesAreRefused) {
  const std::vector<std::vector<Point2>> bad = {
      {{0.3, 0.3}, {0.7, 0.7}, {0.7, 0.3}, {0.3, 0.7}},                                      // a bow tie
      {{0.3, 0.3}, {0.7, 0.3}, {0.7, 0.7}, {0.5, 0.3}, {0.3, 0.7}},                          // a vertex on an edge
      {{0.3, 0.3}, {0.7, 0.3}, {0.7, 0.5}, {0.9, 0.5}, {0.7, 0.5}, {0.7, 0.7}, {0.3, 0.7}},  // a spike: folds back
      {{0.3, 0.3}, {0.7, 0.3}, {0.5, 0.3}, {0.5, 0.7}},                          // folds back on its first edge
      {{0.3, 0.3}, {0.5, 0.5}, {0.7, 0.3}, {0.7, 0.7}, {0.5, 0.5}, {0.3, 0.7}},  // pinched at a vertex
  };
  for (std::size_t k = 0; k < bad.size(); ++k)
    EXPECT_NE(refusal(bad[k]).find("geometry.vertices: the curve intersects or touches itself"), std::string::npos)
        << "shape " << k << ": " << refusal(bad[k]);
  // Edges of a narrow slot 1e-13 apart (of an extent of 0.6) touch.
  EXPECT_NE(refusal({{0.2, 0.2},
                     {0.8, 0.2},
                     {0.8, 0.8},
                     {0.5 + 1e-13, 0.8},
                     {0.5 + 1e-13, 0.3},
                     {0.5, 0.3},
                     {0.5, 0.8},
                     {0.2, 0.8}}),
            "");
}

/// A curve with corners at given parameters (a square traced in t), checked by samples.
class SampledSquare final : public fictus::Curve {
 public:
  explicit SampledSquare(double first_corner) : first_(first_corner) {}
  Point2 position(double t) const override {
    t = std::fmod(t - first_ + 4 * pi, 2 * pi);  // t − first corner in [0, 2π)
    const int side = std::min(3, int(t / (pi / 2)));
    const double w = (t - side * pi / 2) / (pi / 2);
    const Point2 corner[5] = {{0.3, 0.3}, {0.7, 0.3}, {0.7, 0.7}, {0.3, 0.7}, {0.3, 0.3}};
    return corner[side] + w * (corner[side + 1] - corner[side]);
  }
  Point2 derivative(double) const override { return {0, 0}; }
  Point2 second_derivative(double) const override { return {0, 0}; }
  Point2 center() const override { return {0.5, 0.5}; }
  std::vector<double> corners() const override {
    std::vector<double> t;
    for (int k = 0; k < 4; ++k) t.push_back(std::fmod(first_ + k * pi / 2, 2 * pi));
    std::sort(t.begin(), t.end());
    return t;
  }
  bool smooth() const override { return false; }

 private:
  double first_;
};

// A curve that is not a polygon is checked by samples: corners one rounding step from a sample
// (and exactly on one) leave no sub-tolerance pieces.
TEST(CheckSimple, CornersBesideSamplesLeaveNoTinyPieces) {
  for (int j : {0, 1, 512, 1024, 1025, 2047}) {
    const double at = 2 * pi * j / 4096;
    for (double corner :
         {at, std::nextafter(at, 10.0), std::nextafter(std::nextafter(at, 10.0), 10.0), std::nextafter(at + 1e-3, 0.0)})
      EXPECT_NO_THROW(fictus::check_simple(SampledSquare(corner), "geometry")) << "corner at t = " << corner;
  }
}

}  // namespace
