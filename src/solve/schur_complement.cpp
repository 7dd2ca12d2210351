#include "fictus/solve/schur_complement.hpp"

#include <Spectra/SymEigsSolver.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <utility>

namespace fictus {

ImplicitSchur::ImplicitSchur(std::function<void(GridVector&)> solve_in_place, GridVector work,
                             const SparseRows& B_gamma, const SparseRows& C_gamma, const SparseRows& loads,
                             const GmresOptions& options, DirectTerms direct)
    : solve_in_place_(std::move(solve_in_place)),
      B_gamma_(B_gamma),
      C_gamma_(C_gamma),
      B_Gamma_(loads),
      options_(options),
      direct_(std::move(direct)),
      work_(std::move(work)) {}

void ImplicitSchur::apply(const Eigen::VectorXd& lambda, Eigen::VectorXd& sb, Eigen::VectorXd& sc) const {
  lambda_.assign(lambda.data(), lambda.data() + lambda.size());
  std::fill(work_.begin(), work_.end(), 0.0);
  if (distribution_)
    B_Gamma_.add_transposed(lambda_, work_, offset_);
  else
    B_Gamma_.add_transposed(lambda_, work_);
  solve_in_place_(work_);
  ++fast_solves_;
  const auto read = [this](const SparseRows& rows, Eigen::VectorXd& out) {
    if (distribution_) {
      rows.multiply(work_, offset_, rows_);
      distribution_->sum(rows_);
    } else {
      rows.multiply(work_, rows_);
    }
    out = Eigen::Map<const Eigen::VectorXd>(rows_.data(), Eigen::Index(rows_.size()));
  };
  read(B_gamma_, sb);
  read(C_gamma_, sc);
  if (!direct_.empty()) {
    sb += direct_.trace * lambda;
    sc += direct_.normal_derivative * lambda;
  }
}

namespace {

/// x ↦ HᵀHx for Spectra's eigensolvers (symmetric, of size n).
struct GramOperator {
  using Scalar = double;
  Eigen::Index n;
  std::function<void(const double*, double*)> apply;
  Eigen::Index rows() const { return n; }
  Eigen::Index cols() const { return n; }
  void perform_op(const double* x, double* y) const { apply(x, y); }
};

/// y = S_𝒜 x from sb = S_B λ and sc = S_C λ, x = (λ, α) when bordered by `mode`.
void select_newton_rows(const ActiveSet& active, const ConstantMode* mode, const Eigen::VectorXd& x,
                        const Eigen::VectorXd& sb, const Eigen::VectorXd& sc, Eigen::VectorXd& y) {
  const Eigen::Index m = sb.size();
  y.resize(x.size());
  for (Eigen::Index i = 0; i < m; ++i) y(i) = active[i] ? sb(i) : sc(i);
  if (mode) {
    for (Eigen::Index i = 0; i < m; ++i) y(i) += x(m) * (active[i] ? mode->trace_B(i) : mode->trace_C(i));
    y(m) = mode->arc_weights.dot(x.head(m));
  }
}

/// S = S_𝒜: row i of S_B (i ∈ 𝒜) or of S_C, bordered by `mode` when given.
void fill_newton_matrix(const Eigen::MatrixXd& S_B, const Eigen::MatrixXd& S_C, const ActiveSet& active,
                        const ConstantMode* mode, Eigen::MatrixXd& S) {
  const Eigen::Index m = S_B.rows(), n = m + (mode ? 1 : 0);
  S.resize(n, n);
  for (Eigen::Index j = 0; j < m; ++j)  // by columns: the blocks are column-major
    for (Eigen::Index i = 0; i < m; ++i) S(i, j) = active[i] ? S_B(i, j) : S_C(i, j);
  if (mode) {
    for (Eigen::Index i = 0; i < m; ++i) S(i, m) = active[i] ? mode->trace_B(i) : mode->trace_C(i);
    S.row(m).head(m) = mode->arc_weights.transpose();
    S(m, m) = 0.0;
  }
}

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

bool same_mode(const std::optional<ConstantMode>& a, const ConstantMode* b) {
  if (!a || !b) return !a && !b;
  return a->trace_B == b->trace_B && a->trace_C == b->trace_C && a->arc_weights == b->arc_weights;
}

}  // namespace

void ImplicitSchur::apply_newton(const ActiveSet& active, const ConstantMode* mode, const Eigen::VectorXd& x,
                                 Eigen::VectorXd& y) const {
  Eigen::VectorXd sb, sc;
  apply(x.head(size()), sb, sc);
  select_newton_rows(active, mode, x, sb, sc, y);
}

void NewtonFactorization::factor(const ActiveSet& active, const ConstantMode* mode) {
  base_.clear();  // nothing factored until the LU is done (an allocation may throw)
  rows_.clear();
  lu_ = DenseLu();
  Eigen::MatrixXd S;
  fill_newton_matrix(S_B_, S_C_, active, mode, S);
  lu_.compute(std::move(S));
  ++factorizations_;
  base_ = active;
  mode_.reset();
  if (mode) mode_ = *mode;
  Z_ = V_ = Eigen::MatrixXd();
}

void NewtonFactorization::prepare(const ActiveSet& active, const ConstantMode* mode) {
  const Eigen::Index m = S_B_.rows(), n = m + (mode ? 1 : 0);
  if (base_.empty() || !same_mode(mode_, mode)) return factor(active, mode);
  std::vector<Eigen::Index> rows;
  for (Eigen::Index i = 0; i < m; ++i)
    if (bool(active[i]) != bool(base_[i])) rows.push_back(i);
  if (rows == rows_) return;  // prepared already
  if (double(rows.size()) > update_fraction * double(m)) return factor(active, mode);
  // Z's column of a row depends on the row alone (S_𝒜₀⁻¹e_i): keep those of rows already changed, solve
  // for the new ones only. Built aside and committed at the end (an allocation may throw).
  const Eigen::Index k = Eigen::Index(rows.size());
  Eigen::MatrixXd Z(n, k), V(n, k);
  std::vector<Eigen::Index> fresh;  // columns of Z to solve for
  for (Eigen::Index j = 0, p = 0; j < k; ++j) {
    while (p < Eigen::Index(rows_.size()) && rows_[std::size_t(p)] < rows[std::size_t(j)]) ++p;
    if (p < Eigen::Index(rows_.size()) && rows_[std::size_t(p)] == rows[std::size_t(j)])
      Z.col(j) = Z_.col(p);
    else
      fresh.push_back(j);
  }
  for (Eigen::Index j = 0; j < k; ++j) {
    const Eigen::Index i = rows[std::size_t(j)];
    const double sign = active[i] ? 1.0 : -1.0;  // S_B's row replaces S_C's, or the reverse
    V.col(j).head(m) = sign * (S_B_.row(i) - S_C_.row(i)).transpose();
    if (mode) V(m, j) = sign * (mode->trace_B(i) - mode->trace_C(i));
  }
  // The new columns in one solve with many right-hand sides (LAPACK's, threaded).
  Eigen::MatrixXd E = Eigen::MatrixXd::Zero(n, Eigen::Index(fresh.size()));
  for (std::size_t j = 0; j < fresh.size(); ++j) E(rows[std::size_t(fresh[j])], Eigen::Index(j)) = 1.0;
  lu_.solve_in_place(E);
  for (std::size_t j = 0; j < fresh.size(); ++j) Z.col(fresh[j]) = E.col(Eigen::Index(j));
  Eigen::PartialPivLU<Eigen::MatrixXd> capacitance;
  if (k > 0) capacitance.compute(Eigen::MatrixXd::Identity(k, k) + V.transpose() * Z);
  capacitance_ = std::move(capacitance);
  Z_ = std::move(Z);
  V_ = std::move(V);
  active_ = active;
  rows_ = std::move(rows);
}

std::optional<double> NewtonFactorization::condition_number(const ActiveSet& active, const ConstantMode* mode,
                                                            double tolerance, int max_restarts) {
  const Eigen::Index m = S_B_.rows(), n = m + (mode ? 1 : 0);
  if (n < 3) {  // Spectra needs n ≥ 3: the singular values of S_𝒜 in full
    Eigen::MatrixXd S;
    fill_newton_matrix(S_B_, S_C_, active, mode, S);
    const Eigen::VectorXd s = Eigen::JacobiSVD<Eigen::MatrixXd>(S).singularValues();
    const double kappa = s(0) / s(n - 1);
    return std::isfinite(kappa) ? std::optional<double>(kappa) : std::nullopt;
  }
  // The solves with S_𝒜ᵀ need the LU of S_𝒜 itself, not an update of another's.
  if (base_.empty() || base_ != active || !same_mode(mode_, mode)) factor(active, mode);
  const auto product = [&](const Eigen::VectorXd& x) {  // S_𝒜 x
    Eigen::VectorXd sb = S_B_ * x.head(m), sc = S_C_ * x.head(m), y;
    select_newton_rows(active, mode, x, sb, sc, y);
    return y;
  };
  const auto transposed_product = [&](const Eigen::VectorXd& y) {  // S_𝒜ᵀ y
    Eigen::VectorXd on_B(m), on_C(m), x(n);
    for (Eigen::Index i = 0; i < m; ++i) on_B(i) = active[i] ? y(i) : 0.0, on_C(i) = active[i] ? 0.0 : y(i);
    x.head(m).noalias() = S_B_.transpose() * on_B;
    x.head(m).noalias() += S_C_.transpose() * on_C;
    if (mode) {
      x.head(m) += y(m) * mode->arc_weights;
      x(m) = mode->trace_B.dot(on_B) + mode->trace_C.dot(on_C);
    }
    return x;
  };
  // √λ_max(HᵀH) for H given as `half` (x ↦ Hx) and Hᵀ as `other`: the largest eigenvalue of HᵀH by
  // Spectra's implicitly restarted Lanczos (its fixed start vector: the same on every rank), to `tolerance`
  // relative in its residual. Not finite (a singular LU) or not converged: nothing.
  const auto largest_singular_value = [&](const auto& half, const auto& other) -> std::optional<double> {
    bool finite = true;
    GramOperator op{n, [&](const double* x, double* y) {
                      const Eigen::VectorXd out = other(half(Eigen::Map<const Eigen::VectorXd>(x, n)));
                      finite = finite && out.allFinite();
                      Eigen::Map<Eigen::VectorXd>(y, n) = finite ? out : Eigen::VectorXd::Zero(n);
                    }};
    try {  // Spectra throws where the operator is degenerate (the zeros that stand in for a non-finite solve)
      Spectra::SymEigsSolver<GramOperator> lanczos(op, 1, std::min<Eigen::Index>(n, 20));
      lanczos.init();
      lanczos.compute(Spectra::SortRule::LargestAlge, max_restarts, tolerance);
      if (!finite || lanczos.info() != Spectra::CompInfo::Successful) return std::nullopt;
      return std::sqrt(std::max(lanczos.eigenvalues()(0), 0.0));
    } catch (const std::runtime_error&) {
      return std::nullopt;
    }
  };
  const std::optional<double> largest = largest_singular_value(product, transposed_product);  // σ_max
  const std::optional<double> inverse =
      largest_singular_value([&](const Eigen::VectorXd& x) { return lu_.solve(x, true); },
                             [&](const Eigen::VectorXd& y) { return lu_.solve(y); });  // 1/σ_min
  if (!largest || !inverse || !std::isfinite(*largest * *inverse)) return std::nullopt;
  return *largest * *inverse;
}

Eigen::VectorXd NewtonFactorization::update_solve(const Eigen::VectorXd& r) const {
  Eigen::VectorXd y = lu_.solve(r);
  y -= Z_ * capacitance_.solve(V_.transpose() * y);
  return y;
}

Eigen::VectorXd NewtonFactorization::solve(const Eigen::VectorXd& r) const {
  if (rows_.empty()) return lu_.solve(r);
  // The update cancels: S_𝒜₀⁻¹r and Z s are larger than S_𝒜⁻¹r where S_B's and S_C's rows trade places
  // (measured: relative residual 5e-14 at m = 4632, 2.5e-15 for a fresh LU). One step of refinement
  // (two products with the blocks) brings it to the LU's.
  Eigen::VectorXd x = update_solve(r), sb = S_B_ * x.head(S_B_.rows()), sc = S_C_ * x.head(S_B_.rows()), y;
  select_newton_rows(active_, mode_ ? &*mode_ : nullptr, x, sb, sc, y);
  x += update_solve(r - y);
  return x;
}

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
  const NewtonFactorization& preconditioner = approximate_.factorization(active, mode);
  auto [rhs, x] = newton_system(d, mode, lambda, alpha);
  // S_𝒜 S̃_𝒜⁻¹ z = rhs from z = S̃_𝒜 x (the given start), then x = S̃_𝒜⁻¹ z.
  Eigen::VectorXd z, v;
  approximate_.apply_newton(active, mode, x, z);
  const LinearOperator op = [&](const Eigen::VectorXd& w, Eigen::VectorXd& y) {
    v = preconditioner.solve(w);
    exact_.apply_newton(active, mode, v, y);
  };
  const GmresReport g = gmres(op, rhs, z, options_);
  unpack(preconditioner.solve(z), mode, lambda, alpha);
  return {g.iterations, g.relative_residual, g.converged};
}

template <int dim>
ExplicitSchur::ExplicitSchur(const GreenTable<dim>& green, const SparseRows& B_gamma, const SparseRows& C_gamma,
                             const SparseRows& loads, const Execution& execution, const DirectTerms& direct,
                             const FarField& far_field, FarFieldReport* report) {
  std::vector<Eigen::MatrixXd> blocks = green_blocks(green, {&B_gamma, &C_gamma}, loads, execution, far_field, report);
  if (green.partial())  // a distributed run: each rank's table planes gave its part of every entry
    for (Eigen::MatrixXd& block : blocks) execution.distribution().sum(block.data(), std::size_t(block.size()));
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

template <int dim>
ExplicitSchur::ExplicitSchur(Eigen::MatrixXd S_B, Eigen::MatrixXd S_C, const std::vector<int>& changed,
                             const GreenTable<dim>& green, const SparseRows& B_gamma, const SparseRows& C_gamma,
                             const SparseRows& loads, const Execution& execution)
    : S_B_(std::move(S_B)), S_C_(std::move(S_C)) {
  if (changed.empty()) return;
  const SparseRows B = select_rows(B_gamma, changed), C = select_rows(C_gamma, changed),
                   L = select_rows(loads, changed);
  std::vector<Eigen::MatrixXd> rows = green_blocks(green, {&B, &C}, loads, execution);
  std::vector<Eigen::MatrixXd> columns = green_blocks(green, {&B_gamma, &C_gamma}, L, execution);
  if (green.partial())
    for (std::vector<Eigen::MatrixXd>* blocks : {&rows, &columns})
      for (Eigen::MatrixXd& block : *blocks) execution.distribution().sum(block.data(), std::size_t(block.size()));
  for (std::size_t k = 0; k < changed.size(); ++k) {
    const Eigen::Index i = changed[k];
    S_B_.col(i) = columns[0].col(Eigen::Index(k));
    S_C_.col(i) = columns[1].col(Eigen::Index(k));
  }
  for (std::size_t k = 0; k < changed.size(); ++k) {
    const Eigen::Index i = changed[k];
    S_B_.row(i) = rows[0].row(Eigen::Index(k));
    S_C_.row(i) = rows[1].row(Eigen::Index(k));
  }
}

template ExplicitSchur::ExplicitSchur(Eigen::MatrixXd, Eigen::MatrixXd, const std::vector<int>&, const GreenTable<2>&,
                                      const SparseRows&, const SparseRows&, const SparseRows&, const Execution&);
template ExplicitSchur::ExplicitSchur(Eigen::MatrixXd, Eigen::MatrixXd, const std::vector<int>&, const GreenTable<3>&,
                                      const SparseRows&, const SparseRows&, const SparseRows&, const Execution&);

void ExplicitSchur::apply(const Eigen::VectorXd& lambda, Eigen::VectorXd& sb, Eigen::VectorXd& sc) const {
  sb = S_B_ * lambda;
  sc = S_C_ * lambda;
}

Eigen::MatrixXd ExplicitSchur::newton_matrix(const ActiveSet& active, const ConstantMode* mode) const {
  Eigen::MatrixXd S;
  fill_newton_matrix(S_B_, S_C_, active, mode, S);
  return S;
}

void ExplicitSchur::apply_newton(const ActiveSet& active, const ConstantMode* mode, const Eigen::VectorXd& x,
                                 Eigen::VectorXd& y) const {
  Eigen::VectorXd sb, sc;
  apply(x.head(size()), sb, sc);
  select_newton_rows(active, mode, x, sb, sc, y);
}

const NewtonFactorization& ExplicitSchur::factorization(const ActiveSet& active, const ConstantMode* mode) const {
  factorization_.prepare(active, mode);
  return factorization_;
}

LinearSolveReport ExplicitSchur::solve(const ActiveSet& active, const Eigen::VectorXd& d, const ConstantMode* mode,
                                       Eigen::VectorXd& lambda, double& alpha) const {
  const NewtonFactorization& f = factorization(active, mode);
  const Eigen::VectorXd rhs = newton_system(d, mode, lambda, alpha).first;
  Eigen::VectorXd x = f.solve(rhs), y;
  apply_newton(active, mode, x, y);
  unpack(x, mode, lambda, alpha);
  LinearSolveReport report;
  const double rn = rhs.norm();
  report.relative_residual = rn > 0 ? (y - rhs).norm() / rn : 0.0;
  return report;
}

void ExplicitSchur::share(const Distribution& distribution) {
  if (!distribution.distributed()) return;
  distribution.broadcast(S_B_.data(), std::size_t(S_B_.size()));
  distribution.broadcast(S_C_.data(), std::size_t(S_C_.size()));
}

}  // namespace fictus
