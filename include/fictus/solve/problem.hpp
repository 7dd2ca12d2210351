#pragma once
// A Signorini problem on ω ⊂ Ω ⊂ R^dim (dim = 2 or 3), one type for both dimensions:
//   −Δu + c·u = f in ω,  u ≥ g, ∂u/∂n ≥ 0, (∂u/∂n)(u − g) = 0 on γ = ∂ω,
// γ a closed curve (dim = 2, curve.hpp) or a closed surface (dim = 3, surface.hpp); or, with mixed
// conditions (PartConditions), u = u_D on a Dirichlet part and ∂u/∂n = q on a Neumann part of γ and
// the Signorini conditions on the rest.
#include <cmath>
#include <functional>
#include <memory>
#include <string>

#include "fictus/boundary/curve.hpp"
#include "fictus/boundary/surface.hpp"
#include "fictus/grid/load_vector.hpp"
#include "fictus/solve/solver_options.hpp"

namespace fictus {

/// The condition at a point of γ (mixed conditions, docs/math.md): Signorini (its row chosen by the active
/// set), or an equation always in force: Dirichlet (the B row) or Neumann (the C row).
enum class PointCondition : char { signorini = 0, dirichlet = 1, neumann = 2 };

/// What γ is in a dimension: a Curve in 2-D, a Surface in 3-D.
template <int dim>
struct BoundaryShape;
template <>
struct BoundaryShape<2> {
  using type = Curve;
};
template <>
struct BoundaryShape<3> {
  using type = Surface;
};

/// An obstacle that depends on the arc length s along γ too (2-D only: a surface has no arc length).
template <int dim>
struct ObstacleAlongBoundary {};
template <>
struct ObstacleAlongBoundary<2> {
  /// Optional g(x, y, s), used instead of g when set.
  std::function<double(double x, double y, double s)> g_along_curve;
};

/// Conditions other than Signorini's on parts of γ (docs/math.md, "Mixed conditions"). A point x of γ
/// is in the Dirichlet part where dirichlet(x) ≠ 0 (there u = u_D(x)), in the Neumann part where
/// neumann(x) ≠ 0 (there ∂u/∂n = q(x, n), n the outward normal), in no more than one of them, and in
/// the Signorini part (the obstacle g) elsewhere. Unset `dirichlet` and `neumann`: all of γ is Signorini.
template <int dim>
struct PartConditions {
  std::function<double(const Point<dim>&x)> dirichlet, neumann;          // where (non-zero: in the part)
  std::function<double(const Point<dim>& x)> u;                          // u_D on the Dirichlet part
  std::function<double(const Point<dim>& x, const Point<dim>& n)> flux;  // q on the Neumann part (unset: 0)
  /// Placement only (solver.fit_contact, docs/math.md "Fitting the points to the contact set"): non-zero on
  /// the contact side of a located contact boundary. The Signorini part's points are placed as if it
  /// were a junction there (arcs end on it, patches do not straddle it); their conditions stay Signorini's.
  std::function<double(const Point<dim>& x)> contact_side;
  bool mixed() const { return bool(dirichlet) || bool(neumann); }
  /// Whether the points are placed part by part (mixed conditions, or a contact side to fit).
  bool placed() const { return mixed() || bool(contact_side); }
  /// The part x lies in: Dirichlet where that expression is finite and non-zero, else Neumann where that
  /// one is, else Signorini (the overlap of the two parts is refused at the points, not here).
  PointCondition at(const Point<dim>& x) const {
    const auto holds = [&x](const std::function<double(const Point<dim>&)>& part) {
      if (!part) return false;
      const double value = part(x);
      return std::isfinite(value) && value != 0;
    };
    return holds(dirichlet) ? PointCondition::dirichlet
           : holds(neumann) ? PointCondition::neumann
                            : PointCondition::signorini;
  }
  /// The piece of γ x is placed in: int(at(x)), or contact_label on the Signorini part's contact side.
  static constexpr int contact_label = 3;
  int label(const Point<dim>& x) const {
    const PointCondition part = at(x);
    if (part != PointCondition::signorini || !contact_side) return int(part);
    const double side = contact_side(x);
    return std::isfinite(side) && side != 0 ? contact_label : int(part);
  }
  /// The condition of a piece's label.
  static PointCondition condition_of(int label) {
    return label == contact_label ? PointCondition::signorini : PointCondition(label);
  }
};

/// What may change from one solve to the next on the same grid: γ, the obstacle, the conditions on
/// parts of γ and the exact solution (FictitiousDomainSolver::solve).
template <int dim>
struct BasicContactData : ObstacleAlongBoundary<dim> {
  std::shared_ptr<const typename BoundaryShape<dim>::type> gamma;  // γ, strictly inside Ω (a curve counter-clockwise)
  typename Fields<dim>::Scalar g;                                  // obstacle, sampled at the points on γ
  PartConditions<dim> conditions;                                  // Dirichlet and Neumann parts (none: all Signorini)
  /// Optional batch forms (e.g. numpy callables), used instead of g and exact when set.
  typename Fields<dim>::Vectorized g_vectorized, exact_vectorized;
  typename Fields<dim>::Scalar exact;             // optional exact solution on ω (errors are computed if set)
  typename Fields<dim>::Gradient exact_gradient;  // optional ∇u (central differences of `exact` if unset)
};

/// The whole problem: the grid-level data (box, N, boundary conditions, c, f: what the
/// FictitiousDomainSolver is built for) and the contact data.
template <int dim>
struct BasicProblem : BasicContactData<dim> {
  std::string name = "problem";
  Box<dim> box;                                   // Ω (the unit box by default)
  Boundary boundary = Boundary::dirichlet;        // conditions on ∂Ω (periodic: c = 0 is allowed)
  int N = dim == 2 ? 256 : 64;                    // cells along x (h = (x1 − x0)/N)
  double c = 1.0;                                 // c ≥ 0
  typename Fields<dim>::Scalar f;                 // load, on all of Ω
  typename Fields<dim>::Vectorized f_vectorized;  // optional batch form of f, used instead when set
};

using ContactData = BasicContactData<2>;
using Problem = BasicProblem<2>;
using SurfaceProblem = BasicProblem<3>;

}  // namespace fictus
