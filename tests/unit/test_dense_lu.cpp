// The dense LU by LAPACK (dense_lu.hpp) against Eigen's.
#include "fictus/solve/dense_lu.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include <omp.h>

namespace {

Eigen::MatrixXd test_matrix(Eigen::Index n, unsigned seed) {
  std::srand(seed);
  Eigen::MatrixXd A = Eigen::MatrixXd::Random(n, n);
  A.diagonal().array() += 0.5 * double(n);  // far from singular
  return A;
}

TEST(DenseLu, SolvesAsEigensLu) {
  for (const Eigen::Index n : {1, 7, 300}) {
    const Eigen::MatrixXd A = test_matrix(n, unsigned(n));
    const Eigen::MatrixXd B = Eigen::MatrixXd::Random(n, 5);
    const fictus::DenseLu lu{Eigen::MatrixXd(A)};
    Eigen::MatrixXd X = B;
    lu.solve_in_place(X);
    const Eigen::MatrixXd expected = A.partialPivLu().solve(B);
    EXPECT_LT((X - expected).norm(), 1e-13 * expected.norm()) << n;
    EXPECT_LT((A * X - B).norm(), 1e-13 * B.norm()) << n;
    const Eigen::VectorXd x = lu.solve(B.col(2));
    EXPECT_LT((x - expected.col(2)).norm(), 1e-13 * expected.col(2).norm()) << n;
  }
}

TEST(DenseLu, RunsOnEigensThreadsAndRestoresOpenMPs) {
  const Eigen::MatrixXd A = test_matrix(400, 3);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(400, -1.0, 2.0);
  const int eigen_threads = Eigen::nbThreads(), omp_threads = omp_get_max_threads();
  Eigen::VectorXd x[2];
  for (int t = 1; t <= 2; ++t) {
    Eigen::setNbThreads(t);
    x[t - 1] = fictus::DenseLu(Eigen::MatrixXd(A)).solve(b);
    EXPECT_EQ(omp_get_max_threads(), omp_threads);
  }
  Eigen::setNbThreads(eigen_threads);
  EXPECT_LT((x[0] - x[1]).norm(), 1e-13 * x[0].norm());
}

TEST(DenseLu, EstimatesTheConditionNumber) {
  const Eigen::MatrixXd A = test_matrix(200, 5) * Eigen::VectorXd::LinSpaced(200, 1.0, 1e4).asDiagonal();
  const double norm1 = A.cwiseAbs().colwise().sum().maxCoeff();
  const double inverse_norm1 = A.inverse().cwiseAbs().colwise().sum().maxCoeff();
  const double exact = 1.0 / (norm1 * inverse_norm1);
  const double estimate = fictus::DenseLu(Eigen::MatrixXd(A)).reciprocal_condition();
  // dgecon's ‖A⁻¹‖₁ is a lower bound, usually exact: 1/κ₁ from above, within a small factor.
  EXPECT_GE(estimate, exact * (1 - 1e-10));
  EXPECT_LE(estimate, 3 * exact);
}

TEST(DenseLu, SingularGivesNoFiniteSolutionAndAZeroCondition) {
  Eigen::MatrixXd A = test_matrix(20, 7);
  A.row(4).setZero();
  const fictus::DenseLu lu{Eigen::MatrixXd(A)};
  EXPECT_FALSE(lu.solve(Eigen::VectorXd::Ones(20)).allFinite());
  EXPECT_EQ(lu.reciprocal_condition(), 0.0);
}

TEST(DenseLu, RejectsWrongShapes) {
  EXPECT_THROW(fictus::DenseLu(Eigen::MatrixXd::Ones(3, 4)), std::invalid_argument);
  const fictus::DenseLu lu{Eigen::MatrixXd::Identity(3, 3)};
  Eigen::MatrixXd B = Eigen::MatrixXd::Ones(4, 1);
  EXPECT_THROW(lu.solve_in_place(B), std::invalid_argument);
  const fictus::DenseLu empty{Eigen::MatrixXd(0, 0)};
  EXPECT_EQ(empty.size(), 0);
  EXPECT_EQ(empty.reciprocal_condition(), 1.0);
}

}  // namespace
