#pragma once
// What the fictitious domain solver needs from the boundary γ = ∂ω and the boundary Γ carrying λ,
// whatever their shape and dimension: the m points on γ with their outward normals, m and δ
// (spacing_rule.hpp), the sparse trace rows B_γ, C_γ and the load rows (B_Γ, with the kink
// correction's rows in the non-smooth variant), the direct terms D_B, D_C, the obstacle at the points,
// and what ω contributes to checks and errors (docs/math.md).
//
// CurveDiscretization (2-D: collocation points on a curve) and SurfaceDiscretization (3-D: patches of
// a surface) implement it, so the steps of FictitiousDomainSolver<dim>::solve do not know what γ is.
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fictus/boundary/trace_operators.hpp"
#include "fictus/grid/execution.hpp"
#include "fictus/grid/fast_solver.hpp"
#include "fictus/solve/error_norms.hpp"
#include "fictus/solve/problem.hpp"
#include "fictus/solve/schur_complement.hpp"
#include "fictus/solve/solution.hpp"
#include "fictus/solve/spacing_rule.hpp"

namespace fictus {

/// Called with a step's name as it ends (the solver's phase clock).
using MarkPhase = std::function<void(const std::string& phase)>;

/// Every rank of a distributed run (the execution's Distribution) holds the whole boundary part: the
/// points, the rows, the Schur blocks. Its grid vectors (the GridVector arguments) are the rank's layers,
/// and the members that read them (readings, integrals over ω) add the ranks' parts: each is collective.
template <int dim>
class BoundaryDiscretization {
 public:
  using Data = BasicContactData<dim>;
  virtual ~BoundaryDiscretization() = default;

  /// The points x_i on γ and their outward unit normals.
  virtual const std::vector<Point<dim>>& points() const = 0;
  virtual const std::vector<Point<dim>>& normals() const = 0;
  int n_points() const { return int(points().size()); }
  /// m, s and δ as planned, with the warning when the default rule was changed to fit.
  virtual const SpacingPlan& spacing() const = 0;
  /// The distance of Γ from γ (0 in the non-smooth variant).
  virtual double delta() const = 0;

  /// B_γ, C_γ (m rows over the grid unknowns) and the rows whose transposes carry λ into the grid.
  virtual const SparseRows& B_gamma() const = 0;
  virtual const SparseRows& C_gamma() const = 0;
  virtual const SparseRows& B_Gamma() const = 0;
  virtual const SparseRows& loads() const = 0;
  /// D_B, D_C: trace terms that act on λ directly (empty: none).
  virtual const DirectTerms& direct() const = 0;
  /// The far field the explicit Schur assembly may interpolate (FarField{}: every pair exactly).
  virtual FarField far_field(const SolverOptions&) const { return {}; }

  /// The part of the setup that needs the grid's fast solver, once, before the Schur blocks (3-D
  /// non-smooth: the flux balance of the patches, which joins direct().normal_derivative). Returns
  /// the fast solves it made.
  virtual std::size_t finish_setup(const FastSolver<dim>&, const MarkPhase&) { return 0; }
  /// What every reading C_γu₀ of the data's field u₀ moves by (0 but with the flux balance), for the
  /// load f; computed again for each new load.
  virtual double reading_shift(const GridVector&, const typename Fields<dim>::Vectorized&, int) const { return 0; }
  /// The report of the flux balance, with the data's shift (nullopt without it).
  virtual std::optional<FluxBalanceUse> flux_balance(double) const { return std::nullopt; }

  /// g at the points (throws naming data.g where it is not finite or too large).
  virtual std::vector<double> obstacle(const Data& data) const = 0;
  /// Turns u₀ + A⁻¹ loadsᵀλ (+ α) into the output field (the kink-corrected one where it applies).
  virtual void finish_field(const std::vector<double>& lambda, GridVector& u) const = 0;
  /// The readings Newton enforces beyond C_γû: the flux balance's Xλ (none by default).
  virtual void finish_readings(const std::vector<double>&, std::vector<double>&) const {}
  /// ∂u/∂n at the points by a rule independent of C_γ, and its name; nullopt where there is none.
  virtual std::optional<std::vector<double>> independent_normal_derivative(const GridVector& u,
                                                                           std::string& rule) const = 0;
  /// u at the quadrature points of ω, a row at a time (the integrals over ω of a solution). Distributed,
  /// the rows of this rank's cells: the caller adds its sums over the ranks.
  virtual void for_each_omega_sample(const GridVector& u, int quadrature,
                                     const OmegaSampleVisitor<dim>& visit) const = 0;
  /// Errors of u against the exact solution of `data` in ω and on γ (`trace`: B_γu).
  virtual ErrorNorms errors(const GridVector& u, const std::vector<double>& trace, const Data& data,
                            int quadrature) const = 0;
  /// The errors of B_γû and C_γû at the points against the exact solution.
  virtual PointErrors point_errors(const std::vector<double>& trace, const std::vector<double>& normal_derivative,
                                   const Data& data) const = 0;
  /// The solution's description of the points (collocation and Γ, or patches).
  virtual void describe(SolutionBoundary<dim>& out) const = 0;

  /// With mixed conditions, the points are placed part by part, so that no point's part of γ straddles
  /// a junction of two parts (docs/math.md, "Mixed conditions"): each point's part as placed; empty
  /// without mixed conditions.
  const std::vector<PointCondition>& point_parts() const { return point_parts_; }
  /// Whether `parts` divide γ as the parts the points were placed for (then the setup can be kept).
  virtual bool same_parts(const PartConditions<dim>& parts) const { return part_layout(parts) == part_layout_; }
  /// The same boundary with its points placed for `parts` (the contact fit's: docs/math.md, "Fitting the
  /// points to the contact set"), sharing what does not depend on the points (the shape's checks and
  /// grid intersections, m and δ). `options` and c as for this one; `mark` as the constructor's.
  virtual std::unique_ptr<BoundaryDiscretization<dim>> placed_for(const PartConditions<dim>& parts,
                                                                  const SolverOptions& options, double c,
                                                                  const MarkPhase& mark) const = 0;

 protected:
  /// The label (PartConditions::label) of each of γ's fine pieces (2-D: samples of the curve; 3-D: the
  /// triangles) under `parts`; empty without mixed conditions or a contact side.
  virtual std::vector<int> part_layout(const PartConditions<dim>& parts) const = 0;
  std::vector<PointCondition> point_parts_;
  std::vector<int> part_layout_;
};

/// The boundary of dimension dim for γ on `grid`: a CurveDiscretization or a SurfaceDiscretization
/// (steps 1–2 of the solve; throws std::invalid_argument naming the option or "geometry").
template <int dim>
std::unique_ptr<BoundaryDiscretization<dim>> make_boundary(
    std::shared_ptr<const typename BoundaryShape<dim>::type> gamma, const Grid<dim>& grid, const SolverOptions& options,
    double c, const Execution& execution, const MarkPhase& mark);

}  // namespace fictus
