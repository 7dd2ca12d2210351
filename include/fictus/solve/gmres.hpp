#pragma once
// Restarted GMRES (Householder-free, modified Gram–Schmidt with Givens rotations) for small
// dense-size, matrix-free non-symmetric systems: the Schur complement of the Newton step (m ≤ a
// few thousand). Hand-written because Eigen's GMRES lives in the unsupported module and needs a
// custom matrix-expression type to run matrix-free.
#include <functional>

#include <Eigen/Dense>

#include "fictus/solve/solver_options.hpp"

namespace fictus {

struct GmresOptions {
  double relative_tolerance = SolverOptions{}.krylov_tolerance;  // ‖b − Ax‖ ≤ tol·‖b‖
  int max_iterations = SolverOptions{}.krylov_max_iterations;    // operator applications, at most
  int restart = 400;
  std::function<void()> between_iterations;  // called before each operator application (may throw)
};

struct GmresReport {
  int iterations = 0;  // operator applications, the initial residual's included
  double relative_residual = 0.0;
  bool converged = false;
};

using LinearOperator = std::function<void(const Eigen::VectorXd& x, Eigen::VectorXd& y)>;

/// Solves A x = b; x is the starting guess on entry and the solution on exit.
GmresReport gmres(const LinearOperator& apply, const Eigen::VectorXd& b, Eigen::VectorXd& x,
                  const GmresOptions& options);

struct FlexibleGmresReport : GmresReport {
  Eigen::VectorXd coefficients;  // y: x = Σ_k y_k z_k
};

/// One cycle of flexible GMRES for A x = b from x = 0, at most `steps` steps, while each step gains a
/// factor 2: the k-th search direction z_k = precondition(v_k) may change from step to step (an inner
/// iterative solve), and `apply` is called on z_0, z_1, … in order, once each. Returns the
/// coefficients y of x = Σ_k y_k z_k; a caller that keeps z_k and A z_k has x and A x without another
/// product. `iterations` counts the products.
FlexibleGmresReport flexible_gmres(const LinearOperator& apply, const LinearOperator& precondition,
                                   const Eigen::VectorXd& b, int steps, double relative_tolerance);

}  // namespace fictus
