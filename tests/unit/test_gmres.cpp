// GMRES on systems with a known solution: a non-symmetric dense matrix, restarts, and the cap.
#include <gtest/gtest.h>

#include <random>

#include "fictus/solve/gmres.hpp"

namespace {

/// A = I·4 + R/√n with R uniform in [−1, 1]: non-symmetric, well conditioned (eigenvalues near 4).
Eigen::MatrixXd test_matrix(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> dist(-1.0, 1.0);
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) A(i, j) = dist(rng) / std::sqrt(double(n)) + (i == j ? 4.0 : 0.0);
  return A;
}

fictus::LinearOperator as_operator(const Eigen::MatrixXd& A) {
  return [&A](const Eigen::VectorXd& x, Eigen::VectorXd& y) { y = A * x; };
}

TEST(Gmres, SolvesANonSymmetricSystem) {
  const int n = 60;
  const Eigen::MatrixXd A = test_matrix(n, 5);
  const Eigen::VectorXd x_true = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
  const Eigen::VectorXd b = A * x_true;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  fictus::GmresOptions options;
  options.relative_tolerance = 1e-13;
  options.restart = n;
  const fictus::GmresReport report = fictus::gmres(as_operator(A), b, x, options);
  ASSERT_TRUE(report.converged);
  EXPECT_LE(report.relative_residual, 1e-13);
  EXPECT_LE((b - A * x).norm() / b.norm(), 1e-13);        // the reported residual is the true one
  EXPECT_LE((x - x_true).norm() / x_true.norm(), 1e-12);  // cond(A) ≈ 2: error ≈ residual
  EXPECT_LE(report.iterations, n + 1);
}

TEST(Gmres, RestartsStillConverge) {
  const int n = 80;
  const Eigen::MatrixXd A = test_matrix(n, 9);
  const Eigen::VectorXd x_true = Eigen::VectorXd::Ones(n);
  const Eigen::VectorXd b = A * x_true;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  fictus::GmresOptions options;
  options.relative_tolerance = 1e-12;
  options.restart = 10;  // eight restart cycles at least
  const fictus::GmresReport report = fictus::gmres(as_operator(A), b, x, options);
  ASSERT_TRUE(report.converged);
  EXPECT_LE((x - x_true).norm() / x_true.norm(), 1e-11);
}

TEST(Gmres, StartingFromTheSolutionTakesNoStep) {
  const int n = 20;
  const Eigen::MatrixXd A = test_matrix(n, 2);
  Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(n, 0.0, 1.0);
  const Eigen::VectorXd b = A * x, start = x;
  const fictus::GmresReport report = fictus::gmres(as_operator(A), b, x, fictus::GmresOptions{});
  EXPECT_TRUE(report.converged);
  EXPECT_LE(report.iterations, 1);  // the initial residual only
  EXPECT_LE((x - start).norm(), 1e-14);
}

TEST(Gmres, ReportsFailureAtTheCap) {
  const int n = 60;
  const Eigen::MatrixXd A = test_matrix(n, 5);
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(n);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  fictus::GmresOptions options;
  options.relative_tolerance = 1e-14;
  options.max_iterations = 3;  // far too few for 1e-14
  const fictus::GmresReport report = fictus::gmres(as_operator(A), b, x, options);
  EXPECT_FALSE(report.converged);
  EXPECT_LE(report.iterations, 3);
  EXPECT_GT(report.relative_residual, 1e-14);
}

}  // namespace
