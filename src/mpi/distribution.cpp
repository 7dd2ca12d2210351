#include "fictus/mpi/distribution.hpp"

#include <fftw3-mpi.h>

#include <algorithm>
#include <climits>
#include <cstring>
#include <new>
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
/// then in P rounds sends to rank + k what it holds of that rank's wish while it receives from rank − k,
/// straight from its planes into their places (indexed datatypes: no copies). A plane no rank holds, or
/// the answer not allocated on one rank, is an error on every rank, found before anything is sent.
AlignedVector<double> fetch_planes(const double* local, Slab mine, std::size_t plane_size,
                                   const std::vector<int>& wanted, std::size_t zeros, const Communicator& comm) {
  const int P = comm.size(), me = comm.rank();
  const auto np = static_cast<std::size_t>(P);
  std::vector<int> held(2 * np), counts(np);
  const int slab[2] = {mine.first, mine.count}, count = int(wanted.size());
  MPI_Allgather(slab, 2, MPI_INT, held.data(), 2, MPI_INT, comm.get());
  MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, comm.get());
  std::vector<int> firsts(np, 0);
  for (std::size_t r = 1; r < np; ++r) firsts[r] = firsts[r - 1] + counts[r - 1];
  std::vector<int> wishes(std::size_t(firsts.back() + counts.back()));
  MPI_Allgatherv(wanted.data(), count, MPI_INT, wishes.data(), counts.data(), firsts.data(), MPI_INT, comm.get());
  if (plane_size > std::size_t(INT_MAX))  // a plane is one MPI datatype; the same on every rank
    throw std::invalid_argument("planes: a plane of more than INT_MAX numbers");
  int planes = 0;  // the planes held by some rank: [0, planes)
  for (std::size_t r = 0; r < np; ++r) planes = std::max(planes, held[2 * r] + held[2 * r + 1]);
  std::vector<int> holder(std::size_t(planes), -1);
  for (std::size_t r = 0; r < np; ++r)
    for (int z = held[2 * r]; z < held[2 * r] + held[2 * r + 1]; ++z) holder[std::size_t(z)] = int(r);
  for (int w : wishes)
    if (w < 0 || w >= planes || holder[std::size_t(w)] < 0)
      throw std::invalid_argument("planes: a wanted plane that no rank holds");  // every rank sees it
  AlignedVector<double> out;
  bool allocated = true;
  try {
    out.assign(wanted.size() * plane_size + zeros, 0.0);
  } catch (const std::bad_alloc&) {
    allocated = false;
  }
  if (comm.max(allocated ? 0.0 : 1.0) != 0.0) throw std::bad_alloc();
  MPI_Datatype plane;
  MPI_Type_contiguous(int(plane_size), MPI_DOUBLE, &plane);
  MPI_Type_commit(&plane);
  std::vector<int> sent, received;  // in planes: this rank's planes sent to `to`, the places of `from`'s
  for (int k = 0; k < P; ++k) {
    const int to = (me + k) % P, from = (me - k + P) % P;
    sent.clear(), received.clear();
    for (int t = firsts[std::size_t(to)]; t < firsts[std::size_t(to)] + counts[std::size_t(to)]; ++t)
      if (const int w = wishes[std::size_t(t)]; holder[std::size_t(w)] == me) sent.push_back(w - mine.first);
    for (int t = 0; t < count; ++t)
      if (holder[std::size_t(wanted[std::size_t(t)])] == from) received.push_back(t);
    MPI_Datatype send_type = plane, receive_type = plane;
    if (!sent.empty()) {
      MPI_Type_create_indexed_block(int(sent.size()), 1, sent.data(), plane, &send_type);
      MPI_Type_commit(&send_type);
    }
    if (!received.empty()) {
      MPI_Type_create_indexed_block(int(received.size()), 1, received.data(), plane, &receive_type);
      MPI_Type_commit(&receive_type);
    }
    MPI_Sendrecv(local, sent.empty() ? 0 : 1, send_type, to, 0, out.data(), received.empty() ? 0 : 1, receive_type,
                 from, 0, comm.get(), MPI_STATUS_IGNORE);
    if (!sent.empty()) MPI_Type_free(&send_type);
    if (!received.empty()) MPI_Type_free(&receive_type);
  }
  MPI_Type_free(&plane);
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
