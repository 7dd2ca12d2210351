#pragma once
// The one place fictus touches FFTW: a non-copyable RAII plan for 2-D real-to-real transforms,
// executed on caller arrays that come from the FFTW allocator (same alignment as at planning).
#include <fftw3.h>

#include <complex>
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

/// Out-of-place 2-D real DFT pair (FFTW r2c / c2r, unnormalized) of an n_slow × n_fast real array
/// and its n_slow × (n_fast/2 + 1) half spectrum.
class RealDft2d {
 public:
  RealDft2d(int n_slow, int n_fast, int threads);
  ~RealDft2d();
  RealDft2d(const RealDft2d&) = delete;
  RealDft2d& operator=(const RealDft2d&) = delete;

  void forward(double* real, std::complex<double>* spectrum) const;   // keeps `real`
  void backward(std::complex<double>* spectrum, double* real) const;  // overwrites `spectrum`

 private:
  fftw_plan forward_ = nullptr, backward_ = nullptr;
};

}  // namespace fictus::detail
