#pragma once
// The whole method: curves and collocation → trace rows → load → u₀ = A⁻¹f → Schur complement
// (implicit, or explicit from the Green's table) → semismooth Newton on λ → û = u₀ + A⁻¹B_Γᵀλ →
// Signorini checks and errors.
//
// FictitiousDomainSolver keeps what does not depend on the curve or the obstacle: the fast solver,
// the Green's table T (grid, boundary and c only) and u₀ (the load f). A new obstacle g or ρ costs
// only the m×m Newton; a new curve its trace rows, Schur blocks and Newton; the grid field û one
// more fast solve (skip it with compute_field = false: boundary values then come from the Schur
// blocks).
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "fictus/collocation.hpp"
#include "fictus/error_norms.hpp"
#include "fictus/problem.hpp"
#include "fictus/semismooth_newton.hpp"

namespace fictus {

struct SignoriniCheck {
  double min_gap = 0;                // min_i (B_γ û − g)_i        (≥ −tol)
  double min_normal_derivative = 0;  // min_i (C_γ û)_i             (≥ −tol)
  double max_complementarity = 0;    // max_i |(C_γ û)_i (B_γ û − g)_i|
};

/// The Signorini conditions once more with a normal derivative D_γ û from another stencil than the
/// solve's C_γ (docs/math.md, "Checks"): where C_γ is wrong, D_γ û − C_γ û shows it.
struct IndependentCheck {
  std::string rule;                   // the stencil of D_γ
  double min_normal_derivative = 0;   // min_i (D_γ û)_i
  double max_complementarity = 0;     // max_i |(D_γ û)_i (B_γ û − g)_i|
  double max_difference = 0;          // max_i |D_γ û − C_γ û|_i
  double rms_difference = 0;          // root mean square of the same
};

/// Errors at the collocation points against an exact solution.
struct PointErrors {
  double max_trace = 0;               // max_i |(B_γ û)_i − u(x_i)|
  double max_normal_derivative = 0;   // max_i |(C_γ û)_i − ∂u/∂n(x_i)|
};

struct Timings {
  std::vector<std::pair<std::string, double>> phases;  // seconds, in execution order
  double total = 0;
  double operator[](const std::string& name) const;
};

struct Solution {
  explicit Solution(const Grid& g) : grid(g) {}
  Grid grid;
  SolverOptions options;                // in effect (m resolved)
  GridVector u;                         // û at the unknowns (empty when the field was not asked for)
  Collocation collocation;              // points on γ
  std::shared_ptr<const Curve> Gamma;   // the curve carrying λ (γ itself in the non-smooth variant)
  double delta = 0;                     // distance of Γ from γ
  std::vector<double> lambda, g, trace, normal_derivative;  // per point: λ, g, B_γû, C_γû
  double alpha = 0;                     // constant added to û (singular A: periodic box, c = 0)
  NewtonResult newton;
  std::size_t fast_solves = 0;          // applications of A⁻¹ in this solve (the paper's it₁)
  int inner_iterations = 0;             // Krylov iterations over all Newton steps
  bool reused_curve = false;            // trace rows and Schur blocks came from the previous solve
  std::optional<double> condition_number;
  SignoriniCheck signorini;
  std::optional<IndependentCheck> check;  // with the field only
  std::optional<ErrorNorms> errors;
  std::optional<PointErrors> point_errors;
  Timings timings;
  std::size_t peak_memory_bytes = 0;    // of the process so far (VmHWM)
};

class FictitiousDomainSolver {
 public:
  /// Takes the grid-level data of `problem` (box, N, boundary, c, f); throws std::invalid_argument
  /// naming the field on bad input. u₀ and T are computed on the first solve that needs them.
  explicit FictitiousDomainSolver(const Problem& problem, int threads = 1, int load_quadrature = 2);
  ~FictitiousDomainSolver();
  FictitiousDomainSolver(const FictitiousDomainSolver&) = delete;
  FictitiousDomainSolver& operator=(const FictitiousDomainSolver&) = delete;

  const Grid& grid() const;

  /// Solves with the curve, obstacle and exact solution of `problem` (its box, N, boundary, c and f
  /// must be those given to the constructor). Reuses the previous curve's trace rows and Schur
  /// blocks when problem.gamma is the same object and the options that shape them are unchanged.
  Solution solve(const Problem& problem, SolverOptions options, bool compute_field = true);

  struct State;

 private:
  std::unique_ptr<State> state_;
};

/// The one-line report of a Newton failure, with its history (what the CLI and the bindings print).
std::string describe_newton_failure(const Solution& solution);

/// One problem, one call (a thin wrapper over FictitiousDomainSolver).
Solution solve(const Problem& problem, SolverOptions options);

/// Peak resident memory of this process in bytes (0 where unknown).
std::size_t peak_memory_bytes();

}  // namespace fictus
