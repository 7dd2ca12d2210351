#include "fictus/boundary/curve.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "fictus/grid/quadrature.hpp"

namespace fictus {

constexpr double two_pi = 2.0 * std::numbers::pi;

Point2 Curve::outward_normal(double t) const {
  const Point2 d = derivative(t);
  const double s = norm(d);
  return {d.y / s, -d.x / s};
}

double Curve::curvature(double t) const {
  const Point2 d = derivative(t), dd = second_derivative(t);
  const double s = norm(d);
  return (d.x * dd.y - d.y * dd.x) / (s * s * s);
}

Ellipse::Ellipse(Point2 center, double a, double b, double angle)
    : center_(center), a_(a), b_(b), cos_(std::cos(angle)), sin_(std::sin(angle)) {
  if (!(a > 0) || !(b > 0) || !std::isfinite(a) || !std::isfinite(b))
    throw std::invalid_argument("geometry.semi_axes: must be positive and finite");
}

Point2 Ellipse::position(double t) const { return center_ + rotate({a_ * std::cos(t), b_ * std::sin(t)}); }
Point2 Ellipse::derivative(double t) const { return rotate({-a_ * std::sin(t), b_ * std::cos(t)}); }
Point2 Ellipse::second_derivative(double t) const { return rotate({-a_ * std::cos(t), -b_ * std::sin(t)}); }

OffsetCurve::OffsetCurve(std::shared_ptr<const Curve> base, double delta) : base_(std::move(base)), delta_(delta) {}

Point2 OffsetCurve::position(double t) const { return base_->position(t) + delta_ * base_->outward_normal(t); }

Point2 OffsetCurve::derivative(double t) const {
  // n = J p'/|p'| with J(x, y) = (y, −x); n' = J (p''/|p'| − p' (p'·p'')/|p'|³).
  const Point2 d = base_->derivative(t), dd = base_->second_derivative(t);
  const double s = norm(d);
  const Point2 w = (1.0 / s) * dd - (dot(d, dd) / (s * s * s)) * d;
  return d + delta_ * Point2{w.y, -w.x};
}

Point2 OffsetCurve::second_derivative(double t) const {
  const double e = 1e-5;
  return (1.0 / (2 * e)) * (derivative(t + e) - derivative(t - e));
}

TransformedCurve::TransformedCurve(std::shared_ptr<const Curve> base, double angle, Point2 shift)
    : base_(std::move(base)), cos_(std::cos(angle)), sin_(std::sin(angle)), shift_(shift) {}

Point2 TransformedCurve::position(double t) const {
  const Point2 c = base_->center();
  return c + rotate(base_->position(t) - c) + shift_;
}

std::vector<Point2> TransformedCurve::polygon_vertices() const {
  std::vector<Point2> vertices = base_->polygon_vertices();
  const Point2 c = base_->center();
  for (Point2& v : vertices) v = c + rotate(v - c) + shift_;
  return vertices;
}

ArcLengthTable::ArcLengthTable(const Curve& curve, int panels)
    : ArcLengthTable([&curve](double t) { return curve.speed(t); }, panels) {}

ArcLengthTable::ArcLengthTable(std::function<double(double)> speed, int panels)
    : speed_(std::move(speed)), dt_(two_pi / panels), cumulative_(panels + 1, 0.0) {
  if (panels < 1) throw std::invalid_argument("ArcLengthTable: panels must be positive");
  for (int k = 0; k < panels; ++k) cumulative_[k + 1] = cumulative_[k] + partial(k, (k + 1) * dt_);
}

double ArcLengthTable::partial(int panel, double t) const {
  const GaussRule& rule = gauss_legendre(12);
  const double t0 = panel * dt_, span = t - t0;
  double sum = 0.0;
  for (std::size_t g = 0; g < rule.nodes.size(); ++g) sum += rule.weights[g] * speed_(t0 + rule.nodes[g] * span);
  return sum * span;
}

double ArcLengthTable::s_of_t(double t) const {
  const int panels = int(cumulative_.size()) - 1;
  const int k = std::clamp(int(t / dt_), 0, panels - 1);
  return cumulative_[k] + partial(k, t);
}

double ArcLengthTable::t_of_s(double s) const {
  const int panels = int(cumulative_.size()) - 1;
  const auto it = std::upper_bound(cumulative_.begin(), cumulative_.end(), s);
  const int k = std::clamp(int(it - cumulative_.begin()) - 1, 0, panels - 1);
  double lo = k * dt_, hi = (k + 1) * dt_;
  double t = lo + (s - cumulative_[k]) / (cumulative_[k + 1] - cumulative_[k]) * dt_;
  for (int it_count = 0; it_count < 50; ++it_count) {
    const double r = cumulative_[k] + partial(k, t) - s;
    if (r > 0)
      hi = t;
    else
      lo = t;
    double next = t - r / speed_(t);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - t) < 1e-15 * two_pi) return next;
    t = next;
  }
  return t;
}

}  // namespace fictus
