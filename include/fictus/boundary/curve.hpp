#pragma once
// Closed curves γ = ∂ω: a parametrization p(t), t ∈ [0, 2π), 2π-periodic, counter-clockwise
// (ω on the left), with first and second derivatives. The outward normal is
// n = (y', −x')/|p'|, the curvature κ = (x'y'' − y'x'')/|p'|³ (> 0 on a convex curve).
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "fictus/grid/grid.hpp"

namespace fictus {

class Curve {
 public:
  virtual ~Curve() = default;
  virtual Point2 position(double t) const = 0;
  virtual Point2 derivative(double t) const = 0;
  virtual Point2 second_derivative(double t) const = 0;
  /// A point inside ω used for the polar angle φ of user data (the ellipse's center).
  virtual Point2 center() const = 0;

  /// Parameters of corners (where p′ jumps), sorted; none for a smooth curve.
  virtual std::vector<double> corners() const { return {}; }
  /// Has a continuous tangent (the smooth variant's offset curve needs one).
  virtual bool smooth() const { return true; }
  /// The vertices, in the order of t, when the curve is exactly the closed polygon through them;
  /// empty for any other curve. Checks of a polygon use its own edges, not samples.
  virtual std::vector<Point2> polygon_vertices() const { return {}; }

  double speed(double t) const { return norm(derivative(t)); }
  Point2 outward_normal(double t) const;
  double curvature(double t) const;
};

/// Ellipse with center c, semi-axes a (along the rotated x axis) and b, rotated by `angle`:
/// p(t) = c + R(angle)·(a cos t, b sin t).
class Ellipse final : public Curve {
 public:
  Ellipse(Point2 center, double a, double b, double angle = 0.0);
  Point2 position(double t) const override;
  Point2 derivative(double t) const override;
  Point2 second_derivative(double t) const override;
  Point2 center() const override { return center_; }
  double a() const { return a_; }
  double b() const { return b_; }

 private:
  Point2 rotate(Point2 v) const { return {cos_ * v.x - sin_ * v.y, sin_ * v.x + cos_ * v.y}; }
  Point2 center_;
  double a_, b_, cos_, sin_;
};

/// Normal offset curve Γ(t) = γ(t) + δ·n(t) (δ > 0: outside ω), same parameter t as γ, so the
/// arcs of Γ are the images of the arcs of γ. Its speed is |γ'|(1 + δκ).
class OffsetCurve final : public Curve {
 public:
  OffsetCurve(std::shared_ptr<const Curve> base, double delta);
  Point2 position(double t) const override;
  Point2 derivative(double t) const override;
  /// By central differences of derivative() (used only for diagnostics of Γ's curvature).
  Point2 second_derivative(double t) const override;
  Point2 center() const override { return base_->center(); }
  double delta() const { return delta_; }

 private:
  std::shared_ptr<const Curve> base_;
  double delta_;
};

/// γ rotated by `angle` about its center, then moved by `shift`: p(t) = c + R(p₀(t) − c) + shift.
class TransformedCurve final : public Curve {
 public:
  TransformedCurve(std::shared_ptr<const Curve> base, double angle, Point2 shift);
  Point2 position(double t) const override;
  Point2 derivative(double t) const override { return rotate(base_->derivative(t)); }
  Point2 second_derivative(double t) const override { return rotate(base_->second_derivative(t)); }
  Point2 center() const override { return base_->center() + shift_; }
  std::vector<double> corners() const override { return base_->corners(); }  // the same parameter t
  bool smooth() const override { return base_->smooth(); }
  std::vector<Point2> polygon_vertices() const override;

 private:
  Point2 rotate(Point2 v) const { return {cos_ * v.x - sin_ * v.y, sin_ * v.x + cos_ * v.y}; }
  std::shared_ptr<const Curve> base_;
  double cos_, sin_;
  Point2 shift_;
};

/// Cumulative arc length s(t) on [0, 2π] by composite Gauss–Legendre, and its inverse; or, with a
/// `speed` of its own, any length measure ∫ speed dt along the curve (a weighted arc length). The table
/// keeps a reference to the curve (or the speed's captures): the curve must outlive it.
class ArcLengthTable {
 public:
  explicit ArcLengthTable(const Curve& curve, int panels = 2048);
  ArcLengthTable(std::function<double(double t)> speed, int panels = 2048);
  double length() const { return cumulative_.back(); }
  double s_of_t(double t) const;  // t ∈ [0, 2π]
  double t_of_s(double s) const;  // s ∈ [0, L] (Newton, safeguarded by the panel bracket)

 private:
  double partial(int panel, double t) const;  // ∫_{t_panel}^{t} speed
  std::function<double(double)> speed_;
  double dt_;
  std::vector<double> cumulative_;  // s at panel starts, size panels + 1
};

}  // namespace fictus
