#include "fictus/schur_complement.hpp"

#include <omp.h>

#include <atomic>

#include <algorithm>
#include <unordered_map>
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

LinearSolveReport ImplicitSchur::solve(const ActiveSet& active, const Eigen::VectorXd& d, const ConstantMode* mode,
                                       Eigen::VectorXd& lambda, double& alpha) const {
  const Eigen::Index m = lambda.size();
  Eigen::VectorXd sb, sc, lam;
  const LinearOperator op = [&](const Eigen::VectorXd& x, Eigen::VectorXd& y) {
    lam = x.head(m);
    apply(lam, sb, sc);
    y.resize(x.size());
    for (Eigen::Index i = 0; i < m; ++i) y(i) = active[i] ? sb(i) : sc(i);
    if (mode) {
      for (Eigen::Index i = 0; i < m; ++i) y(i) += x(m) * (active[i] ? mode->trace_B(i) : mode->trace_C(i));
      y(m) = mode->arc_weights.dot(lam);
    }
  };
  Eigen::VectorXd x(m + (mode ? 1 : 0)), rhs(x.size());
  x.head(m) = lambda;
  rhs.head(m) = d;
  if (mode) x(m) = alpha, rhs(m) = -mode->load_total;
  const GmresReport g = gmres(op, rhs, x, options_);
  lambda = x.head(m);
  if (mode) alpha = x(m);
  return {g.iterations, g.relative_residual, g.converged};
}

namespace {

/// G between the nodes of two entries.
double green_between(const GreenTable<2>& green, const SparseRows::Entry& a, const SparseRows::Entry& b) {
  return green.G(a.i, a.j, b.i, b.j);
}
double green_between(const GreenTable<3>& green, const SparseRows::Entry& a, const SparseRows::Entry& b) {
  return green.G({a.i, a.j, a.k}, b.i, b.j, b.k);
}

}  // namespace

template <int dim>
Eigen::MatrixXd green_block(const GreenTable<dim>& green, const SparseRows& R, const SparseRows& Q,
                            const Execution& execution) {
  return green_blocks(green, {&R}, Q, execution).front();
}

template <int dim>
std::vector<Eigen::MatrixXd> green_blocks(const GreenTable<dim>& green, const std::vector<const SparseRows*>& row_sets,
                                          const SparseRows& Q, const Execution& execution) {
  // The distinct nodes of all row sets, and every entry as (node slot, weight).
  std::vector<std::size_t> slot_of;  // by entry, over all row sets in order
  std::vector<SparseRows::Entry> nodes;
  {
    std::unordered_map<std::size_t, std::size_t> slots;
    for (const SparseRows* R : row_sets)
      for (const auto& e : R->entries) {
        const auto [it, added] = slots.emplace(e.index, nodes.size());
        if (added) nodes.push_back(e);
        slot_of.push_back(it->second);
      }
  }
  std::vector<Eigen::MatrixXd> blocks;
  for (const SparseRows* R : row_sets) blocks.emplace_back(R->n_rows(), Q.n_rows());
  std::atomic<bool> stop = false;  // an interruption seen by thread 0 (the caller's) ends every thread's work
#pragma omp parallel num_threads(execution.threads())
  {
    std::vector<double> column(nodes.size());  // (G Qᵀ)(node, col) for the nodes of the rows
#pragma omp for schedule(dynamic, 4)
    for (int col = 0; col < Q.n_rows(); ++col) {
      if (omp_get_thread_num() == 0 && col % 8 == 0 && execution.interrupt_requested()) stop = true;
      if (stop) continue;
      for (std::size_t u = 0; u < nodes.size(); ++u) {
        double sum = 0.0;
        for (std::size_t b = Q.row_begin[col]; b < Q.row_begin[col + 1]; ++b) {
          const auto& qb = Q.entries[b];
          sum += green_between(green, nodes[u], qb) * qb.value;
        }
        column[u] = sum;
      }
      std::size_t entry = 0;
      for (std::size_t set = 0; set < row_sets.size(); ++set) {
        const SparseRows& R = *row_sets[set];
        for (int row = 0; row < R.n_rows(); ++row) {
          double sum = 0.0;
          for (std::size_t a = R.row_begin[row]; a < R.row_begin[row + 1]; ++a, ++entry)
            sum += R.entries[a].value * column[slot_of[entry]];
          blocks[set](row, col) = sum;
        }
      }
    }
  }
  if (stop) throw Interrupted();
  return blocks;
}

template <int dim>
ExplicitSchur::ExplicitSchur(const GreenTable<dim>& green, const SparseRows& B_gamma, const SparseRows& C_gamma,
                             const SparseRows& loads, const Execution& execution, const DirectTerms& direct) {
  std::vector<Eigen::MatrixXd> blocks = green_blocks(green, {&B_gamma, &C_gamma}, loads, execution);
  S_B_ = std::move(blocks[0]);
  S_C_ = std::move(blocks[1]);
  if (!direct.empty()) {
    S_B_ += Eigen::MatrixXd(direct.trace);
    S_C_ += Eigen::MatrixXd(direct.normal_derivative);
  }
}

template ExplicitSchur::ExplicitSchur(const GreenTable<2>&, const SparseRows&, const SparseRows&, const SparseRows&,
                                      const Execution&, const DirectTerms&);
template ExplicitSchur::ExplicitSchur(const GreenTable<3>&, const SparseRows&, const SparseRows&, const SparseRows&,
                                      const Execution&, const DirectTerms&);
template Eigen::MatrixXd green_block(const GreenTable<2>&, const SparseRows&, const SparseRows&, const Execution&);
template Eigen::MatrixXd green_block(const GreenTable<3>&, const SparseRows&, const SparseRows&, const Execution&);
template std::vector<Eigen::MatrixXd> green_blocks(const GreenTable<2>&, const std::vector<const SparseRows*>&,
                                                   const SparseRows&, const Execution&);
template std::vector<Eigen::MatrixXd> green_blocks(const GreenTable<3>&, const std::vector<const SparseRows*>&,
                                                   const SparseRows&, const Execution&);

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
  const Eigen::Index m = lambda.size();
  Eigen::VectorXd rhs(S.rows());
  rhs.head(m) = d;
  if (mode) rhs(m) = -mode->load_total;
  const Eigen::VectorXd x = S.partialPivLu().solve(rhs);
  lambda = x.head(m);
  if (mode) alpha = x(m);
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
