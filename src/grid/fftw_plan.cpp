#include "fftw_plan.hpp"

#include <mutex>
#include <new>
#include <stdexcept>

namespace fictus::detail {

std::mutex& planner_mutex() {
  static std::mutex m;
  return m;
}

void init_threads_once() {
  static const bool ok = fftw_init_threads() != 0;
  if (!ok) throw std::runtime_error("FFTW: fftw_init_threads failed");
}

namespace {
std::size_t product(const std::vector<int>& shape) {
  std::size_t n = 1;
  for (int s : shape) n *= std::size_t(s);
  return n;
}
}  // namespace

R2rPlan::R2rPlan(const std::vector<int>& shape, R2rKind kind, int threads) {
  std::lock_guard lock(planner_mutex());
  init_threads_once();
  fftw_plan_with_nthreads(threads < 1 ? 1 : threads);
  const std::size_t n = product(shape);
  double* scratch = static_cast<double*>(fftw_malloc(sizeof(double) * (n == 0 ? 1 : n)));
  if (scratch == nullptr) throw std::bad_alloc();
  const std::vector<fftw_r2r_kind> kinds(shape.size(), kind == R2rKind::dst1 ? FFTW_RODFT00 : FFTW_REDFT00);
  plan_ = fftw_plan_r2r(int(shape.size()), shape.data(), scratch, scratch, kinds.data(), FFTW_ESTIMATE);
  fftw_free(scratch);
  if (plan_ == nullptr) throw std::runtime_error("FFTW: could not plan the transform");
}

R2rPlan::~R2rPlan() {
  std::lock_guard lock(planner_mutex());
  fftw_destroy_plan(plan_);
}

void R2rPlan::execute(double* data) const { fftw_execute_r2r(plan_, data, data); }

R2rLines::R2rLines(int n, std::ptrdiff_t stride, int howmany, std::ptrdiff_t distance, R2rKind kind, double* example) {
  std::lock_guard lock(planner_mutex());
  init_threads_once();
  fftw_plan_with_nthreads(1);
  const fftw_iodim64 line{n, stride, stride}, lines{howmany, distance, distance};
  const fftw_r2r_kind k = kind == R2rKind::dst1 ? FFTW_RODFT00 : FFTW_REDFT00;
  plan_ = fftw_plan_guru64_r2r(1, &line, 1, &lines, example, example, &k, FFTW_ESTIMATE | FFTW_UNALIGNED);
  if (plan_ == nullptr) throw std::runtime_error("FFTW: could not plan the transform of grid lines");
}

R2rLines::~R2rLines() {
  std::lock_guard lock(planner_mutex());
  fftw_destroy_plan(plan_);
}

void R2rLines::execute(double* first) const { fftw_execute_r2r(plan_, first, first); }

RealDft::RealDft(const std::vector<int>& shape, int threads) {
  std::lock_guard lock(planner_mutex());
  init_threads_once();
  fftw_plan_with_nthreads(threads < 1 ? 1 : threads);
  const std::size_t n_real = product(shape);
  const std::size_t n_complex = n_real / std::size_t(shape.back()) * std::size_t(shape.back() / 2 + 1);
  double* real = static_cast<double*>(fftw_malloc(sizeof(double) * n_real));
  fftw_complex* spectrum = static_cast<fftw_complex*>(fftw_malloc(sizeof(fftw_complex) * n_complex));
  if (real == nullptr || spectrum == nullptr) {
    fftw_free(real);
    fftw_free(spectrum);
    throw std::bad_alloc();
  }
  forward_ = fftw_plan_dft_r2c(int(shape.size()), shape.data(), real, spectrum, FFTW_ESTIMATE);
  backward_ = fftw_plan_dft_c2r(int(shape.size()), shape.data(), spectrum, real, FFTW_ESTIMATE);
  fftw_free(real);
  fftw_free(spectrum);
  if (forward_ == nullptr || backward_ == nullptr) throw std::runtime_error("FFTW: could not plan the real DFT");
}

RealDft::~RealDft() {
  std::lock_guard lock(planner_mutex());
  fftw_destroy_plan(forward_);
  fftw_destroy_plan(backward_);
}

void RealDft::forward(double* real, std::complex<double>* spectrum) const {
  fftw_execute_dft_r2c(forward_, real, reinterpret_cast<fftw_complex*>(spectrum));
}

void RealDft::backward(std::complex<double>* spectrum, double* real) const {
  fftw_execute_dft_c2r(backward_, reinterpret_cast<fftw_complex*>(spectrum), real);
}

}  // namespace fictus::detail
