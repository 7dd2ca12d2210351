#pragma once
// The boundary of a 2-D problem: a closed curve γ, its collocation points and the curve Γ that
// carries λ (γ itself in the non-smooth variant, the offset curve at δ outside ω in the smooth one),
// with the trace rows of the chosen rule (docs/math.md, "Trace matrices"). The solver keeps it for as
// long as it keeps the solve's setup (`execution` must outlive it).
#include <memory>

#include "fictus/boundary/collocation.hpp"
#include "fictus/boundary/curve_grid_intersection.hpp"
#include "fictus/boundary/kink_correction.hpp"
#include "fictus/solve/boundary_discretization.hpp"
#include "fictus/solve/spacing_rule.hpp"

namespace fictus {

class CurveDiscretization final : public BoundaryDiscretization<2> {
 public:
  /// Steps 1–2 of the solve for curve γ on `grid` (c: the reaction coefficient the kink rows use):
  ///   1. geometry: γ checked (counter-clockwise, simple, 2h inside the box), m and δ by the rules of
  ///      spacing_rule.hpp, the collocation points and Γ (smooth variant: simple, 2h inside the box);
  ///   2. trace rows: B_γ, C_γ, B_Γ, and the kink correction's rows and direct terms.
  /// With mixed conditions (`parts`), the arcs of the points end at the junctions of the parts (and, in
  /// the non-smooth variant, at γ's corners). Throws std::invalid_argument naming the option or
  /// "geometry" on bad input.
  CurveDiscretization(std::shared_ptr<const Curve> gamma, const Grid2& grid, const SolverOptions& options, double c,
                      const Execution& execution, const PartConditions<2>& parts = {});

  const std::vector<Point2>& points() const override { return collocation_.point; }
  const std::vector<Point2>& normals() const override { return collocation_.normal; }
  /// The arc length s_i of each point from γ(0).
  const std::vector<double>& arc_positions() const { return collocation_.s; }
  const SpacingPlan& spacing() const override { return spacing_; }
  double delta() const override { return delta_; }
  const SparseRows& B_gamma() const override { return B_gamma_; }
  const SparseRows& C_gamma() const override { return C_gamma_; }
  const SparseRows& B_Gamma() const override { return B_Gamma_; }
  const SparseRows& loads() const override { return loads_; }
  const DirectTerms& direct() const override { return direct_; }
  /// g, or g(x, y, s) when data.g_along_curve is set, at the points.
  std::vector<double> obstacle(const Data& data) const override;
  void finish_field(const std::vector<double>& lambda, GridVector& u) const override;
  std::optional<std::vector<double>> independent_normal_derivative(const GridVector& u,
                                                                   std::string& rule) const override;
  void for_each_omega_sample(const GridVector& u, int quadrature, const OmegaSampleVisitor<2>& visit) const override;
  ErrorNorms errors(const GridVector& u, const std::vector<double>& trace, const Data& data,
                    int quadrature) const override;
  /// ∂u/∂n of the exact solution from its gradient when given, else by a one-sided second-order
  /// difference into ω (u may be defined in ω only): (3u(x) − 4u(x − εn) + u(x − 2εn))/(2ε), ε = 1e-5·box width.
  PointErrors point_errors(const std::vector<double>& trace, const std::vector<double>& normal_derivative,
                           const Data& data) const override;
  void describe(SolutionBoundary<2>& out) const override;

  /// The same curve with its points placed for `parts` (the contact fit's); the grid intersections of γ
  /// and Γ, m, δ and the arc-length tables are shared, not made again.
  std::unique_ptr<BoundaryDiscretization<2>> placed_for(const PartConditions<2>& parts, const SolverOptions& options,
                                                        double c, const MarkPhase& mark) const override;

  const Collocation& collocation() const { return collocation_; }
  const std::shared_ptr<const Curve>& gamma() const { return gamma_; }
  const std::shared_ptr<const Curve>& Gamma() const { return Gamma_; }

 private:
  CurveDiscretization(const CurveDiscretization& base, const SolverOptions& options, double c,
                      const PartConditions<2>& parts);
  /// Step 1 without the points: γ's checks and grid intersection, m, δ, Γ and its grid intersection.
  void make_shape(const Grid2& grid, const SolverOptions& options);
  /// The points for `parts`, their arcs ending at its junctions; the arcs placed as in `reuse` (the base's,
  /// for a fitted copy) are taken from it.
  void place_points(const SolverOptions& options, const PartConditions<2>& parts, const Collocation* reuse);
  /// K = max(4096, 16m) samples of γ, at t = 2π(k + ½)/K, made on first use (by the solve's thread: not
  /// for calls from several threads at once).
  const std::shared_ptr<const std::vector<Point2>>& layout_samples() const;
  /// The labels at layout_samples().
  std::vector<int> part_layout(const PartConditions<2>& parts) const override;
  /// The parameters where the pieces meet, each with the label of the piece that follows it, from the
  /// samples' labels (each change bisected to round-off).
  std::vector<std::pair<double, int>> junctions(const PartConditions<2>& parts, const std::vector<int>& layout) const;
  /// The samples' parts and the junctions (to 1e-12 in the parameter) as when the points were placed.
  bool same_parts(const PartConditions<2>& parts) const override;
  std::vector<std::pair<double, int>> junctions_;
  /// B_γ, C_γ, B_Γ (and the kink correction's terms); B_Γ's rows of the points placed as `base`'s are its.
  void make_trace_rows(const Grid2& grid, const SolverOptions& options, double c, const CurveDiscretization* base);

  const Execution& execution_;
  std::shared_ptr<const Curve> gamma_, Gamma_;
  Collocation collocation_;
  double delta_ = 0;
  SpacingPlan spacing_;
  // part_layout's points of γ, made on first use (mixed conditions or a fit) and shared with the fits
  mutable std::shared_ptr<const std::vector<Point2>> samples_;
  std::shared_ptr<const ArcLengthTable> arc_length_, placement_;  // placement_: smooth variant only
  std::shared_ptr<const CurveGridIntersection> gamma_geometry_, Gamma_geometry_;
  SparseRows B_gamma_, C_gamma_, B_Gamma_, loads_;
  DirectTerms direct_;
  std::unique_ptr<KinkCorrection> kink_;
};

}  // namespace fictus
