#include "fictus/schur_complement.hpp"

#include <algorithm>
#include <utility>

namespace fictus {

ImplicitSchur::ImplicitSchur(std::function<void(GridVector&)> solve_in_place, std::size_t n_unknowns,
                             const SparseRows& B_gamma, const SparseRows& C_gamma, const SparseRows& loads,
                             const GmresOptions& options, DirectTerms direct)
    : solve_in_place_(std::move(solve_in_place)),
      B_gamma_(B_gamma),
      C_gamma_(C_gamma),
      B_Gamma_(loads),
      options_(options),
      direct_(std::move(direct)),
      work_(n_unknowns) {}

void ImplicitSchur::apply(const Eigen::VectorXd& lambda, Eigen::VectorXd& sb, Eigen::VectorXd& sc) const {
  lambda_.assign(lambda.data(), lambda.data() + lambda.size());
  std::fill(work_.begin(), work_.end(), 0.0);
  B_Gamma_.add_transposed(lambda_, work_);
  solve_in_place_(work_);
  ++fast_solves_;
  B_gamma_.multiply(work_, rows_);
  sb = Eigen::Map<const Eigen::VectorXd>(rows_.data(), Eigen::Index(rows_.size()));
  C_gamma_.multiply(work_, rows_);
  sc = Eigen::Map<const Eigen::VectorXd>(rows_.data(), Eigen::Index(rows_.size()));
  if (!direct_.empty()) {
    sb += direct_.trace * lambda;
    sc += direct_.normal_derivative * lambda;
  }
}

void ImplicitSchur::apply_newton(const ActiveSet& active, const ConstantMode* mode, const Eigen::VectorXd& x,
                                 Eigen::VectorXd& y) const {
  const Eigen::Index m = size();
  Eigen::VectorXd sb, sc;
  apply(x.head(m), sb, sc);
  y.resize(x.size());
  for (Eigen::Index i = 0; i < m; ++i) y(i) = active[i] ? sb(i) : sc(i);
  if (mode) {
    for (Eigen::Index i = 0; i < m; ++i) y(i) += x(m) * (active[i] ? mode->trace_B(i) : mode->trace_C(i));
    y(m) = mode->arc_weights.dot(x.head(m));
  }
}

namespace {

/// The right-hand side (d, −F) and the unknowns (λ, α) of a Newton step, bordered by `mode`.
std::pair<Eigen::VectorXd, Eigen::VectorXd> newton_system(const Eigen::VectorXd& d, const ConstantMode* mode,
                                                          const Eigen::VectorXd& lambda, double alpha) {
  const Eigen::Index m = lambda.size();
  Eigen::VectorXd rhs(m + (mode ? 1 : 0)), x(rhs.size());
  rhs.head(m) = d;
  x.head(m) = lambda;
  if (mode) rhs(m) = -mode->load_total, x(m) = alpha;
  return {rhs, x};
}

void unpack(const Eigen::VectorXd& x, const ConstantMode* mode, Eigen::VectorXd& lambda, double& alpha) {
  lambda = x.head(lambda.size());
  if (mode) alpha = x(lambda.size());
}

}  // namespace

LinearSolveReport ImplicitSchur::solve(const ActiveSet& active, const Eigen::VectorXd& d, const ConstantMode* mode,
                                       Eigen::VectorXd& lambda, double& alpha) const {
  auto [rhs, x] = newton_system(d, mode, lambda, alpha);
  const LinearOperator op = [&](const Eigen::VectorXd& v, Eigen::VectorXd& y) { apply_newton(active, mode, v, y); };
  const GmresReport g = gmres(op, rhs, x, options_);
  unpack(x, mode, lambda, alpha);
  return {g.iterations, g.relative_residual, g.converged};
}

LinearSolveReport PreconditionedSchur::solve(const ActiveSet& active, const Eigen::VectorXd& d,
                                             const ConstantMode* mode, Eigen::VectorXd& lambda, double& alpha) const {
  const Eigen::MatrixXd S = approximate_.newton_matrix(active, mode);
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(S);
  auto [rhs, x] = newton_system(d, mode, lambda, alpha);
  // S_𝒜 S̃_𝒜⁻¹ z = rhs from z = S̃_𝒜 x (the given start), then x = S̃_𝒜⁻¹ z.
  Eigen::VectorXd z = S * x, v;
  const LinearOperator op = [&](const Eigen::VectorXd& w, Eigen::VectorXd& y) {
    v = lu.solve(w);
    exact_.apply_newton(active, mode, v, y);
  };
  const GmresReport g = gmres(op, rhs, z, options_);
  unpack(lu.solve(z), mode, lambda, alpha);
  return {g.iterations, g.relative_residual, g.converged};
}

template <int dim>
ExplicitSchur::ExplicitSchur(const GreenTable<dim>& green, const SparseRows& B_gamma, const SparseRows& C_gamma,
                             const SparseRows& loads, const Execution& execution, const DirectTerms& direct,
                             const FarField& far_field, FarFieldReport* report) {
  std::vector<Eigen::MatrixXd> blocks = green_blocks(green, {&B_gamma, &C_gamma}, loads, execution, far_field, report);
  S_B_ = std::move(blocks[0]);
  S_C_ = std::move(blocks[1]);
  if (!direct.empty()) {
    S_B_ += Eigen::MatrixXd(direct.trace);
    S_C_ += Eigen::MatrixXd(direct.normal_derivative);
  }
}

template ExplicitSchur::ExplicitSchur(const GreenTable<2>&, const SparseRows&, const SparseRows&, const SparseRows&,
                                      const Execution&, const DirectTerms&, const FarField&, FarFieldReport*);
template ExplicitSchur::ExplicitSchur(const GreenTable<3>&, const SparseRows&, const SparseRows&, const SparseRows&,
                                      const Execution&, const DirectTerms&, const FarField&, FarFieldReport*);

void ExplicitSchur::apply(const Eigen::VectorXd& lambda, Eigen::VectorXd& sb, Eigen::VectorXd& sc) const {
  sb = S_B_ * lambda;
  sc = S_C_ * lambda;
}

Eigen::MatrixXd ExplicitSchur::newton_matrix(const ActiveSet& active, const ConstantMode* mode) const {
  const Eigen::Index m = S_B_.rows(), n = m + (mode ? 1 : 0);
  Eigen::MatrixXd S(n, n);
  for (Eigen::Index i = 0; i < m; ++i) S.row(i).head(m) = active[i] ? S_B_.row(i) : S_C_.row(i);
  if (mode) {
    for (Eigen::Index i = 0; i < m; ++i) S(i, m) = active[i] ? mode->trace_B(i) : mode->trace_C(i);
    S.row(m).head(m) = mode->arc_weights.transpose();
    S(m, m) = 0.0;
  }
  return S;
}

LinearSolveReport ExplicitSchur::solve(const ActiveSet& active, const Eigen::VectorXd& d, const ConstantMode* mode,
                                       Eigen::VectorXd& lambda, double& alpha) const {
  const Eigen::MatrixXd S = newton_matrix(active, mode);
  const Eigen::VectorXd rhs = newton_system(d, mode, lambda, alpha).first;
  const Eigen::VectorXd x = S.partialPivLu().solve(rhs);
  unpack(x, mode, lambda, alpha);
  LinearSolveReport report;
  const double rn = rhs.norm();
  report.relative_residual = rn > 0 ? (S * x - rhs).norm() / rn : 0.0;
  return report;
}

std::optional<double> ExplicitSchur::condition_number(const ActiveSet& active) const {
  const Eigen::BDCSVD<Eigen::MatrixXd> svd(newton_matrix(active));
  const auto& s = svd.singularValues();
  return s(0) / s(s.size() - 1);
}

}  // namespace fictus
