#include "fictus/boundary/collocation.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace fictus {

Collocation make_collocation(const Curve& curve, const ArcLengthTable& arc_length, int m, double phase,
                             const ArcLengthTable* placement) {
  if (m < 1) throw std::invalid_argument("make_collocation: need m >= 1, got " + std::to_string(m));
  Collocation c;
  c.m = m;
  c.length = arc_length.length();
  c.spacing = c.length / m;
  c.phase = phase;
  c.s.resize(m);
  c.arc.resize(m);
  c.t.resize(m);
  c.arc_begin.resize(m);
  c.arc_end.resize(m);
  c.point.resize(m);
  c.normal.resize(m);
  const double two_pi = 2.0 * std::numbers::pi;
  const ArcLengthTable& measure = placement ? *placement : arc_length;
  const double total = measure.length(), step = total / m;
  auto t_at = [&](double w) {  // parameter at measure w (mod the total); exact ends at 0 and the total
    w = std::fmod(w, total);
    w = w < 0 ? w + total : w;
    return w <= 0 ? 0.0 : measure.t_of_s(w);
  };
  for (int i = 0; i < m; ++i) {
    const double w = (i + phase) * step, begin = w - 0.5 * step, end = w + 0.5 * step;
    c.t[i] = t_at(w);
    c.arc_begin[i] = std::abs(begin) < 1e-14 * total ? 0.0 : t_at(begin);
    c.arc_end[i] = std::abs(end - total) < 1e-14 * total ? two_pi : t_at(end);
    c.point[i] = curve.position(c.t[i]);
    c.normal[i] = curve.outward_normal(c.t[i]);
    if (placement) {
      c.s[i] = arc_length.s_of_t(c.t[i]);
      const double from = arc_length.s_of_t(c.arc_begin[i]), to = arc_length.s_of_t(c.arc_end[i]);
      c.arc[i] = to >= from ? to - from : to + c.length - from;
    } else {
      c.s[i] = w;
      c.arc[i] = c.spacing;
    }
  }
  return c;
}

ArcLengthTable offset_placement(const Curve& curve, double delta) {
  return ArcLengthTable(
      [&curve, delta](double t) { return curve.speed(t) * std::max(1.0, 1.0 + delta * curve.curvature(t)); });
}

double phase_off_corners(const Curve& curve, const ArcLengthTable& arc_length, int m) {
  const std::vector<double> corners = curve.corners();
  if (corners.empty()) return 0.5;
  const double spacing = arc_length.length() / m;
  double best_phase = 0.5, best_distance = -1.0;
  for (int k = 0; k < 32; ++k) {
    const double phase = std::fmod(0.5 + k / 32.0, 1.0);
    double distance = 1e300;
    for (double t : corners) {
      const double u = arc_length.s_of_t(t) / spacing - phase;  // in units of the spacing
      distance = std::min(distance, std::abs(u - std::round(u)));
    }
    if (distance > best_distance + 1e-12) best_distance = distance, best_phase = phase;
  }
  return best_phase;
}

int default_multipliers(double curve_length, double h, double spacing_cells) {
  return std::max(minimum_multipliers, int(std::lround(curve_length / (spacing_cells * h))));
}

}  // namespace fictus
