#pragma once
// A Signorini problem on ω ⊂ Ω and the options of the fictitious domain solver.
//   −Δu + c·u = f in ω,  u ≥ g, ∂u/∂n ≥ 0, (∂u/∂n)(u − g) = 0 on γ = ∂ω.
#include <memory>
#include <string>

#include "fictus/curve.hpp"
#include "fictus/error_norms.hpp"
#include "fictus/load_vector.hpp"
#include "fictus/solver_options.hpp"

namespace fictus {

/// What may change from one solve to the next on the same grid: the curve, the obstacle and the
/// exact solution (FictitiousDomainSolver::solve).
struct ContactData {
  std::shared_ptr<const Curve> gamma;  // γ, counter-clockwise, strictly inside Ω
  ScalarField g;                       // obstacle, sampled at the collocation points on γ
  /// Optional obstacle that also depends on the arc length s along γ (used instead of g when set).
  std::function<double(double x, double y, double s)> g_along_curve;
  /// Optional batch forms (e.g. numpy callables), used instead of g and exact when set.
  VectorizedField g_vectorized, exact_vectorized;
  ScalarField exact;             // optional exact solution on ω (errors are computed if set)
  GradientField exact_gradient;  // optional ∇u (central differences of `exact` if unset)
};

/// The whole problem: the grid-level data (box, N, boundary conditions, c, f: what the
/// FictitiousDomainSolver is built for) and the contact data.
struct Problem : ContactData {
  std::string name = "problem";
  Box2 box;                                 // Ω
  Boundary boundary = Boundary::dirichlet;  // conditions on ∂Ω (periodic: c = 0 is allowed)
  int N = 256;                              // cells along x (h = (x1 − x0)/N)
  double c = 1.0;                           // c ≥ 0
  ScalarField f;                            // load, on all of Ω
  VectorizedField f_vectorized;             // optional batch form of f, used instead when set
};

}  // namespace fictus
