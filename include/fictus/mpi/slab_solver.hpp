#pragma once
// The fast solver for A = K + c·M on FFTW-MPI slabs: the same operator as DstSolver (Dirichlet box) and
// PeriodicSolver (periodic box), with the grid's unknowns distributed over the ranks of a communicator
// in whole layers along the slowest axis (Slab, fast_solver.hpp), FFTW-MPI's block distribution.
//   Dirichlet: fftw_mpi_plan_many_r2r (RODFT00 along every axis);
//   periodic:  fftw_mpi_plan_many_dft_r2c / c2r.
// The forward transform leaves its output transposed (FFTW_MPI_TRANSPOSED_OUT: the two slowest axes
// swapped, distributed along the second), the division by λ runs there, and the backward transform takes
// it back (FFTW_MPI_TRANSPOSED_IN): one global transposition per transform, not two. The Schur
// complement's products (solve_in_place_at, Dirichlet box) are made of FFTW's 1-D transforms of the
// lines their load and readings meet, along the axes a rank holds whole, with FFTW-MPI's transposition
// between them: the same layouts, on fewer lines. The constructor, the destructor, solve_in_place,
// solve_in_place_at and apply are collective: every rank of the communicator calls them, in the same
// order (a rank that fails alone leaves the others waiting).
#include <memory>

#include "fictus/grid/fast_solver.hpp"
#include "fictus/mpi/communicator.hpp"

namespace fictus::mpi {

/// FFTW-MPI's default distribution of `layers` layers over `size` ranks: blocks of ⌈layers/size⌉ in rank
/// order (the last ranks may hold fewer, or none).
Slab default_slab(int layers, int rank, int size);

template <int dim>
class SlabSolver final : public FastSolver<dim> {
 public:
  /// c ≥ 0; the threads of `execution` run FFTW's and the scaling's loops on each rank. The communicator
  /// must outlive the solver.
  SlabSolver(const Grid<dim>& grid, double c, const Communicator& comm, const Execution& execution = Execution{});
  ~SlabSolver() override;
  SlabSolver(const SlabSolver&) = delete;
  SlabSolver& operator=(const SlabSolver&) = delete;

  const Grid<dim>& grid() const override { return grid_; }
  double c() const override { return symbol_.c(); }
  Slab slab() const override { return slab_; }
  /// r: this rank's layers (local_size() entries). On a Dirichlet box a vector whose capacity holds
  /// FFTW-MPI's local array (make_vector()'s do; a copy of one need not) is transformed where it lies;
  /// any other goes through a workspace of that size, made at the first such call and kept. A periodic
  /// box always uses the workspace, made by the constructor.
  void solve_in_place(GridVector& r) const override;
  /// r zero outside the nodes of the rows `load` was made from, exact at the nodes of those of `wanted`
  /// (footprint()), unspecified elsewhere. A Dirichlet box transforms along the fastest axis only the
  /// rows that meet the load (forward) or the readings (backward), in 3-D along the middle axis only
  /// the layers that do, and along the slowest axis every line of the transposed layout (its plans are
  /// the constructor's); a periodic box solves everywhere. Collective.
  void solve_in_place_at(GridVector& r, const Footprint& load, const Footprint& wanted) const override;
  void apply(const GridVector& x, GridVector& y) const override;
  GridVector make_vector() const override;
  /// Bytes of the workspace on this rank (0 while every solve ran in place).
  std::size_t workspace_bytes() const;

 private:
  struct Plans;
  struct Lines;
  void plan_transforms(const Communicator& comm, double* planned);
  std::unique_ptr<Lines> plan_lines(double* example) const;
  /// FFTW-MPI's local array holding v's layers: v's own storage where its capacity holds it (v resized
  /// to it), else the workspace with v's rows copied in; `finish` takes the answer back into v.
  double* local_array(GridVector& v) const;
  void finish(GridVector& v, double* data) const;
  void transform(GridVector& v, bool inverse) const;
  void scale(double* data, bool inverse) const;
  /// The lines of the transposed layout along the slowest axis (forward and backward alike: RODFT00).
  void transform_slowest(double* data) const;
  /// The lines along the fastest axis (and in 3-D the middle one) of this rank's layers that `f` meets,
  /// in the order of a forward or a backward transform.
  void transform_near(double* data, const Footprint& f, bool forward) const;
  Grid<dim> grid_;
  Q1Symbol<dim> symbol_;
  int threads_;
  Slab slab_;
  std::unique_ptr<Plans> plans_;
  std::unique_ptr<Lines> lines_;  // solve_in_place_at's (Dirichlet box)
};

}  // namespace fictus::mpi
