#pragma once
// Where a closed curve meets the grid: the curve split at every grid line into pieces that each
// lie in one cell, the crossing points on every grid line, the inside test that follows from them
// (parity of crossings along a grid line), and quadrature rules over ω and along the curve that
// follow the TRUE curve (not a polygon) in cut cells.
#include <array>
#include <cstddef>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

#include "fictus/boundary/curve.hpp"
#include "fictus/grid/execution.hpp"
#include "fictus/grid/quadrature.hpp"

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

struct CellQuadraturePoint {
  int ix;  // the cell (ix, iy) of the row it belongs to
  double x, y, weight;
};

class CurveGridIntersection {
 public:
  /// Throws std::invalid_argument("<what>: …") if the curve is not strictly inside the box.
  CurveGridIntersection(const Curve& curve, const Grid2& grid, const char* what = "geometry");

  const Curve& curve() const { return curve_; }
  const Grid2& grid() const { return grid_; }
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

  /// Quadrature points of ω ∩ (cell row iy), cells in increasing ix: q×q Gauss on cells inside ω,
  /// the curve-following rule on cut cells. `out` is cleared first. The cut cells' rules of each row and q
  /// are made on the first call and kept (a sweep's or a fit's later solves integrate over the same ω);
  /// calls from several threads at once are safe.
  void row_rule(int iy, int q, std::vector<CellQuadraturePoint>& out) const;

 private:
  /// Whether cell (ix, iy), which γ does not cross, lies in ω, given how many of its corners the
  /// crossing parity puts inside (a corner on γ may count either way): the majority of the corners and
  /// the edges' midpoints.
  bool inside_uncut_cell(int ix, int iy, int corners_inside) const;
  const Curve& curve_;
  Grid2 grid_;
  std::vector<CurvePiece> pieces_;
  std::vector<CutCell> cut_cells_;
  std::vector<std::size_t> row_begin_;
  std::vector<std::vector<double>> row_crossings_;  // per grid row j: sorted x of crossings
  std::vector<std::vector<double>> col_crossings_;  // per grid column i: sorted y of crossings
  std::vector<double> corners_;                     // the curve's corners (parameters t), sorted
  /// row_rule's rules of one row's cut cells for one q: its cut cells' points, cell after cell, and where
  /// each cell's points begin (and the end).
  struct CutRules {
    std::vector<QuadraturePoint> points;
    std::vector<std::size_t> begin;
  };
  /// Made outside the lock by the thread that asks first, kept once complete (a throw keeps nothing).
  const CutRules& cut_rules(int iy, int q) const;
  mutable std::mutex rules_mutex_;
  mutable std::map<int, std::vector<std::unique_ptr<const CutRules>>> rules_;  // by q, then by row
};

/// ∫_ω F over ω (F returns K values, integrated together): q×q Gauss on cells inside ω, the
/// curve-following rule on cut cells. F(ix, iy, x, y) must be thread-safe.
template <int K, class F>
std::array<double, K> integrate_over_domain(const CurveGridIntersection& geometry, int q, F&& fn,
                                            const Execution& execution = Execution{});

/// ∫_γ F ds along the whole curve (q-point Gauss on each piece). F(ix, iy, t, p) returns K values.
template <int K, class F>
std::array<double, K> integrate_along_curve(const CurveGridIntersection& geometry, int q, F&& fn);

// ---- implementation of the templates ----

template <int K, class F>
std::array<double, K> integrate_over_domain(const CurveGridIntersection& geometry, int q, F&& fn,
                                            const Execution& execution) {
  const Grid2& grid = geometry.grid();
  std::array<double, K> total{};
#pragma omp parallel num_threads(execution.threads())
  {
    std::array<double, K> local{};
    std::vector<CellQuadraturePoint> points;
#pragma omp for schedule(dynamic, 8)
    for (int iy = 0; iy < grid.ny(); ++iy) {
      // Sums per cell, then per row, then over rows: keeps round-off at ~1e-15 of the total.
      geometry.row_rule(iy, q, points);
      std::array<double, K> row_sum{}, cell_sum{};
      for (std::size_t k = 0; k < points.size(); ++k) {
        const CellQuadraturePoint& p = points[k];
        const auto v = fn(p.ix, iy, p.x, p.y);
        for (int c = 0; c < K; ++c) cell_sum[c] += p.weight * v[c];
        if (k + 1 == points.size() || points[k + 1].ix != p.ix) {
          for (int c = 0; c < K; ++c) row_sum[c] += cell_sum[c], cell_sum[c] = 0.0;
        }
      }
      for (int c = 0; c < K; ++c) local[c] += row_sum[c];
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
