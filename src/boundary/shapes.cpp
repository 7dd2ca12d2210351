#include "fictus/boundary/shapes.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "fictus/grid/quadrature.hpp"

namespace fictus {

namespace {
constexpr double two_pi = 2.0 * std::numbers::pi;

double wrap_parameter(double t) {
  t = std::fmod(t, two_pi);
  return t < 0 ? t + two_pi : t;
}

double cross(Point2 a, Point2 b) { return a.x * b.y - a.y * b.x; }

/// p, known to be on the line a→b, lies on the closed segment ab (exact comparisons).
bool within(Point2 a, Point2 b, Point2 p) {
  return p.x >= std::min(a.x, b.x) && p.x <= std::max(a.x, b.x) && p.y >= std::min(a.y, b.y) &&
         p.y <= std::max(a.y, b.y);
}

/// The point of the closed segment ab nearest to p.
Point2 nearest_on_segment(Point2 p, Point2 a, Point2 b) {
  const Point2 d = b - a;
  const double dd = d.x * d.x + d.y * d.y;
  const double t = dd > 0 ? std::clamp(((p.x - a.x) * d.x + (p.y - a.y) * d.y) / dd, 0.0, 1.0) : 0.0;
  return a + t * d;
}

/// Distance from p to the closed segment ab.
double distance_to_segment(Point2 p, Point2 a, Point2 b) { return norm(p - nearest_on_segment(p, a, b)); }

/// Adds x to the non-overlapping expansion `partials` (increasing magnitude) exactly: Shewchuk's
/// grow-expansion with zero elimination, as in Python's math.fsum.
void grow_expansion(std::vector<double>& partials, double x) {
  std::size_t kept = 0;
  for (double y : partials) {
    if (std::abs(x) < std::abs(y)) std::swap(x, y);
    const double hi = x + y, lo = y - (hi - x);
    if (lo != 0) partials[kept++] = lo;
    x = hi;
  }
  partials.resize(kept);
  partials.push_back(x);
}

/// The sign of the exact sum of `terms`: the sign of the largest component of their expansion.
int exact_sign_of_sum(std::initializer_list<double> terms) {
  std::vector<double> partials;
  partials.reserve(terms.size());
  for (double t : terms) grow_expansion(partials, t);
  for (auto it = partials.rbegin(); it != partials.rend(); ++it)
    if (*it != 0) return *it > 0 ? 1 : -1;
  return 0;
}
}  // namespace

int orientation(Point2 a, Point2 b, Point2 c) {
  const double l = (b.x - a.x) * (c.y - a.y), r = (b.y - a.y) * (c.x - a.x), v = l - r;
  // Shewchuk's first filter: beyond this bound the rounded determinant has the exact sign.
  const double bound = 3.3306690738754716e-16 * (std::abs(l) + std::abs(r));
  if (v > bound) return 1;
  if (v < -bound) return -1;
  // Exact: each difference is hi + lo (TwoDiff), each product of two doubles is p + e with
  // e = fma(x, y, −p) (TwoProduct), and the 16 terms are summed exactly.
  auto split = [](double x, double y) {  // x − y = hi + lo exactly (Knuth's TwoSum on x and −y)
    const double hi = x - y, bv = hi - x, av = hi - bv;
    return std::pair{hi, (x - av) + (-y - bv)};
  };
  const auto [bx, bxe] = split(b.x, a.x);
  const auto [cy, cye] = split(c.y, a.y);
  const auto [by, bye] = split(b.y, a.y);
  const auto [cx, cxe] = split(c.x, a.x);
  auto product = [&](double x, double y, double sign) {
    const double p = x * y;
    return std::pair{sign * p, sign * std::fma(x, y, -p)};
  };
  const std::pair<double, double> parts[] = {product(bx, cy, 1),   product(bx, cye, 1),  product(bxe, cy, 1),
                                             product(bxe, cye, 1), product(by, cx, -1),  product(by, cxe, -1),
                                             product(bye, cx, -1), product(bye, cxe, -1)};
  return exact_sign_of_sum({parts[0].first, parts[0].second, parts[1].first, parts[1].second, parts[2].first,
                            parts[2].second, parts[3].first, parts[3].second, parts[4].first, parts[4].second,
                            parts[5].first, parts[5].second, parts[6].first, parts[6].second, parts[7].first,
                            parts[7].second});
}

bool segments_meet(Point2 a, Point2 b, Point2 c, Point2 d, double closeness) {
  const int o1 = orientation(a, b, c), o2 = orientation(a, b, d);
  const int o3 = orientation(c, d, a), o4 = orientation(c, d, b);
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;  // a proper crossing
  if ((o1 == 0 && within(a, b, c)) || (o2 == 0 && within(a, b, d)) || (o3 == 0 && within(c, d, a)) ||
      (o4 == 0 && within(c, d, b)))
    return true;  // an end on the other segment, or an overlap along a line
  // Apart: closer than `closeness` still counts as touching (decimal input such as a vertex at
  // (0.5, 0.3) on the edge (0, 0)–(1, 0.6) is not on it in binary).
  return std::min({distance_to_segment(a, c, d), distance_to_segment(b, c, d), distance_to_segment(c, a, b),
                   distance_to_segment(d, a, b)}) <= closeness;
}

namespace {

/// Where two segments that meet (segments_meet) do so, for the message: their crossing, or the middle
/// between the nearest end of one and its nearest point on the other.
Point2 meeting_point(Point2 a, Point2 b, Point2 c, Point2 d) {
  const Point2 ab = b - a, cd = d - c, ac = c - a;
  const double det = cross(ab, cd);
  if (det != 0) {
    const double t = cross(ac, cd) / det, u = cross(ac, ab) / det;
    if (t >= 0 && t <= 1 && u >= 0 && u <= 1) return a + t * ab;
  }
  Point2 best = a;
  double least = std::numeric_limits<double>::infinity();
  for (const auto& [x, p, q] : {std::tuple{a, c, d}, std::tuple{b, c, d}, std::tuple{c, a, b}, std::tuple{d, a, b}}) {
    const Point2 y = nearest_on_segment(x, p, q);
    if (const double gap = norm(x - y); gap < least) least = gap, best = 0.5 * (x + y);
  }
  return best;
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
std::vector<Point2> ReversedCurve::polygon_vertices() const {
  std::vector<Point2> vertices = base_->polygon_vertices();  // t ↦ 2π − t: v0, v(n−1), …, v1
  if (!vertices.empty()) std::reverse(vertices.begin() + 1, vertices.end());
  return vertices;
}
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

namespace {

[[noreturn]] void touches_itself(const std::string& what, Point2 near) {
  std::ostringstream msg;
  msg << what << ": the curve intersects or touches itself near (" << near.x << ", " << near.y << ")";
  throw std::invalid_argument(msg.str());
}

/// The extent of the closed polyline p; throws when it is zero or overflows.
double checked_extent(const std::vector<Point2>& p, const std::string& what) {
  double x0 = p[0].x, x1 = x0, y0 = p[0].y, y1 = y0;
  for (const Point2& q : p) {
    if (!std::isfinite(q.x) || !std::isfinite(q.y)) throw std::invalid_argument(what + ": the curve is not finite");
    x0 = std::min(x0, q.x), x1 = std::max(x1, q.x), y0 = std::min(y0, q.y), y1 = std::max(y1, q.y);
  }
  const double size = std::max(x1 - x0, y1 - y0);
  // Far from the origin beside its size the curve's points lose their digits (a centre at 1e308).
  const double far = std::max({std::abs(x0), std::abs(x1), std::abs(y0), std::abs(y1)});
  if (size <= 1e100 && (size > 0 ? size < 1e-13 * far : far > 1e12)) {
    std::ostringstream msg;
    msg << what << ": the curve lies at " << far << " from the origin, too far for its points to keep their digits "
        << "(its extent there: " << size << "); move it nearer the origin";
    throw std::invalid_argument(msg.str());
  }
  if (!(size > 0 && size <= 1e100))  // an extent that overflows (semi-axes of 1e308) or a point
    throw std::invalid_argument(what + ": the curve's extent is " + (size > 0 ? "beyond 1e100" : "zero"));
  return size;
}

/// The closed polyline through p (edge k from p[k] to p[k+1], the last one back to p[0]) is simple:
/// edges that are not neighbours do not meet (decided exactly) nor come within `closeness`;
/// neighbours meet only in their common vertex. The edges are bucketed on a coarse grid so that the
/// check stays near-linear.
void check_simple_polyline(const std::vector<Point2>& p, double closeness, const std::string& what) {
  const std::size_t n = p.size();
  for (std::size_t k = 0; k < n; ++k) {  // neighbours: no fold back along a line, no near-overlap
    const Point2 a = p[k], b = p[(k + 1) % n], c = p[(k + 2) % n];
    const Point2 ab = b - a, bc = c - b;
    if (orientation(a, b, c) == 0 && ab.x * bc.x + ab.y * bc.y < 0) touches_itself(what, b);
    if (distance_to_segment(a, b, c) <= closeness || distance_to_segment(c, a, b) <= closeness) touches_itself(what, b);
  }
  double x0 = p[0].x, x1 = x0, y0 = p[0].y, y1 = y0;
  for (const Point2& q : p)
    x0 = std::min(x0, q.x), x1 = std::max(x1, q.x), y0 = std::min(y0, q.y), y1 = std::max(y1, q.y);
  const int cells = std::clamp(int(std::sqrt(double(n))), 1, 64);
  const double wx = (x1 - x0) / cells + 1e-300, wy = (y1 - y0) / cells + 1e-300;
  std::vector<std::vector<std::size_t>> bucket(cells * cells);
  auto cell = [&](double v, double origin, double w) { return std::clamp(int((v - origin) / w), 0, cells - 1); };
  const double grow = closeness;  // an edge within `closeness` of another shares a bucket with it
  for (std::size_t k = 0; k < n; ++k) {
    const Point2 a = p[k], b = p[(k + 1) % n];
    for (int i = cell(std::min(a.x, b.x) - grow, x0, wx); i <= cell(std::max(a.x, b.x) + grow, x0, wx); ++i)
      for (int j = cell(std::min(a.y, b.y) - grow, y0, wy); j <= cell(std::max(a.y, b.y) + grow, y0, wy); ++j)
        bucket[j * cells + i].push_back(k);
  }
  for (const auto& edges : bucket)
    for (std::size_t u = 0; u < edges.size(); ++u)
      for (std::size_t v = u + 1; v < edges.size(); ++v) {
        const std::size_t a = edges[u], b = edges[v];
        if (a == b || (a + 1) % n == b || (b + 1) % n == a) continue;
        if (segments_meet(p[a], p[(a + 1) % n], p[b], p[(b + 1) % n], closeness))
          touches_itself(what, meeting_point(p[a], p[(a + 1) % n], p[b], p[(b + 1) % n]));
      }
}

}  // namespace

void check_simple_polygon(const std::vector<Point2>& vertices, const std::string& what) {
  if (vertices.size() < 3) throw std::invalid_argument(what + ": a polygon needs at least 3 vertices");
  const double size = checked_extent(vertices, what);
  check_simple_polyline(vertices, 1e-12 * size, what);
}

void check_simple(const Curve& curve, const std::string& what, int samples) {
  if (const std::vector<Point2> vertices = curve.polygon_vertices(); !vertices.empty())
    return check_simple_polygon(vertices, what);
  // Samples equally spaced in t, and the corners; a sample within a quarter spacing of a corner is
  // left out (a corner one rounding step from a sample would leave a piece of 1e-16 whose
  // neighbours "touch").
  std::vector<double> corners = curve.corners();
  for (double& c : corners) c = wrap_parameter(c);
  std::sort(corners.begin(), corners.end());
  const double spacing = two_pi / samples;
  auto near_corner = [&](double t) {
    for (double c : corners) {
      const double d = std::abs(t - c);
      if (std::min(d, two_pi - d) < spacing / 4) return true;
    }
    return false;
  };
  std::vector<double> t = corners;
  for (int k = 0; k < samples; ++k)
    if (!near_corner(spacing * k)) t.push_back(spacing * k);
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
  const double size = checked_extent(p, what);
  {  // closed: p(2π) = p(0) (a jump of x(t), y(t) or r(t) at 2π is not a closed curve)
    const Point2 gap = curve.position(two_pi) - curve.position(0.0);
    if (!(norm(gap) <= 1e-9 * size)) {
      std::ostringstream msg;
      msg << what << ": the curve is not closed: p(2pi) - p(0) = (" << gap.x << ", " << gap.y << ")";
      throw std::invalid_argument(msg.str());
    }
  }
  check_simple_polyline(p, 1e-12 * size, what);
}

void check_regular(const Curve& curve, const std::string& what, int samples) {
  if (!curve.polygon_vertices().empty()) return;
  const double spacing = two_pi / samples;
  const auto cusp = [&](double t, const char* why) {
    const Point2 p = curve.position(t);
    std::ostringstream msg;
    msg << what << ": the curve has a cusp near (" << p.x << ", " << p.y << ") (" << why
        << "): its normal is not defined there; round the point off";
    throw std::invalid_argument(msg.str());
  };
  std::vector<Point2> derivative(static_cast<std::size_t>(samples));
  double mean_speed = 0.0;
  for (int k = 0; k < samples; ++k) {
    derivative[std::size_t(k)] = curve.derivative(spacing * k);
    const double speed = norm(derivative[std::size_t(k)]);
    if (!std::isfinite(speed)) cusp(spacing * k, "p'(t) is not finite");
    mean_speed += speed / samples;
  }
  // p′ from differences (parametric curves) is not exactly zero at a cusp: 3e-11 at the astroid's.
  std::vector<Point2> tangent(derivative.size());
  for (int k = 0; k < samples; ++k) {
    const double speed = norm(derivative[std::size_t(k)]);
    if (!(speed > 1e-9 * mean_speed)) cusp(spacing * k, "the tangent p'(t) vanishes");
    tangent[std::size_t(k)] = (1 / speed) * derivative[std::size_t(k)];
  }
  // The tangent reverses across a cusp: between two neighbouring samples, or between the two beside a
  // sample that falls on it. (A corner turns it by less; 0.99 leaves corners down to 8° inside.)
  const auto at = [&](int k) { return tangent[std::size_t((k + samples) % samples)]; };
  for (int k = 0; k < samples; ++k) {
    if (dot(at(k - 1), at(k + 1)) < -0.99) cusp(spacing * k, "the tangent turns back");
    if (dot(at(k), at(k + 1)) < -0.99) cusp(spacing * (k + 0.5), "the tangent turns back");
  }
}

BoxClearance box_clearance(const Curve& curve, const Box2& box, const std::string& what, int samples) {
  std::vector<double> t = curve.corners();
  for (int k = 0; k < samples; ++k) t.push_back(two_pi * k / samples);
  BoxClearance least{std::numeric_limits<double>::infinity(), {}};
  for (double s : t) {
    const Point2 p = curve.position(s);
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
      std::ostringstream msg;
      msg << what << ": the curve is not finite at t = " << s;
      throw std::invalid_argument(msg.str());
    }
    const double d = std::min({p.x - box.lower.x, box.upper.x - p.x, p.y - box.lower.y, box.upper.y - p.y});
    if (d < least.distance) least = {d, p};
  }
  return least;
}

void check_inside_box(const Curve& curve, const Box2& box, double margin, const std::string& what, int samples) {
  const BoxClearance c = box_clearance(curve, box, what, samples);
  if (c.distance < margin) {
    std::ostringstream msg;
    msg << what << ": the curve comes within " << c.distance << " of the box boundary (or leaves it) at (" << c.at.x
        << ", " << c.at.y << ")";
    throw std::invalid_argument(msg.str());
  }
}

}  // namespace fictus
