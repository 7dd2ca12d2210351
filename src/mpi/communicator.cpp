#include "fictus/mpi/communicator.hpp"

#include <fftw3-mpi.h>

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

#include "../grid/fftw_plan.hpp"

namespace fictus::mpi {

int declared_size() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "SLURM_STEP_NUM_TASKS"})
    if (const char* text = std::getenv(name)) {
      char* end = nullptr;
      const long n = std::strtol(text, &end, 10);
      if (end != text && n > 0 && n < (1L << 30)) return int(n);
    }
  return 0;
}

bool launched() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
    if (std::getenv(name) != nullptr) return true;
  return declared_size() > 1;  // e.g. srun without an MPI plugin: several tasks all the same
}

Environment::Environment(int& argc, char**& argv) {
  int provided = 0;
  if (MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS)
    throw std::runtime_error("MPI: MPI_Init_thread failed");
  if (provided < MPI_THREAD_FUNNELED) {
    MPI_Finalize();
    throw std::runtime_error("MPI: the library does not support threads (MPI_THREAD_FUNNELED)");
  }
  try {
    std::lock_guard lock(detail::planner_mutex());
    detail::init_threads_once();  // FFTW: the threads before the MPI part
    fftw_mpi_init();
  } catch (...) {
    MPI_Finalize();
    throw;
  }
}

Environment::~Environment() {
  {
    std::lock_guard lock(detail::planner_mutex());
    fftw_mpi_cleanup();
  }
  MPI_Finalize();
}

Communicator::Communicator(MPI_Comm comm) : comm_(comm) {
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
}

void Communicator::sum(double* values, std::size_t n) const {
  constexpr std::size_t most = std::size_t(1) << 30;  // MPI counts are int
  for (std::size_t first = 0; first < n; first += most)
    MPI_Allreduce(MPI_IN_PLACE, values + first, int(std::min(most, n - first)), MPI_DOUBLE, MPI_SUM, comm_);
}

void Communicator::sum_onto(double* values, std::size_t n, int root) const {
  constexpr std::size_t most = std::size_t(1) << 30;
  for (std::size_t first = 0; first < n; first += most) {
    const int count = int(std::min(most, n - first));
    if (rank_ == root)
      MPI_Reduce(MPI_IN_PLACE, values + first, count, MPI_DOUBLE, MPI_SUM, root, comm_);
    else
      MPI_Reduce(values + first, nullptr, count, MPI_DOUBLE, MPI_SUM, root, comm_);
  }
}

double Communicator::max(double value) const {
  MPI_Allreduce(MPI_IN_PLACE, &value, 1, MPI_DOUBLE, MPI_MAX, comm_);
  return value;
}

void Communicator::barrier() const { MPI_Barrier(comm_); }

}  // namespace fictus::mpi
