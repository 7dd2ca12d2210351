#pragma once
// Where a closed curve meets the grid: the curve split at every grid line into pieces that each
// lie in one cell, the crossing points on every grid line, the inside test that follows from them
// (parity of crossings along a grid line), and quadrature rules over ω and along the curve that
// follow the TRUE curve (not a polygon) in cut cells.
#include <array>
#include <cstddef>
#include <vector>

#include "fictus/curve.hpp"
#include "fictus/quadrature.hpp"

namespace fictus {

struct CurvePiece {
  double t0, t1;  // parameter interval, t0 < t1, inside [0, 2π]
  int ix, iy;     // the cell it lies in
};

struct CutCell {
  int ix, iy;
  std::vector<int> pieces;  // indices into CurveGridIntersection::pieces()
};

struct QuadraturePoint {
  double x, y, weight;
};

class CurveGridIntersection {
 public:
  /// Throws std::invalid_argument("<what>: …") if the curve is not strictly inside the box.
  CurveGridIntersection(const Curve& curve, const Grid& grid, const char* what = "geometry");

  const Curve& curve() const { return curve_; }
  const Grid& grid() const { return grid_; }
  const std::vector<CurvePiece>& pieces() const { return pieces_; }
  const std::vector<CutCell>& cut_cells() const { return cut_cells_; }
  /// Cut cells of row iy are cut_cells()[row_begin(iy) .. row_begin(iy+1)).
  std::size_t row_begin(int iy) const { return row_begin_[iy]; }

  /// Is (x, y_j) inside ω? (parity of the crossings of grid row j left of x)
  bool inside_on_row(int j, double x) const;
  /// Is (x_i, y) inside ω? (parity of the crossings of grid column i below y)
  bool inside_on_column(int i, double y) const;
  bool node_inside(int i, int j) const { return inside_on_row(j, grid_.x(i)); }

  /// Indices of the pieces overlapping the parameter interval [ta, tb] (binary search).
  std::pair<std::size_t, std::size_t> pieces_in(double ta, double tb) const;

  /// Quadrature points of ω ∩ cell for a cut cell: q×q Gauss on sub-rectangles bounded by the
  /// exact curve crossings (integrates along lines transversal to the curve).
  void cut_cell_rule(const CutCell& cell, int q, std::vector<QuadraturePoint>& out) const;

 private:
  const Curve& curve_;
  Grid grid_;
  std::vector<CurvePiece> pieces_;
  std::vector<CutCell> cut_cells_;
  std::vector<std::size_t> row_begin_;
  std::vector<std::vector<double>> row_crossings_;  // per grid row j: sorted x of crossings
  std::vector<std::vector<double>> col_crossings_;  // per grid column i: sorted y of crossings
};

/// ∫_ω F over ω (F returns K values, integrated together): q×q Gauss on cells inside ω, the
/// curve-following rule on cut cells. F(ix, iy, x, y) must be thread-safe.
template <int K, class F>
std::array<double, K> integrate_over_domain(const CurveGridIntersection& geometry, int q, F&& fn,
                                            int threads = 1);

/// ∫_γ F ds along the whole curve (q-point Gauss on each piece). F(ix, iy, t, p) returns K values.
template <int K, class F>
std::array<double, K> integrate_along_curve(const CurveGridIntersection& geometry, int q, F&& fn);

// ---- implementation of the templates ----

template <int K, class F>
std::array<double, K> integrate_over_domain(const CurveGridIntersection& geometry, int q, F&& fn,
                                            int threads) {
  const Grid& grid = geometry.grid();
  const GaussRule& rule = gauss_legendre(q);
  const double h = grid.h();
  std::array<double, K> total{};
#pragma omp parallel num_threads(threads < 1 ? 1 : threads)
  {
    std::array<double, K> local{};
    std::vector<QuadraturePoint> rule_points;
    std::vector<char> below, above;
#pragma omp for schedule(dynamic, 8)
    for (int iy = 0; iy < grid.ny(); ++iy) {
      // Sums per cell, then per row, then over rows: keeps round-off at ~1e-15 of the total.
      std::array<double, K> row_sum{};
      below.resize(grid.nx() + 1);
      above.resize(grid.nx() + 1);
      for (int i = 0; i <= grid.nx(); ++i) {
        below[i] = geometry.node_inside(i, iy);
        above[i] = geometry.node_inside(i, iy + 1);
      }
      std::size_t next_cut = geometry.row_begin(iy);
      const std::size_t end_cut = geometry.row_begin(iy + 1);
      for (int ix = 0; ix < grid.nx(); ++ix) {
        std::array<double, K> cell_sum{};
        if (next_cut < end_cut && geometry.cut_cells()[next_cut].ix == ix) {
          rule_points.clear();
          geometry.cut_cell_rule(geometry.cut_cells()[next_cut], q, rule_points);
          for (const QuadraturePoint& p : rule_points) {
            const auto v = fn(ix, iy, p.x, p.y);
            for (int k = 0; k < K; ++k) cell_sum[k] += p.weight * v[k];
          }
          ++next_cut;
        } else if (below[ix] && below[ix + 1] && above[ix] && above[ix + 1]) {
          for (int b = 0; b < q; ++b)
            for (int a = 0; a < q; ++a) {
              const auto v = fn(ix, iy, grid.x(ix) + rule.nodes[a] * h, grid.y(iy) + rule.nodes[b] * h);
              const double w = rule.weights[a] * rule.weights[b] * h * h;
              for (int k = 0; k < K; ++k) cell_sum[k] += w * v[k];
            }
        }
        for (int k = 0; k < K; ++k) row_sum[k] += cell_sum[k];
      }
      for (int k = 0; k < K; ++k) local[k] += row_sum[k];
    }
#pragma omp critical
    for (int k = 0; k < K; ++k) total[k] += local[k];
  }
  return total;
}

template <int K, class F>
std::array<double, K> integrate_along_curve(const CurveGridIntersection& geometry, int q, F&& fn) {
  const GaussRule& rule = gauss_legendre(q);
  std::array<double, K> total{};
  for (const CurvePiece& piece : geometry.pieces()) {
    const double span = piece.t1 - piece.t0;
    std::array<double, K> piece_sum{};
    for (int g = 0; g < q; ++g) {
      const double t = piece.t0 + rule.nodes[g] * span;
      const double w = rule.weights[g] * span * geometry.curve().speed(t);
      const auto v = fn(piece.ix, piece.iy, t, geometry.curve().position(t));
      for (int k = 0; k < K; ++k) piece_sum[k] += w * v[k];
    }
    for (int k = 0; k < K; ++k) total[k] += piece_sum[k];
  }
  return total;
}

}  // namespace fictus
