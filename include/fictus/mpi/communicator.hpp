#pragma once
// fictus under mpirun (the FICTUS_MPI build, library fictus_mpi): the MPI environment of a process and
// the communicator its distributed work uses. A serial run never initializes MPI.
#include <mpi.h>

#include <cstddef>

namespace fictus::mpi {

/// Was this process started by an MPI launcher (mpirun, mpiexec, srun)? Read from the variables the
/// launchers set (Open MPI, PMIx, PMI; Slurm's task count), without initializing MPI.
bool launched();
/// The number of processes the launcher says it started (0: it says nothing). When it is more than MPI's
/// world size, the launcher is not this build's MPI (another MPI's mpirun, srun without its MPI plugin)
/// and each process would run alone.
int declared_size();

/// MPI for the life of the object: MPI_Init_thread with MPI_THREAD_FUNNELED (only the thread that made
/// it calls MPI; OpenMP and FFTW threads only compute), FFTW's threads and fftw_mpi_init; at the end
/// fftw_mpi_cleanup (which also ends every FFTW plan: make the Environment before any plan, as main's
/// first object) and MPI_Finalize. One per process.
class Environment {
 public:
  Environment(int& argc, char**& argv);
  ~Environment();
  Environment(const Environment&) = delete;
  Environment& operator=(const Environment&) = delete;
};

/// A communicator's rank and size and the collectives fictus uses, on MPI_COMM_WORLD by default. The
/// object does not own the communicator.
class Communicator {
 public:
  explicit Communicator(MPI_Comm comm = MPI_COMM_WORLD);
  MPI_Comm get() const { return comm_; }
  int rank() const { return rank_; }
  int size() const { return size_; }
  /// values[i] ← Σ over the ranks of values[i], on every rank.
  void sum(double* values, std::size_t n) const;
  /// values[i] ← Σ over the ranks of values[i], on rank `root` only (the others' values are kept).
  void sum_onto(double* values, std::size_t n, int root) const;
  double max(double value) const;
  void barrier() const;

 private:
  MPI_Comm comm_;
  int rank_ = 0, size_ = 1;
};

}  // namespace fictus::mpi
