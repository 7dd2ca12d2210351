#pragma once
// Sparse rows over the unknowns of a grid (any dimension): the trace matrices B_γ, C_γ, B_Γ and the
// kink correction's rows are sets of them, applied to grid vectors and transposed onto them.
#include <cstddef>
#include <vector>

#include "fictus/grid/grid.hpp"

namespace fictus {

struct SparseRows {
  struct Entry {
    std::size_t index;  // Grid::index of the node
    int i, j, k;        // the node (k = 0 in 2-D)
    double value;
  };
  std::vector<std::size_t> row_begin{0};  // entries of row r: [row_begin[r], row_begin[r+1])
  std::vector<Entry> entries;

  int n_rows() const { return int(row_begin.size()) - 1; }
  /// out = R u  (out resized to n_rows)
  void multiply(const GridVector& u, std::vector<double>& out) const;
  /// u += Rᵀ λ
  void add_transposed(const std::vector<double>& lambda, GridVector& u) const;
  /// The same on a slab of the grid's vector (a rank's layers, Slab): u holds the whole vector's entries
  /// from `offset` on, and only the rows' nodes among them count. multiply gives each row's partial sum
  /// there (a distributed run adds them over its ranks); add_transposed writes only there. (The whole
  /// vector's forms above check no index: there u must hold every node of the rows.)
  void multiply(const GridVector& u, std::size_t offset, std::vector<double>& out) const;
  void add_transposed(const std::vector<double>& lambda, GridVector& u, std::size_t offset) const;
  /// R·1: the sum of each row's entries.
  std::vector<double> row_sums() const;
};

/// The rows `which` of `rows`, in that order.
SparseRows select_rows(const SparseRows& rows, const std::vector<int>& which);

/// Rows taken from `kept` where from[r] >= 0 (its row from[r]) and from `made` in order elsewhere (made has
/// one row for each r with from[r] < 0).
SparseRows merge_rows(const SparseRows& kept, const std::vector<int>& from, const SparseRows& made);

/// Whether row r of a and row r of b hold the same entries (nodes and values, bit for bit, in order).
bool same_row(const SparseRows& a, const SparseRows& b, int r);

/// Row-wise sum a + b of two sets of rows with the same number of rows (entries of a node merged).
SparseRows add_rows(const SparseRows& a, const SparseRows& b);

}  // namespace fictus
