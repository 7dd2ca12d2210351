#include "fictus/solve/gmres.hpp"

#include <cmath>
#include <limits>
#include <vector>

namespace fictus {

namespace {

/// One GMRES cycle from the residual r (β = ‖r‖ > 0): the Arnoldi basis V by modified Gram–Schmidt
/// (twice, for stability) with Givens rotations, at most `steps` steps, stopping at ‖residual‖ ≤ target.
/// `step(v, w)` makes w = A·(the next search direction from v = V_k). Returns the coefficients y of
/// the search directions; `residual` is the cycle's last residual norm. V and the Hessenberg columns
/// grow with the steps made (a restart of m + 1 must not allocate (m + 1)² entries up front).
class Cycle {
 public:
  template <class Step, class Keep>
  Eigen::VectorXd run(const Eigen::VectorXd& r, double beta, int steps, double target, Step&& step, Keep&& keep_going,
                      double& residual) {
    V.assign(1, r / beta);
    std::vector<Eigen::VectorXd> H;  // column k of the Hessenberg matrix: k + 2 entries
    std::vector<double> cs, sn, e{beta};
    Eigen::VectorXd w;
    residual = beta;
    int k = 0;
    for (; k < steps && keep_going(); ++k) {
      step(V[std::size_t(k)], w);
      Eigen::VectorXd h = Eigen::VectorXd::Zero(k + 2);
      for (int pass = 0; pass < 2; ++pass)
        for (int j = 0; j <= k; ++j) {
          const double hjk = V[std::size_t(j)].dot(w);
          h(j) += hjk;
          w -= hjk * V[std::size_t(j)];
        }
      h(k + 1) = w.norm();
      V.push_back(h(k + 1) > 0 ? Eigen::VectorXd(w / h(k + 1)) : w);
      for (int j = 0; j < k; ++j) {  // previous rotations
        const double t = cs[std::size_t(j)] * h(j) + sn[std::size_t(j)] * h(j + 1);
        h(j + 1) = -sn[std::size_t(j)] * h(j) + cs[std::size_t(j)] * h(j + 1);
        h(j) = t;
      }
      const double denom = std::hypot(h(k), h(k + 1));
      cs.push_back(h(k) / denom);
      sn.push_back(h(k + 1) / denom);
      h(k) = denom;
      h(k + 1) = 0.0;
      e.push_back(-sn.back() * e[std::size_t(k)]);
      e[std::size_t(k)] *= cs.back();
      residual = std::abs(e.back());
      H.push_back(std::move(h));
      if (residual <= target || H.back()(k) == 0.0) {
        ++k;
        break;
      }
    }
    // H_k y = e_k (upper triangular)
    Eigen::MatrixXd R = Eigen::MatrixXd::Zero(k, k);
    for (int j = 0; j < k; ++j) R.col(j).head(j + 1) = H[std::size_t(j)].head(j + 1);
    return R.triangularView<Eigen::Upper>().solve(Eigen::Map<const Eigen::VectorXd>(e.data(), k));
  }

  /// x += Σ_k y_k V_k
  void add(const Eigen::VectorXd& y, Eigen::VectorXd& x) const {
    for (Eigen::Index j = 0; j < y.size(); ++j) x += y(j) * V[std::size_t(j)];
  }

 private:
  std::vector<Eigen::VectorXd> V;
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
  Cycle cycle;
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
        [&](const auto& v, Eigen::VectorXd& out) {
          if (options.between_iterations) options.between_iterations();
          apply(v, out);
          ++report.iterations;
        },
        keep_going, residual);
    cycle.add(y, x);
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
  Cycle cycle;
  Eigen::VectorXd z;
  double residual = 0, previous = b_norm;
  report.coefficients = cycle.run(
      b, b_norm, steps, relative_tolerance * b_norm,
      [&](const auto& v, Eigen::VectorXd& out) {
        precondition(v, z);
        apply(z, out);
        ++report.iterations;
      },
      [&] {  // after the first step: on while each step gains a factor 2 (round-off ends it)
        const bool gaining = report.iterations == 0 || residual < 0.5 * previous;
        previous = residual;
        return gaining;
      },
      residual);
  report.relative_residual = residual / b_norm;
  report.converged = report.relative_residual <= relative_tolerance;
  return report;
}

}  // namespace fictus
