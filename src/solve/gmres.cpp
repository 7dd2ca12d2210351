#include "fictus/solve/gmres.hpp"

#include <cmath>
#include <limits>
#include <vector>

namespace fictus {

namespace {

/// One GMRES cycle from the residual r (β = ‖r‖ > 0): the Arnoldi basis V by modified Gram–Schmidt
/// (twice, for stability) with Givens rotations, at most `steps` steps, stopping at ‖residual‖ ≤ target.
/// `step(k, v, w)` makes w = A·(the k-th search direction from v = V_k). Returns the coefficients y of
/// the search directions; `residual` is the cycle's last residual norm, `steps_made` the steps.
class Cycle {
 public:
  Cycle(Eigen::Index n, int steps)
      : V(n, steps + 1), H(Eigen::MatrixXd::Zero(steps + 1, steps)), cs(steps), sn(steps) {}

  template <class Step, class Keep>
  Eigen::VectorXd run(const Eigen::VectorXd& r, double beta, int steps, double target, Step&& step, Keep&& keep_going,
                      double& residual) {
    V.col(0) = r / beta;
    Eigen::VectorXd e = Eigen::VectorXd::Zero(steps + 1), w;
    e(0) = beta;
    H.setZero();
    residual = beta;
    int k = 0;
    for (; k < steps && keep_going(); ++k) {
      step(k, V.col(k), w);
      for (int pass = 0; pass < 2; ++pass)
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
      residual = std::abs(e(k + 1));
      if (residual <= target || H(k, k) == 0.0) {
        ++k;
        break;
      }
    }
    // H_k y = e_k (upper triangular)
    return H.topLeftCorner(k, k).triangularView<Eigen::Upper>().solve(e.head(k));
  }

  Eigen::MatrixXd V, H;

 private:
  Eigen::VectorXd cs, sn;
};

}  // namespace

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
  Cycle cycle(n, restart);
  Eigen::VectorXd r(n), w(n);
  double previous_cycle = std::numeric_limits<double>::infinity();
  // One application of the cap is kept for the true residual of the final iterate.
  const auto keep_going = [&] { return report.iterations + 1 < options.max_iterations; };
  while (keep_going()) {
    if (options.between_iterations) options.between_iterations();
    apply(x, w);
    ++report.iterations;
    r = b - w;
    const double beta = r.norm();
    report.relative_residual = beta / b_norm;
    if (report.relative_residual <= options.relative_tolerance) {
      report.converged = true;
      return report;
    }
    // Stagnation at round-off (tolerance below cond·ε): a whole cycle gained less than a factor 2.
    if (report.relative_residual > 0.5 * previous_cycle) return report;
    previous_cycle = report.relative_residual;
    double residual = 0;
    const Eigen::VectorXd y = cycle.run(
        r, beta, restart, options.relative_tolerance * b_norm,
        [&](int, const auto& v, Eigen::VectorXd& out) {
          if (options.between_iterations) options.between_iterations();
          apply(v, out);
          ++report.iterations;
        },
        keep_going, residual);
    x += cycle.V.leftCols(y.size()) * y;
  }
  apply(x, w);  // true residual of the final iterate
  ++report.iterations;
  report.relative_residual = (b - w).norm() / b_norm;
  report.converged = report.relative_residual <= options.relative_tolerance;
  return report;
}

FlexibleGmresReport flexible_gmres(const LinearOperator& apply, const LinearOperator& precondition,
                                   const Eigen::VectorXd& b, int steps, double relative_tolerance) {
  FlexibleGmresReport report;
  const double b_norm = b.norm();
  report.converged = b_norm == 0.0;
  if (report.converged) return report;
  steps = std::max(1, std::min<int>(steps, int(b.size())));
  Cycle cycle(b.size(), steps);
  Eigen::VectorXd z;
  double residual = 0, previous = b_norm;
  bool gaining = true;
  report.coefficients = cycle.run(
      b, b_norm, steps, relative_tolerance * b_norm,
      [&](int, const auto& v, Eigen::VectorXd& out) {
        precondition(v, z);
        apply(z, out);
        ++report.iterations;
      },
      [&] {  // after the first step: on while each step gains a factor 2 (round-off ends it)
        gaining = report.iterations == 0 || residual < 0.5 * previous;
        previous = report.iterations == 0 ? b_norm : residual;
        return gaining;
      },
      residual);
  report.relative_residual = residual / b_norm;
  report.converged = report.relative_residual <= relative_tolerance;
  return report;
}

}  // namespace fictus
