#pragma once
// The one place fictus touches FFTW: non-copyable RAII plans for multi-dimensional real-to-real
// transforms and real DFTs, executed on caller arrays from the aligned allocator (the alignment the
// plans were made for).
#include <fftw3.h>

#include <complex>
#include <cstddef>
#include <mutex>
#include <vector>

namespace fictus::detail {

/// The FFTW planner is not thread-safe: every plan is made and destroyed under this lock.
std::mutex& planner_mutex();
/// fftw_init_threads, once per process (before any plan, and before fftw_mpi_init).
void init_threads_once();

enum class R2rKind { dst1, dct1 };  // FFTW RODFT00 / REDFT00, unnormalized

class R2rPlan {
 public:
  /// Plans an in-place transform of a row-major array of shape `shape` (slowest axis first) with
  /// `threads` threads. FFTW_ESTIMATE: planning never touches data and takes microseconds.
  R2rPlan(const std::vector<int>& shape, R2rKind kind, int threads);
  ~R2rPlan();
  R2rPlan(const R2rPlan&) = delete;
  R2rPlan& operator=(const R2rPlan&) = delete;

  /// In-place transform of data[0 .. Π shape).
  void execute(double* data) const;

 private:
  fftw_plan plan_ = nullptr;
};

/// The fast solvers' transforms of chosen lines (DstSolver, the solver on slabs): adjacent lines along a
/// strided axis transformed together (two cache lines per step along the axis), and contiguous rows per
/// thread's task.
inline constexpr int line_chunk = 16;
inline constexpr int rows_per_task = 64;

/// An in-place 1-D transform of `howmany` lines of length n, each line's entries `stride` apart and the
/// lines `distance` apart, single-threaded and on any pointer (FFTW_UNALIGNED), so that callers run
/// many of them at once on threads (a transform of chosen lines of a grid). Planned on `example`, an
/// array of the extent the plan spans (FFTW_ESTIMATE does not touch it).
class R2rLines {
 public:
  R2rLines(int n, std::ptrdiff_t stride, int howmany, std::ptrdiff_t distance, R2rKind kind, double* example);
  ~R2rLines();
  R2rLines(const R2rLines&) = delete;
  R2rLines& operator=(const R2rLines&) = delete;

  void execute(double* first) const;

 private:
  fftw_plan plan_ = nullptr;
};

/// Out-of-place real DFT pair (unnormalized) of a row-major real array of shape `shape` (at least two
/// axes) and its half spectrum (the fastest axis has shape.back()/2 + 1 entries). Made as layers: one
/// FFTW r2c/c2r of the other axes for every layer of the slowest axis, then FFTW's complex DFTs along the
/// slowest axis on chunks of adjacent lines, single-threaded plans run on `threads` threads. FFTW's
/// estimated plan for the whole array strides along the slowest axis unbuffered: at 256³ it takes 3×
/// as long (bench/results/2026-11-28-mpi-fast-solve.md).
class RealDft {
 public:
  RealDft(const std::vector<int>& shape, int threads);
  ~RealDft();
  RealDft(const RealDft&) = delete;
  RealDft& operator=(const RealDft&) = delete;

  void forward(double* real, std::complex<double>* spectrum) const;   // keeps `real`
  void backward(std::complex<double>* spectrum, double* real) const;  // overwrites `spectrum`

 private:
  void along_slowest(std::complex<double>* spectrum, bool forward) const;
  void destroy_plans();  // under the planner's lock
  fftw_plan layers_forward_ = nullptr, layers_backward_ = nullptr;
  fftw_plan lines_forward_ = nullptr, lines_backward_ = nullptr;    // `chunk` lines
  fftw_plan narrow_forward_ = nullptr, narrow_backward_ = nullptr;  // the last, fewer
  std::size_t layer_ = 0;  // complex entries per layer of the spectrum (the lines along the slowest axis)
  int threads_ = 1;
};

}  // namespace fictus::detail
