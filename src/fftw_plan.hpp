#pragma once
// The one place fictus touches FFTW: a non-copyable RAII plan for 2-D real-to-real transforms,
// executed on caller arrays that come from the FFTW allocator (same alignment as at planning).
#include <fftw3.h>

#include <cstddef>

namespace fictus::detail {

enum class R2rKind { dst1, dct1 };  // FFTW RODFT00 / REDFT00, unnormalized

class R2rPlan2d {
 public:
  /// Plans an in-place transform of an n_slow × n_fast row-major array with `threads` threads.
  /// FFTW_ESTIMATE: planning never touches data and takes microseconds.
  R2rPlan2d(int n_slow, int n_fast, R2rKind kind, int threads);
  ~R2rPlan2d();
  R2rPlan2d(const R2rPlan2d&) = delete;
  R2rPlan2d& operator=(const R2rPlan2d&) = delete;

  /// In-place transform of data[0 .. n_slow·n_fast).
  void execute(double* data) const;

 private:
  fftw_plan plan_ = nullptr;
};

}  // namespace fictus::detail
