#pragma once
// Errors of the grid solution û against an exact solution u on ω and γ, in 2-D and 3-D:
//   ‖û − u‖_{L²(ω)},  |û − u|_{H¹(ω)} (seminorm),  ‖û − u‖_{H¹(ω)} (full),  ‖û − u‖_{L²(γ)},
// absolute and relative (divided by the same norm of u). Cells cut by γ use rules that follow γ,
// so quadrature error is far below the discretization error. The geometry is only named here: a
// curve's cut cells (curve_grid_intersection.hpp), a surface (surface.hpp) and its patches.
#include <array>
#include <cstddef>
#include <functional>
#include <optional>
#include <vector>

#include "fictus/grid/execution.hpp"
#include "fictus/grid/load_vector.hpp"

namespace fictus {

class CurveGridIntersection;
class Surface;
struct PatchedSurface;

struct ErrorNorms {
  double l2_omega = 0, h1semi_omega = 0, h1_omega = 0, l2_gamma = 0;
  double rel_l2_omega = 0, rel_h1semi_omega = 0, rel_h1_omega = 0, rel_l2_gamma = 0;
  double exact_l2_omega = 0, exact_h1semi_omega = 0;  // ‖u‖_{L²(ω)}, |u|_{H¹(ω)} of the exact solution
  // The errors of the quantities (DomainQuantities) against the exact solution's, signed: ∫û − ∫u, the
  // force's (c∫_ω (û − u): ∫f cancels) and the energy's J(û) − J(u). Set by the solver.
  double integral_u = 0, force = 0, energy = 0;
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
/// The same with u_h a slab's layers and the next one (Grid::slab_index).
Q1Sample sample_q1(const Grid2& grid, const GridVector& u_h, const Slab& slab, int ix, int iy, double x, double y);

/// Distributed (the execution's distribution), u_h is this rank's layers: the integrals over ω are made
/// of each rank's cells and added over the ranks (collective).
///
/// 3-D: errors of the trilinear û against `exact` in ω (L², H¹) and on γ from the points
/// (Σ_p |patch p|·(û − u)(x_p)²)^½, absolute and relative.
ErrorNorms compute_errors(const GridVector& u_h, const Grid3& grid, const Surface& gamma, const PatchedSurface& patches,
                          const std::vector<double>& trace, const ScalarField3& exact,
                          const GradientField3& exact_gradient, int q = 3, const Execution& execution = Execution{});
/// The same with `exact` in batches (∇u by central differences in batches when no gradient is given).
ErrorNorms compute_errors(const GridVector& u_h, const Grid3& grid, const Surface& gamma, const PatchedSurface& patches,
                          const std::vector<double>& trace, const VectorizedField3& exact,
                          const GradientField3& exact_gradient, int q = 3, const Execution& execution = Execution{});

/// û sampled at the quadrature points of ω (whole cells by Gauss points, cells cut by γ by the rules
/// that follow γ), one cell row at a time: what every integral over ω of a solution is made of.
template <int dim>
struct OmegaSamples {
  std::array<std::vector<double>, dim> x;         // the points, one array per coordinate
  std::vector<double> weight;                     // their quadrature weights
  std::vector<double> value;                      // û there
  std::array<std::vector<double>, dim> gradient;  // ∇û there
  std::size_t size() const { return weight.size(); }
};
/// Called from `execution.threads()` threads at once, `thread` in [0, threads): keep sums per thread.
template <int dim>
using OmegaSampleVisitor = std::function<void(int thread, const OmegaSamples<dim>& row)>;
/// With `slab`: only the cells of the slab's layers (Grid::cell_layer), u_h holding the slab's layers and
/// the next one (Grid::slab_index): a rank's part of the integrals, which a distributed run adds over
/// its ranks. Without one in a distributed run (the execution's distribution), u_h is this rank's
/// layers, and the next layer is fetched (collective).
void for_each_omega_sample(const GridVector& u_h, const CurveGridIntersection& gamma, int q, const Execution& execution,
                           const OmegaSampleVisitor<2>& visit, std::optional<Slab> slab = std::nullopt);
void for_each_omega_sample(const GridVector& u_h, const Grid3& grid, const Surface& gamma, int q,
                           const Execution& execution, const OmegaSampleVisitor<3>& visit,
                           std::optional<Slab> slab = std::nullopt);

/// The Q1 field u_h of `grid` at the points x (one array per coordinate; points outside the box take
/// the nearest cell's extension), into `out`. With `held`, u_h holds only layers held.first, … (modulo
/// grid.layers()), held.count of them, one after the other (Distribution::layers), and the points' cells
/// must lie there.
template <int dim>
void sample_q1_at(const Grid<dim>& grid, const GridVector& u_h, const std::array<std::vector<double>, dim>& x,
                  std::vector<double>& out, std::optional<Slab> held = std::nullopt);
/// The layers of `coarse` that sample_q1_at needs at the points of the cells of `slab`'s layers of `fine`
/// (the same box; a margin of a layer each side).
template <int dim>
Slab coarse_layers_under(const Grid<dim>& fine, const Slab& slab, const Grid<dim>& coarse);

/// f at the points x (one array per coordinate), into `out`.
void evaluate_at(const VectorizedField& f, const std::array<std::vector<double>, 2>& x, std::vector<double>& out);
void evaluate_at(const VectorizedField3& f, const std::array<std::vector<double>, 3>& x, std::vector<double>& out);

/// The coordinates of points as three arrays (for fields evaluated in batches).
std::array<std::vector<double>, 3> coordinates(const std::vector<Point3>& points);
/// ∇u at the points x (three coordinate arrays): `gradient` when given, else central differences of
/// `u` with step e, in batches.
void gradient_at(const VectorizedField3& u, const GradientField3& gradient, double e,
                 const std::array<std::vector<double>, 3>& x, std::array<std::vector<double>, 3>& du);

}  // namespace fictus
