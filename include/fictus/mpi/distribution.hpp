#pragma once
// The distribution of a run under mpirun (Distribution, distribution.hpp): each rank of a communicator
// holds FFTW-MPI's default slab of every grid vector (default_slab), the fast solves are SlabSolver's,
// and the sums and broadcasts are MPI's collectives on that communicator.
#include "fictus/grid/distribution.hpp"
#include "fictus/mpi/communicator.hpp"

namespace fictus::mpi {

class SlabDistribution final : public Distribution {
 public:
  /// The communicator must outlive the distribution and every solver made from it.
  explicit SlabDistribution(Communicator comm = Communicator{}) : comm_(comm) {}
  const Communicator& communicator() const { return comm_; }
  int rank() const override { return comm_.rank(); }
  int size() const override { return comm_.size(); }
  Slab slab(int layers) const override;
  using Distribution::slab;
  void sum(double* values, std::size_t n) const override { comm_.sum(values, n); }
  using Distribution::sum;
  void sum_onto(double* values, std::size_t n, int root) const override { comm_.sum_onto(values, n, root); }
  double max(double value) const override { return comm_.max(value); }
  void broadcast(double* values, std::size_t n) const override;
  std::vector<unsigned char> concatenate_bytes(const std::vector<unsigned char>& mine) const override;
  std::unique_ptr<FastSolver<2>> fast_solver(const Grid<2>& grid, double c, const Execution& execution) const override;
  std::unique_ptr<FastSolver<3>> fast_solver(const Grid<3>& grid, double c, const Execution& execution) const override;
  GridVector with_next_layer(const Grid<2>& grid, const GridVector& local) const override;
  GridVector with_next_layer(const Grid<3>& grid, const GridVector& local) const override;
  Slab transform_planes(const std::vector<int>& shape, std::size_t& local_size) const override;
  void dct1(const std::vector<int>& shape, double* local, int threads) const override;
  GridVector layers(const Grid<2>& grid, const GridVector& local, Slab wanted) const override;
  GridVector layers(const Grid<3>& grid, const GridVector& local, Slab wanted) const override;
  AlignedVector<double> planes(const double* local, Slab mine, std::size_t plane_size, const std::vector<int>& wanted,
                               std::size_t zeros = 0) const override;
  GridVector gather(const Grid<2>& grid, const GridVector& local, bool everywhere = true) const override;
  GridVector gather(const Grid<3>& grid, const GridVector& local, bool everywhere = true) const override;

 private:
  Communicator comm_;
};

}  // namespace fictus::mpi
