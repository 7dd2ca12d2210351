#include "fictus/solve/paper_problem.hpp"

#include <algorithm>
#include <cmath>

#include "fictus/boundary/collocation.hpp"

namespace fictus {

namespace {
double pos(double v) { return v > 0 ? v : 0.0; }
double u_exact(double x, double y) {
  const double a = pos(x - 0.5), b = pos(y - 0.5);
  return a * a * a + 0.5 * b * b * b;
}
}  // namespace

Problem paper_problem(int N, double c, Boundary boundary) {
  Problem p;
  p.name = boundary == Boundary::periodic ? "paper_ellipse_periodic" : "paper_ellipse";
  p.box = Box2{};
  p.N = N;
  p.boundary = boundary;
  p.gamma = std::make_shared<Ellipse>(Point2{0.5, 0.5}, 0.4, 0.2, 0.0);
  p.c = c;
  p.exact = u_exact;
  p.exact_gradient = [](double x, double y) {
    const double a = pos(x - 0.5), b = pos(y - 0.5);
    return Point2{3 * a * a, 1.5 * b * b};
  };
  // −Δu_ex = −6(x−½)⁺ − 3(y−½)⁺
  p.f = [c](double x, double y) { return -6.0 * pos(x - 0.5) - 3.0 * pos(y - 0.5) + c * u_exact(x, y); };
  p.g = [](double x, double y) {
    if (x < 0.5 && y < 0.5) return std::sin(-2.0 * std::atan2(y - 0.5, x - 0.5));
    return u_exact(x, y);
  };
  return p;
}

const std::array<PaperRow, 6>& paper_table(Variant variant) {
  static const std::array<PaperRow, 6> table1{{
      {128, 34, 5, 24, 0.3, 4.10e-2, 3.33e+0, 1.70e-2},
      {256, 62, 6, 45, 1.8, 2.00e-2, 2.33e+0, 8.52e-3},
      {512, 110, 7, 69, 13.1, 9.78e-3, 1.62e+0, 4.25e-3},
      {1024, 198, 7, 93, 74.7, 4.84e-3, 1.14e+0, 2.08e-3},
      {2048, 360, 7, 115, 432.6, 2.27e-3, 7.85e-1, 1.09e-3},
      {4096, 662, 8, 131, 2328, 1.13e-3, 5.54e-1, 7.21e-4},
  }};
  static const std::array<PaperRow, 6> table2{{
      {128, 34, 5, 48, 0.4, 3.24e-4, 2.95e-1, 5.07e-4},
      {256, 62, 5, 69, 2.5, 6.31e-5, 1.30e-1, 9.10e-5},
      {512, 110, 5, 112, 20.9, 1.59e-5, 6.54e-2, 2.65e-5},
      {1024, 198, 7, 162, 150.6, 4.35e-6, 3.42e-2, 1.17e-5},
      {2048, 360, 6, 190, 674.1, 1.38e-6, 1.92e-2, 5.18e-6},
      {4096, 662, 9, 296, 5000, 8.07e-7, 1.47e-2, 2.28e-6},
  }};
  return variant == Variant::nonsmooth ? table1 : table2;
}

std::optional<PaperRow> paper_row(Variant variant, int N) {
  for (const PaperRow& row : paper_table(variant))
    if (row.N == N) return row;
  return std::nullopt;
}

int paper_multipliers(int N) {
  if (auto row = paper_row(Variant::nonsmooth, N)) return row->m;
  return std::max(8, int(std::lround(34.0 * std::pow(N / 128.0, 0.85))));  // the paper's growth, m ∝ N^0.85
}

SolverOptions paper_options(int N, Variant variant) {
  SolverOptions o;
  o.variant = variant;
  o.multipliers = paper_multipliers(N);
  o.offset = paper_row(variant, N) ? 1.0 : 0.0;  // the paper's δ = L/m at its grids, else the default rule
  return o;
}

std::array<double, 3> paper_rates(Variant variant) {
  return variant == Variant::nonsmooth ? std::array<double, 3>{1.03, 0.51, 0.93}
                                       : std::array<double, 3>{1.76, 0.88, 1.50};
}

}  // namespace fictus
