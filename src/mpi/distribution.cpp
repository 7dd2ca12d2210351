#include "fictus/mpi/distribution.hpp"

#include <fftw3-mpi.h>

#include <algorithm>
#include <climits>
#include <cstring>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "../grid/fftw_plan.hpp"
#include "fictus/mpi/next_layer.hpp"
#include "fictus/mpi/slab_solver.hpp"

namespace fictus::mpi {

namespace {

template <int dim>
GridVector gather_layers(const Grid<dim>& grid, const GridVector& local, const Communicator& comm, bool everywhere) {
  const int P = comm.size();
  const Slab mine = default_slab(grid.layers(), comm.rank(), P);
  if (local.size() != grid.slab_size(mine)) throw std::invalid_argument("gather: vector size mismatch");
  // Counted in layers (a layer of 2048³ has 4.2 million entries): the counts fit an int.
  MPI_Datatype layer;
  MPI_Type_contiguous(int(grid.layer_size()), MPI_DOUBLE, &layer);
  MPI_Type_commit(&layer);
  std::vector<int> counts(static_cast<std::size_t>(P)), firsts(static_cast<std::size_t>(P));
  for (int r = 0; r < P; ++r) {
    const Slab s = default_slab(grid.layers(), r, P);
    counts[std::size_t(r)] = s.count, firsts[std::size_t(r)] = s.first;
  }
  GridVector whole(everywhere || comm.rank() == 0 ? grid.n_unknowns() : 0, 0.0);
  if (everywhere)
    MPI_Allgatherv(local.data(), mine.count, layer, whole.data(), counts.data(), firsts.data(), layer, comm.get());
  else
    MPI_Gatherv(local.data(), mine.count, layer, whole.data(), counts.data(), firsts.data(), layer, 0, comm.get());
  MPI_Type_free(&layer);
  return whole;
}

/// Each rank's wanted layers (wrapped) from their holders: every rank learns every rank's wish, sends the
/// layers it holds of each in the wished order, and the receiver puts each sender's layers in place.
template <int dim>
GridVector fetch_layers(const Grid<dim>& grid, const GridVector& local, Slab wanted, const Communicator& comm) {
  const int P = comm.size(), L = grid.layers();
  const Slab mine = default_slab(L, comm.rank(), P);
  if (local.size() != grid.slab_size(mine)) throw std::invalid_argument("layers: vector size mismatch");
  if (wanted.count < 0 || wanted.count > L || wanted.first < 0)
    throw std::invalid_argument("layers: a range of at most the grid's layers, from layer >= 0");
  std::vector<int> wishes(2 * static_cast<std::size_t>(P));
  const int wish[2] = {wanted.first, wanted.count};
  MPI_Allgather(wish, 2, MPI_INT, wishes.data(), 2, MPI_INT, comm.get());
  std::vector<int> holder(static_cast<std::size_t>(L));
  for (int r = 0; r < P; ++r) {
    const Slab s = default_slab(L, r, P);
    for (int l = s.first; l < s.first + s.count; ++l) holder[std::size_t(l)] = r;
  }
  const std::size_t size = grid.layer_size();
  std::vector<int> send_counts(static_cast<std::size_t>(P), 0), recv_counts(static_cast<std::size_t>(P), 0);
  std::vector<double> send;
  for (int r = 0; r < P; ++r)  // in r's order, the layers this rank holds
    for (int t = 0; t < wishes[2 * std::size_t(r) + 1]; ++t)
      if (const int l = (wishes[2 * std::size_t(r)] + t) % L; mine.holds(l)) {
        send.insert(send.end(), local.begin() + std::ptrdiff_t(std::size_t(l - mine.first) * size),
                    local.begin() + std::ptrdiff_t(std::size_t(l - mine.first + 1) * size));
        ++send_counts[std::size_t(r)];
      }
  for (int t = 0; t < wanted.count; ++t) ++recv_counts[std::size_t(holder[std::size_t((wanted.first + t) % L)])];
  std::vector<int> send_firsts(static_cast<std::size_t>(P), 0), recv_firsts(static_cast<std::size_t>(P), 0);
  for (int r = 1; r < P; ++r) {
    send_firsts[std::size_t(r)] = send_firsts[std::size_t(r) - 1] + send_counts[std::size_t(r) - 1];
    recv_firsts[std::size_t(r)] = recv_firsts[std::size_t(r) - 1] + recv_counts[std::size_t(r) - 1];
  }
  MPI_Datatype layer;  // counted in layers: the counts fit an int
  MPI_Type_contiguous(int(size), MPI_DOUBLE, &layer);
  MPI_Type_commit(&layer);
  GridVector received(std::size_t(wanted.count) * size);
  MPI_Alltoallv(send.data(), send_counts.data(), send_firsts.data(), layer, received.data(), recv_counts.data(),
                recv_firsts.data(), layer, comm.get());
  MPI_Type_free(&layer);
  GridVector out(received.size());  // each sender's layers are in the wished order: take them in turn
  std::vector<int> next = recv_firsts;
  for (int t = 0; t < wanted.count; ++t) {
    const int from = next[std::size_t(holder[std::size_t((wanted.first + t) % L)])]++;
    std::copy_n(received.begin() + std::ptrdiff_t(std::size_t(from) * size), size,
                out.begin() + std::ptrdiff_t(std::size_t(t) * size));
  }
  return out;
}

}  // namespace

GridVector SlabDistribution::layers(const Grid<2>& grid, const GridVector& local, Slab wanted) const {
  return fetch_layers(grid, local, wanted, comm_);
}
GridVector SlabDistribution::layers(const Grid<3>& grid, const GridVector& local, Slab wanted) const {
  return fetch_layers(grid, local, wanted, comm_);
}

Slab SlabDistribution::slab(int layers) const { return default_slab(layers, comm_.rank(), comm_.size()); }

Slab SlabDistribution::transform_planes(const std::vector<int>& shape, std::size_t& local_size) const {
  const std::vector<ptrdiff_t> n(shape.begin(), shape.end());
  ptrdiff_t count = 0, first = 0;
  const ptrdiff_t allocation =
      fftw_mpi_local_size_many(int(n.size()), n.data(), 1, FFTW_MPI_DEFAULT_BLOCK, comm_.get(), &count, &first);
  local_size = std::size_t(std::max<ptrdiff_t>(allocation, 1));
  return count > 0 ? Slab{int(first), int(count)} : Slab{shape[0], 0};
}

void SlabDistribution::dct1(const std::vector<int>& shape, double* local, int threads) const {
  const std::vector<ptrdiff_t> n(shape.begin(), shape.end());
  const std::vector<fftw_r2r_kind> kinds(shape.size(), FFTW_REDFT00);
  fftw_plan plan = nullptr;
  {
    std::lock_guard lock(detail::planner_mutex());
    detail::init_threads_once();
    fftw_plan_with_nthreads(threads < 1 ? 1 : threads);
    plan = fftw_mpi_plan_many_r2r(int(n.size()), n.data(), 1, FFTW_MPI_DEFAULT_BLOCK, FFTW_MPI_DEFAULT_BLOCK, local,
                                  local, comm_.get(), kinds.data(), FFTW_ESTIMATE);
  }
  if (comm_.max(plan == nullptr ? 1.0 : 0.0) != 0.0) {  // all ranks throw, or none
    std::lock_guard lock(detail::planner_mutex());
    if (plan) fftw_destroy_plan(plan);
    throw std::runtime_error("FFTW-MPI: could not plan the Green's table's transform");
  }
  fftw_execute(plan);
  std::lock_guard lock(detail::planner_mutex());
  fftw_destroy_plan(plan);
}

void SlabDistribution::broadcast(double* values, std::size_t n) const {
  for (std::size_t done = 0; done < n;) {
    const int chunk = int(std::min<std::size_t>(n - done, INT_MAX));
    MPI_Bcast(values + done, chunk, MPI_DOUBLE, 0, comm_.get());
    done += std::size_t(chunk);
  }
}

std::vector<unsigned char> SlabDistribution::concatenate_bytes(const std::vector<unsigned char>& mine) const {
  const int P = comm_.size();
  std::vector<unsigned long long> sizes(static_cast<std::size_t>(P));
  const unsigned long long size = mine.size();
  MPI_Allgather(&size, 1, MPI_UNSIGNED_LONG_LONG, sizes.data(), 1, MPI_UNSIGNED_LONG_LONG, comm_.get());
  std::size_t total = 0;
  for (unsigned long long s : sizes) total += std::size_t(s);
  std::vector<unsigned char> all(total);
  // Each rank's part from it to all, in pieces an int counts.
  for (int r = 0; r < P; ++r) {
    unsigned char* const part = all.data() + std::accumulate(sizes.begin(), sizes.begin() + r, std::size_t(0));
    if (r == comm_.rank() && !mine.empty()) std::memcpy(part, mine.data(), mine.size());
    for (std::size_t done = 0; done < sizes[std::size_t(r)];) {
      const int piece = int(std::min<std::size_t>(sizes[std::size_t(r)] - done, INT_MAX));
      MPI_Bcast(part + done, piece, MPI_UNSIGNED_CHAR, r, comm_.get());
      done += std::size_t(piece);
    }
  }
  return all;
}

std::unique_ptr<FastSolver<2>> SlabDistribution::fast_solver(const Grid<2>& grid, double c,
                                                             const Execution& execution) const {
  return std::make_unique<SlabSolver<2>>(grid, c, comm_, execution);
}
std::unique_ptr<FastSolver<3>> SlabDistribution::fast_solver(const Grid<3>& grid, double c,
                                                             const Execution& execution) const {
  return std::make_unique<SlabSolver<3>>(grid, c, comm_, execution);
}
GridVector SlabDistribution::with_next_layer(const Grid<2>& grid, const GridVector& local) const {
  return mpi::with_next_layer(grid, slab(grid), local, comm_);
}
GridVector SlabDistribution::with_next_layer(const Grid<3>& grid, const GridVector& local) const {
  return mpi::with_next_layer(grid, slab(grid), local, comm_);
}
GridVector SlabDistribution::gather(const Grid<2>& grid, const GridVector& local, bool everywhere) const {
  return gather_layers(grid, local, comm_, everywhere);
}
GridVector SlabDistribution::gather(const Grid<3>& grid, const GridVector& local, bool everywhere) const {
  return gather_layers(grid, local, comm_, everywhere);
}

}  // namespace fictus::mpi
