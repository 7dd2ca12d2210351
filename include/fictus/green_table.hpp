#pragma once
// Discrete Green's function of A = K + c·M on the Dirichlet box (docs/math.md, DESIGN §3):
//   G[(i,j),(k,l)] = (A⁻¹)_{(i,j),(k,l)}
//                  = T(i−k, j−l) − T(i+k, j−l) − T(i−k, j+l) + T(i+k, j+l),
//   T(s,t) = 1/(nx·ny) Σ_{p<nx, q<ny, p,q ≥ 1} cos(pπs/nx) cos(qπt/ny) / λ_pq,
// T is even and 2n-periodic in each argument; the table holds T on [0,nx]×[0,ny] and is made by
// ONE 2-D DCT-I (FFTW REDFT00) of size (nx+1)(ny+1). Built once per grid and c.
#include <cstddef>

#include "fictus/grid.hpp"

namespace fictus {

class GreenTable {
 public:
  GreenTable(const Grid& grid, double c, int threads = 1);

  const Grid& grid() const { return grid_; }
  /// T(s, t) for any integers s, t (folded into the table).
  double T(int s, int t) const {
    return table_[std::size_t(fold(t, grid_.ny())) * std::size_t(grid_.nx() + 1) + fold(s, grid_.nx())];
  }
  /// (A⁻¹) between interior nodes (i, j) and (k, l).
  double G(int i, int j, int k, int l) const {
    return T(i - k, j - l) - T(i + k, j - l) - T(i - k, j + l) + T(i + k, j + l);
  }
  std::size_t memory_bytes() const { return table_.size() * sizeof(double); }

 private:
  static int fold(int s, int n) {
    s = s < 0 ? -s : s;
    s %= 2 * n;
    return s > n ? 2 * n - s : s;
  }
  Grid grid_;
  AlignedVector<double> table_;
};

}  // namespace fictus
