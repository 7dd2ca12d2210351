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

namespace {
/// Adjacent lines along the slowest axis per complex DFT plan of RealDft (two cache lines of complex).
constexpr int dft_chunk = 8;
}  // namespace

RealDft::RealDft(const std::vector<int>& shape, int threads) : threads_(threads < 1 ? 1 : threads) {
  if (shape.size() < 2) throw std::invalid_argument("RealDft: needs at least two axes");
  std::lock_guard lock(planner_mutex());
  init_threads_once();
  const int layers = shape.front(), rank = int(shape.size()) - 1;
  const std::vector<int> inner(shape.begin() + 1, shape.end());
  const std::size_t real_layer = product(inner);
  layer_ = real_layer / std::size_t(inner.back()) * std::size_t(inner.back() / 2 + 1);
  double* real = static_cast<double*>(fftw_malloc(sizeof(double) * real_layer * std::size_t(layers)));
  fftw_complex* spectrum = static_cast<fftw_complex*>(fftw_malloc(sizeof(fftw_complex) * layer_ * std::size_t(layers)));
  if (real == nullptr || spectrum == nullptr) {
    fftw_free(real);
    fftw_free(spectrum);
    throw std::bad_alloc();
  }
  fftw_plan_with_nthreads(threads_);
  layers_forward_ = fftw_plan_many_dft_r2c(rank, inner.data(), layers, real, nullptr, 1, int(real_layer), spectrum,
                                           nullptr, 1, int(layer_), FFTW_ESTIMATE);
  layers_backward_ = fftw_plan_many_dft_c2r(rank, inner.data(), layers, spectrum, nullptr, 1, int(layer_), real,
                                            nullptr, 1, int(real_layer), FFTW_ESTIMATE);
  fftw_plan_with_nthreads(1);
  const int narrow = int(layer_ % dft_chunk);
  // FFTW_UNALIGNED although every chunk starts 128·c bytes into the aligned array: without it FFTW's
  // estimate picks a plan for these strided lines that makes the whole solve 3× slower (measured at 256³).
  auto lines = [&](int howmany, int sign) {
    return fftw_plan_many_dft(1, &layers, howmany, spectrum, nullptr, int(layer_), 1, spectrum, nullptr, int(layer_), 1,
                              sign, FFTW_ESTIMATE | FFTW_UNALIGNED);
  };
  if (layer_ >= std::size_t(dft_chunk))
    lines_forward_ = lines(dft_chunk, FFTW_FORWARD), lines_backward_ = lines(dft_chunk, FFTW_BACKWARD);
  if (narrow > 0) narrow_forward_ = lines(narrow, FFTW_FORWARD), narrow_backward_ = lines(narrow, FFTW_BACKWARD);
  fftw_free(real);
  fftw_free(spectrum);
  const bool lines_ok = (layer_ < std::size_t(dft_chunk) || (lines_forward_ && lines_backward_)) &&
                        (narrow == 0 || (narrow_forward_ && narrow_backward_));
  if (layers_forward_ == nullptr || layers_backward_ == nullptr || !lines_ok) {
    destroy_plans();  // the destructor does not run for a constructor that throws
    throw std::runtime_error("FFTW: could not plan the real DFT");
  }
}

void RealDft::destroy_plans() {
  for (fftw_plan* p :
       {&layers_forward_, &layers_backward_, &lines_forward_, &lines_backward_, &narrow_forward_, &narrow_backward_})
    if (*p != nullptr) fftw_destroy_plan(*p), *p = nullptr;
}

RealDft::~RealDft() {
  std::lock_guard lock(planner_mutex());
  destroy_plans();
}

void RealDft::along_slowest(std::complex<double>* spectrum, bool forward) const {
  const std::ptrdiff_t chunks = std::ptrdiff_t((layer_ + dft_chunk - 1) / dft_chunk);
  const fftw_plan wide = forward ? lines_forward_ : lines_backward_,
                  narrow = forward ? narrow_forward_ : narrow_backward_;
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (std::ptrdiff_t c = 0; c < chunks; ++c) {
    fftw_complex* first = reinterpret_cast<fftw_complex*>(spectrum + c * dft_chunk);
    fftw_execute_dft(std::size_t(c + 1) * dft_chunk <= layer_ ? wide : narrow, first, first);
  }
}

void RealDft::forward(double* real, std::complex<double>* spectrum) const {
  fftw_execute_dft_r2c(layers_forward_, real, reinterpret_cast<fftw_complex*>(spectrum));
  along_slowest(spectrum, true);
}

void RealDft::backward(std::complex<double>* spectrum, double* real) const {
  along_slowest(spectrum, false);
  fftw_execute_dft_c2r(layers_backward_, reinterpret_cast<fftw_complex*>(spectrum), real);
}

}  // namespace fictus::detail
