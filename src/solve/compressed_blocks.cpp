// CompressedBlocks (schur_complement.hpp): the kept blocks' storage, products and the preconditioner's
// diagonal blocks; compressed_green_blocks (green_blocks.cpp) makes them.
#include <omp.h>

#include <algorithm>
#include <vector>

#include "fictus/grid/distribution.hpp"
#include "fictus/solve/schur_complement.hpp"

namespace fictus {

double CompressedBlocks::bytes() const {
  double n = 0;
  for (const Block& b : blocks) {
    for (const Eigen::MatrixXd& d : b.dense) n += double(d.size());
    for (const Eigen::MatrixXd& d : b.left) n += double(d.size());
    for (const Eigen::MatrixXd& d : b.right) n += double(d.size());
  }
  return 8.0 * n;
}

void CompressedBlocks::multiply(const Eigen::VectorXd& x, std::vector<Eigen::VectorXd>& y, int threads,
                                const std::vector<char>* set_of_row) const {
  Eigen::VectorXd xt(n_cols);  // x in the columns' tree order
  for (int j = 0; j < n_cols; ++j) xt(j) = x(col_item[std::size_t(j)]);
  // wanted[s][t]: how many of the first t rows in tree order want set s.
  std::vector<std::vector<int>> wanted(std::size_t(set_of_row ? n_sets : 0), std::vector<int>(n_rows + 1, 0));
  for (std::size_t s = 0; s < wanted.size(); ++s)
    for (int t = 0; t < n_rows; ++t)
      wanted[s][std::size_t(t) + 1] =
          wanted[s][std::size_t(t)] + ((*set_of_row)[std::size_t(row_item[std::size_t(t)])] == char(s));
  const auto skip = [&](int s, const Cluster& cx) {
    return set_of_row && wanted[std::size_t(s)][std::size_t(cx.end)] == wanted[std::size_t(s)][std::size_t(cx.begin)];
  };
  // Each thread adds a fixed run of the blocks (of about equal work) into its own copy (tree order),
  // summed after in thread order: the bits depend on the thread count only (a run is reproducible).
  // Distributed, the ranks' products are then added by an allreduce, which gives every rank the same
  // bits (Newton's steps must agree).
  const int n_threads = std::max(1, threads);
  std::vector<Eigen::MatrixXd> partial(static_cast<std::size_t>(n_threads));
  const int n_b = int(blocks.size());
  std::vector<double> work(std::size_t(n_b) + 1, 0.0);  // work[k]: the first k blocks' stored numbers
  for (int k = 0; k < n_b; ++k) {
    const Block& b = blocks[std::size_t(k)];
    double n = 0;
    for (const auto* parts : {&b.dense, &b.left, &b.right})
      for (const Eigen::MatrixXd& d : *parts) n += double(d.size());
    work[std::size_t(k) + 1] = work[std::size_t(k)] + n;
  }
#pragma omp parallel num_threads(n_threads)
  {
    const int t = omp_get_thread_num(), team = omp_get_num_threads();
    Eigen::MatrixXd& mine = partial[std::size_t(t)];
    mine = Eigen::MatrixXd::Zero(n_rows, n_sets);
    Eigen::VectorXd w;
    const auto run_start = [&](int r) {
      return int(std::lower_bound(work.begin(), work.end(), work.back() * r / team) - work.begin());
    };
    const int first = t == 0 ? 0 : run_start(t), last = t + 1 == team ? n_b : run_start(t + 1);
    for (int k = first; k < last; ++k) {
      const Block& b = blocks[std::size_t(k)];
      if (!b.held) continue;
      const Cluster &cx = row_clusters[std::size_t(b.x)], &cy = col_clusters[std::size_t(b.y)];
      const auto xy = xt.segment(cy.begin, cy.end - cy.begin);
      if (!b.dense.empty()) {
        for (int s = 0; s < n_sets; ++s)
          if (!skip(s, cx)) mine.col(s).segment(cx.begin, cx.end - cx.begin).noalias() += b.dense[std::size_t(s)] * xy;
      } else {
        for (int s = 0; s < n_sets; ++s) {
          if (skip(s, cx)) continue;
          w.noalias() = b.right[std::size_t(s)].transpose() * xy;
          mine.col(s).segment(cx.begin, cx.end - cx.begin).noalias() += b.left[std::size_t(s)] * w;
        }
      }
    }
  }
  for (std::size_t p = 1; p < partial.size(); ++p)
    if (partial[p].size() > 0) partial[0] += partial[p];
  if (distribution) distribution->sum(partial[0].data(), std::size_t(partial[0].size()));
  y.assign(std::size_t(n_sets), Eigen::VectorXd(n_rows));
  for (int s = 0; s < n_sets; ++s)
    for (int i = 0; i < n_rows; ++i) y[std::size_t(s)](row_item[std::size_t(i)]) = partial[0](i, s);
}

std::vector<int> CompressedBlocks::groups(int size) const {
  std::vector<int> out;
  for (std::size_t k = 0; k < row_clusters.size(); ++k) {
    const int parent = row_parent[k];
    const auto items = [&](int c) { return row_clusters[std::size_t(c)].end - row_clusters[std::size_t(c)].begin; };
    if (items(int(k)) <= size && (parent < 0 || items(parent) > size)) out.push_back(int(k));
  }
  return out;
}

Eigen::MatrixXd CompressedBlocks::diagonal_block(int k, int g) const {
  const Cluster& cg = row_clusters[std::size_t(g)];
  const int n = cg.end - cg.begin;
  // The group's points and their places among the columns.
  std::vector<int> place(std::size_t(n_cols), -1);
  for (int i = cg.begin; i < cg.end; ++i) place[std::size_t(row_item[std::size_t(i)])] = i - cg.begin;
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n, n);
  std::vector<int> cols, at;  // a block's columns in the group: local column, place
  for (const Block& b : blocks) {
    const Cluster &cx = row_clusters[std::size_t(b.x)], &cy = col_clusters[std::size_t(b.y)];
    const int r0 = std::max(cx.begin, cg.begin), r1 = std::min(cx.end, cg.end);
    if (r0 >= r1 || !b.held) continue;
    cols.clear(), at.clear();
    for (int j = cy.begin; j < cy.end; ++j)
      if (const int p = place[std::size_t(col_item[std::size_t(j)])]; p >= 0)
        cols.push_back(j - cy.begin), at.push_back(p);
    if (cols.empty()) continue;
    if (!b.dense.empty()) {
      const Eigen::MatrixXd& D = b.dense[std::size_t(k)];
      for (std::size_t c = 0; c < cols.size(); ++c)
        for (int i = r0; i < r1; ++i) M(i - cg.begin, at[c]) = D(i - cx.begin, cols[c]);
    } else {
      const Eigen::MatrixXd& L = b.left[std::size_t(k)];
      for (std::size_t c = 0; c < cols.size(); ++c)
        M.block(r0 - cg.begin, at[c], r1 - r0, 1).noalias() =
            L.middleRows(r0 - cx.begin, r1 - r0) * b.right[std::size_t(k)].row(cols[c]).transpose();
    }
  }
  // M's rows are in tree order of the group, its columns at `place`, the same order.
  return M;
}

}  // namespace fictus
