#include "fictus/error_norms.hpp"

#include <cmath>

namespace fictus {

GradientField numerical_gradient(ScalarField u, double scale) {
  const double e = 1e-6 * scale;
  return [u = std::move(u), e](double x, double y) {
    return Point{(u(x + e, y) - u(x - e, y)) / (2 * e), (u(x, y + e) - u(x, y - e)) / (2 * e)};
  };
}

Q1Sample sample_q1(const Grid& grid, const GridVector& u_h, int ix, int iy, double x, double y) {
  auto node = [&](int i, int j) { return grid.has_unknown(i, j) ? u_h[grid.index(i, j)] : 0.0; };
  const double h = grid.h();
  const double xi = (x - grid.x(ix)) / h, eta = (y - grid.y(iy)) / h;
  const double u00 = node(ix, iy), u10 = node(ix + 1, iy), u01 = node(ix, iy + 1), u11 = node(ix + 1, iy + 1);
  return {u00 * (1 - xi) * (1 - eta) + u10 * xi * (1 - eta) + u01 * (1 - xi) * eta + u11 * xi * eta,
          {((u10 - u00) * (1 - eta) + (u11 - u01) * eta) / h, ((u01 - u00) * (1 - xi) + (u11 - u10) * xi) / h}};
}

ErrorNorms compute_errors(const GridVector& u_h, const CurveGridIntersection& gamma, const ScalarField& exact,
                          const GradientField& exact_gradient, int q, int threads) {
  const Grid& grid = gamma.grid();
  // [e², |∇e|², u², |∇u|²] over ω
  const auto omega = integrate_over_domain<4>(
      gamma, q,
      [&](int ix, int iy, double x, double y) {
        const Q1Sample s = sample_q1(grid, u_h, ix, iy, x, y);
        const double u = exact(x, y);
        const Point du = exact_gradient(x, y);
        const Point de = s.gradient - du;
        return std::array<double, 4>{(s.value - u) * (s.value - u), dot(de, de), u * u, dot(du, du)};
      },
      threads);
  const auto boundary = integrate_along_curve<2>(gamma, q, [&](int ix, int iy, double, Point p) {
    const double e = sample_q1(grid, u_h, ix, iy, p.x, p.y).value - exact(p.x, p.y);
    const double u = exact(p.x, p.y);
    return std::array<double, 2>{e * e, u * u};
  });
  ErrorNorms n;
  n.l2_omega = std::sqrt(omega[0]);
  n.h1semi_omega = std::sqrt(omega[1]);
  n.h1_omega = std::sqrt(omega[0] + omega[1]);
  n.l2_gamma = std::sqrt(boundary[0]);
  auto rel = [](double e, double u) { return u > 0 ? e / u : e; };
  n.rel_l2_omega = rel(n.l2_omega, std::sqrt(omega[2]));
  n.rel_h1semi_omega = rel(n.h1semi_omega, std::sqrt(omega[3]));
  n.rel_h1_omega = rel(n.h1_omega, std::sqrt(omega[2] + omega[3]));
  n.rel_l2_gamma = rel(n.l2_gamma, std::sqrt(boundary[1]));
  return n;
}

}  // namespace fictus
