#pragma once
// The trace matrices of the paper's eq. (3) as sparse rows over the interior grid nodes:
//   B_γ  (m × n): u(x_i), bilinear interpolation at the collocation points (4 entries a row);
//   C_γ  (m × n): n_i·∇u_h at x_i − shift·n_i, the gradient of the cell holding that point;
//   B_Γ  (m × n): ∫_{arc_j of Γ} φ_k ds, piecewise-constant multipliers, split at grid lines,
//                 Gauss on each piece (exact up to the curve's own non-polynomial shape).
// Boundary nodes of the box carry no unknown (u = 0 there) and are dropped.
#include <cstddef>
#include <vector>

#include "fictus/boundary/curve_grid_intersection.hpp"
#include "fictus/boundary/surface_integrals.hpp"
#include "fictus/grid/grid.hpp"
#include "fictus/grid/sparse_rows.hpp"

namespace fictus {

class Surface;

SparseRows point_value_rows(const Grid2& grid, const std::vector<Point2>& points);

/// shift: distance (length units) from x_i into ω along −n_i where the gradient is taken.
SparseRows normal_derivative_rows(const Grid2& grid, const std::vector<Point2>& points,
                                  const std::vector<Point2>& normals, double shift);

/// C_γ centered: row i = n_i·∇(I u)(x_i), I the tensor-product Lagrange interpolant of `degree` p on
/// (p+1)² nodes around x_i: p = 1 the cell of x_i (bilinear), p = 2 the 3×3 nodes around the
/// nearest node (biquadratic, ∂u/∂n to O(h²)), p = 3 the 4×4 nodes around the cell (bicubic, O(h³)).
SparseRows normal_derivative_rows_centered(const Grid2& grid, const std::vector<Point2>& points,
                                           const std::vector<Point2>& normals, int degree = 2);

/// One-sided traces from the nodes of ω only: row i = p(x_i) (value) or n_i·∇p(x_i) (normal
/// derivative), p the weighted least-squares polynomial of `degree` (1, 2 or 3) through u at the nodes
/// of ω within `radius` cells of x_i (weights (1 − d²/R²)², the disc grows by ½ cell until the fit
/// has at least twice as many nodes as terms and is well posed). For a û kinked on γ: no node outside ω
/// enters. Orders for smooth u: value h^(p+1), derivative h^p.
enum class OneSidedTrace { value, normal_derivative };
/// The independent check's fit (docs/math.md, "Checks"), both dimensions: cubic, within 3.5 cells.
inline constexpr int check_fit_degree = 3;
inline constexpr double check_fit_radius = 3.5;
inline constexpr const char* check_fit_rule = "one-sided cubic least-squares fit through the nodes of omega";
SparseRows one_sided_rows(const CurveGridIntersection& gamma, const std::vector<Point2>& points,
                          const std::vector<Point2>& normals, OneSidedTrace trace, int degree = 2, double radius = 2.5);

/// One row per arc [arc_begin[r], arc_end[r]] of the curve of `geometry` (q Gauss points on every
/// piece of the arc inside one cell).
SparseRows arc_integral_rows(const CurveGridIntersection& geometry, const std::vector<double>& arc_begin,
                             const std::vector<double>& arc_end, int q = 6);

// 3-D, a closed surface γ in a box (the same rows on the trilinear grid):
//   B_γ: trilinear interpolation at x_i (8 entries); C_γ shifted: n_i·∇u_h of the voxel holding
//   x_i − shift·n_i (8 entries); C_γ centered: n_i·∇ of the triquadratic interpolant on the 3×3×3
//   nodes around the node nearest x_i (O(h²)); B_Γ: row p = ∫_{patch p} φ_k dS (patch_integrals).
SparseRows point_value_rows(const Grid3& grid, const std::vector<Point3>& points);
SparseRows normal_derivative_rows(const Grid3& grid, const std::vector<Point3>& points,
                                  const std::vector<Point3>& normals, double shift);
SparseRows normal_derivative_rows_centered(const Grid3& grid, const std::vector<Point3>& points,
                                           const std::vector<Point3>& normals);
/// One-sided traces from the nodes of ω only (level < 0), as the 2-D rows above: p the weighted
/// least-squares polynomial of `degree` in x, y, z (10 terms for degree 2, 20 for 3) within `radius`
/// cells of x_i.
SparseRows one_sided_rows(const Grid3& grid, const Surface& gamma, const std::vector<Point3>& points,
                          const std::vector<Point3>& normals, OneSidedTrace trace, int degree = 2, double radius = 2.5);
/// Rows from patch_integrals' weights (sorted by patch); nodes without an unknown are dropped.
SparseRows patch_integral_rows(const Grid3& grid, const std::vector<PatchWeight>& weights, int n_patches);

}  // namespace fictus
