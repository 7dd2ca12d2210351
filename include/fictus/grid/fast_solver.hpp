#pragma once
// Fast exact solvers for the Q1 matrix A = K + c·M on the whole box, any dimension:
//   DstSolver<dim>       Dirichlet box, dim-dimensional sine transform (dst_solver.hpp);
//   PeriodicSolver<dim>  periodic box, dim-dimensional real DFT; with c = 0, A is singular (the
//                        constants) and solve_in_place applies the pseudo-inverse A⁺ (the mean of r
//                        is discarded and the result has zero mean).
// λ(p) comes from Q1Symbol. Solvers plan once in the constructor; solve_in_place() is const and
// allocation-free (DstSolver::solve_in_place_at plans its transforms of lines at its first call and
// makes a mask of the lines, a few bytes per column, at each call).
#include <complex>
#include <initializer_list>
#include <memory>
#include <vector>

#include "fictus/grid/execution.hpp"
#include "fictus/grid/grid.hpp"
#include "fictus/grid/q1_symbol.hpp"
#include "fictus/grid/sparse_rows.hpp"

namespace fictus {

/// The columns of a grid's unknowns (its lines along the slowest axis) that hold a node of some sparse
/// rows: where a load Rᵀλ made from those rows can be non-zero, or where rows read a solve's answer.
/// `columns` is indexed by Grid::index with the slowest axis dropped; `lines`, the same for the lines
/// along the fastest axis, by Grid::index over the unknowns along axis 0 (the solver on slabs, which
/// transforms those lines first, takes these).
struct Footprint {
  std::vector<char> columns, lines;
};

template <int dim>
Footprint footprint(const Grid<dim>& grid, std::initializer_list<const SparseRows*> rows);

template <int dim>
class FastSolver {
 public:
  virtual ~FastSolver() = default;
  virtual const Grid<dim>& grid() const = 0;
  virtual double c() const = 0;
  /// The layers of the unknowns this process holds, and their number of entries: the size of the
  /// vectors solve_in_place and apply take.
  virtual Slab slab() const { return grid().every_layer(); }
  std::size_t local_size() const { return grid().slab_size(slab()); }
  /// A vector of local_size() zeros for solve_in_place (a solver may reserve the capacity it transforms
  /// in, as the one on FFTW-MPI slabs does).
  virtual GridVector make_vector() const { return GridVector(local_size(), 0.0); }
  /// Overwrites r (size local_size(): n_unknowns when serial) with A⁻¹r (A⁺r when singular()).
  virtual void solve_in_place(GridVector& r) const = 0;
  /// The same for r zero outside the nodes of the rows `load` was made from (footprint()), exact at the
  /// nodes of those `wanted` was made from and unspecified elsewhere: the Dirichlet solvers transform
  /// only the lines these meet (the Schur complement's products, whose loads and readings lie near γ);
  /// the others solve everywhere.
  virtual void solve_in_place_at(GridVector& r, const Footprint& load, const Footprint& wanted) const {
    (void)load, (void)wanted;
    solve_in_place(r);
  }
  /// y = A x by the same transforms.
  virtual void apply(const GridVector& x, GridVector& y) const = 0;
  /// A has the constants as null space (periodic box with c = 0).
  bool singular() const { return grid().periodic() && c() == 0.0; }
};

/// The solver for the grid's boundary conditions.
template <int dim>
std::unique_ptr<FastSolver<dim>> make_fast_solver(const Grid<dim>& grid, double c,
                                                  const Execution& execution = Execution{});

namespace detail {
class RealDft;
}

template <int dim>
class PeriodicSolver final : public FastSolver<dim> {
 public:
  PeriodicSolver(const Grid<dim>& grid, double c, const Execution& execution = Execution{});
  ~PeriodicSolver() override;
  const Grid<dim>& grid() const override { return grid_; }
  double c() const override { return symbol_.c(); }
  void solve_in_place(GridVector& r) const override;
  void apply(const GridVector& x, GridVector& y) const override;

 private:
  void transform(GridVector& v, bool inverse) const;
  Grid<dim> grid_;
  Q1Symbol<dim> symbol_;
  int threads_;
  std::unique_ptr<detail::RealDft> dft_;
  mutable AlignedVector<std::complex<double>> spectrum_;  // workspace: calls must not overlap
};

}  // namespace fictus
