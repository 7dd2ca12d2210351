#pragma once
// The symbol of the Q1 matrix A = K + c·M on a uniform grid: the eigenvalues of A in the
// eigenvectors of the box's boundary conditions (docs/math.md, "Fast solvers"). A is a sum of
// Kronecker products of the 1-D P1 matrices, so for the mode p = (p_0, …, p_{dim−1})
//   λ(p) = Σ_d k_{p_d} Π_{e≠d} m_{p_e} + c · Π_d m_{p_d},
// with the 1-D eigenvalues
//   Dirichlet (sines, p = 1..n−1, stored at p−1): k_p = (2/h)(1 − cos(pπ/n)),  m_p = (h/3)(2 + cos(pπ/n));
//   periodic (Fourier, p = 0..n−1):               k_p = (2/h)(1 − cos(2πp/n)), m_p = (h/3)(2 + cos(2πp/n)).
// The fast solvers and the Green's table all take λ from here.
#include <array>
#include <vector>

#include "fictus/grid/grid.hpp"

namespace fictus {

/// The largest reaction coefficient c accepted (data.c's rule): beyond it c·M swamps K in double precision.
inline constexpr double largest_reaction = 1e12;

struct Spectrum1d {
  std::vector<double> stiffness, mass;
  Spectrum1d(int n_cells, double h, Boundary boundary);
  int size() const { return int(mass.size()); }
};

template <int dim>
class Q1Symbol {
 public:
  /// c must be in [0, largest_reaction] (throws naming data.c).
  Q1Symbol(const Grid<dim>& grid, double c);
  double c() const { return c_; }
  const Spectrum1d& axis(int d) const { return axes_[d]; }

  /// The factors of λ that do not depend on the first axis, for the modes `slow` of the other axes
  /// (slow[0] is ignored): λ(p_0, slow) = k_{p_0}·M + m_{p_0}·K + c·m_{p_0}·M.
  struct Row {
    double K = 0, M = 1;
  };
  Row row(const std::array<int, dim>& slow) const { return row_without(0, slow); }
  /// The same factors for any one axis left out (`inner`: the axis a loop runs along), from the modes
  /// of the others: λ = lambda(k_inner, m_inner, c, row_without(inner, modes)).
  Row row_without(int inner, const std::array<int, dim>& modes) const {
    Row r;
    for (int d = 0; d < dim; ++d) {
      if (d == inner) continue;
      const double k = axes_[d].stiffness[modes[d]], m = axes_[d].mass[modes[d]];
      r.K = r.K * m + r.M * k;
      r.M *= m;
    }
    return r;
  }
  double operator()(int p0, const Row& r) const { return lambda(axes_[0].stiffness[p0], axes_[0].mass[p0], c_, r); }
  /// λ from the first axis' k, m and a row's factors (loops hoist the first axis' arrays and call this).
  static double lambda(double k0, double m0, double c, const Row& r) { return k0 * r.M + m0 * r.K + c * m0 * r.M; }

 private:
  std::vector<Spectrum1d> axes_;  // one per axis
  double c_;
};

}  // namespace fictus
