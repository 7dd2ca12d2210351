#include "fictus/trace_operators.hpp"

#include <algorithm>
#include <numbers>
#include <stdexcept>

#include "fictus/quadrature.hpp"

namespace fictus {

namespace {

/// Collects the entries of one row, merging repeated nodes.
class RowBuilder {
 public:
  RowBuilder(const Grid& grid, SparseRows& rows) : grid_(grid), rows_(rows) {}
  void add(int i, int j, double value) {
    if (!grid_.has_unknown(i, j)) return;
    const std::size_t index = grid_.index(i, j);  // periodic boxes: (0, j) and (nx, j) are one node
    for (std::size_t k = rows_.row_begin.back(); k < rows_.entries.size(); ++k)
      if (rows_.entries[k].index == index) {
        rows_.entries[k].value += value;
        return;
      }
    rows_.entries.push_back({index, i, j, value});
  }
  /// Bilinear weights of point p in cell (ix, iy), scaled by w.
  void add_bilinear(int ix, int iy, Point p, double w) {
    const double xi = (p.x - grid_.x(ix)) / grid_.h(), eta = (p.y - grid_.y(iy)) / grid_.h();
    add(ix, iy, w * (1 - xi) * (1 - eta));
    add(ix + 1, iy, w * xi * (1 - eta));
    add(ix, iy + 1, w * (1 - xi) * eta);
    add(ix + 1, iy + 1, w * xi * eta);
  }
  void end_row() { rows_.row_begin.push_back(rows_.entries.size()); }

 private:
  const Grid& grid_;
  SparseRows& rows_;
};

}  // namespace

void SparseRows::multiply(const GridVector& u, std::vector<double>& out) const {
  out.assign(n_rows(), 0.0);
  for (int r = 0; r < n_rows(); ++r)
    for (std::size_t k = row_begin[r]; k < row_begin[r + 1]; ++k) out[r] += entries[k].value * u[entries[k].index];
}

void SparseRows::add_transposed(const std::vector<double>& lambda, GridVector& u) const {
  for (int r = 0; r < n_rows(); ++r)
    for (std::size_t k = row_begin[r]; k < row_begin[r + 1]; ++k) u[entries[k].index] += entries[k].value * lambda[r];
}

SparseRows point_value_rows(const Grid& grid, const std::vector<Point>& points) {
  SparseRows rows;
  RowBuilder builder(grid, rows);
  for (const Point& p : points) {
    builder.add_bilinear(grid.cell_x(p.x), grid.cell_y(p.y), p, 1.0);
    builder.end_row();
  }
  return rows;
}

SparseRows normal_derivative_rows(const Grid& grid, const std::vector<Point>& points,
                                  const std::vector<Point>& normals, double shift) {
  if (points.size() != normals.size()) throw std::invalid_argument("normal_derivative_rows: size mismatch");
  SparseRows rows;
  RowBuilder builder(grid, rows);
  const double h = grid.h();
  for (std::size_t r = 0; r < points.size(); ++r) {
    const Point n = normals[r];
    const Point p = points[r] - shift * n;
    const int ix = grid.cell_x(p.x), iy = grid.cell_y(p.y);
    const double xi = (p.x - grid.x(ix)) / h, eta = (p.y - grid.y(iy)) / h;
    // ∇u = (1/h)·( (u10−u00)(1−η) + (u11−u01)η ,  (u01−u00)(1−ξ) + (u11−u10)ξ )
    builder.add(ix, iy, (-n.x * (1 - eta) - n.y * (1 - xi)) / h);
    builder.add(ix + 1, iy, (n.x * (1 - eta) - n.y * xi) / h);
    builder.add(ix, iy + 1, (-n.x * eta + n.y * (1 - xi)) / h);
    builder.add(ix + 1, iy + 1, (n.x * eta + n.y * xi) / h);
    builder.end_row();
  }
  return rows;
}

SparseRows arc_integral_rows(const CurveGridIntersection& geometry, const std::vector<double>& arc_begin,
                             const std::vector<double>& arc_end, int q) {
  const Grid& grid = geometry.grid();
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
