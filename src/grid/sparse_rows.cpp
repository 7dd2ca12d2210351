#include "fictus/grid/sparse_rows.hpp"

#include <algorithm>
#include <stdexcept>

namespace fictus {

void SparseRows::multiply(const GridVector& u, std::vector<double>& out) const {
  out.assign(n_rows(), 0.0);
  for (int r = 0; r < n_rows(); ++r)
    for (std::size_t k = row_begin[r]; k < row_begin[r + 1]; ++k) out[r] += entries[k].value * u[entries[k].index];
}

void SparseRows::add_transposed(const std::vector<double>& lambda, GridVector& u) const {
  for (int r = 0; r < n_rows(); ++r)
    for (std::size_t k = row_begin[r]; k < row_begin[r + 1]; ++k) u[entries[k].index] += entries[k].value * lambda[r];
}

void SparseRows::multiply(const GridVector& u, std::size_t offset, std::vector<double>& out) const {
  out.assign(n_rows(), 0.0);
  for (int r = 0; r < n_rows(); ++r)
    for (std::size_t k = row_begin[r]; k < row_begin[r + 1]; ++k) {
      const std::size_t local = entries[k].index - offset;  // wraps below the slab: then ≥ u.size()
      if (local < u.size()) out[r] += entries[k].value * u[local];
    }
}

void SparseRows::add_transposed(const std::vector<double>& lambda, GridVector& u, std::size_t offset) const {
  for (int r = 0; r < n_rows(); ++r)
    for (std::size_t k = row_begin[r]; k < row_begin[r + 1]; ++k) {
      const std::size_t local = entries[k].index - offset;
      if (local < u.size()) u[local] += entries[k].value * lambda[r];
    }
}

std::vector<double> SparseRows::row_sums() const {
  std::vector<double> sums(std::size_t(n_rows()), 0.0);
  for (int r = 0; r < n_rows(); ++r)
    for (std::size_t k = row_begin[r]; k < row_begin[r + 1]; ++k) sums[std::size_t(r)] += entries[k].value;
  return sums;
}

SparseRows select_rows(const SparseRows& rows, const std::vector<int>& which) {
  SparseRows out;
  for (int r : which) {
    out.entries.insert(out.entries.end(), rows.entries.begin() + std::ptrdiff_t(rows.row_begin[std::size_t(r)]),
                       rows.entries.begin() + std::ptrdiff_t(rows.row_begin[std::size_t(r) + 1]));
    out.row_begin.push_back(out.entries.size());
  }
  return out;
}

SparseRows merge_rows(const SparseRows& kept, const std::vector<int>& from, const SparseRows& made) {
  SparseRows out;
  std::size_t next = 0;  // made's next row
  for (int r : from) {
    const SparseRows& source = r >= 0 ? kept : made;
    const std::size_t row = r >= 0 ? std::size_t(r) : next++;
    if (row + 1 >= source.row_begin.size()) throw std::logic_error("merge_rows: too few rows");
    out.entries.insert(out.entries.end(), source.entries.begin() + std::ptrdiff_t(source.row_begin[row]),
                       source.entries.begin() + std::ptrdiff_t(source.row_begin[row + 1]));
    out.row_begin.push_back(out.entries.size());
  }
  if (next + 1 != made.row_begin.size()) throw std::logic_error("merge_rows: rows of `made` left over");
  return out;
}

bool same_row(const SparseRows& a, const SparseRows& b, int r) {
  const std::size_t n = a.row_begin[std::size_t(r) + 1] - a.row_begin[std::size_t(r)];
  if (n != b.row_begin[std::size_t(r) + 1] - b.row_begin[std::size_t(r)]) return false;
  for (std::size_t k = 0; k < n; ++k) {
    const SparseRows::Entry &x = a.entries[a.row_begin[std::size_t(r)] + k],
                            &y = b.entries[b.row_begin[std::size_t(r)] + k];
    if (x.index != y.index || x.value != y.value) return false;
  }
  return true;
}

SparseRows add_rows(const SparseRows& a, const SparseRows& b) {
  SparseRows out;
  for (int r = 0; r < a.n_rows(); ++r) {
    std::vector<SparseRows::Entry> row(a.entries.begin() + std::ptrdiff_t(a.row_begin[r]),
                                       a.entries.begin() + std::ptrdiff_t(a.row_begin[r + 1]));
    for (std::size_t k = b.row_begin[r]; k < b.row_begin[r + 1]; ++k) {
      const auto& e = b.entries[k];
      auto same = std::find_if(row.begin(), row.end(), [&](const SparseRows::Entry& x) { return x.index == e.index; });
      if (same != row.end())
        same->value += e.value;
      else
        row.push_back(e);
    }
    out.entries.insert(out.entries.end(), row.begin(), row.end());
    out.row_begin.push_back(out.entries.size());
  }
  return out;
}

}  // namespace fictus
