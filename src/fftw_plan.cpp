#include "fftw_plan.hpp"

#include <sys/mman.h>

#include <cstdint>
#include <mutex>
#include <new>
#include <stdexcept>

#include "fictus/aligned_vector.hpp"

namespace fictus {
namespace detail {

namespace {
std::mutex& planner_mutex() {  // the FFTW planner is not thread-safe
  static std::mutex m;
  return m;
}
void init_threads_once() {
  static const bool ok = fftw_init_threads() != 0;
  if (!ok) throw std::runtime_error("FFTW: fftw_init_threads failed");
}
}  // namespace

void* fftw_aligned_malloc(std::size_t bytes) {
  void* p = fftw_malloc(bytes);
  // Grid arrays are touched once in full: ask for transparent huge pages, which makes their first
  // touch (page faults) markedly cheaper. Advisory only; ignored where THP is off.
  constexpr std::size_t large = std::size_t(8) << 20, page = 4096;
  if (p != nullptr && bytes >= large) {
    const std::uintptr_t begin = (reinterpret_cast<std::uintptr_t>(p) + page - 1) & ~(page - 1);
    const std::uintptr_t end = (reinterpret_cast<std::uintptr_t>(p) + bytes) & ~(page - 1);
    if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
  }
  return p;
}
void fftw_aligned_free(void* p) noexcept { fftw_free(p); }

R2rPlan2d::R2rPlan2d(int n_slow, int n_fast, R2rKind kind, int threads) {
  std::lock_guard lock(planner_mutex());
  init_threads_once();
  fftw_plan_with_nthreads(threads < 1 ? 1 : threads);
  const std::size_t n = std::size_t(n_slow) * std::size_t(n_fast);
  double* scratch = static_cast<double*>(fftw_malloc(sizeof(double) * (n == 0 ? 1 : n)));
  if (scratch == nullptr) throw std::bad_alloc();
  const fftw_r2r_kind k = kind == R2rKind::dst1 ? FFTW_RODFT00 : FFTW_REDFT00;
  plan_ = fftw_plan_r2r_2d(n_slow, n_fast, scratch, scratch, k, k, FFTW_ESTIMATE);
  fftw_free(scratch);
  if (plan_ == nullptr) throw std::runtime_error("FFTW: could not plan the transform");
}

R2rPlan2d::~R2rPlan2d() {
  std::lock_guard lock(planner_mutex());
  fftw_destroy_plan(plan_);
}

void R2rPlan2d::execute(double* data) const { fftw_execute_r2r(plan_, data, data); }

RealDft2d::RealDft2d(int n_slow, int n_fast, int threads) {
  std::lock_guard lock(planner_mutex());
  init_threads_once();
  fftw_plan_with_nthreads(threads < 1 ? 1 : threads);
  const std::size_t n_real = std::size_t(n_slow) * std::size_t(n_fast);
  const std::size_t n_complex = std::size_t(n_slow) * std::size_t(n_fast / 2 + 1);
  double* real = static_cast<double*>(fftw_malloc(sizeof(double) * n_real));
  fftw_complex* spectrum = static_cast<fftw_complex*>(fftw_malloc(sizeof(fftw_complex) * n_complex));
  if (real == nullptr || spectrum == nullptr) {
    fftw_free(real);
    fftw_free(spectrum);
    throw std::bad_alloc();
  }
  forward_ = fftw_plan_dft_r2c_2d(n_slow, n_fast, real, spectrum, FFTW_ESTIMATE);
  backward_ = fftw_plan_dft_c2r_2d(n_slow, n_fast, spectrum, real, FFTW_ESTIMATE);
  fftw_free(real);
  fftw_free(spectrum);
  if (forward_ == nullptr || backward_ == nullptr) throw std::runtime_error("FFTW: could not plan the real DFT");
}

RealDft2d::~RealDft2d() {
  std::lock_guard lock(planner_mutex());
  fftw_destroy_plan(forward_);
  fftw_destroy_plan(backward_);
}

void RealDft2d::forward(double* real, std::complex<double>* spectrum) const {
  fftw_execute_dft_r2c(forward_, real, reinterpret_cast<fftw_complex*>(spectrum));
}

void RealDft2d::backward(std::complex<double>* spectrum, double* real) const {
  fftw_execute_dft_c2r(backward_, reinterpret_cast<fftw_complex*>(spectrum), real);
}

}  // namespace detail
}  // namespace fictus
