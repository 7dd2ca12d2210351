#pragma once
// Fast exact solvers for the Q1 matrix A = K + c·M on the whole box:
//   DstSolver        Dirichlet box, 2-D sine transform (dst_solver.hpp);
//   PeriodicSolver   periodic box, 2-D real DFT; with c = 0, A is singular (constants) and
//                    solve_in_place applies the pseudo-inverse A⁺ (the mean of r is discarded and
//                    the result has zero mean).
// Solvers plan once in the constructor; solve_in_place() is const and allocation-free.
#include <complex>
#include <memory>
#include <vector>

#include "fictus/grid.hpp"

namespace fictus {

class FastSolver {
 public:
  virtual ~FastSolver() = default;
  virtual const Grid& grid() const = 0;
  virtual double c() const = 0;
  /// Overwrites r (size n_unknowns, from the FFTW allocator) with A⁻¹r (A⁺r when singular()).
  virtual void solve_in_place(GridVector& r) const = 0;
  /// y = A x by the same transforms.
  virtual void apply(const GridVector& x, GridVector& y) const = 0;
  /// A has the constants as null space (periodic box with c = 0).
  bool singular() const { return grid().periodic() && c() == 0.0; }
};

/// The solver for the grid's boundary conditions.
std::unique_ptr<FastSolver> make_fast_solver(const Grid& grid, double c, int threads = 1);

/// 1-D P1 eigenvalues on n cells: Dirichlet (sines, p = 1..n−1, stored at p−1)
///   k_p = (2/h)(1 − cos(pπ/n)),  m_p = (h/3)(2 + cos(pπ/n));
/// periodic (Fourier modes, p = 0..n−1)  k_p = (2/h)(1 − cos(2πp/n)), m_p = (h/3)(2 + cos(2πp/n)).
struct Spectrum1d {
  std::vector<double> stiffness, mass;
  Spectrum1d(int n_cells, double h, Boundary boundary);
};

namespace detail {
class RealDft2d;
}

class PeriodicSolver final : public FastSolver {
 public:
  PeriodicSolver(const Grid& grid, double c, int threads = 1);
  ~PeriodicSolver() override;
  const Grid& grid() const override { return grid_; }
  double c() const override { return c_; }
  void solve_in_place(GridVector& r) const override;
  void apply(const GridVector& x, GridVector& y) const override;

 private:
  void transform(GridVector& v, bool inverse) const;
  Grid grid_;
  double c_;
  int threads_;
  Spectrum1d sx_, sy_;
  std::unique_ptr<detail::RealDft2d> dft_;
  mutable AlignedVector<std::complex<double>> spectrum_;  // workspace: calls must not overlap
};

}  // namespace fictus
