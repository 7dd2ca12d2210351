// S̃_B and S̃_C kept compressed, GMRES with a block-Jacobi preconditioner on them, and the refinement on
// the exact S (hierarchical_schur.hpp).
#include "fictus/solve/hierarchical_schur.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <exception>
#include <stdexcept>
#include <unordered_map>
#include <vector>

namespace fictus {

void RefinedSchur::apply(const Eigen::VectorXd& lambda, Eigen::VectorXd& sb, Eigen::VectorXd& sc) const {
  if (last_lambda_.size() != lambda.size() || last_lambda_ != lambda) {
    exact_.apply(lambda, last_sb_, last_sc_);
    last_lambda_ = lambda;
  }
  sb = last_sb_;
  sc = last_sc_;
}

LinearSolveReport RefinedSchur::solve(const ActiveSet& active, const Eigen::VectorXd& d, const ConstantMode* mode,
                                      Eigen::VectorXd& lambda, double& alpha) const {
  if (mode) throw std::logic_error("RefinedSchur: no bordering (a singular A takes the dense blocks)");
  alpha = 0.0;
  LinearSolveReport report;
  const Eigen::Index m = d.size();
  const auto rows = [&](const Eigen::VectorXd& sb, const Eigen::VectorXd& sc, Eigen::VectorXd& out) {
    out.resize(m);
    for (Eigen::Index i = 0; i < m; ++i) out(i) = active[std::size_t(i)] ? sb(i) : sc(i);
  };
  const std::size_t before = exact_.fast_solves();
  Eigen::VectorXd sb0, sc0, r;
  apply(lambda, sb0, sc0);  // no fast solve where Newton's residual made this product
  rows(sb0, sc0, r);
  r = d - r;
  const double rn = d.norm(), scale = rn > 0 ? rn : 1.0;
  report.relative_residual = r.norm() / scale;
  report.converged = report.relative_residual <= tolerance_;
  if (!report.converged) {
    // Flexible GMRES on S_𝒜 from λ, each direction S̃_𝒜⁻¹v by GMRES to correction_tolerance; the
    // directions and their exact products are kept, so λ's product needs no fast solve at the end.
    std::vector<Eigen::VectorXd> z, z_sb, z_sc;
    const LinearOperator precondition = [&](const Eigen::VectorXd& v, Eigen::VectorXd& out) {
      out = Eigen::VectorXd::Zero(m);
      approximate_.solve(active, v, out, correction_tolerance_);
      z.push_back(out);
    };
    const LinearOperator exact = [&](const Eigen::VectorXd& x, Eigen::VectorXd& out) {
      Eigen::VectorXd sb, sc;
      exact_.apply(x, sb, sc);
      rows(sb, sc, out);
      z_sb.push_back(std::move(sb));
      z_sc.push_back(std::move(sc));
    };
    const FlexibleGmresReport g = flexible_gmres(exact, precondition, r, max_steps_, tolerance_ * rn / r.norm());
    for (Eigen::Index k = 0; k < g.coefficients.size(); ++k) {
      const double y = g.coefficients(k);
      lambda += y * z[std::size_t(k)];
      sb0 += y * z_sb[std::size_t(k)];
      sc0 += y * z_sc[std::size_t(k)];
    }
    last_lambda_ = lambda, last_sb_ = std::move(sb0), last_sc_ = std::move(sc0);
    report.relative_residual = g.relative_residual * r.norm() / scale;
    report.converged = report.relative_residual <= tolerance_;
  }
  report.inner_iterations = int(exact_.fast_solves() - before);
  return report;
}

LinearSolveReport SettlingSchur::solve(const ActiveSet& active, const Eigen::VectorXd& d, const ConstantMode* mode,
                                       Eigen::VectorXd& lambda, double& alpha) const {
  if (mode) throw std::logic_error("SettlingSchur: no bordering (a singular A takes the dense blocks)");
  alpha = 0.0;
  return approximate_.solve(active, d, lambda, tolerance_);
}

namespace {

/// Rethrows a failure of this rank's threads; distributed, after all ranks agree that one failed (a
/// failure may be one rank's alone, as an allocation of its own groups' LUs), so that none is left
/// waiting in the next sum.
void rethrow_together(const std::exception_ptr& failure, const Distribution* distribution) {
  if (distribution && !distribution->all(!failure) && !failure)
    throw std::runtime_error("hierarchical Schur complement: another rank failed (its error is on its stderr)");
  if (failure) std::rethrow_exception(failure);
}

using RowMajorSparse = Eigen::SparseMatrix<double, Eigen::RowMajor>;

/// M(a, b) += D(items[a], items[b]).
void add_direct(const RowMajorSparse& D, const std::vector<int>& items, Eigen::MatrixXd& M) {
  if (D.nonZeros() == 0) return;
  std::unordered_map<int, int> place;
  for (std::size_t a = 0; a < items.size(); ++a) place[items[a]] = int(a);
  for (std::size_t a = 0; a < items.size(); ++a)
    for (RowMajorSparse::InnerIterator it(D, items[a]); it; ++it)
      if (const auto p = place.find(int(it.col())); p != place.end()) M(Eigen::Index(a), p->second) += it.value();
}

}  // namespace

struct HierarchicalSchur::Impl {
  int m = 0;
  int threads = 1;
  CompressedBlocks blocks;  // S̃_B (set 0) and S̃_C (set 1) without the direct terms
  RowMajorSparse D_B, D_C;
  SchurStorage storage;
  GmresOptions gmres;
  std::vector<std::vector<int>> groups;         // the points of each preconditioner block
  std::vector<char> mine;                       // the groups this rank holds (serially: all)
  std::vector<Eigen::MatrixXd> diag_B, diag_C;  // S̃_B and S̃_C on each group × group (held groups only)
  mutable std::vector<Eigen::PartialPivLU<Eigen::MatrixXd>> lu;
  mutable std::vector<ActiveSet> lu_active;
  mutable int factorizations = 0;

  void apply(const Eigen::VectorXd& x, Eigen::VectorXd& sb, Eigen::VectorXd& sc) const {
    std::vector<Eigen::VectorXd> y;
    blocks.multiply(x, y, threads);
    sb = std::move(y[0]);
    sc = std::move(y[1]);
    if (D_B.nonZeros() > 0) sb += D_B * x;
    if (D_C.nonZeros() > 0) sc += D_C * x;
  }

  /// y = S̃_𝒜 x: of each block only the row set its rows take (S̃_B on 𝒜, S̃_C elsewhere).
  void apply_newton(const ActiveSet& active, const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
    std::vector<char> set_of_row(static_cast<std::size_t>(m));
    for (int i = 0; i < m; ++i) set_of_row[std::size_t(i)] = active[std::size_t(i)] ? 0 : 1;
    std::vector<Eigen::VectorXd> s;
    blocks.multiply(x, s, threads, &set_of_row);
    y.resize(m);
    for (int i = 0; i < m; ++i) y(i) = active[std::size_t(i)] ? s[0](i) : s[1](i);
    const auto add_direct_rows = [&](const RowMajorSparse& D, bool on_active) {
      if (D.nonZeros() == 0) return;
      const Eigen::VectorXd d = D * x;
      for (int i = 0; i < m; ++i)
        if ((active[std::size_t(i)] != 0) == on_active) y(i) += d(i);
    };
    add_direct_rows(D_B, true);
    add_direct_rows(D_C, false);
  }

  /// The preconditioner's LUs for 𝒜 (again only in groups where 𝒜 changed).
  void prepare(const ActiveSet& active) const {
    const int n = int(groups.size());
    std::exception_ptr failure;
    int made = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) reduction(+ : made)
    for (int g = 0; g < n; ++g) try {
        if (!mine[std::size_t(g)]) continue;
        const std::vector<int>& items = groups[std::size_t(g)];
        ActiveSet flags(items.size());
        for (std::size_t a = 0; a < items.size(); ++a) flags[a] = active[std::size_t(items[a])];
        if (flags == lu_active[std::size_t(g)]) continue;
        Eigen::MatrixXd M(Eigen::Index(items.size()), Eigen::Index(items.size()));
        for (Eigen::Index a = 0; a < M.rows(); ++a)
          M.row(a) = flags[std::size_t(a)] ? diag_B[std::size_t(g)].row(a) : diag_C[std::size_t(g)].row(a);
        lu[std::size_t(g)].compute(M);
        lu_active[std::size_t(g)] = std::move(flags);
        ++made;
      } catch (...) {
#pragma omp critical(fictus_hierarchical_failure)
        if (!failure) failure = std::current_exception();
      }
    rethrow_together(failure, blocks.distribution.get());
    if (blocks.distribution) made = int(blocks.distribution->sum(double(made)));  // every rank's groups
    factorizations += made;
  }

  /// y = the block-Jacobi preconditioner applied to r. Distributed: each rank solves on its groups and
  /// the ranks' parts are summed; each entry is one rank's (the others add zeros), so every rank gets
  /// the same bits.
  void precondition(const Eigen::VectorXd& r, Eigen::VectorXd& y) const {
    y.setZero(r.size());
    const int n = int(groups.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int g = 0; g < n; ++g) {
      if (!mine[std::size_t(g)]) continue;
      const std::vector<int>& items = groups[std::size_t(g)];
      Eigen::VectorXd v(Eigen::Index(items.size()));
      for (std::size_t a = 0; a < items.size(); ++a) v(Eigen::Index(a)) = r(items[a]);
      v = lu[std::size_t(g)].solve(v);
      for (std::size_t a = 0; a < items.size(); ++a) y(items[a]) = v(Eigen::Index(a));
    }
    if (blocks.distribution) blocks.distribution->sum(y.data(), std::size_t(y.size()));
  }
};

template <int dim>
HierarchicalSchur::HierarchicalSchur(const GreenTable<dim>& green, const SparseRows& B_gamma, const SparseRows& C_gamma,
                                     const SparseRows& loads, const Execution& execution, const DirectTerms& direct,
                                     const HierarchicalOptions& options, const GmresOptions& gmres)
    : impl_(std::make_unique<Impl>()) {
  const auto start = std::chrono::steady_clock::now();
  Impl& s = *impl_;
  s.m = B_gamma.n_rows();
  s.threads = execution.threads();
  s.gmres = gmres;
  if (C_gamma.n_rows() != s.m || loads.n_rows() != s.m)
    throw std::invalid_argument("hierarchical Schur complement: B_γ, C_γ and the loads differ in their rows");
  if (!(options.far_field.order > 0 && options.group >= 1))
    throw std::invalid_argument("hierarchical Schur complement: needs a far field (order > 0) and groups of >= 1");
  FarFieldReport report;
  s.blocks = compressed_green_blocks(green, {&B_gamma, &C_gamma}, loads, execution, options.far_field, options.storage,
                                     &report);
  execution.throw_if_interrupted();
  s.D_B = direct.trace;
  s.D_C = direct.normal_derivative;
  // The preconditioner: S̃_B and S̃_C on each group of nearby points. Distributed, each group is one
  // rank's (shared out by its LU's work): every rank makes its blocks' entries of each group, they are
  // summed onto the owner, and the other ranks drop them; a batch of groups at a time, so that no rank
  // holds more than its own groups and one batch.
  const std::vector<int> groups = s.blocks.groups(options.group);
  const std::size_t n_groups = groups.size();
  s.groups.resize(n_groups);
  s.diag_B.resize(n_groups);
  s.diag_C.resize(n_groups);
  s.lu.resize(n_groups);
  s.lu_active.resize(n_groups);
  std::vector<double> work(n_groups);
  for (std::size_t g = 0; g < n_groups; ++g) {
    const CompressedBlocks::Cluster& cl = s.blocks.row_clusters[std::size_t(groups[g])];
    s.groups[g].assign(s.blocks.row_item.begin() + cl.begin, s.blocks.row_item.begin() + cl.end);
    work[g] = std::pow(double(s.groups[g].size()), 3);
  }
  const Distribution* distribution = s.blocks.distribution.get();
  const std::vector<int> owner = share_out(work, distribution ? distribution->size() : 1);
  const int rank = distribution ? distribution->rank() : 0;
  s.mine.resize(n_groups);
  for (std::size_t g = 0; g < n_groups; ++g) s.mine[g] = owner[g] == rank;
  // Distributed: 32 MiB of blocks at a time (one message each, as sum_onto_owners sends them); serially
  // all at once.
  const std::size_t batch = distribution ? std::size_t(1) << 22 : SIZE_MAX;
  const auto numbers_of = [&](std::size_t g) { return 2 * s.groups[g].size() * s.groups[g].size(); };
  for (std::size_t first = 0, last = 0; first < n_groups; first = last) {
    std::size_t numbers = 0;
    for (last = first; last < n_groups && (last == first || numbers + numbers_of(last) <= batch); ++last)
      numbers += numbers_of(last);
    std::exception_ptr failure;
#pragma omp parallel for schedule(dynamic, 1) num_threads(s.threads)
    for (std::size_t g = first; g < last; ++g) try {
        s.diag_B[g] = s.blocks.diagonal_block(0, groups[g]);
        s.diag_C[g] = s.blocks.diagonal_block(1, groups[g]);
      } catch (...) {
#pragma omp critical(fictus_hierarchical_failure)
        if (!failure) failure = std::current_exception();
      }
    rethrow_together(failure, distribution);
    if (!distribution) continue;
    std::vector<Eigen::MatrixXd*> parts;
    std::vector<int> part_owner;
    for (std::size_t g = first; g < last; ++g) {
      parts.insert(parts.end(), {&s.diag_B[g], &s.diag_C[g]});
      part_owner.insert(part_owner.end(), {owner[g], owner[g]});
    }
    sum_onto_owners(*distribution, parts, part_owner);
    for (std::size_t g = first; g < last; ++g)
      if (!s.mine[g]) s.diag_B[g] = Eigen::MatrixXd(), s.diag_C[g] = Eigen::MatrixXd();
  }
  for (std::size_t g = 0; g < n_groups; ++g) {
    if (!s.mine[g]) continue;
    add_direct(s.D_B, s.groups[g], s.diag_B[g]);
    add_direct(s.D_C, s.groups[g], s.diag_C[g]);
  }
  SchurStorage& t = s.storage;
  t.kind = "hierarchical";
  t.bytes = s.blocks.bytes();
  t.dense_bytes = 2.0 * 8.0 * double(s.m) * double(s.m);
  for (const CompressedBlocks::Block& b : s.blocks.blocks) {
    if (!b.held) continue;
    if (b.dense.empty()) {
      t.low_rank_blocks += 1;
      for (const Eigen::MatrixXd& r : b.right) t.largest_rank = std::max(t.largest_rank, int(r.cols()));
    } else {
      t.full_blocks += 1;
    }
  }
  for (const Eigen::MatrixXd& M : s.diag_B) t.preconditioner_bytes += 3.0 * 8.0 * double(M.size());  // held
  t.preconditioner_bytes_here = t.preconditioner_bytes;
  if (distribution) {  // the blocks and groups of all ranks
    std::vector<double> totals{t.bytes, t.low_rank_blocks, t.full_blocks, t.preconditioner_bytes};
    distribution->sum(totals);
    t.bytes = totals[0], t.low_rank_blocks = totals[1], t.full_blocks = totals[2], t.preconditioner_bytes = totals[3];
    t.largest_rank = int(distribution->max(t.largest_rank));
  }
  t.bytes += 12.0 * double(s.D_B.nonZeros() + s.D_C.nonZeros());  // every rank's
  t.far_fraction = report.far_pairs / (report.far_pairs + report.near_pairs);
  t.seconds_assembly = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

template HierarchicalSchur::HierarchicalSchur(const GreenTable<2>&, const SparseRows&, const SparseRows&,
                                              const SparseRows&, const Execution&, const DirectTerms&,
                                              const HierarchicalOptions&, const GmresOptions&);
template HierarchicalSchur::HierarchicalSchur(const GreenTable<3>&, const SparseRows&, const SparseRows&,
                                              const SparseRows&, const Execution&, const DirectTerms&,
                                              const HierarchicalOptions&, const GmresOptions&);

HierarchicalSchur::~HierarchicalSchur() = default;

int HierarchicalSchur::size() const { return impl_->m; }

const SchurStorage& HierarchicalSchur::storage() const { return impl_->storage; }

int HierarchicalSchur::factorizations() const { return impl_->factorizations; }

void HierarchicalSchur::apply(const Eigen::VectorXd& lambda, Eigen::VectorXd& sb, Eigen::VectorXd& sc) const {
  impl_->apply(lambda, sb, sc);
}

LinearSolveReport HierarchicalSchur::solve(const ActiveSet& active, const Eigen::VectorXd& d, const ConstantMode* mode,
                                           Eigen::VectorXd& lambda, double& alpha) const {
  if (mode) throw std::logic_error("HierarchicalSchur: no bordering (a singular A takes the dense blocks)");
  alpha = 0.0;
  return solve(active, d, lambda, impl_->gmres.relative_tolerance);
}

LinearSolveReport HierarchicalSchur::solve(const ActiveSet& active, const Eigen::VectorXd& d, Eigen::VectorXd& lambda,
                                           double relative_tolerance) const {
  const Impl& s = *impl_;
  s.prepare(active);
  Eigen::VectorXd y, v;
  if (lambda.isZero(0.0))  // a refinement's correction starts from zero: no product needed
    y = Eigen::VectorXd::Zero(s.m);
  else
    s.apply_newton(active, lambda, y);
  const Eigen::VectorXd r0 = d - y;
  const double dn = d.norm(), rn = r0.norm();
  LinearSolveReport report;
  report.relative_residual = dn > 0 ? rn / dn : rn;
  report.converged = report.relative_residual <= relative_tolerance;
  if (report.converged) return report;
  GmresOptions options = s.gmres;
  options.relative_tolerance = std::min(0.5, relative_tolerance * dn / rn);
  const LinearOperator op = [&](const Eigen::VectorXd& w, Eigen::VectorXd& out) {
    s.precondition(w, v);
    s.apply_newton(active, v, out);
  };
  Eigen::VectorXd z = Eigen::VectorXd::Zero(s.m);
  const GmresReport g = gmres(op, r0, z, options);
  s.precondition(z, v);
  lambda += v;
  report.inner_iterations = g.iterations;
  report.relative_residual = g.relative_residual * rn / (dn > 0 ? dn : 1.0);
  report.converged = g.converged;
  return report;
}

}  // namespace fictus
