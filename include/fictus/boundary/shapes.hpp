#pragma once
// Curves a user can describe (besides Ellipse in curve.hpp), and the checks every user curve gets.
//   PolygonCurve      vertices, parametrized proportionally to arc length, corners reported;
//   ParametricCurve   x(t), y(t) expressions, t ∈ [0, 2π);
//   StarCurve         center + r(t)·(cos t, sin t), r(t) an expression;
//   ReversedCurve     a clockwise curve made counter-clockwise (t ↦ 2π − t).
// Expression curves take derivatives by central differences (errors ~1e-10 in p′, ~1e-8 in p″).
#include <memory>
#include <string>
#include <vector>

#include <functional>
#include "fictus/boundary/curve.hpp"

namespace fictus {

class PolygonCurve final : public Curve {
 public:
  /// At least 3 vertices, no repeated consecutive vertices (the closing edge is implied).
  explicit PolygonCurve(std::vector<Point2> vertices);
  Point2 position(double t) const override;
  Point2 derivative(double t) const override;
  Point2 second_derivative(double) const override { return {0.0, 0.0}; }
  Point2 center() const override { return centroid_; }
  std::vector<double> corners() const override;
  bool smooth() const override { return false; }
  std::vector<Point2> polygon_vertices() const override { return vertices_; }
  const std::vector<Point2>& vertices() const { return vertices_; }

 private:
  int edge_of(double t) const;
  std::vector<Point2> vertices_;
  std::vector<double> cumulative_;  // arc length at each vertex, size n + 1
  Point2 centroid_;
};

/// Base for curves given by expressions: derivatives by central differences of position().
class ExpressionCurve : public Curve {
 public:
  Point2 derivative(double t) const override;
  Point2 second_derivative(double t) const override;
};

class ParametricCurve final : public ExpressionCurve {
 public:
  ParametricCurve(std::function<double(double)> x, std::function<double(double)> y);
  Point2 position(double t) const override;
  Point2 center() const override { return center_; }

 private:
  std::function<double(double)> x_, y_;
  Point2 center_;
};

class StarCurve final : public ExpressionCurve {
 public:
  /// r(t) > 0 and finite (checked on samples; throws naming geometry.r).
  StarCurve(Point2 center, std::function<double(double)> r);
  Point2 position(double t) const override;
  Point2 center() const override { return center_; }

 private:
  Point2 center_;
  std::function<double(double)> r_;
};

class ReversedCurve final : public Curve {
 public:
  explicit ReversedCurve(std::shared_ptr<const Curve> base) : base_(std::move(base)) {}
  Point2 position(double t) const override;
  Point2 derivative(double t) const override;
  Point2 second_derivative(double t) const override;
  Point2 center() const override { return base_->center(); }
  std::vector<double> corners() const override;
  bool smooth() const override { return base_->smooth(); }
  std::vector<Point2> polygon_vertices() const override;

 private:
  std::shared_ptr<const Curve> base_;
};

/// Signed area enclosed by the curve (> 0: counter-clockwise), by Gauss on 512 panels.
double signed_area(const Curve& curve);

/// Area-weighted centroid of the region the curve encloses.
Point2 centroid(const Curve& curve);

/// The side of c relative to the line a→b: +1 left, −1 right, 0 exactly on it. Exact for all finite
/// inputs whose coordinate differences multiply without underflow (a floating-point filter, then
/// the exact sum of the TwoProduct expansion).
int orientation(Point2 a, Point2 b, Point2 c);

/// Do the closed segments ab and cd meet (cross, touch, overlap along a line; decided exactly) or
/// come within `closeness` of each other?
bool segments_meet(Point2 a, Point2 b, Point2 c, Point2 d, double closeness);

/// Throws std::invalid_argument("<what>: the curve intersects or touches itself near (x, y)") if the
/// curve is not simple. A polygon (polygon_vertices() not empty) is checked on its own edges: two
/// edges that are not neighbours must not meet or come within 1e-12 of its extent, and neighbours
/// must meet only in their common vertex (no fold back along a line). Any other curve is checked on
/// the polyline through `samples` points equally spaced in t and its corners; a sample closer than a
/// quarter of the spacing to a corner is left out, so that no piece is shorter than that.
void check_simple(const Curve& curve, const std::string& what, int samples = 4096);

/// Throws std::invalid_argument("<what>: the curve has a cusp near (x, y) …") where a curve other than
/// a polygon has no normal: p′(t) is not finite, or below 1e-9 of its mean, at one of `samples` points
/// equally spaced in t, or the unit tangent reverses (turns by more than 172°) between two neighbouring
/// samples or across one (the astroid's cusps, whose offset curve has no finite speed).
void check_regular(const Curve& curve, const std::string& what, int samples = 4096);

/// check_simple() of the closed polygon through `vertices` (the closing edge implied).
void check_simple_polygon(const std::vector<Point2>& vertices, const std::string& what);

/// The least distance from the curve (samples equally spaced in t, and its corners) to ∂box,
/// negative where it leaves the box, and where; throws "<what>: the curve is not finite …".
struct BoxClearance {
  double distance;
  Point2 at;
};
BoxClearance box_clearance(const Curve& curve, const Box2& box, const std::string& what, int samples = 4096);

/// Throws std::invalid_argument("<what>: …") if the curve comes closer than `margin` to ∂box.
void check_inside_box(const Curve& curve, const Box2& box, double margin, const std::string& what, int samples = 4096);

}  // namespace fictus
