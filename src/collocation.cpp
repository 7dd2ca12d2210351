#include "fictus/collocation.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace fictus {

Collocation make_collocation(const Curve& curve, const ArcLengthTable& arc_length, int m, double phase) {
  if (m < 1) throw std::invalid_argument("make_collocation: need m >= 1, got " + std::to_string(m));
  Collocation c;
  c.m = m;
  c.length = arc_length.length();
  c.spacing = c.length / m;
  c.phase = phase;
  c.s.resize(m);
  c.t.resize(m);
  c.arc_begin.resize(m);
  c.arc_end.resize(m);
  c.point.resize(m);
  c.normal.resize(m);
  const double two_pi = 2.0 * std::numbers::pi;
  auto t_at = [&](double s) {  // parameter at arc length s (mod L); exact ends at 0 and L
    s = std::fmod(s, c.length);
    s = s < 0 ? s + c.length : s;
    return s <= 0 ? 0.0 : arc_length.t_of_s(s);
  };
  for (int i = 0; i < m; ++i) {
    c.s[i] = (i + phase) * c.spacing;
    c.t[i] = t_at(c.s[i]);
    const double begin = c.s[i] - 0.5 * c.spacing, end = c.s[i] + 0.5 * c.spacing;
    c.arc_begin[i] = std::abs(begin) < 1e-14 * c.length ? 0.0 : t_at(begin);
    c.arc_end[i] = std::abs(end - c.length) < 1e-14 * c.length ? two_pi : t_at(end);
    c.point[i] = curve.position(c.t[i]);
    c.normal[i] = curve.outward_normal(c.t[i]);
  }
  return c;
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
