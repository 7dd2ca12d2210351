// Dense blocks R G Qᵀ from sparse rows and the Green's table: exact, or with the far field
// interpolated (schur_complement.hpp, docs/math.md "The far field of the 3-D Schur complement").
#include <omp.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <climits>
#include <cmath>
#include <exception>
#include <memory>
#include <numeric>
#include <stdexcept>
#include <unordered_map>

#include "fictus/grid/distribution.hpp"
#include "fictus/solve/schur_complement.hpp"

namespace fictus {
namespace {

template <int dim>
using Index = std::array<int, dim>;

template <int dim>
Index<dim> node_of(const SparseRows::Entry& e) {
  if constexpr (dim == 2)
    return {e.i, e.j};
  else
    return {e.i, e.j, e.k};
}

/// Inclusive ranges of node indices.
template <int dim>
struct NodeBox {
  Index<dim> lo, hi;
  NodeBox() {
    lo.fill(INT_MAX);
    hi.fill(INT_MIN);
  }
  void add(const Index<dim>& a) {
    for (int d = 0; d < dim; ++d) lo[d] = std::min(lo[d], a[d]), hi[d] = std::max(hi[d], a[d]);
  }
  void add(const NodeBox& b) {
    if (b.empty()) return;
    add(b.lo);
    add(b.hi);
  }
  bool empty() const { return lo[0] > hi[0]; }  // a row without entries
  double center(int d) const { return empty() ? 0.0 : 0.5 * (double(lo[d]) + double(hi[d])); }
  /// Half the diagonal.
  double radius() const {
    double s = 0;
    for (int d = 0; d < dim && !empty(); ++d) s += (double(hi[d]) - lo[d]) * (double(hi[d]) - lo[d]);
    return 0.5 * std::sqrt(s);
  }
};

/// Distance between two boxes, the nearest image of `b` counted: the singularities of G(·, b) lie at
/// b and, in a Dirichlet box, at its reflections −b and 2n − b along each axis (period 2n); in a
/// periodic box at b ± n.
template <int dim>
double image_distance(const NodeBox<dim>& a, const NodeBox<dim>& b, const Grid<dim>& grid) {
  double sum = 0;
  for (int d = 0; d < dim; ++d) {
    const double n = grid.n(d);
    double nearest = INFINITY;
    const auto gap = [&](double lo, double hi) {
      nearest = std::min(nearest, std::max({0.0, lo - a.hi[d], a.lo[d] - hi}));
    };
    if (grid.periodic()) {
      for (int shift = -1; shift <= 1; ++shift) gap(b.lo[d] + shift * n, b.hi[d] + shift * n);
    } else {
      gap(b.lo[d], b.hi[d]);
      gap(-double(b.hi[d]), -double(b.lo[d]));
      gap(2 * n - b.hi[d], 2 * n - b.lo[d]);
    }
    sum += nearest * nearest;
  }
  return std::sqrt(sum);
}

/// A binary tree of items (rows) split at the median of their centers along the longest axis.
template <int dim>
struct ClusterTree {
  struct Cluster {
    int begin, end, left = -1, right = -1;
    NodeBox<dim> box;  // of the items' nodes
    double work = 0;   // entries (exact cost of a block with this cluster)
  };
  std::vector<int> item;  // items in cluster order
  std::vector<Cluster> clusters;
  bool leaf(int c) const { return clusters[std::size_t(c)].left < 0; }

  ClusterTree(const std::vector<NodeBox<dim>>& boxes, const std::vector<double>& work, int leaf_size)
      : item(boxes.size()) {
    std::iota(item.begin(), item.end(), 0);
    if (!boxes.empty()) build(boxes, work, 0, int(boxes.size()), leaf_size);
  }

 private:
  int build(const std::vector<NodeBox<dim>>& boxes, const std::vector<double>& work, int begin, int end,
            int leaf_size) {
    const int c = int(clusters.size());
    clusters.push_back({begin, end, -1, -1, NodeBox<dim>(), 0.0});
    NodeBox<dim> box, centers;
    double sum = 0;
    for (int k = begin; k < end; ++k) {
      const NodeBox<dim>& b = boxes[std::size_t(item[std::size_t(k)])];
      box.add(b);
      Index<dim> mid;
      for (int d = 0; d < dim; ++d) mid[d] = int(std::lround(b.center(d)));
      centers.add(mid);
      sum += work[std::size_t(item[std::size_t(k)])];
    }
    clusters[std::size_t(c)].box = box;
    clusters[std::size_t(c)].work = sum;
    if (end - begin <= leaf_size) return c;
    int axis = 0;
    for (int d = 1; d < dim; ++d)
      if (centers.hi[d] - centers.lo[d] > centers.hi[axis] - centers.lo[axis]) axis = d;
    const int mid = begin + (end - begin) / 2;
    std::nth_element(item.begin() + begin, item.begin() + mid, item.begin() + end, [&](int p, int q) {
      return boxes[std::size_t(p)].center(axis) < boxes[std::size_t(q)].center(axis);
    });
    const int left = build(boxes, work, begin, mid, leaf_size);
    const int right = build(boxes, work, mid, end, leaf_size);
    clusters[std::size_t(c)].left = left;
    clusters[std::size_t(c)].right = right;
    return c;
  }
};

/// Tensor Lagrange interpolation on grid nodes in a box: along each axis min(order, width) nodes
/// near the Chebyshev points of the box's range (all of its nodes when it is narrower).
template <int dim>
struct Interpolation {
  NodeBox<dim> box;
  std::array<std::vector<int>, dim> nodes;
  std::array<std::vector<double>, dim> weights;  // weights[d][(t − lo)·p + k] = L_k(t)

  Interpolation(const NodeBox<dim>& b, int order) : box(b) {
    for (int d = 0; d < dim; ++d) {
      const int lo = b.lo[d], hi = b.hi[d], width = hi - lo + 1;
      std::vector<int>& x = nodes[std::size_t(d)];
      x = interpolation_nodes(lo, hi, order);
      const int p = int(x.size());
      std::vector<double>& w = weights[std::size_t(d)];
      w.assign(std::size_t(width * p), 0.0);
      for (int t = lo; t <= hi; ++t)
        for (int k = 0; k < p; ++k) {
          double v = 1;
          for (int l = 0; l < p; ++l)
            if (l != k) v *= double(t - x[std::size_t(l)]) / double(x[std::size_t(k)] - x[std::size_t(l)]);
          w[std::size_t((t - lo) * p + k)] = v;
        }
    }
  }
  int size() const {
    int s = 1;
    for (int d = 0; d < dim; ++d) s *= int(nodes[std::size_t(d)].size());
    return s;
  }
  /// row += value · Π_d L(a_d) over the tensor nodes (flat index, first axis fastest).
  void add(const Index<dim>& a, double value, double* row) const {
    const int p0 = int(nodes[0].size());
    const double* w0 = &weights[0][std::size_t((a[0] - box.lo[0]) * p0)];
    if constexpr (dim == 2) {
      const int p1 = int(nodes[1].size());
      const double* w1 = &weights[1][std::size_t((a[1] - box.lo[1]) * p1)];
      for (int k1 = 0; k1 < p1; ++k1)
        for (int k0 = 0; k0 < p0; ++k0) row[k1 * p0 + k0] += value * w1[k1] * w0[k0];
    } else {
      const int p1 = int(nodes[1].size()), p2 = int(nodes[2].size());
      const double* w1 = &weights[1][std::size_t((a[1] - box.lo[1]) * p1)];
      const double* w2 = &weights[2][std::size_t((a[2] - box.lo[2]) * p2)];
      for (int k2 = 0; k2 < p2; ++k2)
        for (int k1 = 0; k1 < p1; ++k1) {
          const double v = value * w2[k2] * w1[k1];
          double* r = row + (k2 * p1 + k1) * p0;
          for (int k0 = 0; k0 < p0; ++k0) r[k0] += v * w0[k0];
        }
    }
  }
};

/// The rows of one side: one or more row sets with the same number of rows (row r of every set is
/// item r of the tree).
struct RowSide {
  std::vector<const SparseRows*> sets;
  int n_rows() const { return sets.front()->n_rows(); }
};

template <int dim>
NodeBox<dim> item_box(const RowSide& side, int r) {
  NodeBox<dim> box;
  for (const SparseRows* R : side.sets)
    for (std::size_t a = R->row_begin[std::size_t(r)]; a < R->row_begin[std::size_t(r) + 1]; ++a)
      box.add(node_of<dim>(R->entries[a]));
  return box;
}

/// The distinct nodes of the rows of a cluster and, for each entry of each set in cluster order,
/// its node's slot.
template <int dim>
struct DistinctNodes {
  std::vector<Index<dim>> nodes;
  std::vector<std::uint32_t> slot;
  DistinctNodes(const RowSide& side, const std::vector<int>& items) {
    std::unordered_map<std::size_t, std::uint32_t> slots;
    for (const SparseRows* R : side.sets)
      for (int r : items)
        for (std::size_t a = R->row_begin[std::size_t(r)]; a < R->row_begin[std::size_t(r) + 1]; ++a) {
          const auto [it, added] = slots.emplace(R->entries[a].index, std::uint32_t(nodes.size()));
          if (added) nodes.push_back(node_of<dim>(R->entries[a]));
          slot.push_back(it->second);
        }
  }
};

/// A piece of the assembly's work: a pair of clusters, interpolated (far) or exact.
struct Block {
  int x, y;  // row and column clusters
  bool far;
  double cost;
  int store = -1;         // kept compressed: the kept block whose entries it makes (else written into `out`)
  bool low_rank = false;  // kept compressed: the whole kept block, recompressed to low rank where that is smaller
  bool here = true;       // distributed near block: whether this rank makes it (from whole planes; else zeros)
};

/// A block of the compressed storage: a pair of clusters, far (low rank) or near (dense).
struct Store {
  int x, y;
  bool far;
};

}  // namespace

std::vector<int> interpolation_nodes(int lo, int hi, int order) {
  std::vector<int> x;
  if (hi - lo + 1 <= order) {
    for (int t = lo; t <= hi; ++t) x.push_back(t);
    return x;
  }
  for (int k = order - 1; k >= 0; --k)
    x.push_back(int(std::lround(0.5 * (lo + hi) + 0.5 * (hi - lo) * std::cos((2 * k + 1) * M_PI / (2 * order)))));
  // Nodes that round to the same grid node are pushed apart, inside [lo, hi] (there are more nodes than
  // `order` there).
  for (int k = 1; k < order; ++k) x[std::size_t(k)] = std::max(x[std::size_t(k)], x[std::size_t(k - 1)] + 1);
  x.back() = std::min(x.back(), hi);
  for (int k = order - 2; k >= 0; --k) x[std::size_t(k)] = std::min(x[std::size_t(k)], x[std::size_t(k + 1)] - 1);
  return x;
}

template <int dim>
Eigen::MatrixXd green_block(const GreenTable<dim>& green, const SparseRows& R, const SparseRows& Q,
                            const Execution& execution, const FarField& far_field) {
  return green_blocks(green, {&R}, Q, execution, far_field).front();
}

namespace {

/// M ≈ A Bᵀ (rows × cols) by adaptive cross approximation with partial pivoting, from M's rows and
/// columns (`row(i, r)`, `col(j, c)`), stopped when the last cross is below `tolerance` times the
/// approximation's Frobenius norm, or when the rank reaches `most`.
template <class Row, class Col>
void cross_approximation(Eigen::Index rows, Eigen::Index cols, const Row& row, const Col& col, double tolerance,
                         Eigen::Index most, Eigen::MatrixXd& A, Eigen::MatrixXd& B) {
  most = std::min({most, rows, cols});
  A.resize(rows, most);
  B.resize(cols, most);
  std::vector<char> row_used(std::size_t(rows), 0), col_used(std::size_t(cols), 0);
  double norm2 = 0;
  Eigen::Index k = 0, i = 0;
  Eigen::VectorXd r, c;
  while (k < most) {
    row_used[std::size_t(i)] = 1;
    row(i, r);
    r -= B.leftCols(k) * A.row(i).head(k).transpose();
    Eigen::Index j = -1;
    double best = 0;
    for (Eigen::Index t = 0; t < cols; ++t)
      if (!col_used[std::size_t(t)] && std::abs(r(t)) > best) best = std::abs(r(t)), j = t;
    if (j < 0) {  // this row is done: the next unused one
      Eigen::Index next = 0;
      while (next < rows && row_used[std::size_t(next)]) ++next;
      if (next == rows) break;
      i = next;
      continue;
    }
    col_used[std::size_t(j)] = 1;
    col(j, c);
    c -= A.leftCols(k) * B.row(j).head(k).transpose();
    const Eigen::VectorXd v = r / r(j);
    double cross = 0;
    for (Eigen::Index l = 0; l < k; ++l) cross += A.col(l).dot(c) * B.col(l).dot(v);
    A.col(k) = c;
    B.col(k) = v;
    ++k;
    const double step2 = c.squaredNorm() * v.squaredNorm();
    norm2 += 2 * cross + step2;
    if (step2 <= tolerance * tolerance * norm2) break;
    Eigen::Index next = -1;  // the next row: the largest of this column's residual among the unused rows
    best = -1;
    for (Eigen::Index t = 0; t < rows; ++t)
      if (!row_used[std::size_t(t)] && std::abs(c(t)) > best) best = std::abs(c(t)), next = t;
    if (next < 0) break;
    i = next;
  }
  A.conservativeResize(rows, k);
  B.conservativeResize(cols, k);
}

/// The assembly of green_blocks step by step: the cluster trees, the block partition, each cluster's
/// interpolation or distinct nodes, then the blocks themselves.
template <int dim>
struct BlockAssembly {
  BlockAssembly(const GreenTable<dim>& g, const std::vector<const SparseRows*>& r, const SparseRows& q,
                const Execution& e, const FarField& f, const FarField& kept = {})
      : green(g), row_sets(r), Q(q), execution(e), far_field(f), storage(kept) {}
  const GreenTable<dim>& green;
  const std::vector<const SparseRows*>& row_sets;
  const SparseRows& Q;
  const Execution& execution;
  const FarField& far_field;
  const FarField storage;  // kept compressed: the storage's partition (eta, leaf)
  RowSide rows{row_sets}, cols{{&Q}};
  bool compress = far_field.order > 0;
  std::unique_ptr<ClusterTree<dim>> X, Y;
  std::vector<Block> blocks;
  std::vector<Store> stores;  // kept compressed: the storage's blocks
  std::vector<std::unique_ptr<Interpolation<dim>>> x_interp, y_interp;
  std::vector<std::vector<Eigen::MatrixXd>> U;  // per row cluster with far blocks: R L, one per row set
  std::vector<Eigen::MatrixXd> V;               // per column cluster with far blocks: Q L
  std::vector<std::unique_ptr<DistinctNodes<dim>>> distinct;
  std::exception_ptr failure;              // an exception (out of memory) inside a parallel loop, thrown after it
  std::unique_ptr<GreenTable<dim>> whole;  // distributed: the table's whole planes that this rank's near blocks read
  CompressedBlocks* compressed = nullptr;  // set: the blocks are kept there, not written into `out`

  void keep() {
#pragma omp critical(fictus_green_blocks_failure)
    if (!failure) failure = std::current_exception();
  }
  void trees();
  void partition();
  void cluster_data();
  void share_near(const std::vector<std::vector<std::size_t>>& groups);
  void fill(std::vector<Eigen::MatrixXd>& out);
  /// The workspace of one thread.
  struct Scratch {
    std::vector<double> column;
    Eigen::MatrixXd core, half, block;
  };
  /// work(k, scratch) for k < n on the threads; an exception or an interruption stops them all.
  template <class Work>
  void each(std::size_t n, const Work& work);
  template <class Piece>
  void fill_kept(const Piece& piece);
  void far_core(const Block& b, Eigen::MatrixXd& core) const;
  void core_times_v(const Block& b, const Eigen::MatrixXd& core, Eigen::MatrixXd& out) const;
  void far_block(const Block& b, const Eigen::MatrixXd& core, Eigen::MatrixXd& half, Eigen::MatrixXd& block,
                 std::vector<Eigen::MatrixXd>& out, bool times_v = false) const;
  void near_block(const Block& b, const std::vector<Index<dim>>& q_nodes, const std::vector<double>& q_values,
                  std::vector<double>& column, std::vector<Eigen::MatrixXd>& out) const;
  void report(FarFieldReport& r) const;
  /// Where the entry of row set s at tree positions (i, j) of block b goes.
  double& entry(const Block& b, std::size_t s, int i, int j, std::vector<Eigen::MatrixXd>& out) const {
    if (b.store < 0) return out[s](X->item[std::size_t(i)], Y->item[std::size_t(j)]);
    const Store& kept = stores[std::size_t(b.store)];
    return compressed->blocks[std::size_t(b.store)].dense[s](i - X->clusters[std::size_t(kept.x)].begin,
                                                             j - Y->clusters[std::size_t(kept.y)].begin);
  }
  std::vector<int> cluster_items(const ClusterTree<dim>& T, int c) const {
    const auto& cl = T.clusters[std::size_t(c)];
    return std::vector<int>(T.item.begin() + cl.begin, T.item.begin() + cl.end);
  }
};

/// The trees: without compression one row cluster and columns in fours (the threads' work).
template <int dim>
void BlockAssembly<dim>::trees() {
  const int n_rows = rows.n_rows(), n_cols = Q.n_rows();
  const auto n_r = std::size_t(n_rows), n_c = std::size_t(n_cols);
  std::vector<NodeBox<dim>> row_boxes(n_r), col_boxes(n_c);
  std::vector<double> row_work(n_r, 0.0), col_work(n_c, 0.0);
  for (int r = 0; r < n_rows; ++r) {
    row_boxes[std::size_t(r)] = item_box<dim>(rows, r);
    for (const SparseRows* R : row_sets)
      row_work[std::size_t(r)] += double(R->row_begin[std::size_t(r) + 1] - R->row_begin[std::size_t(r)]);
  }
  for (int c = 0; c < n_cols; ++c) {
    col_boxes[std::size_t(c)] = item_box<dim>(cols, c);
    col_work[std::size_t(c)] = double(Q.row_begin[std::size_t(c) + 1] - Q.row_begin[std::size_t(c)]);
  }
  X = std::make_unique<ClusterTree<dim>>(row_boxes, row_work, compress ? far_field.leaf : n_rows);
  Y = std::make_unique<ClusterTree<dim>>(col_boxes, col_work, compress ? far_field.leaf : 4);
}

/// The block partition: a pair far apart (max radius ≤ eta·distance) is interpolated when that is
/// cheaper than exact; otherwise split, down to pairs of leaves computed exactly. Kept compressed, the
/// storage has its own coarser partition (storage.eta, leaves of storage.leaf rows): each of its
/// admissible pairs is one far block, kept of low rank; each of its near pairs one dense block whose
/// entries the same rule makes (so most of them are interpolated, as in the dense assembly). Dearest first.
template <int dim>
void BlockAssembly<dim>::partition() {
  const auto interpolation_size = [&](const NodeBox<dim>& b) {
    double s = 1;
    for (int d = 0; d < dim && !b.empty(); ++d) s *= std::min(double(far_field.order), double(b.hi[d]) - b.lo[d] + 1);
    return s;
  };
  const auto admissible = [&](int x, int y, double eta) {
    const auto &cx = X->clusters[std::size_t(x)], &cy = Y->clusters[std::size_t(y)];
    return std::max(cx.box.radius(), cy.box.radius()) <= eta * image_distance(cx.box, cy.box, green.grid());
  };
  const auto split = [&](auto&& self, int x, int y, int store) -> void {
    const auto &cx = X->clusters[std::size_t(x)], &cy = Y->clusters[std::size_t(y)];
    const double exact = cx.work * cy.work;
    if (compress) {
      const double interpolated = interpolation_size(cx.box) * interpolation_size(cy.box);
      if (interpolated < exact && admissible(x, y, far_field.eta)) {
        blocks.push_back({x, y, true, interpolated, store});
        return;
      }
    }
    if (X->leaf(x) && Y->leaf(y)) {
      blocks.push_back({x, y, false, exact, store});
    } else if (X->leaf(x) || (!Y->leaf(y) && cy.end - cy.begin > cx.end - cx.begin)) {
      self(self, x, cy.left, store);
      self(self, x, cy.right, store);
    } else {
      self(self, cx.left, y, store);
      self(self, cx.right, y, store);
    }
  };
  const auto size = [](const auto& c) { return c.end - c.begin; };
  const auto kept_leaf = [&](const ClusterTree<dim>& T, int c) {
    return T.leaf(c) || size(T.clusters[std::size_t(c)]) <= storage.leaf;
  };
  const auto store_partition = [&](auto&& self, int x, int y) -> void {
    const auto &cx = X->clusters[std::size_t(x)], &cy = Y->clusters[std::size_t(y)];
    // Kept compressed, a far pair is worth it whenever it is admissible (its storage, not its cost, decides).
    if (admissible(x, y, storage.eta)) {
      stores.push_back({x, y, true});
      Block b{x, y, true, interpolation_size(cx.box) * interpolation_size(cy.box), int(stores.size()) - 1};
      b.low_rank = true;
      blocks.push_back(b);
    } else if (kept_leaf(*X, x) && kept_leaf(*Y, y)) {
      stores.push_back({x, y, false});
      split(split, x, y, int(stores.size()) - 1);
    } else if (kept_leaf(*X, x) || (!kept_leaf(*Y, y) && size(cy) > size(cx))) {
      self(self, x, cy.left);
      self(self, x, cy.right);
    } else {
      self(self, cx.left, y);
      self(self, cx.right, y);
    }
  };
  if (compressed)
    store_partition(store_partition, 0, 0);
  else
    split(split, 0, 0, -1);
  std::sort(blocks.begin(), blocks.end(), [](const Block& a, const Block& b) { return a.cost > b.cost; });
}

/// Per cluster: the interpolation and U = R L (rows) or V = Q L (columns) for the far blocks; the
/// distinct nodes for the near ones.
template <int dim>
void BlockAssembly<dim>::cluster_data() {
  const std::size_t nx = X->clusters.size(), ny = Y->clusters.size();
  std::vector<char> x_far(nx, 0), y_far(ny, 0), x_near(nx, 0);
  for (const Block& b : blocks) {
    if (b.far)
      x_far[std::size_t(b.x)] = y_far[std::size_t(b.y)] = 1;
    else
      x_near[std::size_t(b.x)] = 1;
  }
  x_interp.resize(nx), y_interp.resize(ny), U.resize(nx), V.resize(ny), distinct.resize(nx);
  const auto interpolate = [&](const RowSide& side, const std::vector<int>& items, const Interpolation<dim>& L,
                               std::vector<Eigen::MatrixXd>& mats) {
    mats.clear();
    for (const SparseRows* R : side.sets) {
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> rowmajor =
          Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>::Zero(Eigen::Index(items.size()),
                                                                                       L.size());
      for (std::size_t i = 0; i < items.size(); ++i)
        for (std::size_t a = R->row_begin[std::size_t(items[i])]; a < R->row_begin[std::size_t(items[i]) + 1]; ++a)
          L.add(node_of<dim>(R->entries[a]), R->entries[a].value, rowmajor.row(Eigen::Index(i)).data());
      mats.push_back(rowmajor);
    }
  };
#pragma omp parallel for schedule(dynamic, 1) num_threads(execution.threads())
  for (int c = 0; c < int(nx) + int(ny); ++c) try {
      if (c < int(nx)) {
        if (x_far[std::size_t(c)]) {
          x_interp[std::size_t(c)] =
              std::make_unique<Interpolation<dim>>(X->clusters[std::size_t(c)].box, far_field.order);
          interpolate(rows, cluster_items(*X, c), *x_interp[std::size_t(c)], U[std::size_t(c)]);
        }
        if (x_near[std::size_t(c)])
          distinct[std::size_t(c)] = std::make_unique<DistinctNodes<dim>>(rows, cluster_items(*X, c));
      } else {
        const int y = c - int(nx);
        if (!y_far[std::size_t(y)]) continue;
        y_interp[std::size_t(y)] =
            std::make_unique<Interpolation<dim>>(Y->clusters[std::size_t(y)].box, far_field.order);
        std::vector<Eigen::MatrixXd> mats;
        interpolate(cols, cluster_items(*Y, y), *y_interp[std::size_t(y)], mats);
        V[std::size_t(y)] = std::move(mats.front());
      }
    } catch (...) {
      keep();
    }
  if (failure) std::rethrow_exception(failure);
  execution.throw_if_interrupted();
}

/// A far block's core: G between the interpolation nodes of its clusters (with a partial table, this
/// rank's part of it).
template <int dim>
void BlockAssembly<dim>::far_core(const Block& b, Eigen::MatrixXd& core) const {
  const Interpolation<dim>&Lx = *x_interp[std::size_t(b.x)], &Ly = *y_interp[std::size_t(b.y)];
  core.resize(Lx.size(), Ly.size());
  green.G(Lx.nodes, Ly.nodes, core.data(), std::size_t(Lx.size()));
}

/// out = core V_yᵀ for a rank's part of a far block's core (a partial table): its blocks between the
/// interpolation nodes of one plane along the slowest axis (x's) and one (y's) are zero where the rank
/// holds neither plane of the pair, and their products are skipped, so each rank makes about its share.
template <int dim>
void BlockAssembly<dim>::core_times_v(const Block& b, const Eigen::MatrixXd& core, Eigen::MatrixXd& out) const {
  const Interpolation<dim>&Lx = *x_interp[std::size_t(b.x)], &Ly = *y_interp[std::size_t(b.y)];
  const Eigen::MatrixXd& Vy = V[std::size_t(b.y)];  // q × |L_y|
  const auto nx = Eigen::Index(Lx.nodes[dim - 1].size()), ny = Eigen::Index(Ly.nodes[dim - 1].size());
  out.setZero(core.rows(), Vy.rows());
  if (nx == 0 || ny == 0) return;                               // a cluster without nodes
  const Eigen::Index rx = Lx.size() / nx, ry = Ly.size() / ny;  // the nodes of one plane
  for (Eigen::Index j = 0; j < ny; ++j)
    for (Eigen::Index i = 0; i < nx; ++i) {
      const auto part = core.block(i * rx, j * ry, rx, ry);
      if ((part.array() == 0.0).all()) continue;
      out.middleRows(i * rx, rx).noalias() += part * Vy.middleCols(j * ry, ry).transpose();
    }
}

/// A far block from its core: U_x core V_yᵀ (`times_v`: `core` is core V_yᵀ already).
template <int dim>
void BlockAssembly<dim>::far_block(const Block& b, const Eigen::MatrixXd& core, Eigen::MatrixXd& half,
                                   Eigen::MatrixXd& block, std::vector<Eigen::MatrixXd>& out, bool times_v) const {
  const auto &cx = X->clusters[std::size_t(b.x)], &cy = Y->clusters[std::size_t(b.y)];
  CompressedBlocks::Block* kept = b.low_rank ? &compressed->blocks[std::size_t(b.store)] : nullptr;
  if (!times_v) half.noalias() = core * V[std::size_t(b.y)].transpose();
  const Eigen::MatrixXd& core_V = times_v ? core : half;  // |L_x| × q
  if (kept) {  // low rank where that is smaller than the dense block, from the block's rows and columns
    const Eigen::Index p = cx.end - cx.begin, q = cy.end - cy.begin, most = p * q / (p + q);
    std::vector<Eigen::MatrixXd> left(row_sets.size()), right(row_sets.size());
    bool small = true;
    for (std::size_t s = 0; s < row_sets.size() && small; ++s) {
      const Eigen::MatrixXd& Ux = U[std::size_t(b.x)][s];
      cross_approximation(
          p, q, [&](Eigen::Index i, Eigen::VectorXd& r) { r = core_V.transpose() * Ux.row(i).transpose(); },
          [&](Eigen::Index j, Eigen::VectorXd& c) { c = Ux * core_V.col(j); }, far_field_recompression, most, left[s],
          right[s]);
      small = left[s].cols() < most;
    }
    if (small) {
      kept->left = std::move(left);
      kept->right = std::move(right);
      return;
    }
  }
  for (std::size_t s = 0; s < row_sets.size(); ++s) {
    block.noalias() = U[std::size_t(b.x)][s] * core_V;
    if (kept) {
      kept->dense.push_back(block);
      continue;
    }
    for (int j = cy.begin; j < cy.end; ++j)
      for (int i = cx.begin; i < cx.end; ++i) entry(b, s, i, j, out) = block(i - cx.begin, j - cy.begin);
  }
}

/// A near block, exactly: for each column, G between the row cluster's distinct nodes and the column's
/// entries, then each row's weighted sum.
template <int dim>
void BlockAssembly<dim>::near_block(const Block& b, const std::vector<Index<dim>>& q_nodes,
                                    const std::vector<double>& q_values, std::vector<double>& column,
                                    std::vector<Eigen::MatrixXd>& out) const {
  const auto &cx = X->clusters[std::size_t(b.x)], &cy = Y->clusters[std::size_t(b.y)];
  if (!b.here) {  // another rank's: its entries are that rank's, and this rank's part of them is zero
    for (std::size_t s = 0; s < row_sets.size(); ++s)
      for (int j = cy.begin; j < cy.end; ++j)
        for (int i = cx.begin; i < cx.end; ++i) entry(b, s, i, j, out) = 0.0;
    return;
  }
  const GreenTable<dim>& table = whole ? *whole : green;
  const DistinctNodes<dim>& nodes = *distinct[std::size_t(b.x)];
  column.resize(nodes.nodes.size());
  for (int j = cy.begin; j < cy.end; ++j) {
    const int col = Y->item[std::size_t(j)];
    const std::size_t first = Q.row_begin[std::size_t(col)];
    table.G(nodes.nodes.data(), nodes.nodes.size(), q_nodes.data() + first, q_values.data() + first,
            Q.row_begin[std::size_t(col) + 1] - first, column.data());
    std::size_t slot = 0;
    for (std::size_t s = 0; s < row_sets.size(); ++s) {
      const SparseRows& R = *row_sets[s];
      for (int i = cx.begin; i < cx.end; ++i) {
        const int row = X->item[std::size_t(i)];
        double sum = 0.0;
        for (std::size_t a = R.row_begin[std::size_t(row)]; a < R.row_begin[std::size_t(row) + 1]; ++a, ++slot)
          sum += R.entries[a].value * column[nodes.slot[slot]];
        entry(b, s, i, j, out) = sum;
      }
    }
  }
}

/// Distributed, with a far field (the near pairs are near each other): each near block is made by one
/// rank, from whole planes of the table fetched for it, so the ranks share the near blocks' visits rather
/// than each visiting every pair for its planes' part. `groups` are the blocks made between two sums
/// over the ranks (every block of a dense assembly; a batch of the kept ones): each group's near blocks,
/// sorted by where their planes lie (the sum of the clusters' centres along the slowest axis), are cut
/// into one run of equal work per rank, so that a rank's blocks read few planes and every rank has its
/// share of each group. The key is the plane of a_z + b_z (folded into the table), which the pairs of
/// each run share: a box-centred γ's upper and lower halves read the same planes. Only where that pays
/// on every rank: where the visits a rank is spared are at least near_visits_per_fetched times the
/// doubles it fetches (chosen between two measurements on the sphere: 4.8 lost time, 47 gained), and
/// the planes fetched are at most twice those the rank holds. Far blocks stay every rank's (their cores
/// are linear in the planes held). Collective. Serially (or without a far field) every block is made
/// here from the table itself.
template <int dim>
void BlockAssembly<dim>::share_near(const std::vector<std::vector<std::size_t>>& groups) {
  const Distribution& distribution = execution.distribution();
  if (!green.partial() || !compress) return;
  constexpr double near_visits_per_fetched = 16;
  const int P = distribution.size(), z = dim - 1, n = green.grid().n(z);
  const bool periodic = green.grid().periodic();
  const auto center = [&](std::size_t k) {  // the plane of a_z + b_z at the clusters' centres
    const double sum =
        X->clusters[std::size_t(blocks[k].x)].box.center(z) + Y->clusters[std::size_t(blocks[k].y)].box.center(z);
    return periodic || sum <= n ? sum : 2.0 * n - sum;
  };
  std::vector<char> planes(std::size_t(green.planes()), 0);
  std::vector<std::size_t> near;
  double visits = 0;  // of every near block: the pairs of entries the sums visit
  for (const std::vector<std::size_t>& group : groups) {
    near.clear();
    double total = 0;
    for (std::size_t k : group)
      if (!blocks[k].far) near.push_back(k), total += blocks[k].cost;
    visits += total;
    std::stable_sort(near.begin(), near.end(), [&](std::size_t a, std::size_t b) { return center(a) < center(b); });
    double before = 0;
    for (std::size_t k : near) {
      Block& b = blocks[k];
      const int maker = total > 0 ? std::min(P - 1, int(P * (before + 0.5 * b.cost) / total)) : 0;
      before += b.cost;
      b.here = maker == distribution.rank();
      if (!b.here) continue;
      const NodeBox<dim>&bx = X->clusters[std::size_t(b.x)].box, &by = Y->clusters[std::size_t(b.y)].box;
      if (!bx.empty() && !by.empty()) green.mark_planes(bx.lo[z], bx.hi[z], by.lo[z], by.hi[z], planes);
    }
  }
  const double fetched = double(std::count(planes.begin(), planes.end(), 1)) * double(green.plane_size());
  const double held = double(green.memory_bytes() / sizeof(double));  // this rank's planes and the zero plane
  if (!distribution.all(visits * (P - 1) / P >= near_visits_per_fetched * fetched && fetched <= 2 * held)) {
    for (Block& b : blocks) b.here = true;
    return;
  }
  whole = std::make_unique<GreenTable<dim>>(green, planes, distribution);
}

constexpr std::size_t summed_chunk = std::size_t(1) << 22;  // doubles (32 MiB) in one sum over the ranks

template <int dim>
template <class Work>
void BlockAssembly<dim>::each(std::size_t n, const Work& work) {
  std::atomic<bool> stop = false;  // an interruption seen by thread 0 (the caller's) ends every thread's work
#pragma omp parallel num_threads(execution.threads())
  {
    Scratch scratch;
#pragma omp for schedule(dynamic, 1)
    for (std::size_t k = 0; k < n; ++k) try {
        if (omp_get_thread_num() == 0 && execution.interrupt_requested()) stop = true;
        if (stop) continue;
        work(k, scratch);
      } catch (...) {
        keep();
        stop = true;
      }
  }
  // Distributed, every rank calls this in step and a collective step follows: a failure or an
  // interruption on one rank is every rank's (serially: rethrown, or Interrupted).
  execution.distribution().throw_first_failure(failure, stop);
}

/// Every block, dearest first, on the threads. The entries are linear in the table's values: with a
/// partial table (a distributed run) each rank makes its planes' part of every far entry, and each near
/// block is one rank's where share_near finds that pays (the others' parts are zeros), else every rank's
/// part as the far ones. The dense blocks' parts are added by ExplicitSchur; the kept ones by fill_kept.
template <int dim>
void BlockAssembly<dim>::fill(std::vector<Eigen::MatrixXd>& out) {
  std::vector<Index<dim>> q_nodes;  // Q's entries' nodes and values, for the near blocks' sums
  std::vector<double> q_values;
  q_nodes.reserve(Q.entries.size());
  q_values.reserve(Q.entries.size());
  for (const SparseRows::Entry& e : Q.entries) q_nodes.push_back(node_of<dim>(e)), q_values.push_back(e.value);
  const auto piece = [&](const Block& b, Scratch& s) {
    if (!b.far) return near_block(b, q_nodes, q_values, s.column, out);
    far_core(b, s.core);
    far_block(b, s.core, s.half, s.block, out);
  };
  if (!compressed) {
    std::vector<std::size_t> all(blocks.size());
    std::iota(all.begin(), all.end(), std::size_t(0));
    share_near({all});
    return each(blocks.size(), [&](std::size_t k, Scratch& s) { piece(blocks[k], s); });
  }
  fill_kept(piece);
}

/// The kept blocks, in batches of them whose numbers (near: the entries; far: the core, G between the
/// interpolation nodes, or that times V_yᵀ) take about summed_chunk doubles. A batch's near entries and
/// far cores are made (with a partial table: this rank's part, as in fill), and each block is kept by
/// one rank, chosen for equal work: the ranks' parts are summed onto it alone, and it compresses the
/// block if it is far (cross approximation is not linear in the entries: it takes the sum).
/// Serially every block is kept and comes out as in one pass.
template <int dim>
template <class Piece>
void BlockAssembly<dim>::fill_kept(const Piece& piece) {
  const Distribution& distribution = execution.distribution();
  const std::size_t n = stores.size();
  std::vector<std::vector<std::size_t>> pieces(n);  // of each kept block, dearest first
  for (std::size_t k = 0; k < blocks.size(); ++k) pieces[std::size_t(blocks[k].store)].push_back(k);
  const auto size = [](const auto& T, int c) {
    return std::size_t(T.clusters[std::size_t(c)].end - T.clusters[std::size_t(c)].begin);
  };
  const auto rows = [&](std::size_t k) { return size(*X, stores[k].x); };
  const auto cols = [&](std::size_t k) { return size(*Y, stores[k].y); };
  const auto core_size = [&](std::size_t k) {
    return std::size_t(x_interp[std::size_t(stores[k].x)]->size()) *
           std::size_t(y_interp[std::size_t(stores[k].y)]->size());
  };
  // The owners: the blocks by their work (near: the entries; far: the cross approximation's rows and
  // columns through the core), dearest first, each to the rank with the least so far.
  std::vector<double> work(n);
  for (std::size_t k = 0; k < n; ++k)
    work[k] = stores[k].far ? double(rows(k) + cols(k)) * double(x_interp[std::size_t(stores[k].x)]->size() +
                                                                 y_interp[std::size_t(stores[k].y)]->size())
                            : double(rows(k) * cols(k));
  const std::vector<int> owner = share_out(work, distribution.size());
  const std::size_t n_sets = row_sets.size();
  // Distributed, what the ranks sum of a far block is its core C (|L_x| × |L_y|), or C V_yᵀ (|L_x| × q,
  // what the owner's compression starts from) where that is smaller: the cores are most of the numbers
  // summed, and each rank's part of C V_yᵀ is its part of C times V_yᵀ.
  std::vector<char> times_v(n, 0);
  if (distribution.distributed())
    for (std::size_t k = 0; k < n; ++k)
      times_v[k] = stores[k].far && cols(k) < std::size_t(y_interp[std::size_t(stores[k].y)]->size());
  const auto summed_size = [&](std::size_t k) {
    if (!stores[k].far) return n_sets * rows(k) * cols(k);
    return times_v[k] ? std::size_t(x_interp[std::size_t(stores[k].x)]->size()) * cols(k) : core_size(k);
  };
  // The batches (kept blocks first ≤ k < last) and the pieces each makes; the near ones shared out.
  std::vector<std::pair<std::size_t, std::size_t>> batches;
  std::vector<std::vector<std::size_t>> made;
  for (std::size_t first = 0, last = 0; first < n; first = last) {
    std::size_t numbers = 0;
    for (last = first; last < n && (last == first || numbers <= summed_chunk); ++last) numbers += summed_size(last);
    batches.emplace_back(first, last);
    made.emplace_back();
    for (std::size_t k = first; k < last; ++k)
      made.back().insert(made.back().end(), pieces[k].begin(), pieces[k].end());
  }
  share_near(made);
  std::vector<Eigen::MatrixXd> cores;
  std::vector<Eigen::MatrixXd*> summed;
  std::vector<int> summed_owner;  // only a block's owner uses its sums
  std::vector<std::size_t> kept_far;
  for (std::size_t batch = 0; batch < batches.size(); ++batch) {
    const auto [first, last] = batches[batch];
    cores.assign(last - first, Eigen::MatrixXd());
    summed.clear(), summed_owner.clear(), kept_far.clear();
    for (std::size_t k = first; k < last; ++k) {
      CompressedBlocks::Block& kept = compressed->blocks[k];
      if (stores[k].far) {
        summed.push_back(&cores[k - first]);
        if (owner[k] == distribution.rank()) kept_far.push_back(k);
      } else {
        kept.dense.assign(n_sets, Eigen::MatrixXd(Eigen::Index(rows(k)), Eigen::Index(cols(k))));
        for (Eigen::MatrixXd& d : kept.dense) summed.push_back(&d);
      }
      summed_owner.resize(summed.size(), owner[k]);
    }
    each(made[batch].size(), [&](std::size_t a, Scratch& s) {
      const Block& b = blocks[made[batch][a]];
      const std::size_t k = std::size_t(b.store);
      if (b.low_rank && times_v[k]) {
        far_core(b, s.core);
        core_times_v(b, s.core, cores[k - first]);
      } else if (b.low_rank) {
        far_core(b, cores[k - first]);
      } else
        piece(b, s);
    });
    sum_onto_owners(distribution, summed, summed_owner);
    each(kept_far.size(), [&](std::size_t a, Scratch& s) {
      const std::size_t k = kept_far[a];
      std::vector<Eigen::MatrixXd> unused;
      far_block(blocks[pieces[k].front()], cores[k - first], s.half, s.block, unused, times_v[k]);
    });
    for (std::size_t k = first; k < last; ++k)
      if (owner[k] != distribution.rank()) {
        compressed->blocks[k].held = false;
        compressed->blocks[k].dense.clear();
        compressed->blocks[k].dense.shrink_to_fit();
      }
  }
}

template <int dim>
void BlockAssembly<dim>::report(FarFieldReport& r) const {
  r = {};
  for (const Block& b : blocks) {
    const double pairs = double(X->clusters[std::size_t(b.x)].end - X->clusters[std::size_t(b.x)].begin) *
                         double(Y->clusters[std::size_t(b.y)].end - Y->clusters[std::size_t(b.y)].begin);
    (b.far ? r.far_pairs : r.near_pairs) += pairs;
    (b.far ? r.far_blocks : r.near_blocks) += 1;
    if (!b.far && b.here) r.near_pairs_here += pairs;
  }
  if (whole) r.whole_planes_bytes = double(whole->memory_bytes());
}

}  // namespace

template <int dim>
std::vector<Eigen::MatrixXd> green_blocks(const GreenTable<dim>& green, const std::vector<const SparseRows*>& row_sets,
                                          const SparseRows& Q, const Execution& execution, const FarField& far_field,
                                          FarFieldReport* report) {
  for (const SparseRows* R : row_sets)
    if (R->n_rows() != row_sets.front()->n_rows())
      throw std::invalid_argument("green_blocks: the row sets differ in their number of rows");
  const int n_cols = Q.n_rows();
  std::vector<Eigen::MatrixXd> out;
  for (const SparseRows* R : row_sets) out.emplace_back(R->n_rows(), n_cols);
  if (far_field.order < 0 || (far_field.order > 0 && !(far_field.eta > 0 && far_field.leaf >= 1)))
    throw std::invalid_argument("green_blocks: a far field needs order >= 0, eta > 0 and leaves of >= 1 row");
  if (row_sets.front()->n_rows() == 0 || n_cols == 0) return out;
  BlockAssembly<dim> assembly(green, row_sets, Q, execution, far_field);
  assembly.trees();
  assembly.partition();
  assembly.cluster_data();
  assembly.fill(out);
  if (report) assembly.report(*report);
  return out;
}

template <int dim>
CompressedBlocks compressed_green_blocks(const GreenTable<dim>& green, const std::vector<const SparseRows*>& row_sets,
                                         const SparseRows& Q, const Execution& execution, const FarField& far_field,
                                         const FarField& storage, FarFieldReport* report) {
  for (const SparseRows* R : row_sets)
    if (R->n_rows() != row_sets.front()->n_rows())
      throw std::invalid_argument("compressed_green_blocks: the row sets differ in their number of rows");
  if (far_field.order <= 0 || !(far_field.eta > 0 && far_field.leaf >= 1) || !(storage.eta > 0 && storage.leaf >= 1))
    throw std::invalid_argument(
        "compressed_green_blocks: needs a far field (order > 0, eta > 0, leaves of >= 1 row) and a storage partition "
        "(eta > 0, leaves of >= 1 row)");
  CompressedBlocks c;
  c.n_rows = row_sets.front()->n_rows();
  c.n_cols = Q.n_rows();
  c.n_sets = int(row_sets.size());
  if (c.n_rows == 0 || c.n_cols == 0) return c;
  BlockAssembly<dim> assembly(green, row_sets, Q, execution, far_field, storage);
  assembly.compressed = &c;
  assembly.trees();
  assembly.partition();
  assembly.cluster_data();
  c.blocks.resize(assembly.stores.size());
  for (std::size_t k = 0; k < assembly.stores.size(); ++k)
    c.blocks[k].x = assembly.stores[k].x, c.blocks[k].y = assembly.stores[k].y;
  if (green.partial() != execution.distribution().distributed())
    throw std::logic_error("compressed_green_blocks: a partial Green's table needs the distribution it was made with");
  if (execution.distribution().distributed()) c.distribution = execution.shared_distribution();
  std::vector<Eigen::MatrixXd> unused;
  assembly.fill(unused);
  if (report) assembly.report(*report);
  c.row_item = assembly.X->item;
  c.col_item = assembly.Y->item;
  for (const auto& cl : assembly.X->clusters) c.row_clusters.push_back({cl.begin, cl.end});
  for (const auto& cl : assembly.Y->clusters) c.col_clusters.push_back({cl.begin, cl.end});
  c.row_parent.assign(assembly.X->clusters.size(), -1);
  for (std::size_t k = 0; k < assembly.X->clusters.size(); ++k)
    if (!assembly.X->leaf(int(k)))
      c.row_parent[std::size_t(assembly.X->clusters[k].left)] =
          c.row_parent[std::size_t(assembly.X->clusters[k].right)] = int(k);
  return c;
}

std::vector<int> share_out(const std::vector<double>& work, int ranks) {
  std::vector<int> owner(work.size(), 0);
  if (ranks <= 1) return owner;
  std::vector<double> load(std::size_t(ranks), 0.0);
  std::vector<std::size_t> order(work.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return work[a] > work[b]; });
  for (std::size_t k : order) {
    const auto least = std::size_t(std::min_element(load.begin(), load.end()) - load.begin());
    owner[k] = int(least);
    load[least] += work[k];
  }
  return owner;
}

void sum_onto_owners(const Distribution& distribution, const std::vector<Eigen::MatrixXd*>& mats,
                     const std::vector<int>& owners) {
  if (!distribution.distributed()) return;
  if (owners.size() != mats.size()) throw std::logic_error("sum_onto_owners: one owner for each matrix");
  std::vector<double> buffer;
  for (std::size_t first = 0, last = 0; first < mats.size(); first = last) {
    std::size_t n = 0;
    for (last = first; last < mats.size() && (last == first || n + std::size_t(mats[last]->size()) <= summed_chunk);)
      n += std::size_t(mats[last++]->size());
    for (int owner = 0; owner < distribution.size(); ++owner) {  // one message per owner: the same turns everywhere
      buffer.clear();
      for (std::size_t k = first; k < last; ++k)
        if (owners[k] == owner) buffer.insert(buffer.end(), mats[k]->data(), mats[k]->data() + mats[k]->size());
      if (buffer.empty()) continue;
      distribution.sum_onto(buffer.data(), buffer.size(), owner);
      if (owner != distribution.rank()) continue;
      const double* at = buffer.data();
      for (std::size_t k = first; k < last; ++k)
        if (owners[k] == owner) {
          std::copy_n(at, mats[k]->size(), mats[k]->data());
          at += mats[k]->size();
        }
    }
  }
}

template CompressedBlocks compressed_green_blocks(const GreenTable<2>&, const std::vector<const SparseRows*>&,
                                                  const SparseRows&, const Execution&, const FarField&, const FarField&,
                                                  FarFieldReport*);
template CompressedBlocks compressed_green_blocks(const GreenTable<3>&, const std::vector<const SparseRows*>&,
                                                  const SparseRows&, const Execution&, const FarField&, const FarField&,
                                                  FarFieldReport*);

template Eigen::MatrixXd green_block(const GreenTable<2>&, const SparseRows&, const SparseRows&, const Execution&,
                                     const FarField&);
template Eigen::MatrixXd green_block(const GreenTable<3>&, const SparseRows&, const SparseRows&, const Execution&,
                                     const FarField&);
template std::vector<Eigen::MatrixXd> green_blocks(const GreenTable<2>&, const std::vector<const SparseRows*>&,
                                                   const SparseRows&, const Execution&, const FarField&,
                                                   FarFieldReport*);
template std::vector<Eigen::MatrixXd> green_blocks(const GreenTable<3>&, const std::vector<const SparseRows*>&,
                                                   const SparseRows&, const Execution&, const FarField&,
                                                   FarFieldReport*);

}  // namespace fictus
