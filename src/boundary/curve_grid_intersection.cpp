#include "fictus/boundary/curve_grid_intersection.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>

namespace fictus {

namespace {

constexpr double two_pi = 2.0 * std::numbers::pi;

double component(Point2 p, int axis) { return axis == 0 ? p.x : p.y; }

/// t ∈ [ta, tb] with component(p(t), axis) = value, given that the component minus value changes
/// sign on [ta, tb] (Newton's method kept inside the shrinking bracket, bisection as fallback).
double find_parameter(const Curve& curve, int axis, double value, double ta, double tb) {
  double fa = component(curve.position(ta), axis) - value;
  if (fa == 0.0) return ta;
  double lo = ta, hi = tb;
  double t = 0.5 * (ta + tb);
  for (int it = 0; it < 100; ++it) {
    const double f = component(curve.position(t), axis) - value;
    if (f == 0.0) return t;
    if ((f > 0) == (fa > 0))
      lo = t;
    else
      hi = t;
    const double df = component(curve.derivative(t), axis);
    double next = df != 0.0 ? t - f / df : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - t) <= 1e-15 * two_pi || hi - lo <= 1e-15 * two_pi) return next;
    t = next;
  }
  return t;
}

struct Crossing {
  double t;
  int line;       // grid line index
  bool vertical;  // x = x_line (else y = y_line)
  Point2 p;
};

/// The crossings of the curve with the grid lines, in steps of at most h/8 along it (the walk checks
/// that the curve stays inside the box and can be followed), sorted by parameter.
std::vector<Crossing> grid_crossings(const Curve& curve, const Grid2& grid, const char* what) {
  const double h = grid.h();
  const Box2& box = grid.box();
  double max_speed = 0.0;
  for (int k = 0; k < 4096; ++k) max_speed = std::max(max_speed, curve.speed(two_pi * k / 4096));
  // Steps of at most h/8 along the curve; a speed that is not finite, or so large that the walk
  // would take more than 1e8 steps (a cusp, a blow-up), is not a curve fictus can follow.
  const double wanted = std::ceil(two_pi * max_speed / (h / 8));
  if (!(wanted <= 1e8)) {
    std::ostringstream msg;
    msg << what << ": the curve's speed |p'(t)| reaches " << max_speed
        << " (not finite, or a cusp): too irregular to follow";
    throw std::invalid_argument(msg.str());
  }
  const int steps = std::max(256, int(wanted));
  const double dt = two_pi / steps;

  auto check_inside_box = [&](Point2 p) {
    if (!(p.x > box.lower.x && p.x < box.upper.x && p.y > box.lower.y && p.y < box.upper.y)) {
      std::ostringstream msg;
      msg << what << ": the curve leaves the box at (" << p.x << ", " << p.y << ")";
      throw std::invalid_argument(msg.str());
    }
  };

  std::vector<Crossing> crossings;
  Point2 pa = curve.position(0.0);
  check_inside_box(pa);
  for (int k = 0; k < steps; ++k) {
    const double ta = k * dt, tb = k + 1 == steps ? two_pi : (k + 1) * dt;
    // The last step ends at the start point exactly: a curve that starts on a grid line must cross
    // it again when it closes (position(2π) may differ from position(0) by rounding).
    const Point2 pb = k + 1 == steps ? curve.position(0.0) : curve.position(tb);
    check_inside_box(pb);
    for (int axis = 0; axis < 2; ++axis) {
      const double origin = axis == 0 ? box.lower.x : box.lower.y;
      const int la = int(std::floor((component(pa, axis) - origin) / h));
      const int lb = int(std::floor((component(pb, axis) - origin) / h));
      for (int line = std::min(la, lb) + 1; line <= std::max(la, lb); ++line) {
        const double value = origin + line * h;
        const double t = find_parameter(curve, axis, value, ta, tb);
        Point2 p = curve.position(t);
        (axis == 0 ? p.x : p.y) = value;
        crossings.push_back({t, line, axis == 0, p});
      }
    }
    pa = pb;
  }
  std::sort(crossings.begin(), crossings.end(), [](const Crossing& a, const Crossing& b) { return a.t < b.t; });
  return crossings;
}

}  // namespace

CurveGridIntersection::CurveGridIntersection(const Curve& curve, const Grid2& grid, const char* what)
    : curve_(curve), grid_(grid), corners_(curve.corners()) {
  std::sort(corners_.begin(), corners_.end());
  const std::vector<Crossing> crossings = grid_crossings(curve, grid, what);

  row_crossings_.assign(grid.ny() + 1, {});
  col_crossings_.assign(grid.nx() + 1, {});
  for (const Crossing& c : crossings) {
    if (c.vertical)
      col_crossings_[c.line].push_back(c.p.y);
    else
      row_crossings_[c.line].push_back(c.p.x);
  }
  for (auto& row : row_crossings_) std::sort(row.begin(), row.end());
  for (auto& col : col_crossings_) std::sort(col.begin(), col.end());

  double start = 0.0;
  auto add_piece = [&](double t0, double t1) {
    if (t1 - t0 <= 1e-14) return;
    const Point2 mid = curve.position(0.5 * (t0 + t1));
    pieces_.push_back({t0, t1, grid.cell_x(mid.x), grid.cell_y(mid.y)});
  };
  for (const Crossing& c : crossings) {
    add_piece(start, c.t);
    start = std::max(start, c.t);
  }
  add_piece(start, two_pi);

  std::vector<std::pair<long long, int>> by_cell(pieces_.size());
  for (std::size_t k = 0; k < pieces_.size(); ++k)
    by_cell[k] = {(long long)pieces_[k].iy * grid.nx() + pieces_[k].ix, int(k)};
  std::sort(by_cell.begin(), by_cell.end());
  for (const auto& [cell, piece] : by_cell) {
    if (cut_cells_.empty() || (long long)cut_cells_.back().iy * grid.nx() + cut_cells_.back().ix != cell)
      cut_cells_.push_back({pieces_[piece].ix, pieces_[piece].iy, {}});
    cut_cells_.back().pieces.push_back(piece);
  }
  row_begin_.assign(grid.ny() + 1, 0);
  for (int iy = 0, k = 0; iy <= grid.ny(); ++iy) {
    while (k < int(cut_cells_.size()) && cut_cells_[k].iy < iy) ++k;
    row_begin_[iy] = k;
  }
}

bool CurveGridIntersection::inside_on_row(int j, double x) const {
  const auto& row = row_crossings_[j];
  return (std::lower_bound(row.begin(), row.end(), x) - row.begin()) % 2 == 1;
}

bool CurveGridIntersection::inside_on_column(int i, double y) const {
  const auto& col = col_crossings_[i];
  return (std::lower_bound(col.begin(), col.end(), y) - col.begin()) % 2 == 1;
}

std::pair<std::size_t, std::size_t> CurveGridIntersection::pieces_in(double ta, double tb) const {
  const auto first =
      std::lower_bound(pieces_.begin(), pieces_.end(), ta, [](const CurvePiece& p, double t) { return p.t1 <= t; });
  const auto last = std::lower_bound(first, pieces_.end(), tb, [](const CurvePiece& p, double t) { return p.t0 < t; });
  return {std::size_t(first - pieces_.begin()), std::size_t(last - pieces_.begin())};
}

const CurveGridIntersection::CutRules& CurveGridIntersection::cut_rules(int iy, int q) const {
  {
    const std::lock_guard<std::mutex> lock(rules_mutex_);
    std::vector<std::unique_ptr<const CutRules>>& rows = rules_[q];
    if (rows.empty()) rows.resize(std::size_t(grid_.ny()));
    if (const CutRules* made = rows[std::size_t(iy)].get()) return *made;
  }
  auto made = std::make_unique<CutRules>();
  for (std::size_t c = row_begin_[iy]; c < row_begin_[iy + 1]; ++c) {
    made->begin.push_back(made->points.size());
    cut_cell_rule(cut_cells_[c], q, made->points);
  }
  made->begin.push_back(made->points.size());
  const std::lock_guard<std::mutex> lock(rules_mutex_);
  std::unique_ptr<const CutRules>& slot = rules_[q][std::size_t(iy)];
  if (!slot) slot = std::move(made);  // (another thread may have made the same row meanwhile)
  return *slot;
}

bool CurveGridIntersection::inside_uncut_cell(int ix, int iy, int corners_inside) const {
  // γ does not enter the cell, so its corners and edges are all on one side, except where γ touches
  // them: a point on γ is counted with the side just below and left of it, whatever ω's side is (γ
  // through a grid node leaves the cell above and right of that node, inside ω, with a corner that tests
  // outside). Such points can only be the lower-left, lower-right and upper-left corners: the upper-right
  // corner and the upper and right edges' midpoints test from inside the cell, and γ along the lower or
  // left edge would make the cell a cut one. So at most 3 of the 8 points test wrongly, and 5 decide.
  if (corners_inside == 4 || corners_inside == 0) return corners_inside == 4;
  const double xm = grid_.x(ix) + 0.5 * grid_.h(), ym = grid_.y(iy) + 0.5 * grid_.h();
  const int midpoints_inside =
      int(inside_on_row(iy, xm)) + inside_on_row(iy + 1, xm) + inside_on_column(ix, ym) + inside_on_column(ix + 1, ym);
  return corners_inside + midpoints_inside >= 5;
}

void CurveGridIntersection::row_rule(int iy, int q, std::vector<CellQuadraturePoint>& out) const {
  out.clear();
  const GaussRule& rule = gauss_legendre(q);
  const double h = grid_.h();
  std::size_t next_cut = row_begin_[iy];
  const std::size_t end_cut = row_begin_[iy + 1];
  const CutRules& cut = cut_rules(iy, q);
  const std::vector<QuadraturePoint>& cut_points = cut.points;
  const std::vector<std::size_t>& cut_begin = cut.begin;
  // Node flags of the row's two grid lines, walked left to right with the crossing lists.
  const auto& lower = row_crossings_[iy];
  const auto& upper = row_crossings_[iy + 1];
  std::size_t lo_k = 0, up_k = 0;
  auto inside_lower = [&](int i) {
    while (lo_k < lower.size() && lower[lo_k] < grid_.x(i)) ++lo_k;
    return lo_k % 2 == 1;
  };
  auto inside_upper = [&](int i) {
    while (up_k < upper.size() && upper[up_k] < grid_.x(i)) ++up_k;
    return up_k % 2 == 1;
  };
  bool left_lower = inside_lower(0), left_upper = inside_upper(0);
  for (int ix = 0; ix < grid_.nx(); ++ix) {
    const bool right_lower = inside_lower(ix + 1), right_upper = inside_upper(ix + 1);
    if (next_cut < end_cut && cut_cells_[next_cut].ix == ix) {
      const std::size_t k = next_cut - row_begin_[iy];
      for (std::size_t j = cut_begin[k]; j < cut_begin[k + 1]; ++j)
        out.push_back({ix, cut_points[j].x, cut_points[j].y, cut_points[j].weight});
      ++next_cut;
    } else if (inside_uncut_cell(ix, iy, int(left_lower) + left_upper + right_lower + right_upper)) {
      for (int b = 0; b < q; ++b)
        for (int a = 0; a < q; ++a)
          out.push_back({ix, grid_.x(ix) + rule.nodes[a] * h, grid_.y(iy) + rule.nodes[b] * h,
                         rule.weights[a] * rule.weights[b] * h * h});
    }
    left_lower = right_lower;
    left_upper = right_upper;
  }
}

namespace {

/// The pieces of `cell` split where the outer coordinate turns, so that each part is monotone in
/// it; the outer coordinates of the parts' ends are appended to `breaks`.
struct MonotonePart {
  double t0, t1, c_min, c_max;
};
std::vector<MonotonePart> monotone_parts(const Curve& curve, const std::vector<CurvePiece>& pieces, const CutCell& cell,
                                         int outer, std::vector<double>& breaks) {
  std::vector<MonotonePart> parts;
  for (int k : cell.pieces) {
    const CurvePiece& piece = pieces[k];
    std::vector<double> cuts = {piece.t0};
    constexpr int probes = 8;
    double prev_t = piece.t0, prev_d = component(curve.derivative(prev_t), outer);
    for (int s = 1; s <= probes; ++s) {
      const double t = piece.t0 + (piece.t1 - piece.t0) * s / probes;
      const double d = component(curve.derivative(t), outer);
      if ((d > 0) != (prev_d > 0) && d != 0.0 && prev_d != 0.0) {
        double a = prev_t, b = t, da = prev_d;
        for (int it = 0; it < 60; ++it) {
          const double m = 0.5 * (a + b), dm = component(curve.derivative(m), outer);
          if ((dm > 0) == (da > 0))
            a = m, da = dm;
          else
            b = m;
        }
        cuts.push_back(0.5 * (a + b));
      }
      prev_t = t;
      prev_d = d;
    }
    cuts.push_back(piece.t1);
    for (std::size_t s = 0; s + 1 < cuts.size(); ++s) {
      const double c0 = component(curve.position(cuts[s]), outer);
      const double c1 = component(curve.position(cuts[s + 1]), outer);
      parts.push_back({cuts[s], cuts[s + 1], std::min(c0, c1), std::max(c0, c1)});
      breaks.push_back(c0);
      breaks.push_back(c1);
    }
  }
  return parts;
}

}  // namespace

void CurveGridIntersection::cut_cell_rule(const CutCell& cell, int q, std::vector<QuadraturePoint>& out) const {
  const double h = grid_.h();
  const double lo[2] = {grid_.x(cell.ix), grid_.y(cell.iy)};
  const double hi[2] = {lo[0] + h, lo[1] + h};

  // Integrate along lines of the direction the curve crosses most transversally.
  double extent[2] = {0.0, 0.0};
  for (int k : cell.pieces) {
    const Point2 d = curve_.position(pieces_[k].t1) - curve_.position(pieces_[k].t0);
    extent[0] += std::abs(d.x);
    extent[1] += std::abs(d.y);
  }
  const int outer = extent[0] >= extent[1] ? 0 : 1, inner = 1 - outer;

  // Split the pieces where the outer coordinate turns, so that each part is monotone.
  std::vector<double> breaks = {lo[outer], hi[outer]};
  const std::vector<MonotonePart> parts = monotone_parts(curve_, pieces_, cell, outer, breaks);
  // A corner of γ (a polygon's vertex) in the cell kinks the inside segments' length: split there too.
  for (int k : cell.pieces)
    for (auto c = std::upper_bound(corners_.begin(), corners_.end(), pieces_[k].t0);
         c != corners_.end() && *c < pieces_[k].t1; ++c)
      breaks.push_back(component(curve_.position(*c), outer));
  for (double& b : breaks) b = std::clamp(b, lo[outer], hi[outer]);
  std::sort(breaks.begin(), breaks.end());

  // The boundary is analytic but not polynomial in the outer coordinate: use more points there.
  const GaussRule& rule = gauss_legendre(q);
  const GaussRule& outer_rule = gauss_legendre(std::max(2 * q, 8));
  std::vector<std::pair<double, double>> hits;  // (inner coordinate, inner component of n)
  auto emit = [&](double xi, double w_outer, double a, double b) {
    for (int g = 0; g < q; ++g) {
      const double eta = a + rule.nodes[g] * (b - a);
      const double w = w_outer * rule.weights[g] * (b - a);
      out.push_back(outer == 0 ? QuadraturePoint{xi, eta, w} : QuadraturePoint{eta, xi, w});
    }
  };
  for (std::size_t s = 0; s + 1 < breaks.size(); ++s) {
    const double a = breaks[s], b = breaks[s + 1];
    if (b - a <= 1e-13 * h) continue;
    for (std::size_t g = 0; g < outer_rule.nodes.size(); ++g) {
      const double xi = a + outer_rule.nodes[g] * (b - a), w_outer = outer_rule.weights[g] * (b - a);
      hits.clear();
      for (const MonotonePart& part : parts) {
        if (!(xi > part.c_min && xi < part.c_max)) continue;
        const double t = find_parameter(curve_, outer, xi, part.t0, part.t1);
        hits.push_back({component(curve_.position(t), inner), component(curve_.outward_normal(t), inner)});
      }
      std::sort(hits.begin(), hits.end());
      bool inside;
      if (hits.empty())
        inside = outer == 0 ? inside_on_row(cell.iy, xi) : inside_on_column(cell.ix, xi);
      else
        inside = hits.front().second > 0;  // n points up the line: below the first hit is ω
      double begin = lo[inner];
      for (const auto& hit : hits) {
        const double end = std::clamp(hit.first, lo[inner], hi[inner]);
        if (inside && end > begin) emit(xi, w_outer, begin, end);
        begin = std::max(begin, end);
        inside = !inside;
      }
      if (inside && hi[inner] > begin) emit(xi, w_outer, begin, hi[inner]);
    }
  }
}

}  // namespace fictus
