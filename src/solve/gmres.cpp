#include "fictus/solve/gmres.hpp"

#include <cmath>
#include <limits>
#include <vector>

namespace fictus {

GmresReport gmres(const LinearOperator& apply, const Eigen::VectorXd& b, Eigen::VectorXd& x,
                  const GmresOptions& options) {
  GmresReport report;
  const Eigen::Index n = b.size();
  const double b_norm = b.norm();
  if (b_norm == 0.0) {
    x.setZero();
    report.converged = true;
    return report;
  }
  const int restart = std::max(1, std::min<int>(options.restart, int(n)));
  Eigen::VectorXd r(n), w(n);
  Eigen::MatrixXd V(n, restart + 1), H = Eigen::MatrixXd::Zero(restart + 1, restart);
  Eigen::VectorXd cs(restart), sn(restart), e(restart + 1);
  double previous_cycle = std::numeric_limits<double>::infinity();
  // One application of the cap is kept for the true residual of the final iterate.
  while (report.iterations + 1 < options.max_iterations) {
    if (options.between_iterations) options.between_iterations();
    apply(x, w);
    ++report.iterations;
    r = b - w;
    double beta = r.norm();
    report.relative_residual = beta / b_norm;
    if (report.relative_residual <= options.relative_tolerance) {
      report.converged = true;
      return report;
    }
    // Stagnation at round-off (tolerance below cond·ε): a whole cycle gained less than a factor 2.
    if (report.relative_residual > 0.5 * previous_cycle) return report;
    previous_cycle = report.relative_residual;
    V.col(0) = r / beta;
    e.setZero();
    e(0) = beta;
    H.setZero();
    int k = 0;
    for (; k < restart && report.iterations + 1 < options.max_iterations; ++k) {
      if (options.between_iterations) options.between_iterations();
      apply(V.col(k), w);
      ++report.iterations;
      for (int j = 0; j <= k; ++j) {  // modified Gram–Schmidt, twice for stability
        const double hjk = V.col(j).dot(w);
        H(j, k) += hjk;
        w -= hjk * V.col(j);
      }
      for (int j = 0; j <= k; ++j) {
        const double hjk = V.col(j).dot(w);
        H(j, k) += hjk;
        w -= hjk * V.col(j);
      }
      H(k + 1, k) = w.norm();
      if (H(k + 1, k) > 0) V.col(k + 1) = w / H(k + 1, k);
      for (int j = 0; j < k; ++j) {  // previous rotations
        const double t = cs(j) * H(j, k) + sn(j) * H(j + 1, k);
        H(j + 1, k) = -sn(j) * H(j, k) + cs(j) * H(j + 1, k);
        H(j, k) = t;
      }
      const double denom = std::hypot(H(k, k), H(k + 1, k));
      cs(k) = H(k, k) / denom;
      sn(k) = H(k + 1, k) / denom;
      H(k, k) = denom;
      H(k + 1, k) = 0.0;
      e(k + 1) = -sn(k) * e(k);
      e(k) = cs(k) * e(k);
      report.relative_residual = std::abs(e(k + 1)) / b_norm;
      if (report.relative_residual <= options.relative_tolerance || H(k, k) == 0.0) {
        ++k;
        break;
      }
    }
    // x += V_k y, with H_k y = e_k (upper triangular)
    Eigen::VectorXd y = H.topLeftCorner(k, k).triangularView<Eigen::Upper>().solve(e.head(k));
    x += V.leftCols(k) * y;
  }
  apply(x, w);  // true residual of the final iterate
  ++report.iterations;
  report.relative_residual = (b - w).norm() / b_norm;
  report.converged = report.relative_residual <= options.relative_tolerance;
  return report;
}

}  // namespace fictus
