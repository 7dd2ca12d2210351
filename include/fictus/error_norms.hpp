#pragma once
// Errors of the grid solution û against an exact solution u on ω and γ:
//   ‖û − u‖_{L²(ω)},  |û − u|_{H¹(ω)} (seminorm),  ‖û − u‖_{H¹(ω)} (full),  ‖û − u‖_{L²(γ)},
// absolute and relative (divided by the same norm of u). Cut cells use the curve-following rule,
// so quadrature error is far below the discretization error.
#include <functional>

#include "fictus/curve_grid_intersection.hpp"
#include "fictus/load_vector.hpp"

namespace fictus {

using GradientField = std::function<Point2(double x, double y)>;

struct ErrorNorms {
  double l2_omega = 0, h1semi_omega = 0, h1_omega = 0, l2_gamma = 0;
  double rel_l2_omega = 0, rel_h1semi_omega = 0, rel_h1_omega = 0, rel_l2_gamma = 0;
};

/// Central differences of u with step 1e-6·(box width) where no gradient is given.
GradientField numerical_gradient(ScalarField u, double scale);

ErrorNorms compute_errors(const GridVector& u_h, const CurveGridIntersection& gamma, const ScalarField& exact,
                          const GradientField& exact_gradient, int q = 3, const Execution& execution = Execution{});

/// ∇u on many points at once: (gx[k], gy[k]) = ∇u(x[k], y[k]).
using VectorizedGradient = std::function<void(std::size_t n, const double* x, const double* y, double* gx, double* gy)>;

/// The same for an exact solution evaluated in batches (one per cell row, one along γ). Without a
/// gradient, ∇u by central differences (step 1e-6·box width): four more batches.
ErrorNorms compute_errors(const GridVector& u_h, const CurveGridIntersection& gamma, const VectorizedField& exact,
                          const VectorizedGradient& exact_gradient = {}, int q = 3,
                          const Execution& execution = Execution{});

/// Value and gradient of the Q1 function u_h in cell (ix, iy) at (x, y).
struct Q1Sample {
  double value;
  Point2 gradient;
};
Q1Sample sample_q1(const Grid2& grid, const GridVector& u_h, int ix, int iy, double x, double y);

}  // namespace fictus
