#pragma once
// Exact fast solver for the Q1 matrix A = K + c·M on the grid's interior nodes (homogeneous
// Dirichlet box), by the 2-D sine transform (FFTW RODFT00, see docs/math.md):
//   A⁻¹ r = DST( DST(r) ./ λ ) / (4·nx·ny),
//   λ_pq = k_p^x m_q^y + m_p^x k_q^y + c m_p^x m_q^y,
//   k_p = (2/h)(1 − cos(pπ/n)), m_p = (h/3)(2 + cos(pπ/n)).
// Plans once in the constructor; solve_in_place() is const, allocation-free and reentrant for
// distinct arrays.
#include <memory>
#include <vector>

#include "fictus/fast_solver.hpp"
#include "fictus/grid.hpp"

namespace fictus {

namespace detail {
class R2rPlan2d;
}

class DstSolver final : public FastSolver {
 public:
  /// c ≥ 0 (c = 0 is fine: the Dirichlet Laplacian is positive definite). threads ≥ 1.
  DstSolver(const Grid& grid, double c, int threads = 1);
  ~DstSolver() override;
  DstSolver(const DstSolver&) = delete;
  DstSolver& operator=(const DstSolver&) = delete;

  const Grid& grid() const override { return grid_; }
  double c() const override { return c_; }
  void solve_in_place(GridVector& r) const override;
  void apply(const GridVector& x, GridVector& y) const override;
  /// One in-place 2-D DST-I (RODFT00) of a grid vector: the unit of cost benchmarks compare to.
  void transform(GridVector& v) const;

 private:
  void scale_by(GridVector& v, bool inverse) const;
  Grid grid_;
  double c_;
  int threads_;
  Spectrum1d sx_, sy_;
  std::unique_ptr<detail::R2rPlan2d> plan_;
};

}  // namespace fictus
