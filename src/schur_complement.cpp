#include "fictus/schur_complement.hpp"

#include <algorithm>

namespace fictus {

ImplicitSchur::ImplicitSchur(const DstSolver& solver, const SparseRows& B_gamma, const SparseRows& C_gamma,
                             const SparseRows& B_Gamma, const GmresOptions& options)
    : solver_(solver), B_gamma_(B_gamma), C_gamma_(C_gamma), B_Gamma_(B_Gamma), options_(options),
      work_(solver.grid().n_unknowns()) {}

void ImplicitSchur::apply(const Eigen::VectorXd& lambda, Eigen::VectorXd& sb, Eigen::VectorXd& sc) const {
  lambda_.assign(lambda.data(), lambda.data() + lambda.size());
  std::fill(work_.begin(), work_.end(), 0.0);
  B_Gamma_.add_transposed(lambda_, work_);
  solver_.solve_in_place(work_);
  ++fast_solves_;
  B_gamma_.multiply(work_, rows_);
  sb = Eigen::Map<const Eigen::VectorXd>(rows_.data(), Eigen::Index(rows_.size()));
  C_gamma_.multiply(work_, rows_);
  sc = Eigen::Map<const Eigen::VectorXd>(rows_.data(), Eigen::Index(rows_.size()));
}

LinearSolveReport ImplicitSchur::solve(const ActiveSet& active, const Eigen::VectorXd& d, Eigen::VectorXd& lambda) const {
  Eigen::VectorXd sb, sc;
  const LinearOperator op = [&](const Eigen::VectorXd& x, Eigen::VectorXd& y) {
    apply(x, sb, sc);
    y.resize(x.size());
    for (Eigen::Index i = 0; i < x.size(); ++i) y(i) = active[i] ? sb(i) : sc(i);
  };
  const GmresReport g = gmres(op, d, lambda, options_);
  return {g.iterations, g.relative_residual, g.converged};
}

Eigen::MatrixXd green_block(const GreenTable& green, const SparseRows& R, const SparseRows& Q, int threads) {
  Eigen::MatrixXd S(R.n_rows(), Q.n_rows());
#pragma omp parallel for num_threads(threads < 1 ? 1 : threads) schedule(dynamic, 4)
  for (int col = 0; col < Q.n_rows(); ++col) {
    for (int row = 0; row < R.n_rows(); ++row) {
      double sum = 0.0;
      for (std::size_t a = R.row_begin[row]; a < R.row_begin[row + 1]; ++a) {
        const auto& ra = R.entries[a];
        double inner = 0.0;
        for (std::size_t b = Q.row_begin[col]; b < Q.row_begin[col + 1]; ++b) {
          const auto& qb = Q.entries[b];
          inner += green.G(ra.i, ra.j, qb.i, qb.j) * qb.value;
        }
        sum += ra.value * inner;
      }
      S(row, col) = sum;
    }
  }
  return S;
}

ExplicitSchur::ExplicitSchur(const GreenTable& green, const SparseRows& B_gamma, const SparseRows& C_gamma,
                             const SparseRows& B_Gamma, int threads)
    : S_B_(green_block(green, B_gamma, B_Gamma, threads)), S_C_(green_block(green, C_gamma, B_Gamma, threads)) {}

void ExplicitSchur::apply(const Eigen::VectorXd& lambda, Eigen::VectorXd& sb, Eigen::VectorXd& sc) const {
  sb = S_B_ * lambda;
  sc = S_C_ * lambda;
}

Eigen::MatrixXd ExplicitSchur::newton_matrix(const ActiveSet& active) const {
  Eigen::MatrixXd S(S_B_.rows(), S_B_.cols());
  for (Eigen::Index i = 0; i < S.rows(); ++i) S.row(i) = active[i] ? S_B_.row(i) : S_C_.row(i);
  return S;
}

LinearSolveReport ExplicitSchur::solve(const ActiveSet& active, const Eigen::VectorXd& d, Eigen::VectorXd& lambda) const {
  const Eigen::MatrixXd S = newton_matrix(active);
  lambda = S.partialPivLu().solve(d);
  LinearSolveReport report;
  const double dn = d.norm();
  report.relative_residual = dn > 0 ? (S * lambda - d).norm() / dn : 0.0;
  return report;
}

std::optional<double> ExplicitSchur::condition_number(const ActiveSet& active) const {
  const Eigen::BDCSVD<Eigen::MatrixXd> svd(newton_matrix(active));
  const auto& s = svd.singularValues();
  return s(0) / s(s.size() - 1);
}

}  // namespace fictus
