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

/// Each rank's wanted planes from their holders: every rank learns every rank's held planes and wish,
/// sends the planes it holds of each wish in the wished order, and the receiver puts each sender's planes
/// in place. A plane no rank holds is an error on every rank (found before anything is sent).
AlignedVector<double> fetch_planes(const double* local, Slab mine, std::size_t plane_size,
                                   const std::vector<int>& wanted, std::size_t zeros, const Communicator& comm) {
  const int P = comm.size();
  const auto np = static_cast<std::size_t>(P);
  std::vector<int> held(2 * np), counts(np);
  const int slab[2] = {mine.first, mine.count}, count = int(wanted.size());
  MPI_Allgather(slab, 2, MPI_INT, held.data(), 2, MPI_INT, comm.get());
  MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, comm.get());
  std::vector<int> firsts(np, 0);
  for (std::size_t r = 1; r < np; ++r) firsts[r] = firsts[r - 1] + counts[r - 1];
  std::vector<int> wishes(std::size_t(firsts.back() + counts.back()));
  MPI_Allgatherv(wanted.data(), count, MPI_INT, wishes.data(), counts.data(), firsts.data(), MPI_INT, comm.get());
  const auto holder = [&](int plane) {
    for (std::size_t r = 0; r < np; ++r)
      if (plane >= held[2 * r] && plane < held[2 * r] + held[2 * r + 1]) return int(r);
    return -1;
  };
  std::vector<int> owner(wishes.size());
  bool held_somewhere = plane_size <= std::size_t(INT_MAX);  // a plane is one MPI datatype
  for (std::size_t t = 0; t < wishes.size(); ++t)
    held_somewhere = held_somewhere && (owner[t] = holder(wishes[t])) >= 0;
  if (!held_somewhere) throw std::invalid_argument("planes: a wanted plane that no rank holds");  // every rank sees it
  std::vector<int> send_counts(np, 0), recv_counts(np, 0);
  for (std::size_t r = 0; r < np; ++r)
    for (int t = firsts[r]; t < firsts[r] + counts[r]; ++t) send_counts[r] += owner[std::size_t(t)] == comm.rank();
  AlignedVector<double> send(std::size_t(std::accumulate(send_counts.begin(), send_counts.end(), 0)) * plane_size);
  double* to = send.data();
  for (std::size_t r = 0; r < np; ++r)  // in r's order, the planes this rank holds
    for (int t = firsts[r]; t < firsts[r] + counts[r]; ++t)
      if (owner[std::size_t(t)] == comm.rank())
        to = std::copy_n(local + std::size_t(wishes[std::size_t(t)] - mine.first) * plane_size, plane_size, to);
  const int* my_owners = owner.data() + firsts[std::size_t(comm.rank())];
  for (int t = 0; t < count; ++t) ++recv_counts[std::size_t(my_owners[t])];
  std::vector<int> send_firsts(np, 0), recv_firsts(np, 0);
  for (std::size_t r = 1; r < np; ++r) {
    send_firsts[r] = send_firsts[r - 1] + send_counts[r - 1];
    recv_firsts[r] = recv_firsts[r - 1] + recv_counts[r - 1];
  }
  MPI_Datatype plane;  // counted in planes: the counts fit an int
  MPI_Type_contiguous(int(plane_size), MPI_DOUBLE, &plane);
  MPI_Type_commit(&plane);
  AlignedVector<double> received(wanted.size() * plane_size + zeros, 0.0);
  MPI_Alltoallv(send.data(), send_counts.data(), send_firsts.data(), plane, received.data(), recv_counts.data(),
                recv_firsts.data(), plane, comm.get());
  MPI_Type_free(&plane);
  send = AlignedVector<double>();
  // Received by sender, each sender's planes in the wished order: that is the wished order where the
  // wish goes from holder to holder in rank order (ascending planes do), else each is taken in turn.
  if (std::is_sorted(my_owners, my_owners + count)) return received;
  AlignedVector<double> out(received.size(), 0.0);
  std::vector<int> next = recv_firsts;
  for (int t = 0; t < count; ++t) {
    const int from = next[std::size_t(my_owners[t])]++;
    std::copy_n(received.begin() + std::ptrdiff_t(std::size_t(from) * plane_size), plane_size,
                out.begin() + std::ptrdiff_t(std::size_t(t) * plane_size));
  }
  return out;
}

/// Each rank's wanted layers (wrapped) from their holders.
template <int dim>
GridVector fetch_layers(const Grid<dim>& grid, const GridVector& local, Slab wanted, const Communicator& comm) {
  const int L = grid.layers();
  const Slab mine = default_slab(L, comm.rank(), comm.size());
  if (local.size() != grid.slab_size(mine)) throw std::invalid_argument("layers: vector size mismatch");
  if (wanted.count < 0 || wanted.count > L || wanted.first < 0)
    throw std::invalid_argument("layers: a range of at most the grid's layers, from layer >= 0");
  std::vector<int> list(static_cast<std::size_t>(wanted.count));
  for (int t = 0; t < wanted.count; ++t) list[std::size_t(t)] = (wanted.first + t) % L;
  return fetch_planes(local.data(), mine, grid.layer_size(), list, 0, comm);
}

}  // namespace

GridVector SlabDistribution::layers(const Grid<2>& grid, const GridVector& local, Slab wanted) const {
  return fetch_layers(grid, local, wanted, comm_);
}
GridVector SlabDistribution::layers(const Grid<3>& grid, const GridVector& local, Slab wanted) const {
  return fetch_layers(grid, local, wanted, comm_);
}

AlignedVector<double> SlabDistribution::planes(const double* local, Slab mine, std::size_t plane_size,
                                               const std::vector<int>& wanted, std::size_t zeros) const {
  return fetch_planes(local, mine, plane_size, wanted, zeros, comm_);
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
