#include "fictus/boundary/trace_operators.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include <Eigen/Dense>

#include "fictus/boundary/surface.hpp"
#include "fictus/grid/q1_element.hpp"
#include "fictus/grid/quadrature.hpp"

namespace fictus {

namespace {

/// Collects the entries of one row, merging repeated nodes (2-D or 3-D grids).
template <int dim>
class RowBuilder {
 public:
  RowBuilder(const Grid<dim>& grid, SparseRows& rows) : grid_(grid), rows_(rows) {}
  void add(int i, int j, double value) requires(dim == 2) { add(typename Grid<dim>::Index{i, j}, value); }
  void add(const typename Grid<dim>::Index& node, double value) {
    if (!grid_.has_unknown(node)) return;
    const std::size_t index = grid_.index(node);  // periodic boxes: (0, j) and (nx, j) are one node
    for (std::size_t k = rows_.row_begin.back(); k < rows_.entries.size(); ++k)
      if (rows_.entries[k].index == index) {
        rows_.entries[k].value += value;
        return;
      }
    rows_.entries.push_back({index, node[0], node[1], dim == 3 ? node[dim - 1] : 0, value});
  }
  /// Multilinear weights of point p in cell `cell`, scaled by w.
  void add_multilinear(const typename Grid<dim>::Index& cell, const Point<dim>& p, double w) {
    Point<dim> xi;
    for (int d = 0; d < dim; ++d) xi[d] = (p[d] - grid_.coordinate(d, cell[d])) / grid_.h();
    const Q1Element<dim> element(xi, grid_.h());
    for (int k = 0; k < Q1Element<dim>::n_nodes; ++k) {
      typename Grid<dim>::Index node = cell;
      for (int d = 0; d < dim; ++d) node[d] += Q1Element<dim>::offset(k, d);
      add(node, w * element.value[k]);
    }
  }
  void add_bilinear(int ix, int iy, Point2 p, double w) requires(dim == 2) { add_multilinear({ix, iy}, p, w); }
  void end_row() { rows_.row_begin.push_back(rows_.entries.size()); }

 private:
  const Grid<dim>& grid_;
  SparseRows& rows_;
};

template <int dim>
typename Grid<dim>::Index cell_of(const Grid<dim>& grid, const Point<dim>& p) {
  typename Grid<dim>::Index cell;
  for (int d = 0; d < dim; ++d) cell[d] = grid.cell(d, p[d]);
  return cell;
}

}  // namespace

SparseRows point_value_rows(const Grid2& grid, const std::vector<Point2>& points) {
  SparseRows rows;
  RowBuilder builder(grid, rows);
  for (const Point2& p : points) {
    builder.add_bilinear(grid.cell_x(p.x), grid.cell_y(p.y), p, 1.0);
    builder.end_row();
  }
  return rows;
}

SparseRows normal_derivative_rows(const Grid2& grid, const std::vector<Point2>& points,
                                  const std::vector<Point2>& normals, double shift) {
  if (points.size() != normals.size()) throw std::invalid_argument("normal_derivative_rows: size mismatch");
  SparseRows rows;
  RowBuilder builder(grid, rows);
  for (std::size_t r = 0; r < points.size(); ++r) {
    const Point2 n = normals[r];
    const Point2 p = points[r] - shift * n;
    const Q1Cell2 cell = q1_cell(grid, p);  // n·∇u_h of the cell holding p
    for (int k = 0; k < Q1Element<2>::n_nodes; ++k)
      builder.add(cell.ix + Q1Element<2>::offset(k, 0), cell.iy + Q1Element<2>::offset(k, 1),
                  dot(n, cell.element.gradient(k)));
    builder.end_row();
  }
  return rows;
}

namespace {

/// Values and derivatives at ξ of the 1-D Lagrange basis on the nodes first, first + 1, …, first + p.
struct LagrangeBasis {
  std::array<double, 4> value{}, derivative{};
};

LagrangeBasis lagrange_basis(int first, int p, double xi) {
  LagrangeBasis b;
  for (int a = 0; a <= p; ++a) {
    const double xa = first + a;
    double value = 1.0, derivative = 0.0;
    for (int c = 0; c <= p; ++c) {
      if (c == a) continue;
      const double xc = first + c;
      derivative = derivative * (xi - xc) / (xa - xc) + value / (xa - xc);
      value *= (xi - xc) / (xa - xc);
    }
    b.value[a] = value;
    b.derivative[a] = derivative;
  }
  return b;
}

}  // namespace

SparseRows normal_derivative_rows_centered(const Grid2& grid, const std::vector<Point2>& points,
                                           const std::vector<Point2>& normals, int degree) {
  if (points.size() != normals.size()) throw std::invalid_argument("normal_derivative_rows: size mismatch");
  if (degree < 1 || degree > 3)
    throw std::invalid_argument("normal_derivative_rows_centered: degree must be 1, 2 or 3");
  SparseRows rows;
  RowBuilder builder(grid, rows);
  const double h = grid.h();
  for (std::size_t r = 0; r < points.size(); ++r) {
    const Point2 p = points[r], n = normals[r];
    // Local coordinates in cells from the lower-left node of the cell of p; the stencil's first
    // node: the cell itself (p = 1), the nearest node − 1 (p = 2), the cell's node − 1 (p = 3).
    const int ix = grid.cell_x(p.x), iy = grid.cell_y(p.y);
    const double xi = (p.x - grid.x(ix)) / h, eta = (p.y - grid.y(iy)) / h;
    auto first = [&](double t) { return degree == 2 ? (t < 0.5 ? -1 : 0) : (degree == 3 ? -1 : 0); };
    const int fx = first(xi), fy = first(eta);
    const LagrangeBasis bx = lagrange_basis(fx, degree, xi), by = lagrange_basis(fy, degree, eta);
    for (int b = 0; b <= degree; ++b)
      for (int a = 0; a <= degree; ++a)
        builder.add(ix + fx + a, iy + fy + b,
                    (n.x * bx.derivative[a] * by.value[b] + n.y * bx.value[a] * by.derivative[b]) / h);
    builder.end_row();
  }
  return rows;
}

namespace {

/// The one-sided least-squares rows of one_sided_rows (trace_operators.hpp) on a grid of either
/// dimension; `inside(node)` says whether a node lies in ω.
template <int dim, class Inside>
SparseRows one_sided_fit(const Grid<dim>& grid, const Inside& inside, const std::vector<Point<dim>>& points,
                         const std::vector<Point<dim>>& normals, OneSidedTrace trace, int degree, double radius) {
  if (points.size() != normals.size()) throw std::invalid_argument("one_sided_rows: size mismatch");
  if (degree < 1 || degree > 3) throw std::invalid_argument("one_sided_rows: degree must be 1, 2 or 3");
  if (!(radius > 0 && radius <= 64)) throw std::invalid_argument("one_sided_rows: radius must be in (0, 64] cells");
  const double h = grid.h();
  // 1, ξ_d (+ ξ_a ξ_b, halved where a = b, for a ≤ b; + ξ_a ξ_b ξ_c, a ≤ b ≤ c, unscaled: only the
  // linear coefficients are read), ξ = (x − x_i)/h; in 2-D, degree 2: 1, ξ, η, ξ²/2, ξη, η²/2
  const int n_terms = degree == 1 ? 1 + dim : degree == 2 ? 1 + dim + dim * (dim + 1) / 2 : (dim == 2 ? 10 : 20);
  SparseRows rows;
  RowBuilder builder(grid, rows);
  std::vector<typename Grid<dim>::Index> nodes;
  std::vector<Point<dim>> offsets;
  std::vector<double> w;
  Eigen::MatrixXd M;
  Eigen::VectorXd W;
  for (std::size_t r = 0; r < points.size(); ++r) {
    const Point<dim> p = points[r], n = normals[r];
    // Nodes of ω in a ball around x_i; the ball grows by ½ cell until the fit is well posed.
    for (double R = radius;; R += 0.5) {
      if (R > radius + 8) throw std::runtime_error("one_sided_rows: too few nodes of ω near a collocation point");
      nodes.clear(), offsets.clear(), w.clear();
      typename Grid<dim>::Index lo, hi, node;
      bool finite = true, empty = false;
      for (int d = 0; d < dim; ++d) {
        const double c = std::clamp((p[d] - grid.box().lower[d]) / h, -R - 1, grid.n(d) + R + 1);  // NaN stays NaN
        finite = finite && std::isfinite(c);
        if (!finite) break;
        lo[d] = std::max(int(std::floor(c - R)), 0), hi[d] = std::min(int(std::ceil(c + R)), grid.n(d));
        empty = empty || lo[d] > hi[d];
      }
      if (!finite) break;   // refused below
      if (empty) continue;  // p outside the box, farther than R: a larger ball may reach it
      node = lo;
      for (;;) {  // the first axis fastest
        Point<dim> e;
        double d2 = 0;
        for (int d = 0; d < dim; ++d) e[d] = (grid.coordinate(d, node[d]) - p[d]) / h, d2 += e[d] * e[d];
        if (d2 <= R * R && inside(node)) {
          nodes.push_back(node);
          offsets.push_back(e);
          const double q = 1.0 - d2 / (R * R);
          w.push_back(std::sqrt(q * q + 1e-3));  // square root of the weight
        }
        int d = 0;
        while (d < dim && node[d] == hi[d]) node[d] = lo[d], ++d;
        if (d == dim) break;
        ++node[d];
      }
      const int K = int(nodes.size());
      if (K < 2 * n_terms) continue;
      M.resize(K, n_terms);
      W.resize(K);
      for (int k = 0; k < K; ++k) {
        const Point<dim>& e = offsets[std::size_t(k)];
        int t = 0;
        M(k, t++) = w[k];
        for (int d = 0; d < dim; ++d) M(k, t++) = w[k] * e[d];
        if (degree >= 2)
          for (int a = 0; a < dim; ++a)
            for (int b = a; b < dim; ++b) M(k, t++) = w[k] * (a == b ? 0.5 : 1.0) * e[a] * e[b];
        if (degree == 3)
          for (int a = 0; a < dim; ++a)
            for (int b = a; b < dim; ++b)
              for (int c = b; c < dim; ++c) M(k, t++) = w[k] * e[a] * e[b] * e[c];
        W(k) = w[k];
      }
      const Eigen::JacobiSVD<Eigen::MatrixXd> svd(M);
      const auto& sv = svd.singularValues();
      if (sv(n_terms - 1) > 1e-3 * sv(0)) break;
    }
    if (int(nodes.size()) < 2 * n_terms)
      throw std::runtime_error("one_sided_rows: too few nodes of ω near a collocation point");
    // Coefficients of the fit as linear functionals of the nodal values: (WM)⁺W.
    const Eigen::MatrixXd coefficients = M.completeOrthogonalDecomposition().pseudoInverse() * W.asDiagonal();
    for (int k = 0; k < int(nodes.size()); ++k) {
      double value = coefficients(0, k);
      if (trace == OneSidedTrace::normal_derivative) {
        value = 0;
        for (int d = 0; d < dim; ++d) value += n[d] * coefficients(1 + d, k);
        value /= h;
      }
      builder.add(nodes[std::size_t(k)], value);
    }
    builder.end_row();
  }
  return rows;
}

}  // namespace

SparseRows one_sided_rows(const CurveGridIntersection& gamma, const std::vector<Point2>& points,
                          const std::vector<Point2>& normals, OneSidedTrace trace, int degree, double radius) {
  return one_sided_fit<2>(
      gamma.grid(), [&](const Grid2::Index& node) { return gamma.node_inside(node[0], node[1]); }, points, normals,
      trace, degree, radius);
}

SparseRows arc_integral_rows(const CurveGridIntersection& geometry, const std::vector<double>& arc_begin,
                             const std::vector<double>& arc_end, int q) {
  const Grid2& grid = geometry.grid();
  const Curve& curve = geometry.curve();
  const GaussRule& rule = gauss_legendre(q);
  SparseRows rows;
  RowBuilder builder(grid, rows);
  auto add_interval = [&](double ta, double tb) {
    const auto [first, last] = geometry.pieces_in(ta, tb);
    for (std::size_t k = first; k < last; ++k) {
      const CurvePiece& piece = geometry.pieces()[k];
      const double t0 = std::max(piece.t0, ta), t1 = std::min(piece.t1, tb);
      if (!(t1 > t0)) continue;
      for (int g = 0; g < q; ++g) {
        const double t = t0 + rule.nodes[g] * (t1 - t0);
        builder.add_bilinear(piece.ix, piece.iy, curve.position(t), rule.weights[g] * (t1 - t0) * curve.speed(t));
      }
    }
  };
  for (std::size_t r = 0; r < arc_begin.size(); ++r) {
    if (arc_begin[r] <= arc_end[r]) {
      add_interval(arc_begin[r], arc_end[r]);
    } else {  // the arc wraps past t = 0
      add_interval(arc_begin[r], 2.0 * std::numbers::pi);
      add_interval(0.0, arc_end[r]);
    }
    builder.end_row();
  }
  return rows;
}

}  // namespace fictus

namespace fictus {

SparseRows point_value_rows(const Grid3& grid, const std::vector<Point3>& points) {
  SparseRows rows;
  RowBuilder builder(grid, rows);
  for (const Point3& p : points) {
    builder.add_multilinear(cell_of(grid, p), p, 1.0);
    builder.end_row();
  }
  return rows;
}

SparseRows normal_derivative_rows(const Grid3& grid, const std::vector<Point3>& points,
                                  const std::vector<Point3>& normals, double shift) {
  if (points.size() != normals.size()) throw std::invalid_argument("normal_derivative_rows: size mismatch");
  SparseRows rows;
  RowBuilder builder(grid, rows);
  for (std::size_t r = 0; r < points.size(); ++r) {
    const Point3 n = normals[r], p = points[r] - shift * n;
    const Grid3::Index cell = cell_of(grid, p);
    Point3 xi;
    for (int d = 0; d < 3; ++d) xi[d] = (p[d] - grid.coordinate(d, cell[d])) / grid.h();
    const Q1Element<3> element(xi, grid.h());
    for (int k = 0; k < Q1Element<3>::n_nodes; ++k) {
      Grid3::Index node = cell;
      for (int d = 0; d < 3; ++d) node[d] += Q1Element<3>::offset(k, d);
      builder.add(node, dot(n, element.gradient(k)));
    }
    builder.end_row();
  }
  return rows;
}

SparseRows normal_derivative_rows_centered(const Grid3& grid, const std::vector<Point3>& points,
                                           const std::vector<Point3>& normals) {
  if (points.size() != normals.size()) throw std::invalid_argument("normal_derivative_rows: size mismatch");
  SparseRows rows;
  RowBuilder builder(grid, rows);
  const double h = grid.h();
  for (std::size_t r = 0; r < points.size(); ++r) {
    const Point3 p = points[r], n = normals[r];
    const Grid3::Index cell = cell_of(grid, p);
    std::array<LagrangeBasis, 3> basis;  // the 3 nodes around the nearest node, per axis
    std::array<int, 3> first;
    for (int d = 0; d < 3; ++d) {
      const double xi = (p[d] - grid.coordinate(d, cell[d])) / h;
      first[d] = xi < 0.5 ? -1 : 0;
      basis[d] = lagrange_basis(first[d], 2, xi);
    }
    for (int c = 0; c <= 2; ++c)
      for (int b = 0; b <= 2; ++b)
        for (int a = 0; a <= 2; ++a) {
          const auto &bx = basis[0], &by = basis[1], &bz = basis[2];
          const double weight = n.x * bx.derivative[a] * by.value[b] * bz.value[c] +
                                n.y * bx.value[a] * by.derivative[b] * bz.value[c] +
                                n.z * bx.value[a] * by.value[b] * bz.derivative[c];
          builder.add({cell[0] + first[0] + a, cell[1] + first[1] + b, cell[2] + first[2] + c}, weight / h);
        }
    builder.end_row();
  }
  return rows;
}

SparseRows one_sided_rows(const Grid3& grid, const Surface& gamma, const std::vector<Point3>& points,
                          const std::vector<Point3>& normals, OneSidedTrace trace, int degree, double radius) {
  const auto inside = [&](const Grid3::Index& node) {
    return gamma.level({grid.coordinate(0, node[0]), grid.coordinate(1, node[1]), grid.coordinate(2, node[2])}) < 0;
  };
  return one_sided_fit<3>(grid, inside, points, normals, trace, degree, radius);
}

SparseRows patch_integral_rows(const Grid3& grid, const std::vector<PatchWeight>& weights, int n_patches) {
  SparseRows rows;
  RowBuilder builder(grid, rows);
  std::size_t k = 0;
  for (int patch = 0; patch < n_patches; ++patch) {
    for (; k < weights.size() && weights[k].patch == patch; ++k) builder.add(weights[k].node, weights[k].value);
    builder.end_row();
  }
  if (k != weights.size()) throw std::invalid_argument("patch_integral_rows: weights not sorted by patch");
  return rows;
}

}  // namespace fictus
