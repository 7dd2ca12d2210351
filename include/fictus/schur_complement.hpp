#pragma once
// The Schur complement of the discrete problem (3) with respect to λ:
//   u(λ) = u₀ + A⁻¹ B_Γᵀ λ,   S_B = B_γ A⁻¹ B_Γᵀ,   S_C = C_γ A⁻¹ B_Γᵀ   (m × m).
// In the non-smooth variant the traces are those of the kink-corrected field (kink_correction.hpp):
// the load rows are B_Γ + R and sparse terms D_B, D_C act on λ directly:
//   S_B = B_γ A⁻¹ (B_Γ + R)ᵀ + D_B,   S_C = C_γ A⁻¹ (B_Γ + R)ᵀ + D_C.
// The Newton matrix for an active set 𝒜 takes row i of S_B if i ∈ 𝒜 and row i of S_C otherwise.
// Two implementations behind one interface:
//   ImplicitSchur  the paper's: never formed, one fast A⁻¹ per application, GMRES per step;
//   ExplicitSchur  ours: S_B and S_C assembled from the discrete Green's function, dense LU.
#include <cstddef>
#include <functional>
#include <optional>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/Sparse>

#include "fictus/fast_solver.hpp"
#include "fictus/gmres.hpp"
#include "fictus/green_table.hpp"
#include "fictus/trace_operators.hpp"

namespace fictus {

using ActiveSet = std::vector<char>;  // 1: contact row (B_γ u = g), 0: free row (C_γ u = 0)

/// Bordering for a singular A (periodic box, c = 0: constants in the null space), as in the
/// projected Schur complement method: unknowns (λ, α) with u = u₀ + A⁺B_Γᵀλ + α·1; Newton row i
/// gains α·(B_γ1)_i (contact) or α·(C_γ1)_i (free), and the solvability row ℓᵀλ = −F with
/// ℓ = B_Γ1, F = 1ᵀf (that is 1ᵀ(f + B_Γᵀλ) = 0) closes the system.
struct ConstantMode {
  Eigen::VectorXd trace_B, trace_C;  // B_γ·1, C_γ·1
  Eigen::VectorXd arc_weights;       // ℓ = B_Γ·1
  double load_total = 0.0;           // F = 1ᵀf
};

/// Trace terms that act on λ directly (m × m; empty matrices: none).
struct DirectTerms {
  Eigen::SparseMatrix<double> trace, normal_derivative;  // D_B, D_C
  bool empty() const { return trace.nonZeros() == 0 && normal_derivative.nonZeros() == 0; }
};

struct LinearSolveReport {
  int inner_iterations = 0;  // Krylov operator applications (0 for a direct solve)
  double relative_residual = 0.0;
  bool converged = true;
};

class SchurComplement {
 public:
  virtual ~SchurComplement() = default;
  virtual int size() const = 0;
  /// sb = S_B λ, sc = S_C λ.
  virtual void apply(const Eigen::VectorXd& lambda, Eigen::VectorXd& sb, Eigen::VectorXd& sc) const = 0;
  /// Solves S_𝒜 λ = d (bordered by `mode` when given, then α is the second unknown); λ and α hold
  /// the starting guess on entry.
  virtual LinearSolveReport solve(const ActiveSet& active, const Eigen::VectorXd& d, const ConstantMode* mode,
                                  Eigen::VectorXd& lambda, double& alpha) const = 0;
  /// Applications of A⁻¹ so far (the paper's it₁).
  virtual std::size_t fast_solves() const = 0;
  /// 2-norm condition number of S_𝒜, where it is available without extra fast solves.
  virtual std::optional<double> condition_number(const ActiveSet& active) const = 0;
};

class ImplicitSchur final : public SchurComplement {
 public:
  /// `loads`: the rows whose transposes carry λ into the grid (B_Γ, or B_Γ + R). Any dimension.
  template <int dim>
  ImplicitSchur(const FastSolver<dim>& solver, const SparseRows& B_gamma, const SparseRows& C_gamma,
                const SparseRows& loads, const GmresOptions& options, DirectTerms direct = {})
      : ImplicitSchur([&solver](GridVector& r) { solver.solve_in_place(r); }, solver.grid().n_unknowns(), B_gamma,
                      C_gamma, loads, options, std::move(direct)) {}
  /// With A⁻¹ as `solve_in_place` on vectors of `n_unknowns`.
  ImplicitSchur(std::function<void(GridVector&)> solve_in_place, std::size_t n_unknowns, const SparseRows& B_gamma,
                const SparseRows& C_gamma, const SparseRows& loads, const GmresOptions& options,
                DirectTerms direct = {});
  int size() const override { return B_Gamma_.n_rows(); }
  void apply(const Eigen::VectorXd& lambda, Eigen::VectorXd& sb, Eigen::VectorXd& sc) const override;
  LinearSolveReport solve(const ActiveSet& active, const Eigen::VectorXd& d, const ConstantMode* mode,
                          Eigen::VectorXd& lambda, double& alpha) const override;
  std::size_t fast_solves() const override { return fast_solves_; }
  std::optional<double> condition_number(const ActiveSet&) const override { return std::nullopt; }

 private:
  std::function<void(GridVector&)> solve_in_place_;
  const SparseRows &B_gamma_, &C_gamma_, &B_Gamma_;
  GmresOptions options_;
  DirectTerms direct_;
  mutable GridVector work_;
  mutable std::vector<double> lambda_, rows_;
  mutable std::size_t fast_solves_ = 0;
};

class ExplicitSchur final : public SchurComplement {
 public:
  /// Assembles S_B and S_C from the Green's table (threaded over columns); `loads` as above.
  template <int dim>
  ExplicitSchur(const GreenTable<dim>& green, const SparseRows& B_gamma, const SparseRows& C_gamma,
                const SparseRows& loads, const Execution& execution = Execution{}, const DirectTerms& direct = {});
  /// From given blocks (tests).
  ExplicitSchur(Eigen::MatrixXd S_B, Eigen::MatrixXd S_C) : S_B_(std::move(S_B)), S_C_(std::move(S_C)) {}
  int size() const override { return int(S_B_.rows()); }
  void apply(const Eigen::VectorXd& lambda, Eigen::VectorXd& sb, Eigen::VectorXd& sc) const override;
  LinearSolveReport solve(const ActiveSet& active, const Eigen::VectorXd& d, const ConstantMode* mode,
                          Eigen::VectorXd& lambda, double& alpha) const override;
  std::size_t fast_solves() const override { return 0; }
  std::optional<double> condition_number(const ActiveSet& active) const override;
  const Eigen::MatrixXd& S_B() const { return S_B_; }
  const Eigen::MatrixXd& S_C() const { return S_C_; }

 private:
  Eigen::MatrixXd newton_matrix(const ActiveSet& active, const ConstantMode* mode = nullptr) const;
  Eigen::MatrixXd S_B_, S_C_;
};

/// Dense (rows × cols) block R G Qᵀ from sparse rows and the Green's table (dim = 2 or 3).
template <int dim>
Eigen::MatrixXd green_block(const GreenTable<dim>& green, const SparseRows& R, const SparseRows& Q,
                            const Execution& execution = Execution{});
/// The blocks R_k G Qᵀ of several row sets at once: (G Qᵀ) is evaluated once per distinct node of
/// the R_k (B_γ's four nodes of x_i lie in C_γ's 3×3), so the cost is (distinct nodes)·nnz(Q) lookups.
template <int dim>
std::vector<Eigen::MatrixXd> green_blocks(const GreenTable<dim>& green, const std::vector<const SparseRows*>& row_sets,
                                          const SparseRows& Q, const Execution& execution = Execution{});

}  // namespace fictus
