#pragma once
// Where a solve's grid lies. Serial (the default): one process holds every layer of every grid vector.
// Distributed (fictus_mpi's, under mpirun): each rank holds whole layers along the slowest axis (a
// Slab, grid.hpp), the fast solves run on FFTW-MPI, and what sums over the grid (readings of sparse
// rows, integrals over ω) is added over the ranks. The boundary's unknowns (λ, the Schur blocks,
// Newton) are small and every rank holds all of them.
//
// Every member that touches other ranks is collective: each rank calls it, in the same order. A rank
// that failed alone would leave the others waiting, so a check whose answer may differ between ranks
// (a NaN in one rank's layers) asks all() first and every rank throws together.
#include <cstddef>
#include <cstring>
#include <exception>
#include <memory>
#include <type_traits>
#include <vector>

#include "fictus/grid/grid.hpp"
#include "fictus/grid/sparse_rows.hpp"

namespace fictus {

class Execution;
template <int dim>
class FastSolver;

class Distribution {
 public:
  virtual ~Distribution() = default;
  virtual int rank() const { return 0; }
  virtual int size() const { return 1; }
  bool distributed() const { return size() > 1; }

  /// The layers this rank holds of a grid with `layers` layers (serial: all of them).
  virtual Slab slab(int layers) const { return Slab{0, layers}; }
  template <int dim>
  Slab slab(const Grid<dim>& grid) const {
    return slab(grid.layers());
  }

  /// values[i] ← Σ over the ranks of values[i], on every rank (serial: unchanged).
  virtual void sum(double* values, std::size_t n) const { (void)values, (void)n; }
  void sum(std::vector<double>& values) const { sum(values.data(), values.size()); }
  double sum(double value) const {
    sum(&value, 1);
    return value;
  }
  /// values[i] ← Σ over the ranks of values[i], on rank `root` only: what one rank alone needs, at about
  /// half an all-ranks sum's traffic. The other ranks' values are kept (serial: unchanged).
  virtual void sum_onto(double* values, std::size_t n, int root) const { (void)values, (void)n, (void)root; }
  virtual double max(double value) const { return value; }
  /// values ← rank 0's values, on every rank.
  virtual void broadcast(double* values, std::size_t n) const { (void)values, (void)n; }
  /// Every rank's `mine`, one after the other in rank order, on every rank (serial: mine). Collective.
  virtual std::vector<unsigned char> concatenate_bytes(const std::vector<unsigned char>& mine) const { return mine; }
  /// The same for items of a trivially copyable type (what a rank made of a task shared out by rank).
  template <class T>
  std::vector<T> concatenate(const std::vector<T>& mine) const {
    static_assert(std::is_trivially_copyable_v<T>, "concatenate: items copied as bytes");
    if (!distributed()) return mine;
    std::vector<unsigned char> bytes(mine.size() * sizeof(T));
    if (!mine.empty()) std::memcpy(bytes.data(), mine.data(), bytes.size());
    bytes = concatenate_bytes(bytes);
    std::vector<T> all(bytes.size() / sizeof(T));
    if (!all.empty()) std::memcpy(static_cast<void*>(all.data()), bytes.data(), bytes.size());
    return all;
  }
  /// Is `ok` true on every rank? The same answer on all of them.
  bool all(bool ok) const { return max(ok ? 0.0 : 1.0) == 0.0; }
  /// After work shared out: throws on every rank the error of the first rank that had one (`failure`,
  /// or an interruption where `interrupted`), of its kind (std::invalid_argument, Interrupted, else
  /// std::runtime_error) with its message; the rank that had it rethrows it. Returns where no rank had
  /// one. Collective. Serial: rethrows `failure`, then throws Interrupted where `interrupted`.
  void throw_first_failure(const std::exception_ptr& failure, bool interrupted) const;

  /// The fast solver of A = K + c·M for this distribution (serial: make_fast_solver's).
  virtual std::unique_ptr<FastSolver<2>> fast_solver(const Grid<2>& grid, double c, const Execution& execution) const;
  virtual std::unique_ptr<FastSolver<3>> fast_solver(const Grid<3>& grid, double c, const Execution& execution) const;

  /// This rank's layers (`local`, its slab's) followed by the next layer, from the rank that holds it;
  /// zeros where there is none. What the samplers over ω take with a slab. Serial: never asked.
  virtual GridVector with_next_layer(const Grid<2>& grid, const GridVector& local) const;
  virtual GridVector with_next_layer(const Grid<3>& grid, const GridVector& local) const;
  /// A DCT-I (REDFT00 along every axis) of an array of `shape` (slowest axis first) split in planes
  /// along its slowest axis (the Green's table's): this rank's planes, and (`local_size`) the doubles its
  /// local array must hold for the transform. Serial: every plane.
  virtual Slab transform_planes(const std::vector<int>& shape, std::size_t& local_size) const;
  /// The transform, in place on this rank's planes (`local`, transform_planes' size). Collective.
  /// Serial: never asked (GreenTable transforms its whole table itself).
  virtual void dct1(const std::vector<int>& shape, double* local, int threads) const;

  /// Layers first, first + 1, …, first + count − 1 of a grid vector (taken modulo grid.layers(); `local`
  /// is this rank's slab of it), one after the other, from the ranks that hold them. Each rank asks for
  /// its own layers (count 0: none). Collective. Serial: never asked.
  virtual GridVector layers(const Grid<2>& grid, const GridVector& local, Slab wanted) const;
  virtual GridVector layers(const Grid<3>& grid, const GridVector& local, Slab wanted) const;
  /// Planes `wanted` (any order, repeats allowed) of an array split in planes of `plane_size` doubles
  /// along its slowest axis, of which this rank holds `mine` (`local`: those planes, one after the
  /// other): the wanted planes, one after the other in the wanted order, from the ranks that hold them,
  /// then `zeros` zeros (room the caller fills). Each rank asks for its own. A plane no rank holds is an
  /// error on every rank. Collective. Serial: copies of `local`'s planes.
  virtual AlignedVector<double> planes(const double* local, Slab mine, std::size_t plane_size,
                                       const std::vector<int>& wanted, std::size_t zeros = 0) const;
  /// The whole grid vector from each rank's layers: on every rank, or (`everywhere` false) on rank 0
  /// only (the others get an empty vector).
  virtual GridVector gather(const Grid<2>& grid, const GridVector& local, bool everywhere = true) const;
  virtual GridVector gather(const Grid<3>& grid, const GridVector& local, bool everywhere = true) const;
};

/// The process's distribution: what an Execution made without one takes. Serial until a program that
/// runs under mpirun sets its own (the CLI does, on more than one rank); the library and the Python
/// module never do.
std::shared_ptr<const Distribution> process_distribution();
void set_process_distribution(std::shared_ptr<const Distribution> distribution);

/// out = rows·u with u this rank's part of a grid vector (its slab of `grid`, from the distribution of
/// `execution`): each rank's partial sums, added over the ranks. Serial: rows.multiply(u, out).
template <int dim>
void read_rows(const SparseRows& rows, const Grid<dim>& grid, const GridVector& u, const Distribution& distribution,
               std::vector<double>& out);
/// u += rowsᵀλ on this rank's part of a grid vector.
template <int dim>
void add_rows(const SparseRows& rows, const Grid<dim>& grid, const std::vector<double>& lambda, GridVector& u,
              const Distribution& distribution);

}  // namespace fictus
