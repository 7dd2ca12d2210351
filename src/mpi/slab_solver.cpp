#include "fictus/mpi/slab_solver.hpp"

#include <fftw3-mpi.h>

#include <algorithm>
#include <array>
#include <complex>
#include <cstring>
#include <mutex>
#include <new>
#include <stdexcept>

#include "../grid/fftw_plan.hpp"

namespace fictus::mpi {

Slab default_slab(int layers, int rank, int size) {
  const int block = (layers + size - 1) / size;
  const int first = std::min(layers, rank * block);
  return Slab{first, std::min(layers, first + block) - first};
}

/// FFTW-MPI's plans and their workspace. FFTW's axes are the grid's in reverse (slowest first): axis k
/// of `n` is the grid's axis dim − 1 − k. The spectrum is transposed: its axes are FFTW's with the
/// first two swapped, this rank holding `spectral_count` entries along the first from `spectral_first`.
template <int dim>
struct SlabSolver<dim>::Plans {
  std::array<ptrdiff_t, dim> n{};         // the transform's sizes (unknowns per axis), FFTW order
  std::array<ptrdiff_t, dim> spectrum{};  // the spectrum's sizes, FFTW order (periodic: last n/2 + 1)
  ptrdiff_t spectral_first = 0, spectral_count = 0;
  ptrdiff_t allocation = 0;  // doubles of FFTW-MPI's local array
  double* work = nullptr;    // made at the first solve that cannot run on its caller's vector
  std::once_flag work_made;
  fftw_plan forward = nullptr, backward = nullptr;
  ~Plans() {
    std::lock_guard lock(detail::planner_mutex());
    if (forward) fftw_destroy_plan(forward);
    if (backward) fftw_destroy_plan(backward);
    fftw_free(work);
  }
};

template <int dim>
SlabSolver<dim>::SlabSolver(const Grid<dim>& grid, double c, const Communicator& comm, const Execution& execution)
    : grid_(grid), symbol_(grid, c), threads_(execution.threads()), plans_(std::make_unique<Plans>()) {
  static_assert(dim == 2 || dim == 3, "SlabSolver: 2-D and 3-D");
  Plans& p = *plans_;
  const bool periodic = grid.periodic();
  for (int k = 0; k < dim; ++k) p.n[k] = periodic ? grid.n(dim - 1 - k) : grid.n(dim - 1 - k) - 1;
  p.spectrum = p.n;
  if (periodic) p.spectrum[dim - 1] = p.n[dim - 1] / 2 + 1;
  ptrdiff_t local_n0 = 0, local_0_start = 0;
  // Counted in complex entries for the real DFT (its real array is padded to 2(n/2 + 1) per row).
  const ptrdiff_t units =
      fftw_mpi_local_size_many_transposed(dim, p.spectrum.data(), 1, FFTW_MPI_DEFAULT_BLOCK, FFTW_MPI_DEFAULT_BLOCK,
                                          comm.get(), &local_n0, &local_0_start, &p.spectral_count, &p.spectral_first);
  p.allocation = std::max<ptrdiff_t>(1, periodic ? 2 * units : units);
  // FFTW-MPI's blocks are default_slab's (a rank without layers may be told any start: it takes the
  // default's). Checked on every rank together, so that all throw or none.
  slab_ = default_slab(grid.layers(), comm.rank(), comm.size());
  const bool same = local_n0 == slab_.count && (local_n0 == 0 || local_0_start == slab_.first);
  if (comm.max(same ? 0.0 : 1.0) != 0.0)
    throw std::logic_error("SlabSolver: FFTW-MPI's distribution is not the default blocks");

  std::lock_guard lock(detail::planner_mutex());
  detail::init_threads_once();
  fftw_plan_with_nthreads(threads_ < 1 ? 1 : threads_);
  // Planned on a scratch array (FFTW_ESTIMATE does not touch it), executed on the caller's vector or the
  // workspace: both aligned as FFTW's allocator aligns.
  struct Scratch {
    double* data;
    ~Scratch() { fftw_free(data); }
  } scratch{fftw_alloc_real(std::size_t(p.allocation))};
  if (scratch.data == nullptr) throw std::bad_alloc();
  double* const planned = scratch.data;
  const unsigned out = FFTW_ESTIMATE | FFTW_MPI_TRANSPOSED_OUT, in = FFTW_ESTIMATE | FFTW_MPI_TRANSPOSED_IN;
  if (periodic) {
    fftw_complex* spectrum = reinterpret_cast<fftw_complex*>(planned);
    p.forward = fftw_mpi_plan_many_dft_r2c(dim, p.n.data(), 1, FFTW_MPI_DEFAULT_BLOCK, FFTW_MPI_DEFAULT_BLOCK, planned,
                                           spectrum, comm.get(), out);
    p.backward = fftw_mpi_plan_many_dft_c2r(dim, p.n.data(), 1, FFTW_MPI_DEFAULT_BLOCK, FFTW_MPI_DEFAULT_BLOCK,
                                            spectrum, planned, comm.get(), in);
  } else {
    const std::array<fftw_r2r_kind, dim> kinds = [] {
      std::array<fftw_r2r_kind, dim> k;
      k.fill(FFTW_RODFT00);
      return k;
    }();
    p.forward = fftw_mpi_plan_many_r2r(dim, p.n.data(), 1, FFTW_MPI_DEFAULT_BLOCK, FFTW_MPI_DEFAULT_BLOCK, planned,
                                       planned, comm.get(), kinds.data(), out);
    p.backward = fftw_mpi_plan_many_r2r(dim, p.n.data(), 1, FFTW_MPI_DEFAULT_BLOCK, FFTW_MPI_DEFAULT_BLOCK, planned,
                                        planned, comm.get(), kinds.data(), in);
  }
  if (p.forward == nullptr || p.backward == nullptr)
    throw std::runtime_error("FFTW-MPI: could not plan the transforms");
  // The periodic box's padded rows always go through the workspace: made here, every rank's success
  // agreed, so that all ranks throw or none (a Dirichlet box makes it at the first solve that needs it).
  if (periodic) {
    std::call_once(p.work_made, [&] { p.work = fftw_alloc_real(std::size_t(p.allocation)); });
    if (comm.max(p.work == nullptr ? 1.0 : 0.0) != 0.0) throw std::bad_alloc();
  }
}

template <int dim>
SlabSolver<dim>::~SlabSolver() = default;

template <int dim>
std::size_t SlabSolver<dim>::workspace_bytes() const {
  return plans_->work != nullptr ? std::size_t(plans_->allocation) * sizeof(double) : 0;
}

template <int dim>
GridVector SlabSolver<dim>::make_vector() const {
  GridVector v;
  if (!grid_.periodic()) v.reserve(std::max(this->local_size(), std::size_t(plans_->allocation)));
  v.resize(this->local_size(), 0.0);
  return v;
}

template <int dim>
void SlabSolver<dim>::scale(double* data, bool inverse) const {
  const Plans& p = *plans_;
  // The transposed spectrum's axes, slowest first: FFTW's 1, 0, 2, …; its rows run along the last. Each
  // spectral axis is the grid axis dim − 1 − (FFTW axis): in 3-D the rows run along grid axis 0, in 2-D
  // along grid axis 1.
  const int inner_axis = dim == 3 ? 0 : 1;
  const ptrdiff_t row_length = dim == 3 ? p.spectrum[2] : p.spectrum[0];
  const ptrdiff_t rows = dim == 3 ? p.spectral_count * p.spectrum[0] : p.spectral_count;
  double denominator = grid_.periodic() ? 1.0 : double(1 << dim);
  for (int d = 0; d < dim; ++d) denominator *= grid_.n(d);
  const double norm = 1.0 / denominator, c = symbol_.c();
  const std::vector<double>& k_inner = symbol_.axis(inner_axis).stiffness;
  const std::vector<double>& m_inner = symbol_.axis(inner_axis).mass;
  const int width = grid_.periodic() ? 2 : 1;  // doubles per spectral entry
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (ptrdiff_t r = 0; r < rows; ++r) {
    // The modes of the row's other axes: in 3-D grid axis 1 (FFTW 1, transposed first) and grid axis 2
    // (FFTW 0); in 2-D grid axis 0 (FFTW 1).
    std::array<int, dim> mode{};
    if constexpr (dim == 3) {
      mode[1] = int(p.spectral_first + r / p.spectrum[0]);
      mode[2] = int(r % p.spectrum[0]);
    } else {
      mode[0] = int(p.spectral_first + r);
    }
    const typename Q1Symbol<dim>::Row factors = symbol_.row_without(inner_axis, mode);
    double* row = data + std::size_t(r) * std::size_t(row_length) * std::size_t(width);
    for (ptrdiff_t q = 0; q < row_length; ++q) {
      const double lambda = Q1Symbol<dim>::lambda(k_inner[std::size_t(q)], m_inner[std::size_t(q)], c, factors);
      const double factor = inverse ? (lambda > 0 ? norm / lambda : 0.0) : norm * lambda;  // λ = 0: constants, c = 0
      for (int w = 0; w < width; ++w) row[q * width + w] *= factor;
    }
  }
}

template <int dim>
void SlabSolver<dim>::transform(GridVector& v, bool inverse) const {
  if (v.size() != this->local_size()) throw std::invalid_argument("SlabSolver: vector size mismatch");
  const Plans& p = *plans_;
  const std::size_t row = std::size_t(p.n[dim - 1]);  // the grid's first axis
  const std::size_t padded = grid_.periodic() ? 2 * std::size_t(p.spectrum[dim - 1]) : row;
  const std::size_t rows = v.size() / row;
  auto copy_rows = [&](const double* from, std::size_t from_stride, double* to, std::size_t to_stride) {
#pragma omp parallel for num_threads(threads_) schedule(static)
    for (std::size_t r = 0; r < rows; ++r)
      std::memcpy(to + r * to_stride, from + r * from_stride, row * sizeof(double));
  };
  // A Dirichlet box's slab is FFTW-MPI's input layout: in place on the caller's vector where its
  // capacity holds FFTW-MPI's local array (make_vector), else through the workspace.
  const std::size_t allocation = std::size_t(p.allocation), local = v.size();
  const bool in_place = !grid_.periodic() && v.capacity() >= allocation;
  double* data = nullptr;
  if (in_place) {
    v.resize(std::max(local, allocation), 0.0);
    data = v.data();
  } else {
    std::call_once(plans_->work_made, [&] {
      plans_->work = fftw_alloc_real(allocation);
      if (plans_->work == nullptr) throw std::bad_alloc();
    });
    data = p.work;
    copy_rows(v.data(), row, data, padded);
  }
  if (grid_.periodic())
    fftw_mpi_execute_dft_r2c(p.forward, data, reinterpret_cast<fftw_complex*>(data));
  else
    fftw_mpi_execute_r2r(p.forward, data, data);
  scale(data, inverse);
  if (grid_.periodic())
    fftw_mpi_execute_dft_c2r(p.backward, reinterpret_cast<fftw_complex*>(data), data);
  else
    fftw_mpi_execute_r2r(p.backward, data, data);
  if (in_place)
    v.resize(local);
  else
    copy_rows(data, padded, v.data(), row);
}

template <int dim>
void SlabSolver<dim>::solve_in_place(GridVector& r) const {
  transform(r, true);
}

template <int dim>
void SlabSolver<dim>::apply(const GridVector& x, GridVector& y) const {
  y = x;
  transform(y, false);
}

template class SlabSolver<2>;
template class SlabSolver<3>;

}  // namespace fictus::mpi
