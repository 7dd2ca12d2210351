#pragma once
// The whole method, as the steps of FictitiousDomainSolver::solve (docs/math.md):
//   once per curve and the options that shape its rows (reused while they stay), first, so that bad
//   input is refused before any grid-sized work:
//     1. geometry: γ checked, m and δ (spacing_rule.hpp), collocation points and Γ;
//     2. trace rows: B_γ, C_γ, B_Γ (and the kink correction);
//     3. Schur blocks: S_B, S_C (explicit from the Green's table T, made on the first of them, or
//        implicit with GMRES);
//   once per solver (grid, boundary conditions, c, f):
//     0. load and u₀ = A⁻¹f (then B_γu₀, C_γu₀);
//   every solve:
//     4. obstacle g at the points;
//     5. semismooth Newton on λ;
//     6. field û = u₀ + A⁻¹B_Γᵀλ (+ α; kink-corrected in the non-smooth variant), or the boundary
//        values from the Schur blocks without it;
//     7. Signorini checks, with an independent ∂u/∂n;
//     8. errors against an exact solution.
#include <cstddef>
#include <functional>
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
  std::string rule;                       // the stencil of D_γ
  double min_normal_derivative = 0;       // min_i (D_γ û)_i
  double max_complementarity = 0;         // max_i |(D_γ û)_i (B_γ û − g)_i|
  double max_difference = 0;              // max_i |D_γ û − C_γ û|_i
  double rms_difference = 0;              // root mean square of the same
  std::vector<double> normal_derivative;  // (D_γ û)_i at every point
};

/// Errors at the collocation points against an exact solution.
struct PointErrors {
  double max_trace = 0;              // max_i |(B_γ û)_i − u(x_i)|
  double max_normal_derivative = 0;  // max_i |(C_γ û)_i − ∂u/∂n(x_i)|
};

struct Timings {
  std::vector<std::pair<std::string, double>> phases;  // seconds, in execution order
  double total = 0;
  double operator[](const std::string& name) const;
};

struct Solution {
  explicit Solution(const Grid2& g) : grid(g) {}
  Grid2 grid;
  SolverOptions options;               // in effect (m and the offset resolved)
  std::vector<std::string> warnings;   // what the solve changed to fit (one line each), for the user
  GridVector u;                        // û at the unknowns (empty when the field was not asked for)
  Collocation collocation;             // points on γ
  std::shared_ptr<const Curve> Gamma;  // the curve carrying λ (γ itself in the non-smooth variant)
  double delta = 0;                    // distance of Γ from γ
  std::vector<double> lambda, g, trace, normal_derivative;  // per point: λ, g, B_γû, C_γû
  double lambda_total = 0;  // Σ_i λ_i·|Γ_i| = 1ᵀB_Γᵀλ, the total load λ adds to the box (∫_Γ λ ds)
  double alpha = 0;         // constant added to û (singular A: periodic box, c = 0)
  NewtonResult newton;
  std::size_t fast_solves = 0;  // applications of A⁻¹ in this solve (the paper's it₁)
  int inner_iterations = 0;     // Krylov iterations over all Newton steps
  bool reused_curve = false;    // trace rows and Schur blocks came from the previous solve
  std::optional<double> condition_number;
  SignoriniCheck signorini;
  std::optional<IndependentCheck> check;  // with the field only
  std::optional<ErrorNorms> errors;
  std::optional<PointErrors> point_errors;
  Timings timings;
  std::size_t peak_memory_bytes = 0;  // of the process so far (VmHWM; set by the caller, 0 if unknown)
};

class FictitiousDomainSolver {
 public:
  /// The grid-level data of `problem` (box, N, boundary, c, f) and the options that shape the
  /// grid-level work (threads, load_quadrature); throws std::invalid_argument naming the field on bad
  /// input. u₀ and T are computed on the first solve that needs them.
  explicit FictitiousDomainSolver(const Problem& problem, const SolverOptions& options = {});
  ~FictitiousDomainSolver();
  FictitiousDomainSolver(const FictitiousDomainSolver&) = delete;
  FictitiousDomainSolver& operator=(const FictitiousDomainSolver&) = delete;

  const Grid2& grid() const;

  /// A check polled on the calling thread between the steps of a solve, in Newton and GMRES
  /// iterations and in the Schur assembly; when it returns true the solve ends with Interrupted
  /// (execution.hpp) within about one fast solve. The bindings use it for Ctrl-C.
  void set_interrupt_check(std::function<bool()> check);

  /// A new load f (problem.f or problem.f_vectorized) on the same grid, c and boundary conditions:
  /// u₀ is recomputed on the next solve; the Green's table and the curve's trace rows and Schur blocks
  /// are kept (a sweep over a parameter of f costs one fast solve and one Newton per member).
  void replace_load(const Problem& problem);

  /// Called with each step's name and seconds as the step ends (the CLI's progress lines).
  void set_progress(std::function<void(const std::string& phase, double seconds)> progress);

  /// Solves with the curve, obstacle and exact solution of `data` and the per-solve options
  /// (options.threads and options.load_quadrature must be the constructor's: they shaped the
  /// grid-level work). Reuses the previous curve's trace rows and Schur blocks when data.gamma is the
  /// same object and the options that shape them are unchanged.
  Solution solve(const ContactData& data, SolverOptions options, bool compute_field = true);

  struct State;

 private:
  std::unique_ptr<State> state_;
};

/// The contact in numbers, from the per-point values of a solution (point i owns the arc
/// collocation.arc[i] of γ around it).
struct ContactSummary {
  long points = 0;     // points in contact (the active set)
  double measure = 0;  // length of the contact set: points · L/m
  double force = 0;    // total contact force ∫ ∂u/∂n ds over the contact set: Σ_active (C_γû)_i · L/m
  double lambda = 0;   // ∫_Γ λ ds = Σ λ_i·|Γ_i| (Solution::lambda_total): non-smooth, the jump [∂û/∂n]
                       // integrated over γ (it includes the fictitious field outside ω: not the
                       // contact force); smooth, the total control on Γ
  double min_gap = 0;  // min_i (B_γû − g)_i  (≈ 0: the contact points)
  double max_gap = 0;  // max_i (B_γû − g)_i  (the widest opening)
};
ContactSummary contact_summary(const Solution& solution);

/// The peak memory of a solve, estimated before anything is allocated: three grid arrays (u₀, the
/// field, and the Green's table or the Krylov work vector) of 8 bytes per node, four dense m×m blocks
/// (S_B, S_C, the Newton matrix and its LU), and 32 MiB for the rest. m is the one the solve will use
/// (the default rule, with the curve's length). Measured peaks at h = 1/1024 … 1/4096 are within 10 %.
std::size_t estimated_peak_bytes(const Problem& problem, const SolverOptions& options);

/// The wall time of a solve, estimated before anything is allocated from the grid's nodes and m, by a
/// model calibrated on a 2-core machine (bench/results) and scaled by the threads. Rough: within a
/// factor of about 2 there for the green solver, looser for GMRES (its iteration count depends on
/// the problem). For a progress header, never a limit.
double estimated_seconds(const Problem& problem, const SolverOptions& options);

/// The one-line report of a Newton failure, with its history (what the CLI and the bindings print).
std::string describe_newton_failure(const Solution& solution);

/// One problem, one call (a thin wrapper over FictitiousDomainSolver).
Solution solve(const Problem& problem, SolverOptions options);

}  // namespace fictus
