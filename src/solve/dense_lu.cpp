#include "fictus/solve/dense_lu.hpp"

#include <climits>
#include <cstddef>
#include <stdexcept>
#include <string>

#include <omp.h>

// LAPACK's Fortran interface (OpenBLAS; 32-bit integers). The trailing lengths are those of the
// character arguments (gfortran's convention).
extern "C" {
void dgetrf_(const int* m, const int* n, double* a, const int* lda, int* ipiv, int* info);
void dgetrs_(const char* trans, const int* n, const int* nrhs, const double* a, const int* lda, const int* ipiv,
             double* b, const int* ldb, int* info, std::size_t trans_length);
void dgecon_(const char* norm, const int* n, const double* a, const int* lda, const double* anorm, double* rcond,
             double* work, int* iwork, int* info, std::size_t norm_length);
}

namespace fictus {

namespace {

int lapack_size(Eigen::Index n, const char* what) {
  if (n < 0 || n > INT_MAX) throw std::length_error(std::string("DenseLu: ") + what + " too large for LAPACK");
  return int(n);
}

void check(int info, const char* routine) {
  if (info < 0) throw std::logic_error(std::string(routine) + ": argument " + std::to_string(-info) + " is invalid");
}

/// OpenBLAS (its OpenMP build) runs on omp_get_max_threads() threads: those of Eigen while alive.
class LapackThreads {
 public:
  LapackThreads() : saved_(omp_get_max_threads()) { omp_set_num_threads(Eigen::nbThreads()); }
  ~LapackThreads() { omp_set_num_threads(saved_); }
  LapackThreads(const LapackThreads&) = delete;
  LapackThreads& operator=(const LapackThreads&) = delete;

 private:
  int saved_;
};

}  // namespace

void DenseLu::compute(Eigen::MatrixXd&& A) {
  if (A.rows() != A.cols()) throw std::invalid_argument("DenseLu: the matrix is not square");
  const int n = lapack_size(A.rows(), "matrix");
  factors_.resize(0, 0);  // empty until the factors are done: a throw below leaves nothing to solve with
  pivots_.clear();
  Eigen::MatrixXd factors = std::move(A);
  const double norm1 = n > 0 ? factors.cwiseAbs().colwise().sum().maxCoeff() : 0.0;
  std::vector<int> pivots(static_cast<std::size_t>(n));
  if (n > 0) {
    int info = 0;
    {
      const LapackThreads threads;
      dgetrf_(&n, &n, factors.data(), &n, pivots.data(), &info);
    }
    check(info, "dgetrf");  // info > 0: an exact zero pivot (singular); solutions are then not finite
  }
  factors_ = std::move(factors);
  pivots_ = std::move(pivots);
  norm1_ = norm1;
}

void DenseLu::solve_in_place(Eigen::MatrixXd& B, bool transposed) const {
  if (B.rows() != size()) throw std::invalid_argument("DenseLu::solve: the right-hand side has the wrong size");
  if (empty() || B.cols() == 0) return;
  const int n = int(size()), nrhs = lapack_size(B.cols(), "right-hand side");
  int info = 0;
  const LapackThreads threads;
  dgetrs_(transposed ? "T" : "N", &n, &nrhs, factors_.data(), &n, pivots_.data(), B.data(), &n, &info, 1);
  check(info, "dgetrs");
}

Eigen::VectorXd DenseLu::solve(const Eigen::VectorXd& r, bool transposed) const {
  Eigen::MatrixXd x = r;
  solve_in_place(x, transposed);
  return x.col(0);
}

double DenseLu::reciprocal_condition() const {
  if (empty()) return size() == 0 ? 1.0 : 0.0;
  const int n = int(size());
  double rcond = 0.0;
  std::vector<double> work(4 * std::size_t(n));
  std::vector<int> iwork(static_cast<std::size_t>(n));
  int info = 0;
  const LapackThreads threads;
  dgecon_("1", &n, factors_.data(), &n, &norm1_, &rcond, work.data(), iwork.data(), &info, 1);
  check(info, "dgecon");
  return rcond;
}

}  // namespace fictus
