#include "fictus/collocation.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace fictus {

Collocation make_collocation(const Curve& curve, const ArcLengthTable& arc_length, int m) {
  if (m < 4) throw std::invalid_argument("formulation.multipliers: need m >= 4, got " + std::to_string(m));
  Collocation c;
  c.m = m;
  c.length = arc_length.length();
  c.spacing = c.length / m;
  c.t.resize(m);
  c.arc_begin.resize(m);
  c.arc_end.resize(m);
  c.point.resize(m);
  c.normal.resize(m);
  for (int i = 0; i < m; ++i) {
    c.t[i] = arc_length.t_of_s((i + 0.5) * c.spacing);
    c.arc_begin[i] = i == 0 ? 0.0 : arc_length.t_of_s(i * c.spacing);
    c.arc_end[i] = i == m - 1 ? 2.0 * std::numbers::pi : arc_length.t_of_s((i + 1) * c.spacing);
    c.point[i] = curve.position(c.t[i]);
    c.normal[i] = curve.outward_normal(c.t[i]);
  }
  return c;
}

int default_multipliers(double curve_length, double box_width, double h) {
  constexpr double paper_length = 1.9376896441095;  // perimeter of the 0.4 × 0.2 ellipse
  const double m = 34.0 * (curve_length / box_width) / paper_length *
                   std::pow(box_width / (128.0 * h), 0.85);
  return std::max(8, int(std::lround(m)));
}

}  // namespace fictus
