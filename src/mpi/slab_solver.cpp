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
  // Dirichlet: FFTW-MPI's transposition of the two slowest axes (the layout of TRANSPOSED_OUT), and back.
  fftw_plan transpose = nullptr, transpose_back = nullptr;
  ~Plans() {
    std::lock_guard lock(detail::planner_mutex());
    for (fftw_plan plan : {forward, backward, transpose, transpose_back})
      if (plan) fftw_destroy_plan(plan);
    fftw_free(work);
  }
};

namespace {
// The serial solver's tuning (DstSolver): adjacent strided lines per plan, contiguous rows per task.
constexpr int chunk = detail::line_chunk;
constexpr int rows_per_task = detail::rows_per_task;
}  // namespace

/// FFTW's 1-D plans (RODFT00) for solve_in_place_at, FFTW order [slowest … fastest]:
///   rows: lines along the fastest axis of this rank's layers (the grid's axis 0), `rows_per_task` at a
///         time, and one;
///   slow_rows (2-D): the transposed layout's lines along the slowest axis, contiguous there;
///   middle, slowest (3-D): `chunk` adjacent lines along the grid's axis 1 (this rank's layers) and axis
///         2 (the transposed layout), strided by the fastest axis, and the last, narrower chunk.
template <int dim>
struct SlabSolver<dim>::Lines {
  struct Rows {
    std::unique_ptr<detail::R2rLines> many, one;
    int length = 0;
  };
  struct Chunks {
    std::unique_ptr<detail::R2rLines> wide, narrow;
    int length = 0;
  };
  Rows rows, slow_rows;
  Chunks middle, slowest;
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
  if (!periodic) {
    // solve_in_place_at's transposition runs in the same array, in the same blocks.
    ptrdiff_t n0 = 0, first0 = 0, n1 = 0, first1 = 0;
    const std::array<ptrdiff_t, 2> two{p.n[0], p.n[1]};
    const ptrdiff_t doubles =
        fftw_mpi_local_size_many_transposed(2, two.data(), dim == 3 ? p.n[2] : 1, FFTW_MPI_DEFAULT_BLOCK,
                                            FFTW_MPI_DEFAULT_BLOCK, comm.get(), &n0, &first0, &n1, &first1);
    p.allocation = std::max(p.allocation, doubles);
    const bool same = n1 == p.spectral_count && (n1 == 0 || first1 == p.spectral_first);
    if (comm.max(same ? 0.0 : 1.0) != 0.0)
      throw std::logic_error("SlabSolver: FFTW-MPI's transposition is not in the transform's blocks");
  }
  // FFTW-MPI's blocks are default_slab's (a rank without layers may be told any start: it takes the
  // default's). Checked on every rank together, so that all throw or none.
  slab_ = default_slab(grid.layers(), comm.rank(), comm.size());
  const bool same = local_n0 == slab_.count && (local_n0 == 0 || local_0_start == slab_.first);
  if (comm.max(same ? 0.0 : 1.0) != 0.0)
    throw std::logic_error("SlabSolver: FFTW-MPI's distribution is not the default blocks");

  // Planned on a scratch array (FFTW_ESTIMATE does not touch it), executed on the caller's vector or the
  // workspace: both aligned as FFTW's allocator aligns.
  struct Scratch {
    double* data;
    ~Scratch() { fftw_free(data); }
  } scratch{fftw_alloc_real(std::size_t(p.allocation))};
  if (scratch.data == nullptr) throw std::bad_alloc();
  double* const planned = scratch.data;
  plan_transforms(comm, planned);
  // The pruned solve's plans of lines (solve_in_place_at), every rank's success agreed: that call is
  // collective, so none may fail in it alone.
  bool lines_made = true;
  if (!periodic) try {
      lines_ = plan_lines(planned);
    } catch (const std::exception&) {
      lines_made = false;
    }
  if (comm.max(lines_made ? 0.0 : 1.0) != 0.0)
    throw std::runtime_error("FFTW: could not plan the transforms of grid lines");
  // The periodic box's padded rows always go through the workspace: made here, every rank's success
  // agreed, so that all ranks throw or none (a Dirichlet box makes it at the first solve that needs it).
  if (periodic) {
    std::call_once(p.work_made, [&] { p.work = fftw_alloc_real(std::size_t(p.allocation)); });
    if (comm.max(p.work == nullptr ? 1.0 : 0.0) != 0.0) throw std::bad_alloc();
  }
}

/// FFTW-MPI's plans of the whole transforms and of the transposition, on `planned`.
template <int dim>
void SlabSolver<dim>::plan_transforms(const Communicator& comm, double* planned) {
  Plans& p = *plans_;
  const bool periodic = grid_.periodic();
  std::lock_guard lock(detail::planner_mutex());
  detail::init_threads_once();
  fftw_plan_with_nthreads(threads_ < 1 ? 1 : threads_);
  if (!periodic) {
    // The transposition of the lines along the fastest axis (3-D) or of single entries (2-D), in
    // FFTW-MPI's default blocks: those of TRANSPOSED_OUT, as scale() reads them.
    const ptrdiff_t rows = dim == 3 ? p.n[2] : 1;
    p.transpose = fftw_mpi_plan_many_transpose(p.n[0], p.n[1], rows, FFTW_MPI_DEFAULT_BLOCK, FFTW_MPI_DEFAULT_BLOCK,
                                               planned, planned, comm.get(), FFTW_ESTIMATE);
    p.transpose_back =
        fftw_mpi_plan_many_transpose(p.n[1], p.n[0], rows, FFTW_MPI_DEFAULT_BLOCK, FFTW_MPI_DEFAULT_BLOCK, planned,
                                     planned, comm.get(), FFTW_ESTIMATE);
  }
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
  if (p.forward == nullptr || p.backward == nullptr || (!periodic && (!p.transpose || !p.transpose_back)))
    throw std::runtime_error("FFTW-MPI: could not plan the transforms");
}

/// FFTW's 1-D plans of solve_in_place_at (FFTW_ESTIMATE: made on `example` without touching it).
template <int dim>
std::unique_ptr<typename SlabSolver<dim>::Lines> SlabSolver<dim>::plan_lines(double* example) const {
  const Plans& p = *plans_;
  auto lines = std::make_unique<Lines>();
  const auto kind = detail::R2rKind::dst1;
  const int x = int(p.n[dim - 1]);
  lines->rows = {std::make_unique<detail::R2rLines>(x, 1, rows_per_task, x, kind, example),
                 std::make_unique<detail::R2rLines>(x, 1, 1, x, kind, example), x};
  if constexpr (dim == 2) {
    const int y = int(p.n[0]);
    lines->slow_rows = {std::make_unique<detail::R2rLines>(y, 1, rows_per_task, y, kind, example),
                        std::make_unique<detail::R2rLines>(y, 1, 1, y, kind, example), y};
  } else {
    auto chunks = [&](int n) {
      typename Lines::Chunks c;
      c.length = n;
      if (x >= chunk) c.wide = std::make_unique<detail::R2rLines>(n, x, chunk, 1, kind, example);
      if (x % chunk != 0) c.narrow = std::make_unique<detail::R2rLines>(n, x, x % chunk, 1, kind, example);
      return c;
    };
    lines->middle = chunks(int(p.n[1]));
    lines->slowest = chunks(int(p.n[0]));
  }
  return lines;
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

namespace {
void copy_rows(const double* from, std::size_t from_stride, double* to, std::size_t to_stride, std::size_t rows,
               std::size_t row, int threads) {
#pragma omp parallel for num_threads(threads) schedule(static)
  for (std::size_t r = 0; r < rows; ++r) std::memcpy(to + r * to_stride, from + r * from_stride, row * sizeof(double));
}
}  // namespace

template <int dim>
double* SlabSolver<dim>::local_array(GridVector& v) const {
  if (v.size() != this->local_size()) throw std::invalid_argument("SlabSolver: vector size mismatch");
  Plans& p = *plans_;
  const std::size_t row = std::size_t(p.n[dim - 1]);  // the grid's first axis
  const std::size_t padded = grid_.periodic() ? 2 * std::size_t(p.spectrum[dim - 1]) : row;
  // A Dirichlet box's slab is FFTW-MPI's input layout: in place on the caller's vector where its
  // capacity holds FFTW-MPI's local array (make_vector), else through the workspace.
  const std::size_t allocation = std::size_t(p.allocation);
  if (!grid_.periodic() && v.capacity() >= allocation) {
    v.resize(std::max(v.size(), allocation), 0.0);
    return v.data();
  }
  std::call_once(p.work_made, [&] {
    p.work = fftw_alloc_real(allocation);
    if (p.work == nullptr) throw std::bad_alloc();
  });
  copy_rows(v.data(), row, p.work, padded, v.size() / row, row, threads_);
  return p.work;
}

template <int dim>
void SlabSolver<dim>::finish(GridVector& v, double* data) const {
  const std::size_t local = this->local_size();
  if (data == v.data()) {
    v.resize(local);
    return;
  }
  const Plans& p = *plans_;
  const std::size_t row = std::size_t(p.n[dim - 1]);
  const std::size_t padded = grid_.periodic() ? 2 * std::size_t(p.spectrum[dim - 1]) : row;
  copy_rows(data, padded, v.data(), row, local / row, row, threads_);
}

template <int dim>
void SlabSolver<dim>::transform(GridVector& v, bool inverse) const {
  const Plans& p = *plans_;
  double* const data = local_array(v);
  if (grid_.periodic())
    fftw_mpi_execute_dft_r2c(p.forward, data, reinterpret_cast<fftw_complex*>(data));
  else
    fftw_mpi_execute_r2r(p.forward, data, data);
  scale(data, inverse);
  if (grid_.periodic())
    fftw_mpi_execute_dft_c2r(p.backward, reinterpret_cast<fftw_complex*>(data), data);
  else
    fftw_mpi_execute_r2r(p.backward, data, data);
  finish(v, data);
}

namespace {
/// Tasks t < tasks on `threads` threads, those with `wanted(t)`.
template <typename Wanted, typename Task>
void run_tasks(std::size_t tasks, int threads, const Wanted& wanted, const Task& task) {
#pragma omp parallel for num_threads(threads) schedule(dynamic, 4)
  for (std::size_t t = 0; t < tasks; ++t)
    if (wanted(t)) task(t);
}

/// Contiguous rows [0, rows) of `length` doubles from `data`, rows_per_task per task (the tasks whose
/// rows [from, to) are `wanted`): by `many` at a time, the last few by `one`.
template <typename Wanted>
void transform_rows(const detail::R2rLines& many, const detail::R2rLines& one, double* data, std::size_t rows,
                    std::size_t length, int threads, const Wanted& wanted) {
  run_tasks((rows + rows_per_task - 1) / rows_per_task, threads,
            [&](std::size_t t) { return wanted(t * rows_per_task, std::min(rows, (t + 1) * rows_per_task)); },
            [&](std::size_t t) {
              const std::size_t from = t * rows_per_task, to = std::min(rows, from + rows_per_task);
              if (to - from == rows_per_task)
                many.execute(data + from * length);
              else
                for (std::size_t r = from; r < to; ++r) one.execute(data + r * length);
            });
}
}  // namespace

template <int dim>
void SlabSolver<dim>::transform_near(double* data, const Footprint& f, bool forward) const {
  const Lines& lines = *lines_;
  const std::size_t row = std::size_t(lines.rows.length);
  const std::size_t rows_per_layer = grid_.layer_size() / row, rows = std::size_t(slab_.count) * rows_per_layer;
  const std::size_t first_row = std::size_t(slab_.first) * rows_per_layer;
  auto meets = [&](std::size_t from, std::size_t to) {  // this rank's rows [from, to) meet f's lines
    return std::any_of(f.lines.begin() + std::ptrdiff_t(first_row + from),
                       f.lines.begin() + std::ptrdiff_t(first_row + to), [](char c) { return c != 0; });
  };
  auto run_rows = [&] { transform_rows(*lines.rows.many, *lines.rows.one, data, rows, row, threads_, meets); };
  if constexpr (dim == 2) {
    run_rows();
  } else {
    // Forward the rows come first, then the layers' lines along the middle axis (their chunks of the
    // fastest axis all carry the rows' transforms); backward the other way round.
    const std::size_t chunks = (row + chunk - 1) / chunk, middle = std::size_t(lines.middle.length);
    auto run_middle = [&] {
      run_tasks(
          std::size_t(slab_.count) * chunks, threads_,
          [&](std::size_t t) { return meets(t / chunks * rows_per_layer, (t / chunks + 1) * rows_per_layer); },
          [&](std::size_t t) {
            const std::size_t layer = t / chunks, c = t % chunks;
            double* first = data + layer * middle * row + c * chunk;
            ((c + 1) * chunk <= row ? lines.middle.wide : lines.middle.narrow)->execute(first);
          });
    };
    if (forward) {
      run_rows();
      run_middle();
    } else {
      run_middle();
      run_rows();
    }
  }
}

template <int dim>
void SlabSolver<dim>::transform_slowest(double* data) const {
  const Lines& lines = *lines_;
  const Plans& p = *plans_;
  const std::size_t count = std::size_t(p.spectral_count);  // this rank's entries of the middle axis
  if constexpr (dim == 2) {
    // The transposed layout [x][y]: this rank's lines along y are its rows.
    transform_rows(*lines.slow_rows.many, *lines.slow_rows.one, data, count, std::size_t(lines.slow_rows.length),
                   threads_, [](std::size_t, std::size_t) { return true; });
  } else {
    // The transposed layout [y][z][x]: for each of this rank's y, the lines along z, by chunks of x.
    const std::size_t row = std::size_t(lines.rows.length), chunks = (row + chunk - 1) / chunk;
    const std::size_t plane = std::size_t(lines.slowest.length) * row;
    run_tasks(
        count * chunks, threads_, [](std::size_t) { return true; },
        [&](std::size_t t) {
          const std::size_t y = t / chunks, c = t % chunks;
          ((c + 1) * chunk <= row ? lines.slowest.wide : lines.slowest.narrow)->execute(data + y * plane + c * chunk);
        });
  }
}

template <int dim>
void SlabSolver<dim>::solve_in_place_at(GridVector& r, const Footprint& load, const Footprint& wanted) const {
  if (grid_.periodic()) {
    solve_in_place(r);
    return;
  }
  const Plans& p = *plans_;
  const std::size_t row = std::size_t(p.n[dim - 1]), lines_along_row = grid_.n_unknowns() / row;
  if (load.lines.size() != lines_along_row || wanted.lines.size() != lines_along_row)
    throw std::invalid_argument("SlabSolver: footprint size mismatch");
  double* const data = local_array(r);
  transform_near(data, load, true);
  fftw_mpi_execute_r2r(p.transpose, data, data);
  transform_slowest(data);
  scale(data, true);
  transform_slowest(data);
  fftw_mpi_execute_r2r(p.transpose_back, data, data);
  transform_near(data, wanted, false);
  finish(r, data);
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
