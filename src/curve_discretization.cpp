#include "fictus/curve_discretization.hpp"

#include <cstdio>
#include <stdexcept>
#include <string>

#include "fictus/shapes.hpp"

namespace fictus {

CurveDiscretization::CurveDiscretization(std::shared_ptr<const Curve> gamma, const Grid2& grid,
                                         const SolverOptions& options, double c, const Execution& execution)
    : gamma_(std::move(gamma)) {
  if (!gamma_) throw std::invalid_argument("geometry: no curve given");
  make_geometry(grid, options);
  make_trace_rows(grid, options, c, execution);
}

void CurveDiscretization::make_geometry(const Grid2& grid, SolverOptions options) {
  const Curve& gamma = *gamma_;
  const double h = grid.h();
  check_simple(gamma, "geometry");
  if (signed_area(gamma) <= 0)
    throw std::invalid_argument("geometry: the curve must be counter-clockwise (ω on its left)");
  check_inside_box(gamma, grid.box(), 2 * h, "geometry");
  gamma_geometry_ = std::make_unique<CurveGridIntersection>(gamma, grid, "geometry");

  const ArcLengthTable arc_length(gamma);
  const double L = arc_length.length();
  const double spacing_cells =
      options.variant == Variant::smooth ? default_spacing_cells_smooth : default_spacing_cells_nonsmooth;
  const int m = options.multipliers == 0 ? default_multipliers(L, h, spacing_cells) : options.multipliers;
  if (m < minimum_multipliers)
    throw std::invalid_argument("formulation.multipliers: m = " + std::to_string(m) +
                                " is too small (need m >= " + std::to_string(minimum_multipliers) + ")");
  if (L / m < 2 * h)
    throw std::invalid_argument("formulation.multipliers: m = " + std::to_string(m) +
                                " is too large for the grid (spacing L/m = " + std::to_string(L / m) +
                                " < 2h; use m <= " + std::to_string(int(L / (2 * h))) + ")");
  if (options.variant == Variant::nonsmooth) {
    collocation_ = make_collocation(gamma, arc_length, m, phase_off_corners(gamma, arc_length, m));
    Gamma_ = gamma_;
    return;
  }
  if (!gamma.smooth())
    throw std::invalid_argument(
        "formulation.variant: the smooth variant needs a curve with a continuous normal "
        "(use \"nonsmooth\" for polygons)");
  delta_ = options.offset * L / m;
  // Points placed so that the arcs of Γ behind them are equal where γ is convex (there Γ's arcs are
  // stretched by 1 + δκ): the longest arc of Γ, which sets the ripple of the controls, is as short as m
  // allows (docs/math.md, "Placement of the points").
  const ArcLengthTable placement = offset_placement(gamma, delta_);
  collocation_ = make_collocation(gamma, arc_length, m, 0.5, &placement);
  // The biquadratic stencil of C_γ reaches 1.5·√2·h ≈ 2.1h from x_i; its nodes must stay out of the
  // cells cut by Γ (which reach 1.4h from Γ), where the kink of û pollutes the nodal values.
  if (options.normal_derivative == NormalDerivative::reconstructed && delta_ < 4 * h)
    throw std::invalid_argument("formulation.offset: Γ at δ = offset·L/m = " + std::to_string(delta_ / h) +
                                " h is within reach of the C_γ stencil (need δ >= 4h: a larger offset or a smaller m)");
  Gamma_ = std::make_shared<OffsetCurve>(gamma_, delta_);
  try {
    check_simple(*Gamma_, "formulation.offset");
    check_inside_box(*Gamma_, grid.box(), 2 * h, "formulation.offset");
  } catch (const std::invalid_argument& e) {  // say what moves Γ closer to γ
    char hint[160];
    std::snprintf(hint, sizeof hint,
                  "; Γ lies δ = offset·L/m = %.3g from γ (%.1f h): a larger N or a smaller formulation.offset "
                  "brings it closer",
                  delta_, delta_ / h);
    throw std::invalid_argument(e.what() + std::string(hint));
  }
  Gamma_geometry_ = std::make_unique<CurveGridIntersection>(*Gamma_, grid, "formulation.offset");
}

void CurveDiscretization::make_trace_rows(const Grid2& grid, const SolverOptions& options, double c,
                                          const Execution& execution) {
  const Collocation& points = collocation_;
  B_gamma_ = point_value_rows(grid, points.point);
  B_Gamma_ = arc_integral_rows(Gamma_geometry_ ? *Gamma_geometry_ : *gamma_geometry_, points.arc_begin, points.arc_end);
  loads_ = B_Gamma_;
  if (options.normal_derivative == NormalDerivative::shifted) {
    C_gamma_ = normal_derivative_rows(grid, points.point, points.normal, options.normal_shift * grid.h());
    return;
  }
  C_gamma_ = normal_derivative_rows_centered(grid, points.point, points.normal, 2);
  if (options.variant == Variant::nonsmooth) {
    kink_ = std::make_unique<KinkCorrection>(*gamma_geometry_, collocation_, c, execution);
    loads_ = add_rows(B_Gamma_, kink_->galerkin());
    direct_.trace = kink_->direct(B_gamma_);
    direct_.normal_derivative = kink_->direct(C_gamma_);
  }
}

void CurveDiscretization::finish_field(const std::vector<double>& lambda, GridVector& u) const {
  if (kink_) kink_->add_kinks(lambda, u);
}

std::optional<std::vector<double>> CurveDiscretization::independent_normal_derivative(const GridVector& u,
                                                                                      std::string& rule) const {
  std::vector<double> d;
  if (kink_) {
    rule = "bicubic interpolant of the kink-corrected field";
    normal_derivative_rows_centered(gamma_geometry_->grid(), points(), normals(), 3).multiply(u, d);
    return d;
  }
  rule = "one-sided quadratic least-squares fit through the nodes of omega";
  try {
    one_sided_rows(*gamma_geometry_, points(), normals(), OneSidedTrace::normal_derivative, 2, 2.5).multiply(u, d);
  } catch (const std::runtime_error&) {  // ω too thin for the fit: no check, not a failed solve
    return std::nullopt;
  }
  return d;
}

ErrorNorms CurveDiscretization::errors(const GridVector& u, const ContactData& data, int quadrature,
                                       const Execution& execution) const {
  if (data.exact_vectorized)
    return compute_errors(u, *gamma_geometry_, data.exact_vectorized, {}, quadrature, execution);
  return compute_errors(u, *gamma_geometry_, data.exact, data.exact_gradient, quadrature, execution);
}

}  // namespace fictus
