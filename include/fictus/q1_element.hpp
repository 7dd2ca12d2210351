#pragma once
// The Q1 (multilinear) element on a cubic cell of side h, any dimension: its 2^dim shape functions
// and their gradients at local coordinates ξ ∈ [0, 1]^dim. Local node k sits at the corner whose
// offset along axis d is bit d of k (2-D: k = a + 2b for the node (ix + a, iy + b)):
//   φ_k(ξ) = Π_d f_d,  f_d = ξ_d (bit set) or 1 − ξ_d,   ∂φ_k/∂x_d = ±(1/h) Π_{e≠d} f_e.
// Every Q1 evaluation in fictus (interpolation, loads, trace rows, errors, the kink correction)
// takes its weights from here.
#include <array>

#include "fictus/grid.hpp"
#include "fictus/point.hpp"

namespace fictus {

template <int dim>
struct Q1Element {
  static constexpr int n_nodes = 1 << dim;
  std::array<double, n_nodes> value;
  std::array<Point<dim>, n_nodes> gradient;  // in physical units (1/h)

  Q1Element(const Point<dim>& xi, double h) {
    for (int k = 0; k < n_nodes; ++k) {
      std::array<double, dim> f;
      for (int d = 0; d < dim; ++d) f[d] = (k >> d) & 1 ? xi[d] : 1 - xi[d];
      double v = f[0];
      for (int d = 1; d < dim; ++d) v *= f[d];
      value[k] = v;
      for (int d = 0; d < dim; ++d) {
        double others = 1.0;
        for (int e = 0; e < dim; ++e)
          if (e != d) others *= f[e];
        gradient[k][d] = ((k >> d) & 1 ? 1.0 : -1.0) * others / h;
      }
    }
  }
  /// The offset of local node k along axis d (0 or 1).
  static int offset(int k, int d) { return (k >> d) & 1; }
};

/// The element of the cell of `grid` that holds p (clamped), with p's local coordinates.
struct Q1Cell2 {
  int ix, iy;
  Q1Element<2> element;
};
inline Q1Cell2 q1_cell(const Grid2& grid, Point2 p) {
  const int ix = grid.cell_x(p.x), iy = grid.cell_y(p.y);
  return {ix, iy, Q1Element<2>({(p.x - grid.x(ix)) / grid.h(), (p.y - grid.y(iy)) / grid.h()}, grid.h())};
}

}  // namespace fictus
