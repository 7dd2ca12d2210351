#pragma once
// The whole method, one code for both dimensions (dim = 2: a curve in a rectangle; dim = 3: a surface
// in a box), as the steps of FictitiousDomainSolver<dim>::solve (docs/math.md):
//   once per boundary γ and the options that shape its rows (reused while they stay), first, so that
//   bad input is refused before any grid-sized work:
//     1. geometry: γ checked, m and δ (spacing_rule.hpp), the points (collocation points or patches) and Γ;
//     2. trace rows: B_γ, C_γ, B_Γ (and the kink correction);
//   the nested start (optional, solver.nested_start): the same problem on the grid of N/2, whose
//   active set starts Newton here;
//   once per solver (grid, boundary conditions, c, f):
//     0. load and u₀ = A⁻¹f;
//   once per boundary, after u₀ exists:
//     2b. what the boundary's rows need from the grid's fast solver (the 3-D flux balance);
//     3. Schur blocks: S_B, S_C (explicit from the Green's table T, made on the first of them, with the
//        far field interpolated where the boundary allows it; or implicit with GMRES);
//     then B_γu₀ and C_γu₀ (again for each new load);
//   every solve:
//     4. obstacle g at the points;
//     5. semismooth Newton on λ (on the interpolated S first, then on the exact one, where the far
//        field was interpolated);
//     6. field û = u₀ + A⁻¹B_Γᵀλ (+ α; kink-corrected in the non-smooth variant), or the boundary
//        values from the Schur blocks without it;
//     7. Signorini checks, with an independent ∂u/∂n where the boundary has one;
//     8. errors against an exact solution.
#include <cstddef>
#include <functional>
#include <memory>
#include <string>

#include "fictus/solve/problem.hpp"
#include "fictus/solve/solution.hpp"

namespace fictus {

/// Newton runs on the interpolated S̃ until a step changes at most this fraction of the points (at
/// least one), then on the exact S.
inline constexpr double far_field_hand_on = 0.05;
/// GMRES's relative residual for the Newton steps on the exact S behind an interpolated far field.
inline constexpr double far_field_gmres_tolerance = 1e-13;
/// Hierarchical storage: the relative residual of GMRES on S̃_𝒜 (Newton's steps before the exact S).
inline constexpr double hierarchical_gmres_tolerance = 1e-12;
/// The nested start's coarse grid has at least this many cells along x (solver.nested_start).
inline constexpr int minimum_nested_grid = 8;
/// Gauss points per direction of the integrals over ω of a solution (DomainQuantities): 2 integrate
/// û², |∇û|² and the difference of two grids' fields exactly on whole cells, and f, fû to O(h⁴).
inline constexpr int quantity_quadrature = 2;
/// A warning when the estimated error of û passes this fraction of ‖û‖_{L²(ω)} (solver.error_estimate).
inline constexpr double estimate_warning = 0.01;
/// A warning when the root mean square of D_γû − C_γû (the independent check) passes this fraction of
/// the largest |C_γû| (docs/math.md, "Checks").
inline constexpr double check_warning = 0.05;

template <int dim>
class FictitiousDomainSolver {
 public:
  /// The grid-level data of `problem` (box, N, boundary, c, f) and the options that shape the
  /// grid-level work (threads, load_quadrature); throws std::invalid_argument naming the field on bad
  /// input. u₀ and T are computed on the first solve that needs them.
  explicit FictitiousDomainSolver(const BasicProblem<dim>& problem, const SolverOptions& options = {});
  ~FictitiousDomainSolver();
  FictitiousDomainSolver(const FictitiousDomainSolver&) = delete;
  FictitiousDomainSolver& operator=(const FictitiousDomainSolver&) = delete;

  const Grid<dim>& grid() const;

  /// A check polled on the calling thread between the steps of a solve, in Newton and GMRES
  /// iterations and in the Schur assembly; when it returns true the solve ends with Interrupted
  /// (execution.hpp) within about one fast solve. The bindings use it for Ctrl-C.
  void set_interrupt_check(std::function<bool()> check);

  /// A new load f (problem.f or problem.f_vectorized) on the same grid, c and boundary conditions:
  /// u₀ is recomputed on the next solve; the Green's table and the boundary's trace rows and Schur
  /// blocks are kept (a sweep over a parameter of f costs one fast solve and one Newton per member).
  void replace_load(const BasicProblem<dim>& problem);

  /// Called with each step's name and seconds as the step ends (the CLI's progress lines).
  void set_progress(std::function<void(const std::string& phase, double seconds)> progress);

  /// Solves with the boundary, obstacle and exact solution of `data` and the per-solve options
  /// (options.threads and options.load_quadrature must be the constructor's: they shaped the
  /// grid-level work). Reuses the previous boundary's trace rows and Schur blocks when data.gamma is the
  /// same object and the options that shape them are unchanged. With `keep` false the Schur blocks and
  /// u₀ are freed as soon as they are used (a one-off solve: the least memory), and the next solve
  /// makes them again.
  BasicSolution<dim> solve(const BasicContactData<dim>& data, SolverOptions options, bool compute_field = true,
                           bool keep = true);

  struct State;

 private:
  std::unique_ptr<State> state_;
};

/// One problem, one call (a thin wrapper over FictitiousDomainSolver, with keep = false); `progress` is
/// called with each step's name and seconds as it ends, `interrupt` asked between them.
template <int dim>
BasicSolution<dim> solve(const BasicProblem<dim>& problem, SolverOptions options,
                         std::function<void(const std::string& phase, double seconds)> progress = {},
                         std::function<bool()> interrupt = {});

/// The peak memory of a solve, estimated before anything is allocated: three grid arrays (u₀, the
/// field, and the Green's table or the Krylov work vector; four in 3-D) of 8 bytes per node, the dense
/// m×m blocks (S_B, S_C, the Newton matrix and its LU), and 32 MiB for the rest. m is the one the solve
/// will use (the default rule, with γ's length or area). Measured 2-D peaks at h = 1/1024 … 1/4096 are
/// within 10 %.
template <int dim>
std::size_t estimated_peak_bytes(const BasicProblem<dim>& problem, const SolverOptions& options);

/// The wall time of a solve, estimated before anything is allocated from the grid's nodes and m, by a
/// model calibrated on a 2-core machine (bench/results) and scaled by the threads. Rough: within a
/// factor of about 2 there for the green solver, looser for GMRES (its iteration count depends on
/// the problem). For a progress header, never a limit.
template <int dim>
double estimated_seconds(const BasicProblem<dim>& problem, const SolverOptions& options);

}  // namespace fictus
