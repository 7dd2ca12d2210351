#include "fictus/solve/error_norms.hpp"

#include <array>
#include <cmath>
#include <vector>

#include "fictus/boundary/curve_grid_intersection.hpp"
#include "fictus/boundary/omega_quadrature.hpp"
#include "fictus/grid/q1_element.hpp"

namespace fictus {

GradientField numerical_gradient(ScalarField u, double scale) {
  const double e = 1e-6 * scale;
  return [u = std::move(u), e](double x, double y) {
    return Point2{(u(x + e, y) - u(x - e, y)) / (2 * e), (u(x, y + e) - u(x, y - e)) / (2 * e)};
  };
}

Q1Sample sample_q1(const Grid2& grid, const GridVector& u_h, int ix, int iy, double x, double y) {
  auto node = [&](int i, int j) { return grid.has_unknown(i, j) ? u_h[grid.index(i, j)] : 0.0; };
  const double h = grid.h();
  const Q1Element<2>::Sample s =
      Q1Element<2>::interpolate(node(ix, iy), node(ix + 1, iy), node(ix, iy + 1), node(ix + 1, iy + 1),
                                {(x - grid.x(ix)) / h, (y - grid.y(iy)) / h}, h);
  return {s.value, s.gradient};
}

namespace {

/// ∇u at the points: the given gradient, or central differences of u (four batches).
void gradient_at(const VectorizedField& u, const VectorizedGradient& gradient, double e, const std::vector<double>& x,
                 const std::vector<double>& y, std::vector<double>& gx, std::vector<double>& gy) {
  const std::size_t n = x.size();
  gx.resize(n);
  gy.resize(n);
  if (gradient) {
    gradient(n, x.data(), y.data(), gx.data(), gy.data());
    return;
  }
  std::vector<double> shifted(n), plus(n), minus(n);
  for (int axis = 0; axis < 2; ++axis) {
    const std::vector<double>& base = axis == 0 ? x : y;
    for (std::size_t k = 0; k < n; ++k) shifted[k] = base[k] + e;
    axis == 0 ? u(n, shifted.data(), y.data(), plus.data()) : u(n, x.data(), shifted.data(), plus.data());
    for (std::size_t k = 0; k < n; ++k) shifted[k] = base[k] - e;
    axis == 0 ? u(n, shifted.data(), y.data(), minus.data()) : u(n, x.data(), shifted.data(), minus.data());
    std::vector<double>& g = axis == 0 ? gx : gy;
    for (std::size_t k = 0; k < n; ++k) g[k] = (plus[k] - minus[k]) / (2 * e);
  }
}

}  // namespace

ErrorNorms compute_errors(const GridVector& u_h, const CurveGridIntersection& gamma, const ScalarField& exact,
                          const GradientField& exact_gradient, int q, const Execution& execution) {
  VectorizedGradient gradient;
  if (exact_gradient)
    gradient = [exact_gradient](std::size_t n, const double* x, const double* y, double* gx, double* gy) {
      for (std::size_t k = 0; k < n; ++k) {
        const Point2 g = exact_gradient(x[k], y[k]);
        gx[k] = g.x, gy[k] = g.y;
      }
    };
  return compute_errors(u_h, gamma, vectorize(exact), gradient, q, execution);
}

ErrorNorms compute_errors(const GridVector& u_h, const CurveGridIntersection& gamma, const VectorizedField& exact,
                          const VectorizedGradient& exact_gradient, int q, const Execution& execution) {
  const Grid2& grid = gamma.grid();
  const double e = 1e-6 * (grid.box().upper.x - grid.box().lower.x);
  // Over ω, row by row: [e², |∇e|², u², |∇u|²], summed per cell, per row, then over rows.
  std::array<double, 4> omega{};
#pragma omp parallel num_threads(execution.threads())
  {
    std::array<double, 4> local{};
    std::vector<CellQuadraturePoint> points;
    std::vector<double> x, y, u, gx, gy;
#pragma omp for schedule(dynamic, 8)
    for (int iy = 0; iy < grid.ny(); ++iy) {
      gamma.row_rule(iy, q, points);
      const std::size_t n = points.size();
      if (n == 0) continue;
      x.resize(n), y.resize(n), u.resize(n);
      for (std::size_t k = 0; k < n; ++k) x[k] = points[k].x, y[k] = points[k].y;
      exact(n, x.data(), y.data(), u.data());
      gradient_at(exact, exact_gradient, e, x, y, gx, gy);
      std::array<double, 4> row{}, cell{};
      for (std::size_t k = 0; k < n; ++k) {
        const Q1Sample s = sample_q1(grid, u_h, points[k].ix, iy, x[k], y[k]);
        const Point2 du{gx[k], gy[k]};
        const Point2 de = s.gradient - du;
        const double w = points[k].weight;
        cell[0] += w * (s.value - u[k]) * (s.value - u[k]);
        cell[1] += w * dot(de, de);
        cell[2] += w * u[k] * u[k];
        cell[3] += w * dot(du, du);
        if (k + 1 == n || points[k + 1].ix != points[k].ix)
          for (int c = 0; c < 4; ++c) row[c] += cell[c], cell[c] = 0.0;
      }
      for (int c = 0; c < 4; ++c) local[c] += row[c];
    }
#pragma omp critical
    for (int c = 0; c < 4; ++c) omega[c] += local[c];
  }

  // Along γ: the Gauss points of every piece, one batch; [e², u²].
  const GaussRule& rule = gauss_legendre(q);
  std::vector<double> x, y, w, u;
  std::vector<int> cell_x, cell_y;
  for (const CurvePiece& piece : gamma.pieces())
    for (int g = 0; g < q; ++g) {
      const double t = piece.t0 + rule.nodes[g] * (piece.t1 - piece.t0);
      const Point2 p = gamma.curve().position(t);
      x.push_back(p.x), y.push_back(p.y), cell_x.push_back(piece.ix), cell_y.push_back(piece.iy);
      w.push_back(rule.weights[g] * (piece.t1 - piece.t0) * gamma.curve().speed(t));
    }
  u.resize(x.size());
  exact(x.size(), x.data(), y.data(), u.data());
  double boundary_error = 0, boundary_norm = 0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    const double err = sample_q1(grid, u_h, cell_x[k], cell_y[k], x[k], y[k]).value - u[k];
    boundary_error += w[k] * err * err;
    boundary_norm += w[k] * u[k] * u[k];
  }

  ErrorNorms n;
  n.l2_omega = std::sqrt(omega[0]);
  n.h1semi_omega = std::sqrt(omega[1]);
  n.h1_omega = std::sqrt(omega[0] + omega[1]);
  n.l2_gamma = std::sqrt(boundary_error);
  auto rel = [](double err, double norm) { return norm > 0 ? err / norm : err; };
  n.rel_l2_omega = rel(n.l2_omega, std::sqrt(omega[2]));
  n.rel_h1semi_omega = rel(n.h1semi_omega, std::sqrt(omega[3]));
  n.rel_h1_omega = rel(n.h1_omega, std::sqrt(omega[2] + omega[3]));
  n.rel_l2_gamma = rel(n.l2_gamma, std::sqrt(boundary_norm));
  return n;
}

namespace {

/// û at the eight nodes of `cell` (local node k as in Q1Element; 0 where a node has no unknown).
std::array<double, 8> nodal_values(const Grid3& grid, const GridVector& u, const Grid3::Index& cell) {
  std::array<double, 8> v;
  for (int k = 0; k < 8; ++k) {
    const Grid3::Index node{cell[0] + Q1Element<3>::offset(k, 0), cell[1] + Q1Element<3>::offset(k, 1),
                            cell[2] + Q1Element<3>::offset(k, 2)};
    v[std::size_t(k)] = grid.has_unknown(node) ? u[grid.index(node)] : 0.0;
  }
  return v;
}

}  // namespace

void gradient_at(const VectorizedField3& u, const GradientField3& gradient, double e,
                 const std::array<std::vector<double>, 3>& x, std::array<std::vector<double>, 3>& du) {
  const std::size_t n = x[0].size();
  for (auto& d : du) d.resize(n);
  if (gradient) {
    for (std::size_t k = 0; k < n; ++k) {
      const Point3 g = gradient(x[0][k], x[1][k], x[2][k]);
      for (int d = 0; d < 3; ++d) du[d][k] = g[d];
    }
    return;
  }
  std::vector<double> shifted(n), plus(n), minus(n);
  for (int axis = 0; axis < 3; ++axis) {
    const auto at = [&](std::vector<double>& out) {
      const double* c[3] = {x[0].data(), x[1].data(), x[2].data()};
      c[axis] = shifted.data();
      u(n, c[0], c[1], c[2], out.data());
    };
    for (std::size_t k = 0; k < n; ++k) shifted[k] = x[axis][k] + e;
    at(plus);
    for (std::size_t k = 0; k < n; ++k) shifted[k] = x[axis][k] - e;
    at(minus);
    for (std::size_t k = 0; k < n; ++k) du[axis][k] = (plus[k] - minus[k]) / (2 * e);
  }
}

std::array<std::vector<double>, 3> coordinates(const std::vector<Point3>& points) {
  std::array<std::vector<double>, 3> x;
  for (auto& c : x) c.reserve(points.size());
  for (const Point3& p : points)
    for (int d = 0; d < 3; ++d) x[d].push_back(p[d]);
  return x;
}

ErrorNorms compute_errors(const GridVector& u_h, const Grid3& grid, const Surface& gamma, const PatchedSurface& patches,
                          const std::vector<double>& trace, const ScalarField3& exact,
                          const GradientField3& exact_gradient, int q, const Execution& execution) {
  return compute_errors(u_h, grid, gamma, patches, trace, vectorize(exact), exact_gradient, q, execution);
}

ErrorNorms compute_errors(const GridVector& u_h, const Grid3& grid, const Surface& gamma, const PatchedSurface& patches,
                          const std::vector<double>& trace, const VectorizedField3& exact,
                          const GradientField3& exact_gradient, int q, const Execution& execution) {
  const double e = 1e-6 * grid.box().width(0);
  struct Sums {
    double e2 = 0, de2 = 0, u2 = 0, du2 = 0;
  };
  struct Buffers {
    std::array<std::vector<double>, 3> x, du;
    std::vector<double> u;
  };
  std::vector<Sums> sums(execution.threads());
  std::vector<Buffers> buffers(execution.threads());
  for_each_omega_row(grid, gamma, q, execution, [&](int thread, const std::vector<OmegaPoint>& row) {
    Buffers& b = buffers[thread];
    const std::size_t n = row.size();
    for (int d = 0; d < 3; ++d) {
      b.x[d].resize(n);
      for (std::size_t k = 0; k < n; ++k) b.x[d][k] = row[k].x[d];
    }
    b.u.resize(n);
    exact(n, b.x[0].data(), b.x[1].data(), b.x[2].data(), b.u.data());
    gradient_at(exact, exact_gradient, e, b.x, b.du);
    Sums& s = sums[thread];
    std::array<double, 8> nodal{};
    for (std::size_t k = 0; k < n; ++k) {
      if (k == 0 || row[k].cell != row[k - 1].cell) nodal = nodal_values(grid, u_h, row[k].cell);
      Point3 xi;
      for (int d = 0; d < 3; ++d) xi[d] = (row[k].x[d] - grid.coordinate(d, row[k].cell[d])) / grid.h();
      const auto [value, slope] = Q1Element<3>::interpolate(nodal, xi, grid.h());
      const double u = b.u[k];
      const Point3 du{b.du[0][k], b.du[1][k], b.du[2][k]};
      const Point3 de = slope - du;
      const double w = row[k].weight;
      s.e2 += w * (value - u) * (value - u);
      s.de2 += w * dot(de, de);
      s.u2 += w * u * u;
      s.du2 += w * dot(du, du);
    }
  });
  Sums total;
  for (const Sums& s : sums) total.e2 += s.e2, total.de2 += s.de2, total.u2 += s.u2, total.du2 += s.du2;
  const std::array<std::vector<double>, 3> x = coordinates(patches.point);
  std::vector<double> u(x[0].size());
  exact(u.size(), x[0].data(), x[1].data(), x[2].data(), u.data());
  double g2 = 0, gu2 = 0;
  for (int p = 0; p < patches.m; ++p) {
    g2 += patches.area[p] * (trace[p] - u[p]) * (trace[p] - u[p]);
    gu2 += patches.area[p] * u[p] * u[p];
  }
  ErrorNorms out;
  out.l2_omega = std::sqrt(total.e2);
  out.h1semi_omega = std::sqrt(total.de2);
  out.h1_omega = std::sqrt(total.e2 + total.de2);
  out.l2_gamma = std::sqrt(g2);
  const auto relative = [](double error, double norm) { return norm > 0 ? error / norm : error; };
  out.rel_l2_omega = relative(out.l2_omega, std::sqrt(total.u2));
  out.rel_h1semi_omega = relative(out.h1semi_omega, std::sqrt(total.du2));
  out.rel_h1_omega = relative(out.h1_omega, std::sqrt(total.u2 + total.du2));
  out.rel_l2_gamma = relative(out.l2_gamma, std::sqrt(gu2));
  return out;
}

}  // namespace fictus
