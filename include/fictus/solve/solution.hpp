#pragma once
// What a solve returns, one type for both dimensions: the field û on the grid, the values at the m
// points of γ (λ, g, B_γû, C_γû, contact flags), Newton's report, checks, errors and timings. The
// points are a curve's collocation points in 2-D and a surface's patches in 3-D (SolutionBoundary).
#include <array>
#include <cmath>
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "fictus/boundary/collocation.hpp"
#include "fictus/boundary/curve.hpp"
#include "fictus/boundary/surface_integrals.hpp"
#include "fictus/grid/grid.hpp"
#include "fictus/solve/error_norms.hpp"
#include "fictus/solve/schur_complement.hpp"
#include "fictus/solve/semismooth_newton.hpp"
#include "fictus/solve/solver_options.hpp"

namespace fictus {

struct SignoriniCheck {
  double min_gap = 0;                // min_i (B_γ û − g)_i        (≥ −tol)
  double min_normal_derivative = 0;  // min_i (C_γ û)_i             (≥ −tol)
  double max_complementarity = 0;    // max_i |(C_γ û)_i (B_γ û − g)_i|
};

/// The Signorini conditions once more with a normal derivative D_γ û from another stencil than the
/// solve's C_γ (docs/math.md, "Checks"): where C_γ is wrong, D_γ û − C_γ û shows it.
struct IndependentCheck {
  std::string rule;                  // the stencil of D_γ
  double min_normal_derivative = 0;  // min_i (D_γ û)_i
  double max_complementarity = 0;    // max_i |(D_γ û)_i (B_γ û − g)_i|
  double max_difference = 0;         // max_i |D_γ û − C_γ û|_i
  double rms_difference = 0;         // root mean square of the same
  double relative_difference = 0;    // rms_difference / max_i |C_γ û|_i, or / the trace's slope along γ where the
                                     // readings carry no flux (0 where both are 0)
  std::vector<double> normal_derivative;  // (D_γ û)_i at every point
};

/// Errors at the points against an exact solution.
struct PointErrors {
  double max_trace = 0;              // max_i |(B_γ û)_i − u(x_i)|
  double max_normal_derivative = 0;  // max_i |(C_γ û)_i − ∂u/∂n(x_i)|
};

struct Timings {
  std::vector<std::pair<std::string, double>> phases;  // seconds, in execution order
  double total = 0;
  double operator[](const std::string& name) const;
};

/// With solver.far_field: what the assembly interpolated, and the Newton steps run on the exact S
/// (preconditioned by S̃) after those on S̃ (all counted in newton.iterations).
struct FarFieldUse {
  FarFieldReport assembly;
  int exact_steps = 0;
};

/// With solver.nested_start (N at or above it): the solve of the same problem on the grid of N/2
/// whose active set, taken at each point from the nearest coarse point, started Newton here; or,
/// when that solve could not be made, why (`skipped`), and Newton started as solver.start says.
struct NestedStart {
  int N = 0;             // the coarse grid's
  int multipliers = 0;   // the coarse m
  int newton_steps = 0;  // the coarse solve's (not counted in newton.iterations)
  int active = 0;        // its points in contact
  double seconds = 0;    // the whole coarse solve, its own nested start included
  std::string skipped;   // non-empty: no nested start, and why
};

/// With formulation.flux_balance (3-D non-smooth): how far the kink-corrected readings missed the
/// discrete flux balance before the correction (docs/math.md, "The flux balance of the patches").
struct FluxBalanceUse {
  double scatter = 0;     // the standard deviation over the patches of β_j/a_j
  double mean = 0;        // μ: a constant layer's error of the mean reading, per unit λ
  double data_shift = 0;  // what every reading of the data's field u₀ moved by
};

/// Integrals over ω of the field û and the load f (with the field only), and what users quote from them
/// (docs/math.md, "Quantities"): the energy J(û) = ½∫|∇û|² + ½c∫û² − ∫fû and the flux through γ,
/// ∫_γ ∂u/∂n = ∫_ω (cu − f), which is the contact force (the free part of γ carries none).
struct DomainQuantities {
  double volume = 0;          // |ω| by the same rule (area in 2-D)
  double integral_u = 0;      // ∫_ω û
  double integral_u2 = 0;     // ∫_ω û²
  double integral_grad2 = 0;  // ∫_ω |∇û|²
  double integral_f = 0;      // ∫_ω f
  double integral_fu = 0;     // ∫_ω f û
  double energy = 0;          // J(û)
  double flux = 0;            // c∫_ω û − ∫_ω f
};

/// Errors estimated from the same problem solved on the grid of N/2 (docs/math.md, "The error
/// estimate"): for each quantity Q, |Q_N − Q_{N/2}|/(2^p − 1) with p its order (2; 1 for the contact
/// measure), and ‖û_N − û_{N/2}‖_{L²(ω)}/3 for û; or, when that solve could not be made, why.
struct ErrorEstimate {
  int N = 0;                // the coarse grid's
  double l2_omega = 0;      // ‖û − u‖_{L²(ω)}
  double rel_l2_omega = 0;  // the same over ‖û‖_{L²(ω)}
  double force = 0;         // |force − exact force|
  double measure = 0;       // |contact measure − exact|
  double energy = 0;        // |J(û) − J(u)|
  double integral_u = 0;    // |∫û − ∫u|
  double seconds = 0;       // the coarse solve (shared with the nested start where there is one)
  std::string skipped;      // non-empty: no estimate, and why
  std::string caveat;       // non-empty: where the solve of N/2 left this one's rule (m, δ, the fit), so that
                            // the two grids are not one method's path and the estimate is rougher
};

/// Neighbouring points of γ: consecutive points of a curve, patches sharing a triangle edge of a surface.
struct NeighbourPair {
  int i = 0, j = 0;
  double distance = 0;       // between x_i and x_j (along the curve in 2-D, the chord in 3-D)
  double border = 0;         // the measure of the parts' common border: 1 in 2-D, the shared edges' length in 3-D
  std::vector<int> corners;  // 3-D: the triangulation's vertices (by index) at the ends of the border's edges
};

/// Mixed conditions: two neighbouring points under different conditions, and where between them the
/// condition changes (docs/math.md, "Mixed conditions"): at the fraction θ of the way from x_i to x_j.
template <int dim>
struct PartJunction {
  NeighbourPair pair;
  double theta = 0.5;
  Point<dim> at;
};

/// The points of γ a solution's values belong to, and the boundary carrying λ.
template <int dim>
struct SolutionBoundary;

template <>
struct SolutionBoundary<2> {
  Collocation collocation;             // the points on γ, with the arcs they own
  std::shared_ptr<const Curve> Gamma;  // the curve carrying λ (γ itself in the non-smooth variant)
  int n_points() const { return collocation.m; }
  const std::vector<Point2>& points() const { return collocation.point; }
  const std::vector<Point2>& normals() const { return collocation.normal; }
  const std::vector<double>& weights() const { return collocation.arc; }  // the length of γ each point owns
  double spacing() const { return collocation.spacing; }                  // s = L/m
};

template <>
struct SolutionBoundary<3> {
  PatchedSurface gamma;  // γ's patches: triangles, points, normals, areas
  PatchedSurface Gamma;  // the surface carrying λ (γ itself in the non-smooth variant)
  int n_points() const { return gamma.m; }
  const std::vector<Point3>& points() const { return gamma.point; }
  const std::vector<Point3>& normals() const { return gamma.normal; }
  const std::vector<double>& weights() const { return gamma.area; }  // the area of γ each point owns
  double spacing() const {                                           // s = √(A/m)
    double area = 0;
    for (double a : gamma.area) area += a;
    return gamma.m > 0 ? std::sqrt(area / gamma.m) : 0.0;
  }
};

/// solver.fit_contact: the solves whose points were placed to the previous solve's contact boundary.
struct ContactFit {
  int passes = 0;                 // solves after the first (the solution is the last one's)
  std::vector<double> moved;      // per pass: the largest distance of a located end from the nearest end
                                  // it was placed for, in spacings s
  std::vector<int> newton_steps;  // per solve, the first included
  double seconds = 0;             // the solves before the last one
};

template <int dim>
struct BasicSolution : SolutionBoundary<dim> {
  explicit BasicSolution(const Grid<dim>& g) : grid(g) {}
  Grid<dim> grid;
  SolverOptions options;              // in effect (m, the offset, the variant and the threads resolved)
  std::vector<std::string> warnings;  // what the solve changed to fit (one line each), for the user
  GridVector u;                       // û at the unknowns (empty when the field was not asked for)
  double delta = 0;                   // distance of Γ from γ
  std::vector<double> lambda, g, trace, normal_derivative;  // per point: λ, g (u_D at Dirichlet points), B_γû, C_γû
  /// Mixed conditions: each point's condition and q at the Neumann points; kind empty: all Signorini.
  PointConditions conditions;
  std::vector<PartJunction<dim>> junctions;  // mixed conditions: where the parts meet, located between points
  PointCondition condition(int i) const {
    return conditions.kind.empty() ? PointCondition::signorini : conditions.kind[std::size_t(i)];
  }
  /// A Signorini point in contact (Dirichlet points keep their B rows but are not in contact).
  bool in_contact(int i) const {
    return newton.active[std::size_t(i)] == 1 && condition(i) == PointCondition::signorini;
  }
  double lambda_total = 0;  // Σ_i λ_i·|Γ_i| = 1ᵀB_Γᵀλ, the total load λ adds to the box (∫_Γ λ)
  double alpha = 0;         // constant added to û (singular A: periodic box, c = 0)
  NewtonResult newton;
  std::size_t fast_solves = 0;  // applications of A⁻¹ in this solve (the paper's it₁)
  int inner_iterations = 0;     // Krylov iterations over all Newton steps
  int factorizations = 0;       // LUs of Newton matrices (green dense: the others by updates; hierarchical:
                                // LUs of the preconditioner's blocks)
  bool reused_curve = false;    // γ's trace rows and Schur blocks came from the previous solve
  std::optional<double> condition_number;
  using FarFieldUse = fictus::FarFieldUse;
  using NestedStart = fictus::NestedStart;
  using FluxBalanceUse = fictus::FluxBalanceUse;
  std::optional<FarFieldUse> far_field;
  std::optional<SchurStorage> schur_storage;  // green only
  std::optional<NestedStart> nested_start;
  std::optional<FluxBalanceUse> flux_balance;
  SignoriniCheck signorini;
  std::optional<IndependentCheck> check;   // with the field only
  std::optional<DomainQuantities> domain;  // with the field only
  std::optional<ErrorEstimate> estimate;   // with solver.error_estimate and the field
  // The contact set resolved inside the points' parts (docs/math.md, "The contact set"): where γ leaves
  // contact between an active point and its free neighbour, and the measure that follows.
  std::vector<Point<dim>> contact_boundary;                // one point per active–free pair of neighbours
  std::vector<std::array<int, 2>> contact_boundary_lines;  // 3-D: consecutive points of contact_boundary
  std::vector<std::array<int, 2>> contact_boundary_pairs;  // each such point's active and free point
  double contact_measure = 0;                              // length (2-D) or area (3-D)
  std::optional<ContactFit> contact_fit;                   // with solver.fit_contact
  std::optional<ErrorNorms> errors;
  std::optional<PointErrors> point_errors;
  Timings timings;
  std::size_t peak_memory_bytes = 0;                // of the process so far (VmHWM; set by the caller, 0 if unknown)
  std::vector<std::size_t> rank_peak_memory_bytes;  // under mpirun: each rank's (rank 0's is the above)
};

using Solution = BasicSolution<2>;
using SurfaceSolution = BasicSolution<3>;

template <int dim>
std::vector<NeighbourPair> neighbour_pairs(const SolutionBoundary<dim>& boundary);

/// Where the contact ends between an active point (its reading q > 0) and its free neighbour (gap r > 0)
/// a distance d away, as the fraction θ of d from the active point: the generic Signorini end, gap
/// K·t^{3/2} on the free side and ∂u/∂n = (3/2)K·t^{1/2} on the contact side (t: distance to the end),
/// through both values: √θ/(1 − θ)^{3/2} = q·d/(1.5·r).
double contact_end_fraction(double q, double r, double d);

/// The same where the free side is a band that another end closes a distance `beyond` past the free
/// point (docs/math.md, "The contact set"). Along the line, with the ends at 0 and e = (1 − θ)d + beyond,
/// the local solution Im (z(z − e))^{3/2} has the gap K·(x(e − x))^{3/2}/3 on the band and
/// ∂u/∂n = K·|x − e/2|·√(x(x − e)) beyond it; through both values
/// 3(α + e/2)√(α(α + e)) / (β·beyond)^{3/2} = q/r, α = θd, β = (1 − θ)d. As beyond → ∞ this is the law above.
double contact_end_fraction(double q, double r, double d, double beyond);

/// Sets solution.contact_boundary, contact_boundary_lines, contact_boundary_pairs and contact_measure from
/// the per-point values.
template <int dim>
void resolve_contact(BasicSolution<dim>& solution);

/// The contact side of a solution's located contact boundary, for placing the points of the next solve
/// (PartConditions::contact_side, solver.fit_contact): 1 at a point x of γ on the contact side, else 0.
/// Within 1.5·s of the boundary, the side of its nearest segment (in 2-D: of the nearest located end,
/// along the chord from the free point to the active one); farther away, the status of the nearest point
/// of the Signorini part.
/// Empty where the solution has no located end (nothing to fit).
template <int dim>
std::function<double(const Point<dim>&)> contact_side(const BasicSolution<dim>& solution);

/// One part of γ under one condition: its points, its measure Σ part_i and the flux through it
/// Σ (C_γû)_i·part_i.
struct PartSummary {
  long points = 0;
  double measure = 0;
  double flux = 0;
};

/// The contact in numbers, from the per-point values of a solution (point i owns the part
/// weights()[i] of γ: an arc length in 2-D, a patch area in 3-D). With mixed conditions only the
/// Signorini part has contact, and `force` is the patch sum (the domain identity gives the flux
/// through all of γ).
struct ContactSummary {
  PartSummary signorini, dirichlet, neumann;  // the parts of γ (all of it Signorini without mixed conditions)
  long points = 0;                            // points in contact (the active set)
  double measure = 0;         // length (2-D) or area (3-D) of the contact set, resolved inside the parts
                              // (BasicSolution::contact_measure)
  double measure_points = 0;  // the same as Σ over the contact points of their part
  double force = 0;  // total contact force ∫ ∂u/∂n over the contact set: the flux c∫_ω û − ∫_ω f where the
                     // field was computed (DomainQuantities) and all of γ is Signorini, else force_patches
  double force_patches = 0;        // the same as Σ_active (C_γû)_i·part_i: from the readings, a check of `force`
  bool force_from_domain = false;  // `force` is the domain identity
  double lambda = 0;   // ∫_Γ λ = Σ λ_i·|Γ_i| (BasicSolution::lambda_total): non-smooth, the jump [∂û/∂n]
                       // integrated over γ (it includes the fictitious field outside ω: not the
                       // contact force); smooth, the total control on Γ
  double min_gap = 0;  // min_i (B_γû − g)_i over the Signorini points (≈ 0: the contact points)
  double max_gap = 0;  // max_i (B_γû − g)_i over the Signorini points (the widest opening)
};
template <int dim>
ContactSummary contact_summary(const BasicSolution<dim>& solution);

/// The one-line report of a Newton failure, with its history (what the CLI and the bindings print).
template <int dim>
std::string describe_newton_failure(const BasicSolution<dim>& solution);

}  // namespace fictus
