#pragma once
// Semismooth Newton method for the boundary equation of the paper's eq. (3), in λ alone:
//   u(λ) = u₀ + A⁻¹B_Γᵀλ,  b(λ) = B_γ u = b₀ + S_B λ,  c(λ) = C_γ u = c₀ + S_C λ,
//   F(λ) = c(λ) − max{0, c(λ) − ρ(b(λ) − g)} = 0.
// Algorithm (numbered as in the code):
//   0. λ = 0; 𝒜 = all points ("all" start) or 𝒜 = {i : (c₀ − ρ(b₀ − g))_i > 0} ("zero" start)
//      or a given 𝒜 (NewtonOptions::start_active: the 3-D nested start's, from a coarser grid);
//      or λ, α and 𝒜 of an earlier run (NewtonOptions::start: another S takes over from there).
//   1. Linear solve: S_𝒜 λ = d, rows i ∈ 𝒜: (S_B λ)_i = g_i − b₀_i (contact, u = g),
//                               rows i ∉ 𝒜: (S_C λ)_i = −c₀_i     (free, ∂u/∂n = 0).
//   2. Residual: b, c at the new λ and F(λ).
//   3. Active set: 𝒜' = {i : (c − ρ(b − g))_i > 0}.
//   4. Stop when 𝒜' = 𝒜 and ‖F‖∞ ≤ tol·scale (finite termination); fail when 𝒜' repeats an
//      older set (cycling) or after max_iterations; hand on (NewtonOptions::hand_on_at_changes)
//      when 𝒜' differs from 𝒜 in at most that many points, returning 𝒜' as the next set.
// λ is not sign-constrained: the B/C rows carry the Signorini conditions.
// Mixed conditions (NewtonOptions::conditions): a Dirichlet point keeps its B row (B_γu = g_i, g_i its
// value u_D) and a Neumann point its C row (C_γu = q_i) in every step, with F_i = ρ(b − g)_i and
// (c − q)_i; only the Signorini points change sides. With no Signorini point one step solves it.
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "fictus/solve/problem.hpp"
#include "fictus/solve/schur_complement.hpp"
#include "fictus/solve/solver_options.hpp"

namespace fictus {

struct NewtonResult;

/// The conditions at the points: each point's kind and q at the Neumann points (0 elsewhere).
struct PointConditions {
  std::vector<PointCondition> kind;
  Eigen::VectorXd flux;
  bool fixed(int i) const { return kind[std::size_t(i)] != PointCondition::signorini; }
  /// The row a fixed point always takes (1: B, 0: C).
  char row(int i) const { return kind[std::size_t(i)] == PointCondition::dirichlet ? 1 : 0; }
};

/// The Newton part of SolverOptions (its defaults).
struct NewtonOptions {
  double rho = SolverOptions{}.rho;                 // ρ > 0 of the projection
  int max_iterations = SolverOptions{}.max_newton;  // linear solves
  bool start_all_active = SolverOptions{}.start_all_active;
  double tolerance = SolverOptions{}.newton_tolerance;  // ‖F‖∞ ≤ tolerance · max(‖b‖∞, ‖c‖∞, ‖g‖∞)
  std::function<void()> between_steps;                  // called before each linear solve (may throw)
  const NewtonResult* start = nullptr;                  // go on from an earlier run's active set, λ and α (not owned)
  const ActiveSet* start_active = nullptr;              // the first active set, with λ = 0 (not owned)
  const PointConditions* conditions = nullptr;          // mixed conditions (not owned); nullptr: all Signorini
  /// Hand on (stop, not converged, `active` the next set to try) once a step changes at most this
  /// many points; negative: never.
  int hand_on_at_changes = -1;
};

struct NewtonStep {
  int n_active = 0;          // |𝒜| used in this step's linear solve
  int inner_iterations = 0;  // Krylov applications in this step
  double residual = 0.0;     // ‖F(λ)‖∞ after the step
  int n_changed = 0;         // points whose status changed after the step
};

struct NewtonResult {
  Eigen::VectorXd lambda;
  double alpha = 0.0;                        // the constant added to u (singular A only)
  Eigen::VectorXd trace, normal_derivative;  // B_γu and C_γu at the final λ (from the Schur blocks)
  ActiveSet active;
  int iterations = 0;  // linear solves (the paper's it₀)
  bool converged = false;
  bool handed_on = false;     // stopped by hand_on_at_changes
  std::string failure;        // why not, when not converged
  bool inner_failed = false;  // some step's inner (Krylov) solve stopped at its cap or tolerance short
  bool stalled = false;       // the active set repeated with the residual above the tolerance
  double residual = 0.0;
  std::vector<NewtonStep> history;
};

/// `mode`: bordering for a singular A (see ConstantMode); nullptr otherwise.
NewtonResult solve_semismooth_newton(const SchurComplement& schur, const Eigen::VectorXd& b0, const Eigen::VectorXd& c0,
                                     const Eigen::VectorXd& g, const NewtonOptions& options,
                                     const ConstantMode* mode = nullptr);

}  // namespace fictus
