#pragma once
// What the fictitious domain solver needs from the boundary γ = ∂ω and the curve Γ carrying λ,
// whatever their shape: the m collocation points on γ with their outward normals, the sparse trace
// rows B_γ, C_γ and the load rows (B_Γ, with the kink correction's rows in the non-smooth variant),
// the direct terms D_B, D_C, and what ω contributes to checks and errors (docs/math.md).
//
// CurveDiscretization (2-D curves) implements it; a surface in a 3-D box will implement it beside,
// so the steps of FictitiousDomainSolver::solve do not know what γ is.
#include <optional>
#include <string>
#include <vector>

#include "fictus/error_norms.hpp"
#include "fictus/execution.hpp"
#include "fictus/problem.hpp"
#include "fictus/schur_complement.hpp"
#include "fictus/trace_operators.hpp"

namespace fictus {

class BoundaryDiscretization {
 public:
  virtual ~BoundaryDiscretization() = default;

  /// The collocation points x_i on γ, their outward unit normals n_i and arc-length positions s_i.
  virtual const std::vector<Point2>& points() const = 0;
  virtual const std::vector<Point2>& normals() const = 0;
  virtual const std::vector<double>& arc_positions() const = 0;
  int n_points() const { return int(points().size()); }

  /// B_γ, C_γ (m rows over the grid unknowns) and the rows whose transposes carry λ into the grid.
  virtual const SparseRows& B_gamma() const = 0;
  virtual const SparseRows& C_gamma() const = 0;
  virtual const SparseRows& B_Gamma() const = 0;
  virtual const SparseRows& loads() const = 0;
  /// D_B, D_C: trace terms that act on λ directly (empty: none).
  virtual const DirectTerms& direct() const = 0;

  /// Turns u₀ + A⁻¹ loadsᵀλ (+ α) into the output field (the kink-corrected one where it applies).
  virtual void finish_field(const std::vector<double>& lambda, GridVector& u) const = 0;
  /// ∂u/∂n at the points by a rule independent of C_γ, and its name; nullopt where ω is too thin.
  virtual std::optional<std::vector<double>> independent_normal_derivative(const GridVector& u,
                                                                           std::string& rule) const = 0;
  /// Errors of u against the exact solution of `data` in ω and on γ.
  virtual ErrorNorms errors(const GridVector& u, const ContactData& data, int quadrature,
                            const Execution& execution) const = 0;
};

}  // namespace fictus
