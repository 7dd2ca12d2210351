#pragma once
// The Q1 (multilinear) element on a cubic cell of side h, any dimension: its 2^dim shape functions
// and their gradients at local coordinates ξ ∈ [0, 1]^dim. Local node k sits at the corner whose
// offset along axis d is bit d of k (2-D: k = a + 2b for the node (ix + a, iy + b)):
//   φ_k(ξ) = Π_d f_d,  f_d = ξ_d (bit set) or 1 − ξ_d,   ∂φ_k/∂ξ_d = ±Π_{e≠d} f_e,  ∇φ_k = (∂φ_k/∂ξ)/h.
// Every Q1 evaluation in fictus (interpolation, loads, trace rows, errors, the kink correction)
// takes its weights from here.
#include <array>

#include "fictus/grid/grid.hpp"
#include "fictus/grid/point.hpp"

namespace fictus {

template <int dim>
struct Q1Element {
  static constexpr int n_nodes = 1 << dim;
  std::array<double, n_nodes> value;
  std::array<Point<dim>, n_nodes> slope;  // ∂φ_k/∂ξ, per unit of the local coordinates
  double h;

  /// ∇φ_k in physical units. A sum Σ_k u_k ∇φ_k is cheaper as (Σ_k u_k slope_k)/h.
  Point<dim> gradient(int k) const {
    Point<dim> g = slope[k];
    for (int d = 0; d < dim; ++d) g[d] = g[d] / h;
    return g;
  }

  Q1Element(const Point<dim>& xi, double cell_side) : h(cell_side) {
    if constexpr (dim == 2) {  // the same numbers, written out: this runs at every quadrature point
      const double fx0 = 1 - xi.x, fx1 = xi.x, fy0 = 1 - xi.y, fy1 = xi.y;
      value = {fx0 * fy0, fx1 * fy0, fx0 * fy1, fx1 * fy1};
      slope = {Point<2>{-fy0, -fx0}, Point<2>{fy0, -fx1}, Point<2>{-fy1, fx0}, Point<2>{fy1, fx1}};
      return;
    }
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
        slope[k][d] = ((k >> d) & 1 ? 1.0 : -1.0) * others;
      }
    }
  }
  /// Σ_k u_k φ_k and Σ_k u_k ∇φ_k at ξ from the nodal values u_0 … u_3, without forming the φ_k: the
  /// factorized 2-D form, for the loops that sample a grid function at many points.
  struct Sample {
    double value;
    Point<dim> gradient;
  };
  static Sample interpolate(double u0, double u1, double u2, double u3, const Point<2>& xi,
                            double h) requires(dim == 2) {
    const double x = xi.x, y = xi.y;
    return {u0 * (1 - x) * (1 - y) + u1 * x * (1 - y) + u2 * (1 - x) * y + u3 * x * y,
            {((u1 - u0) * (1 - y) + (u3 - u2) * y) / h, ((u2 - u0) * (1 - x) + (u3 - u1) * x) / h}};
  }
  /// The same in 3-D from the nodal values u[k] (local node k as above), by nested linear
  /// interpolation along x, then y, then z.
  static Sample interpolate(const std::array<double, 8>& u, const Point<3>& xi, double h) requires(dim == 3) {
    const double x = xi.x, y = xi.y, z = xi.z;
    double a[2][2], dx[2][2];  // along x on the four edges (y, z) ∈ {0, 1}², and the edges' differences
    for (int k = 0; k < 2; ++k)
      for (int j = 0; j < 2; ++j) {
        const double u0 = u[std::size_t(2 * j + 4 * k)], u1 = u[std::size_t(1 + 2 * j + 4 * k)];
        a[k][j] = u0 + (u1 - u0) * x;
        dx[k][j] = u1 - u0;
      }
    double b[2], ex[2], dy[2];  // along y on the two faces z ∈ {0, 1}
    for (int k = 0; k < 2; ++k) {
      b[k] = a[k][0] + (a[k][1] - a[k][0]) * y;
      ex[k] = dx[k][0] + (dx[k][1] - dx[k][0]) * y;
      dy[k] = a[k][1] - a[k][0];
    }
    return {b[0] + (b[1] - b[0]) * z,
            {(ex[0] + (ex[1] - ex[0]) * z) / h, (dy[0] + (dy[1] - dy[0]) * z) / h, (b[1] - b[0]) / h}};
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
