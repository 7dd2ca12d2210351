#pragma once
// LU factorization with partial pivoting of a dense square matrix by LAPACK (dgetrf, dgetrs and
// dgecon of OpenBLAS). It is blocked, threaded and vectorized for the machine it runs on (OpenBLAS
// picks its kernels at run time): about 80 GFlop/s on 2 cores against Eigen's PartialPivLU's 25
// (docs/math.md, "Newton's linear solves in 3-D"). The dense Newton solves of 3-D problems are LUs of m ≈ 10⁴.
#include <vector>

#include <Eigen/Dense>

namespace fictus {

class DenseLu {
 public:
  DenseLu() = default;
  /// Factors A (square; it is moved in and overwritten by its factors). The threads are Eigen's
  /// (Eigen::nbThreads(), which the solvers set from their threads option). A singular A gives
  /// infinite or NaN solutions, as Eigen's LU does; the reciprocal condition number says so.
  explicit DenseLu(Eigen::MatrixXd&& A) { compute(std::move(A)); }
  void compute(Eigen::MatrixXd&& A);
  bool empty() const { return pivots_.empty(); }
  Eigen::Index size() const { return factors_.rows(); }
  /// B ← A⁻¹B, or A⁻ᵀB when `transposed` (B has size() rows).
  void solve_in_place(Eigen::MatrixXd& B, bool transposed = false) const;
  Eigen::VectorXd solve(const Eigen::VectorXd& r, bool transposed = false) const;
  /// An estimate of 1/κ₁(A) (LAPACK's dgecon, O(m²) after the factorization).
  double reciprocal_condition() const;

 private:
  Eigen::MatrixXd factors_;  // L (unit diagonal, below) and U
  std::vector<int> pivots_;  // LAPACK's, 1-based
  double norm1_ = 0.0;       // ‖A‖₁, for the condition estimate
};

}  // namespace fictus
