#include "fictus/solve/error_norms.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <omp.h>

#include "fictus/boundary/curve_grid_intersection.hpp"
#include "fictus/boundary/omega_quadrature.hpp"
#include "fictus/grid/distribution.hpp"
#include "fictus/grid/q1_element.hpp"

namespace fictus {

GradientField numerical_gradient(ScalarField u, double scale) {
  const double e = 1e-6 * scale;
  return [u = std::move(u), e](double x, double y) {
    return Point2{(u(x + e, y) - u(x - e, y)) / (2 * e), (u(x, y + e) - u(x, y - e)) / (2 * e)};
  };
}

Q1Sample sample_q1(const Grid2& grid, const GridVector& u_h, int ix, int iy, double x, double y) {
  return sample_q1(grid, u_h, grid.every_layer(), ix, iy, x, y);
}

Q1Sample sample_q1(const Grid2& grid, const GridVector& u_h, const Slab& slab, int ix, int iy, double x, double y) {
  auto node = [&](int i, int j) { return grid.has_unknown(i, j) ? u_h[grid.slab_index({i, j}, slab)] : 0.0; };
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

void for_each_omega_sample(const GridVector& u_h, const CurveGridIntersection& gamma, int q, const Execution& execution,
                           const OmegaSampleVisitor<2>& visit, std::optional<Slab> slab) {
  const Grid2& grid = gamma.grid();
  const Distribution& distribution = execution.distribution();
  if (!slab && distribution.distributed())  // this rank's layers: add the next one
    return for_each_omega_sample(distribution.with_next_layer(grid, u_h), gamma, q, execution, visit,
                                 distribution.slab(grid));
  const Slab s = slab.value_or(grid.every_layer());
#pragma omp parallel num_threads(execution.threads())
  {
    const int thread = omp_get_thread_num();
    std::vector<CellQuadraturePoint> points;
    OmegaSamples<2> row;
#pragma omp for schedule(dynamic, 8)
    for (int iy = 0; iy < grid.ny(); ++iy) {
      if (!s.holds(grid.cell_layer(iy))) continue;
      gamma.row_rule(iy, q, points);
      const std::size_t n = points.size();
      if (n == 0) continue;
      for (auto* v : {&row.x[0], &row.x[1], &row.weight, &row.value, &row.gradient[0], &row.gradient[1]}) v->resize(n);
      for (std::size_t k = 0; k < n; ++k) {
        const CellQuadraturePoint& p = points[k];
        const Q1Sample sample = sample_q1(grid, u_h, s, p.ix, iy, p.x, p.y);
        row.x[0][k] = p.x, row.x[1][k] = p.y, row.weight[k] = p.weight, row.value[k] = sample.value;
        row.gradient[0][k] = sample.gradient.x, row.gradient[1][k] = sample.gradient.y;
      }
      visit(thread, row);
    }
  }
}

void evaluate_at(const VectorizedField& f, const std::array<std::vector<double>, 2>& x, std::vector<double>& out) {
  out.resize(x[0].size());
  f(out.size(), x[0].data(), x[1].data(), out.data());
}

void evaluate_at(const VectorizedField3& f, const std::array<std::vector<double>, 3>& x, std::vector<double>& out) {
  out.resize(x[0].size());
  f(out.size(), x[0].data(), x[1].data(), x[2].data(), out.data());
}

namespace {

/// Σ w·[(û − u)², |∇û − ∇u|², u², |∇u|²] over ω, u and ∇u evaluated by `exact` on each row's points.
template <int dim, class Sampler, class Exact>
std::array<double, 4> omega_error_sums(const Sampler& for_each_sample, const Exact& exact, const Execution& execution) {
  struct Buffers {
    std::vector<double> u;
    std::array<std::vector<double>, dim> du;
  };
  std::vector<std::array<double, 4>> sums(std::size_t(execution.threads()), std::array<double, 4>{});
  std::vector<Buffers> buffers(sums.size());
  for_each_sample([&](int thread, const OmegaSamples<dim>& row) {
    Buffers& b = buffers[std::size_t(thread)];
    exact(row.x, b.u, b.du);
    std::array<double, 4> s{};  // per row, then per thread: round-off stays ~1e-15 of the total
    for (std::size_t k = 0; k < row.size(); ++k) {
      double de2 = 0, du2 = 0;
      for (int d = 0; d < dim; ++d) {
        const double de = row.gradient[d][k] - b.du[d][k];
        de2 += de * de, du2 += b.du[d][k] * b.du[d][k];
      }
      const double w = row.weight[k], e = row.value[k] - b.u[k];
      s[0] += w * e * e, s[1] += w * de2, s[2] += w * b.u[k] * b.u[k], s[3] += w * du2;
    }
    for (int c = 0; c < 4; ++c) sums[std::size_t(thread)][std::size_t(c)] += s[std::size_t(c)];
  });
  std::array<double, 4> total{};
  for (const auto& s : sums)
    for (int c = 0; c < 4; ++c) total[std::size_t(c)] += s[std::size_t(c)];
  execution.distribution().sum(total.data(), total.size());  // the ranks' cells
  return total;
}

/// The norms from the sums over ω ([e², |∇e|², u², |∇u|²]) and along γ (e², u²).
ErrorNorms norms_from(const std::array<double, 4>& omega, double boundary_error, double boundary_norm) {
  ErrorNorms n;
  n.l2_omega = std::sqrt(omega[0]);
  n.h1semi_omega = std::sqrt(omega[1]);
  n.h1_omega = std::sqrt(omega[0] + omega[1]);
  n.l2_gamma = std::sqrt(boundary_error);
  const auto relative = [](double error, double norm) { return norm > 0 ? error / norm : error; };
  n.rel_l2_omega = relative(n.l2_omega, std::sqrt(omega[2]));
  n.rel_h1semi_omega = relative(n.h1semi_omega, std::sqrt(omega[3]));
  n.rel_h1_omega = relative(n.h1_omega, std::sqrt(omega[2] + omega[3]));
  n.rel_l2_gamma = relative(n.l2_gamma, std::sqrt(boundary_norm));
  n.exact_l2_omega = std::sqrt(omega[2]);
  n.exact_h1semi_omega = std::sqrt(omega[3]);
  return n;
}

}  // namespace

ErrorNorms compute_errors(const GridVector& u_h, const CurveGridIntersection& gamma, const VectorizedField& exact,
                          const VectorizedGradient& exact_gradient, int q, const Execution& execution) {
  const Grid2& grid = gamma.grid();
  const double e = 1e-6 * (grid.box().upper.x - grid.box().lower.x);
  // Distributed: u_h is this rank's layers; the cells of its layers read them and the next one.
  const Distribution& distribution = execution.distribution();
  const Slab slab = distribution.slab(grid);
  const GridVector held = distribution.distributed() ? distribution.with_next_layer(grid, u_h) : GridVector();
  const GridVector& u = distribution.distributed() ? held : u_h;
  const std::array<double, 4> omega = omega_error_sums<2>(
      [&](const OmegaSampleVisitor<2>& visit) { for_each_omega_sample(u, gamma, q, execution, visit, slab); },
      [&](const std::array<std::vector<double>, 2>& x, std::vector<double>& u, std::array<std::vector<double>, 2>& du) {
        evaluate_at(exact, x, u);
        gradient_at(exact, exact_gradient, e, x[0], x[1], du[0], du[1]);
      },
      execution);

  // Along γ: the Gauss points of every piece, one batch; [e², u²].
  const GaussRule& rule = gauss_legendre(q);
  std::vector<double> x, y, w, values;
  std::vector<int> cell_x, cell_y;
  for (const CurvePiece& piece : gamma.pieces())
    for (int g = 0; g < q; ++g) {
      const double t = piece.t0 + rule.nodes[g] * (piece.t1 - piece.t0);
      const Point2 p = gamma.curve().position(t);
      x.push_back(p.x), y.push_back(p.y), cell_x.push_back(piece.ix), cell_y.push_back(piece.iy);
      w.push_back(rule.weights[g] * (piece.t1 - piece.t0) * gamma.curve().speed(t));
    }
  values.resize(x.size());
  exact(x.size(), x.data(), y.data(), values.data());
  std::array<double, 2> boundary{};  // [e², u²]
  for (std::size_t k = 0; k < x.size(); ++k) {
    if (!slab.holds(grid.cell_layer(cell_y[k]))) continue;
    const double err = sample_q1(grid, u, slab, cell_x[k], cell_y[k], x[k], y[k]).value - values[k];
    boundary[0] += w[k] * err * err;
    boundary[1] += w[k] * values[k] * values[k];
  }
  distribution.sum(boundary.data(), boundary.size());
  return norms_from(omega, boundary[0], boundary[1]);
}

namespace {

/// û at the eight nodes of `cell` (local node k as in Q1Element; 0 where a node has no unknown).
std::array<double, 8> nodal_values(const Grid3& grid, const GridVector& u, const Slab& slab, const Grid3::Index& cell) {
  std::array<double, 8> v;
  for (int k = 0; k < 8; ++k) {
    const Grid3::Index node{cell[0] + Q1Element<3>::offset(k, 0), cell[1] + Q1Element<3>::offset(k, 1),
                            cell[2] + Q1Element<3>::offset(k, 2)};
    v[std::size_t(k)] = grid.has_unknown(node) ? u[grid.slab_index(node, slab)] : 0.0;
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

void for_each_omega_sample(const GridVector& u_h, const Grid3& grid, const Surface& gamma, int q,
                           const Execution& execution, const OmegaSampleVisitor<3>& visit, std::optional<Slab> slab) {
  const Distribution& distribution = execution.distribution();
  if (!slab && distribution.distributed())  // this rank's layers: add the next one
    return for_each_omega_sample(distribution.with_next_layer(grid, u_h), grid, gamma, q, execution, visit,
                                 distribution.slab(grid));
  const Slab s = slab.value_or(grid.every_layer());
  std::vector<OmegaSamples<3>> rows(std::size_t(execution.threads()));
  for_each_omega_row(grid, gamma, q, execution, s, [&](int thread, const std::vector<OmegaPoint>& points) {
    OmegaSamples<3>& row = rows[std::size_t(thread)];
    const std::size_t n = points.size();
    for (auto* v : {&row.x[0], &row.x[1], &row.x[2], &row.weight, &row.value, &row.gradient[0], &row.gradient[1],
                    &row.gradient[2]})
      v->resize(n);
    std::array<double, 8> nodal{};
    for (std::size_t k = 0; k < n; ++k) {
      const OmegaPoint& p = points[k];
      if (k == 0 || p.cell != points[k - 1].cell) nodal = nodal_values(grid, u_h, s, p.cell);
      Point3 xi;
      for (int d = 0; d < 3; ++d) xi[d] = (p.x[d] - grid.coordinate(d, p.cell[d])) / grid.h();
      const auto [value, slope] = Q1Element<3>::interpolate(nodal, xi, grid.h());
      for (int d = 0; d < 3; ++d) row.x[d][k] = p.x[d], row.gradient[d][k] = slope[d];
      row.weight[k] = p.weight, row.value[k] = value;
    }
    visit(thread, row);
  });
}

template <int dim>
void sample_q1_at(const Grid<dim>& grid, const GridVector& u_h, const std::array<std::vector<double>, dim>& x,
                  std::vector<double>& out, std::optional<Slab> held) {
  const std::size_t n = x[0].size();
  out.resize(n);
  const int L = grid.layers();
  const std::size_t layer_size = grid.layer_size();
  const auto at = [&](const typename Grid<dim>::Index& node) {
    if (!held) return u_h[grid.index(node)];
    const int l = grid.layer(node[dim - 1]), place = ((l - held->first) % L + L) % L;
    if (place >= held->count) throw std::logic_error("sample_q1_at: a point's cell lies outside the held layers");
    return u_h[grid.index(node) - std::size_t(l) * layer_size + std::size_t(place) * layer_size];
  };
  for (std::size_t k = 0; k < n; ++k) {
    typename Grid<dim>::Index cell;
    Point<dim> xi;
    for (int d = 0; d < dim; ++d) {
      cell[d] = std::clamp(int(std::floor((x[d][k] - grid.box().lower[d]) / grid.h())), 0, grid.n(d) - 1);
      xi[d] = (x[d][k] - grid.coordinate(d, cell[d])) / grid.h();
    }
    std::array<double, 1 << dim> nodal;
    for (int c = 0; c < (1 << dim); ++c) {
      typename Grid<dim>::Index node = cell;
      for (int d = 0; d < dim; ++d) node[d] += (c >> d) & 1;
      nodal[std::size_t(c)] = grid.has_unknown(node) ? at(node) : 0.0;
    }
    if constexpr (dim == 2)
      out[k] = Q1Element<2>::interpolate(nodal[0], nodal[1], nodal[2], nodal[3], xi, grid.h()).value;
    else
      out[k] = Q1Element<3>::interpolate(nodal, xi, grid.h()).value;
  }
}

template <int dim>
Slab coarse_layers_under(const Grid<dim>& fine, const Slab& slab, const Grid<dim>& coarse) {
  if (slab.count == 0) return Slab{0, 0};
  constexpr int s = dim - 1;  // the slowest axis
  // The cells of the slab's layers (Grid::cell_layer), their extent, the coarse nodes around it.
  const int c_lo = fine.periodic() ? slab.first : slab.first > 0 ? slab.first + 1 : 0;
  const int c_hi = fine.periodic() ? slab.first + slab.count - 1 : slab.first + slab.count;
  const double lower = coarse.box().lower[s], H = coarse.h();
  const int lo = int(std::floor((fine.coordinate(s, c_lo) - lower) / H)) - 1;
  const int hi = int(std::floor((fine.coordinate(s, c_hi + 1) - lower) / H)) + 2;
  const int L = coarse.layers();
  if (coarse.periodic()) return Slab{((lo % L) + L) % L, std::min(hi - lo + 1, L)};
  const int first = std::max(lo - 1, 0), last = std::min(hi - 1, L - 1);  // layer = node − 1
  return Slab{first, std::max(last - first + 1, 0)};
}

template void sample_q1_at<2>(const Grid<2>&, const GridVector&, const std::array<std::vector<double>, 2>&,
                              std::vector<double>&, std::optional<Slab>);
template void sample_q1_at<3>(const Grid<3>&, const GridVector&, const std::array<std::vector<double>, 3>&,
                              std::vector<double>&, std::optional<Slab>);
template Slab coarse_layers_under(const Grid<2>&, const Slab&, const Grid<2>&);
template Slab coarse_layers_under(const Grid<3>&, const Slab&, const Grid<3>&);

ErrorNorms compute_errors(const GridVector& u_h, const Grid3& grid, const Surface& gamma, const PatchedSurface& patches,
                          const std::vector<double>& trace, const VectorizedField3& exact,
                          const GradientField3& exact_gradient, int q, const Execution& execution) {
  const double e = 1e-6 * grid.box().width(0);
  const std::array<double, 4> omega = omega_error_sums<3>(
      [&](const OmegaSampleVisitor<3>& visit) { for_each_omega_sample(u_h, grid, gamma, q, execution, visit); },
      [&](const std::array<std::vector<double>, 3>& x, std::vector<double>& u, std::array<std::vector<double>, 3>& du) {
        evaluate_at(exact, x, u);
        gradient_at(exact, exact_gradient, e, x, du);
      },
      execution);
  const std::array<std::vector<double>, 3> x = coordinates(patches.point);
  std::vector<double> u;
  evaluate_at(exact, x, u);
  double g2 = 0, gu2 = 0;
  for (int p = 0; p < patches.m; ++p) {
    g2 += patches.area[p] * (trace[p] - u[p]) * (trace[p] - u[p]);
    gu2 += patches.area[p] * u[p] * u[p];
  }
  return norms_from(omega, g2, gu2);
}

}  // namespace fictus
