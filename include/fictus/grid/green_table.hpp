#pragma once
// Discrete Green's function of A = K + c·M (docs/math.md), any dimension.
// Dirichlet box: G between nodes a and b is the sum over the 2^dim reflections
//   G[a, b] = Σ_{σ ∈ {−,+}^dim} (−1)^{#+} T(a ∓ b),
//   T(s) = 1/Π_d n_d · Σ_{p, 1 ≤ p_d ≤ n_d−1} Π_d cos(p_d π s_d / n_d) / λ(p),
//   even and 2n-periodic in each s_d; the table holds Π_d [0, n_d]: ONE DCT-I (REDFT00) of size Π(n_d + 1).
//   In 2-D: G[(i,j),(k,l)] = T(i−k, j−l) − T(i+k, j−l) − T(i−k, j+l) + T(i+k, j+l).
// Periodic box (n_d even):
//   G[a, b] = T(a − b),  T(s) = 1/Π n_d · Σ_{0 ≤ p_d < n_d} Π_d cos(2π p_d s_d / n_d) / λ(p),
//   even and n-periodic; the table holds Π_d [0, n_d/2], one REDFT00 of size Π(n_d/2 + 1).
//   With c = 0 the zero mode is dropped: G is the pseudo-inverse A⁺.
// λ(p) comes from Q1Symbol. Built once per grid, boundary and c; lookups are const and thread-safe.
// Distributed (the execution's Distribution), a rank holds only its planes of the table along the
// slowest axis (FFTW-MPI's blocks, made by one distributed DCT-I), and every lookup elsewhere reads 0:
// each rank's sums over lookups (the Schur entries) are its part, and the ranks' parts add up to the
// serial sums.
#include <array>
#include <cstddef>
#include <vector>

#include <cstdint>

#include "fictus/grid/execution.hpp"
#include "fictus/grid/grid.hpp"

namespace fictus {

class Distribution;

template <int dim>
class GreenTable {
 public:
  using Index = typename Grid<dim>::Index;
  GreenTable(const Grid<dim>& grid, double c, const Execution& execution = Execution{});
  /// Whole planes of a table on planes: this rank's copy of `table`'s planes along the slowest axis that
  /// `wanted` marks (wanted[z] != 0), their whole values fetched from the ranks that hold them (a
  /// distributed table), or copied (a serial one). The node-weighted sums (the near blocks') on it give
  /// whole entries where the nodes' pairs read only wanted planes (mark_planes), and throw
  /// std::logic_error where a pair reads another. Collective where `table` is partial.
  GreenTable(const GreenTable& table, const std::vector<char>& wanted, const Distribution& distribution);

  const Grid<dim>& grid() const { return grid_; }
  double c() const { return c_; }
  /// T(s) for any integer offsets s (folded into the table).
  double T(const Index& s) const {
    Index folded;
    for (int d = 0; d < dim; ++d) folded[d] = fold(s[d], period_[d]);
    return at(folded);
  }
  /// (A⁻¹)_{a,b} between nodes carrying unknowns (A⁺ for a singular periodic A), 0 ≤ a_d, b_d ≤ n_d
  /// (so the offsets need one reflection, no division).
  double G(const Index& a, const Index& b) const {
    Index s;
    if (periodic_) {
      for (int d = 0; d < dim; ++d) s[d] = near_fold(a[d] - b[d], period_[d]);
      return at(s);
    }
    double sum = 0.0;
    for (int pattern = 0; pattern < (1 << dim); ++pattern) {
      bool minus = false;
      for (int d = 0; d < dim; ++d) {
        const bool plus = (pattern >> d) & 1;
        s[d] = near_fold(plus ? a[d] + b[d] : a[d] - b[d], period_[d]);
        minus ^= plus;
      }
      sum += minus ? -at(s) : at(s);
    }
    return sum;
  }
  /// G between every node of the tensor grid a[0] × … × a[dim−1] (flat index p, first axis fastest)
  /// and every node of the tensor grid b (flat index q), 0 ≤ a_d, b_d ≤ n_d: out[p + ld·q]. The same
  /// sums as G(a, b), with each axis's reflections folded once per pair of coordinates rather than once
  /// per pair of nodes (the far blocks' cores in the Schur assembly).
  void G(const std::array<std::vector<int>, dim>& a, const std::array<std::vector<int>, dim>& b, double* out,
         std::size_t ld) const;
  /// out[u] = Σ_k G(a_u, b_k)·w_k (k in order) for the nodes a_u, u < n_a, and the weighted nodes
  /// (b_k, w_k), k < n_b: the near blocks' sums in the Schur assembly, the same sums as G's.
  void G(const Index* a, std::size_t n_a, const Index* b, const double* w, std::size_t n_b, double* out) const;
  /// Marks in `planes` (one per table plane along the slowest axis, planes() of them) the planes that G
  /// between nodes a and b reads for every a_{dim−1} in [a_lo, a_hi] and b_{dim−1} in [b_lo, b_hi].
  void mark_planes(int a_lo, int a_hi, int b_lo, int b_hi, std::vector<char>& planes) const;
  int planes() const { return int(size_[dim - 1]); }
  /// The table's entries in one plane.
  std::size_t plane_size() const {
    std::size_t n = 1;
    for (int d = 0; d < dim - 1; ++d) n *= size_[d];
    return n;
  }
  std::size_t memory_bytes() const { return table_.size() * sizeof(double); }
  /// Whether this rank holds only some planes (a distributed run): its lookups give its part of a sum.
  bool partial() const { return partial_; }

 private:
  /// Dirichlet: period 2n, table [0, n]; periodic: period n, table [0, n/2]. `period` is the period.
  static int fold(int s, int period) {
    s %= period;
    s = s < 0 ? s + period : s;
    return s > period / 2 ? period - s : s;
  }
  /// fold() for |s| ≤ period: one reflection instead of a remainder (|s| = period gives 0).
  static int near_fold(int s, int period) {
    s = s < 0 ? -s : s;
    return s > period / 2 ? period - s : s;
  }
  /// Where table offset s of axis d begins (stride: the axis's, serially); the slowest axis through plane_.
  std::size_t offset(int d, int s, std::size_t stride) const {
    return d == dim - 1 ? plane_[std::size_t(s)] : std::size_t(s) * stride;
  }
  double at(const Index& s) const {
    std::size_t k = 0;
    for (int d = dim - 2; d >= 0; --d) k = k * size_[d] + std::size_t(s[d]);
    return table_[plane_[std::size_t(s[dim - 1])] + k];
  }
  Grid<dim> grid_;
  double c_;
  bool periodic_;
  std::array<int, dim> period_;        // of T along each axis
  std::array<std::size_t, dim> size_;  // table entries along each axis: period/2 + 1
  bool partial_ = false;
  Slab held_;                       // this rank's planes along the slowest axis (every plane serially)
  std::size_t missing_ = SIZE_MAX;  // a table of some planes (the copy's): where the planes not copied begin
  std::vector<std::size_t> plane_;  // where plane z of the slowest axis begins in table_ (a zero plane if not held)
  std::size_t zeros_ = SIZE_MAX;    // where the zero plane begins (none serially): the block sums skip its lookups
  AlignedVector<double> table_;
};

}  // namespace fictus
