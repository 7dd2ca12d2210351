#include "fictus/shapes.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "fictus/quadrature.hpp"

namespace fictus {

namespace {
constexpr double two_pi = 2.0 * std::numbers::pi;

double wrap_parameter(double t) {
  t = std::fmod(t, two_pi);
  return t < 0 ? t + two_pi : t;
}

double cross(Point2 a, Point2 b) { return a.x * b.y - a.y * b.x; }

/// The side of c relative to the line a→b: +1 left, −1 right, 0 within `tolerance` (an area) of it.
int orientation(Point2 a, Point2 b, Point2 c, double tolerance) {
  const double v = cross(b - a, c - a);
  return v > tolerance ? 1 : v < -tolerance ? -1 : 0;
}

/// p, known to be on the line a→b, lies on the segment (ends included, to `slack`).
bool within(Point2 a, Point2 b, Point2 p, double slack) {
  return p.x >= std::min(a.x, b.x) - slack && p.x <= std::max(a.x, b.x) + slack && p.y >= std::min(a.y, b.y) - slack &&
         p.y <= std::max(a.y, b.y) + slack;
}

/// Do the segments ab and cd meet: cross, touch (an end on the other segment) or overlap along a
/// line? Orientations within `scale`·1e-12 (of the curve's size) count as collinear.
bool segments_meet(Point2 a, Point2 b, Point2 c, Point2 d, double scale) {
  const double area = 1e-12 * scale * scale, slack = 1e-12 * scale;
  const int o1 = orientation(a, b, c, area), o2 = orientation(a, b, d, area);
  const int o3 = orientation(c, d, a, area), o4 = orientation(c, d, b, area);
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;  // a proper crossing
  return (o1 == 0 && within(a, b, c, slack)) || (o2 == 0 && within(a, b, d, slack)) ||
         (o3 == 0 && within(c, d, a, slack)) || (o4 == 0 && within(c, d, b, slack));
}
}  // namespace

PolygonCurve::PolygonCurve(std::vector<Point2> vertices) : vertices_(std::move(vertices)) {
  const std::size_t n = vertices_.size();
  if (n < 3) throw std::invalid_argument("geometry.vertices: a polygon needs at least 3 vertices");
  cumulative_.assign(n + 1, 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    const double len = norm(vertices_[(k + 1) % n] - vertices_[k]);
    if (!(len > 0)) throw std::invalid_argument("geometry.vertices: vertex " + std::to_string(k) + " is repeated");
    cumulative_[k + 1] = cumulative_[k] + len;
  }
  double area = 0, cx = 0, cy = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const Point2 a = vertices_[k], b = vertices_[(k + 1) % n];
    const double w = cross(a, b);
    area += w / 2;
    cx += (a.x + b.x) * w / 6;
    cy += (a.y + b.y) * w / 6;
  }
  centroid_ = {cx / area, cy / area};
}

int PolygonCurve::edge_of(double t) const {
  const double s = wrap_parameter(t) / two_pi * cumulative_.back();
  const auto it = std::upper_bound(cumulative_.begin(), cumulative_.end(), s);
  return std::clamp(int(it - cumulative_.begin()) - 1, 0, int(vertices_.size()) - 1);
}

Point2 PolygonCurve::position(double t) const {
  const int k = edge_of(t);
  const double s = wrap_parameter(t) / two_pi * cumulative_.back();
  const Point2 a = vertices_[k], b = vertices_[(k + 1) % vertices_.size()];
  const double w = (s - cumulative_[k]) / (cumulative_[k + 1] - cumulative_[k]);
  return a + w * (b - a);
}

Point2 PolygonCurve::derivative(double t) const {
  const int k = edge_of(t);
  const Point2 a = vertices_[k], b = vertices_[(k + 1) % vertices_.size()];
  return (cumulative_.back() / two_pi / (cumulative_[k + 1] - cumulative_[k])) * (b - a);
}

std::vector<double> PolygonCurve::corners() const {
  std::vector<double> t;
  for (std::size_t k = 0; k < vertices_.size(); ++k) t.push_back(two_pi * cumulative_[k] / cumulative_.back());
  return t;
}

Point2 ExpressionCurve::derivative(double t) const {
  const double e = 1e-5;
  return (1.0 / (2 * e)) * (position(t + e) - position(t - e));
}

Point2 ExpressionCurve::second_derivative(double t) const {
  const double e = 1e-4;
  return (1.0 / (e * e)) * (position(t + e) - 2.0 * position(t) + position(t - e));
}

ParametricCurve::ParametricCurve(std::function<double(double)> x, std::function<double(double)> y)
    : x_(std::move(x)), y_(std::move(y)) {
  center_ = centroid(*this);
}

Point2 ParametricCurve::position(double t) const { return {x_(t), y_(t)}; }

StarCurve::StarCurve(Point2 center, std::function<double(double)> r) : center_(center), r_(std::move(r)) {
  for (int k = 0; k <= 65536; ++k) {  // dense: r < 0 or NaN between coarser samples would pass unseen
    const double t = two_pi * k / 65536, r = r_(t);
    if (!(r > 0) || !std::isfinite(r))
      throw std::invalid_argument("geometry.r: must be positive and finite for all t (r(" + std::to_string(t) +
                                  ") = " + std::to_string(r) + ")");
  }
}

Point2 StarCurve::position(double t) const {
  const double r = r_(t);
  return center_ + Point2{r * std::cos(t), r * std::sin(t)};
}

Point2 ReversedCurve::position(double t) const { return base_->position(two_pi - t); }
Point2 ReversedCurve::derivative(double t) const { return -1.0 * base_->derivative(two_pi - t); }
Point2 ReversedCurve::second_derivative(double t) const { return base_->second_derivative(two_pi - t); }
std::vector<double> ReversedCurve::corners() const {
  std::vector<double> t;
  for (double c : base_->corners()) t.push_back(c == 0.0 ? 0.0 : two_pi - c);
  std::sort(t.begin(), t.end());
  return t;
}

namespace {
/// ∫ F(p, p′) dt over [0, 2π], split at corners, Gauss on panels.
template <class F>
double integrate_parameter(const Curve& curve, F&& fn) {
  std::vector<double> breaks = curve.corners();
  breaks.push_back(0.0);
  breaks.push_back(two_pi);
  std::sort(breaks.begin(), breaks.end());
  const GaussRule& rule = gauss_legendre(8);
  double sum = 0;
  for (std::size_t b = 0; b + 1 < breaks.size(); ++b) {
    const double t0 = breaks[b], t1 = breaks[b + 1];
    if (!(t1 > t0)) continue;
    const int panels = std::max(1, int(512 * (t1 - t0) / two_pi));
    for (int k = 0; k < panels; ++k) {
      const double a = t0 + (t1 - t0) * k / panels, w = (t1 - t0) / panels;
      for (int g = 0; g < 8; ++g) {
        const double t = a + rule.nodes[g] * w;
        sum += rule.weights[g] * w * fn(curve.position(t), curve.derivative(t));
      }
    }
  }
  return sum;
}
}  // namespace

double signed_area(const Curve& curve) {
  return integrate_parameter(curve, [](Point2 p, Point2 d) { return 0.5 * cross(p, d); });
}

Point2 centroid(const Curve& curve) {
  const double area = signed_area(curve);
  // Green: ∫x dA = ½∮x² dy, ∫y dA = −½∮y² dx
  const double mx = integrate_parameter(curve, [](Point2 p, Point2 d) { return 0.5 * p.x * p.x * d.y; });
  const double my = integrate_parameter(curve, [](Point2 p, Point2 d) { return -0.5 * p.y * p.y * d.x; });
  return {mx / area, my / area};
}

void check_simple(const Curve& curve, const std::string& what, int samples) {
  std::vector<double> t = curve.corners();
  for (int k = 0; k < samples; ++k) t.push_back(two_pi * k / samples);
  std::sort(t.begin(), t.end());
  t.erase(std::unique(t.begin(), t.end()), t.end());
  std::vector<Point2> p;
  for (double s : t) {
    p.push_back(curve.position(s));
    if (!std::isfinite(p.back().x) || !std::isfinite(p.back().y)) {
      std::ostringstream msg;
      msg << what << ": the curve is not finite at t = " << s;
      throw std::invalid_argument(msg.str());
    }
  }
  const std::size_t n = p.size();
  // Bucket the segments on a coarse grid so the check stays near-linear.
  double x0 = p[0].x, x1 = x0, y0 = p[0].y, y1 = y0;
  for (const Point2& q : p)
    x0 = std::min(x0, q.x), x1 = std::max(x1, q.x), y0 = std::min(y0, q.y), y1 = std::max(y1, q.y);
  const double size = std::max(x1 - x0, y1 - y0);
  {  // closed: p(2π) = p(0) (a jump of x(t), y(t) or r(t) at 2π is not a closed curve)
    const Point2 gap = curve.position(two_pi) - curve.position(0.0);
    if (!(norm(gap) <= 1e-9 * size)) {
      std::ostringstream msg;
      msg << what << ": the curve is not closed: p(2pi) - p(0) = (" << gap.x << ", " << gap.y << ")";
      throw std::invalid_argument(msg.str());
    }
  }
  const int cells = 64;
  const double wx = (x1 - x0) / cells + 1e-300, wy = (y1 - y0) / cells + 1e-300;
  std::vector<std::vector<std::size_t>> bucket(cells * cells);
  auto cell = [&](double v, double origin, double w) { return std::clamp(int((v - origin) / w), 0, cells - 1); };
  for (std::size_t k = 0; k < n; ++k) {
    const Point2 a = p[k], b = p[(k + 1) % n];
    for (int i = cell(std::min(a.x, b.x), x0, wx); i <= cell(std::max(a.x, b.x), x0, wx); ++i)
      for (int j = cell(std::min(a.y, b.y), y0, wy); j <= cell(std::max(a.y, b.y), y0, wy); ++j)
        bucket[j * cells + i].push_back(k);
  }
  for (const auto& segs : bucket)
    for (std::size_t u = 0; u < segs.size(); ++u)
      for (std::size_t v = u + 1; v < segs.size(); ++v) {
        const std::size_t a = segs[u], b = segs[v];
        if (a == b || (a + 1) % n == b || (b + 1) % n == a) continue;
        if (segments_meet(p[a], p[(a + 1) % n], p[b], p[(b + 1) % n], size)) {
          std::ostringstream msg;
          msg << what << ": the curve intersects or touches itself near (" << p[a].x << ", " << p[a].y << ")";
          throw std::invalid_argument(msg.str());
        }
      }
}

void check_inside_box(const Curve& curve, const Box2& box, double margin, const std::string& what, int samples) {
  std::vector<double> t = curve.corners();
  for (int k = 0; k < samples; ++k) t.push_back(two_pi * k / samples);
  for (double s : t) {
    const Point2 p = curve.position(s);
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
      std::ostringstream msg;
      msg << what << ": the curve is not finite at t = " << s;
      throw std::invalid_argument(msg.str());
    }
    if (p.x - box.lower.x < margin || box.upper.x - p.x < margin || p.y - box.lower.y < margin ||
        box.upper.y - p.y < margin) {
      std::ostringstream msg;
      msg << what << ": the curve comes within " << margin << " of the box boundary (or leaves it) at (" << p.x << ", "
          << p.y << ")";
      throw std::invalid_argument(msg.str());
    }
  }
}

}  // namespace fictus
