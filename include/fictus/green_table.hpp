#pragma once
// Discrete Green's function of A = K + c·M (docs/math.md, DESIGN §3).
// Dirichlet box:
//   G[(i,j),(k,l)] = T(i−k, j−l) − T(i+k, j−l) − T(i−k, j+l) + T(i+k, j+l),
//   T(s,t) = 1/(nx·ny) Σ_{p=1}^{nx−1} Σ_{q=1}^{ny−1} cos(pπs/nx) cos(qπt/ny) / λ_pq,
//   even and 2n-periodic; the table holds [0,nx]×[0,ny], ONE 2-D DCT-I (REDFT00) of size (nx+1)(ny+1).
// Periodic box (nx, ny even):
//   G[(i,j),(k,l)] = T(i−k, j−l),  T(s,t) = 1/(nx·ny) Σ_{p<nx} Σ_{q<ny} cos(2πps/nx) cos(2πqt/ny) / λ_pq,
//   even and n-periodic; the table holds [0,nx/2]×[0,ny/2], one REDFT00 of size (nx/2+1)(ny/2+1).
//   With c = 0 the zero mode is dropped: G is the pseudo-inverse A⁺.
// Built once per grid, boundary and c; lookups are const and thread-safe.
#include <cstddef>

#include "fictus/grid.hpp"

namespace fictus {

class GreenTable {
 public:
  GreenTable(const Grid& grid, double c, int threads = 1);

  const Grid& grid() const { return grid_; }
  double c() const { return c_; }
  /// T(s, t) for any integers s, t (folded into the table).
  double T(int s, int t) const { return table_[std::size_t(fold(t, ny_)) * width_ + std::size_t(fold(s, nx_))]; }
  /// (A⁻¹)_{(i,j),(k,l)} between nodes carrying unknowns (A⁺ for a singular periodic A);
  /// 0 ≤ i, k ≤ nx and 0 ≤ j, l ≤ ny (so the arguments of T need one reflection, no division).
  double G(int i, int j, int k, int l) const {
    if (periodic_) return at(near_fold(i - k, nx_), near_fold(j - l, ny_));
    const int sm = near_fold(i - k, nx_), sp = near_fold(i + k, nx_);
    const int tm = near_fold(j - l, ny_), tp = near_fold(j + l, ny_);
    return at(sm, tm) - at(sp, tm) - at(sm, tp) + at(sp, tp);
  }
  std::size_t memory_bytes() const { return table_.size() * sizeof(double); }

 private:
  /// Dirichlet: period 2n, table [0, n]; periodic: period n, table [0, n/2]. `n` is the period.
  static int fold(int s, int period) {
    s %= period;
    s = s < 0 ? s + period : s;
    return s > period / 2 ? period - s : s;
  }
  /// fold() for |s| ≤ period: one reflection instead of a remainder.
  static int near_fold(int s, int period) {
    s = s < 0 ? -s : s;
    s = s == period ? 0 : s;
    return s > period / 2 ? period - s : s;
  }
  double at(int s, int t) const { return table_[std::size_t(t) * width_ + std::size_t(s)]; }
  Grid grid_;
  double c_;
  bool periodic_;
  int nx_, ny_;  // periods in s and t
  std::size_t width_;
  AlignedVector<double> table_;
};

}  // namespace fictus
