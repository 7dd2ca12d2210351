// Newton on the paper's problem: convergence, discrete Signorini conditions, agreement of the
// explicit (Green) and implicit (Krylov) Schur complements and of the two starts.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "fictus/solve/fictitious_domain_solver.hpp"
#include "fictus/solve/paper_problem.hpp"

namespace {

fictus::Solution solve_paper(int N, fictus::Variant variant, fictus::InnerSolver inner, bool all_active = true) {
  fictus::SolverOptions o = fictus::paper_options(N, variant);
  o.inner = inner;
  o.start_all_active = all_active;
  return fictus::solve(fictus::paper_problem(N), o);
}

class NewtonTest : public ::testing::TestWithParam<fictus::Variant> {};

TEST_P(NewtonTest, ConvergesAndSatisfiesSignorini) {
  const fictus::Solution s = solve_paper(128, GetParam(), fictus::InnerSolver::green);
  ASSERT_TRUE(s.newton.converged) << s.newton.failure;
  EXPECT_LE(s.newton.iterations, 12);
  constexpr double tol = 1e-10;  // the B/C rows are solved by a dense LU: round-off level
  EXPECT_GE(s.signorini.min_gap, -tol);
  EXPECT_GE(s.signorini.min_normal_derivative, -tol);
  EXPECT_LE(s.signorini.max_complementarity, tol);
  // The contact set is γ₁ = γ minus the quarter x < ½, y < ½: about three quarters of the points.
  const long active = std::count(s.newton.active.begin(), s.newton.active.end(), 1);
  EXPECT_NEAR(double(active) / s.collocation.m, 0.75, 0.1);
}

TEST_P(NewtonTest, GreenAndKrylovAgree) {
  const fictus::Solution green = solve_paper(128, GetParam(), fictus::InnerSolver::green);
  const fictus::Solution krylov = solve_paper(128, GetParam(), fictus::InnerSolver::krylov);
  ASSERT_TRUE(green.newton.converged && krylov.newton.converged);
  EXPECT_EQ(green.newton.active, krylov.newton.active);
  EXPECT_EQ(green.newton.iterations, krylov.newton.iterations);
  double diff = 0, size = 0;
  for (std::size_t i = 0; i < green.lambda.size(); ++i) {
    diff = std::max(diff, std::abs(green.lambda[i] - krylov.lambda[i]));
    size = std::max(size, std::abs(green.lambda[i]));
  }
  // GMRES stops at 1e-10 relative residual; cond(S) ≤ 1e4 here.
  EXPECT_LE(diff / size, 1e-6);
  EXPECT_NEAR(green.errors->rel_l2_omega, krylov.errors->rel_l2_omega, 1e-6 * green.errors->rel_l2_omega);
  EXPECT_GT(krylov.fast_solves, std::size_t(krylov.newton.iterations));
}

TEST_P(NewtonTest, BothStartsReachTheSameSolution) {
  const fictus::Solution all = solve_paper(128, GetParam(), fictus::InnerSolver::green, true);
  const fictus::Solution zero = solve_paper(128, GetParam(), fictus::InnerSolver::green, false);
  ASSERT_TRUE(all.newton.converged && zero.newton.converged);
  EXPECT_EQ(all.newton.active, zero.newton.active);
  for (std::size_t i = 0; i < all.lambda.size(); ++i)
    EXPECT_NEAR(all.lambda[i], zero.lambda[i], 1e-8 * (1 + std::abs(all.lambda[i])));
}

INSTANTIATE_TEST_SUITE_P(Variants, NewtonTest, ::testing::Values(fictus::Variant::nonsmooth, fictus::Variant::smooth),
                         [](const auto& info) { return std::string(fictus::to_string(info.param)); });

TEST(Solve, RejectsBadOptions) {
  fictus::SolverOptions o;
  o.rho = -1;
  EXPECT_THROW(fictus::solve(fictus::paper_problem(64), o), std::invalid_argument);
  o = {};
  o.multipliers = 500;  // spacing < 2h at N = 64
  EXPECT_THROW(fictus::solve(fictus::paper_problem(64), o), std::invalid_argument);
  o = {};
  EXPECT_THROW(fictus::solve(fictus::paper_problem(4), o), std::invalid_argument);
}

}  // namespace

namespace {

// A small variational inequality with a known answer, built backwards: pick λ*, the contact set 𝒜
// and the traces b* = B_γu, c* = C_γu with b* = g, c* > 0 on 𝒜 and c* = 0, b* > g off it; then
// b₀ = b* − S_Bλ*, c₀ = c* − S_Cλ*. The blocks are diagonally dominant (a P-matrix problem: the
// answer is unique), so Newton must return exactly (λ*, 𝒜).
TEST(SemismoothNewton, SolvesASmallVariationalInequalityWithAKnownAnswer) {
  const int m = 8;
  const fictus::ActiveSet contact = {1, 0, 1, 1, 0, 0, 1, 0};
  Eigen::MatrixXd S_B(m, m), S_C(m, m);
  Eigen::VectorXd lambda(m), g(m), b(m), c(m);
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < m; ++j) {
      S_B(i, j) = (i == j ? 1.0 : 0.0) + 0.05 * std::sin(1.3 * i + 0.7 * j);
      S_C(i, j) = (i == j ? 2.0 : 0.0) + 0.05 * std::cos(0.9 * i - 1.1 * j);
    }
    lambda(i) = 0.5 + 0.1 * i;
    g(i) = std::sin(0.8 * i);
    b(i) = contact[i] ? g(i) : g(i) + 0.2 + 0.05 * i;
    c(i) = contact[i] ? 0.3 + 0.07 * i : 0.0;
  }
  const Eigen::VectorXd b0 = b - S_B * lambda, c0 = c - S_C * lambda;
  const fictus::ExplicitSchur schur(S_B, S_C);
  for (bool all_active : {true, false}) {
    fictus::NewtonOptions options;
    options.start_all_active = all_active;
    options.tolerance = 1e-13;
    const fictus::NewtonResult r = fictus::solve_semismooth_newton(schur, b0, c0, g, options);
    ASSERT_TRUE(r.converged) << r.failure;
    EXPECT_EQ(r.active, contact);
    EXPECT_LE((r.lambda - lambda).cwiseAbs().maxCoeff(), 1e-13);  // dense LU of an 8 × 8, cond ≈ 3
    EXPECT_LE((r.trace - b).cwiseAbs().maxCoeff(), 1e-13);
    EXPECT_LE((r.normal_derivative - c).cwiseAbs().maxCoeff(), 1e-13);
    EXPECT_LE(r.iterations, 6);  // finite termination: a few active-set changes
  }
  // Handed on after the first step, then on from there (another Schur complement's run may take over):
  // the same answer, the same steps in all.
  fictus::NewtonOptions options;
  options.tolerance = 1e-13;
  const fictus::NewtonResult whole = fictus::solve_semismooth_newton(schur, b0, c0, g, options);
  ASSERT_GE(whole.history.size(), 2u);
  const int changed = whole.history.front().n_changed;  // by the first step
  ASSERT_GT(changed, 0);
  options.hand_on_at_changes = changed - 1;  // not yet after the first step
  const fictus::NewtonResult later = fictus::solve_semismooth_newton(schur, b0, c0, g, options);
  EXPECT_GT(later.iterations, 1);
  options.hand_on_at_changes = changed;  // at the first step
  const fictus::NewtonResult first = fictus::solve_semismooth_newton(schur, b0, c0, g, options);
  EXPECT_TRUE(first.handed_on);
  EXPECT_FALSE(first.converged);
  EXPECT_EQ(first.iterations, 1);
  options.hand_on_at_changes = -1;
  options.start = &first;
  const fictus::NewtonResult rest = fictus::solve_semismooth_newton(schur, b0, c0, g, options);
  ASSERT_TRUE(rest.converged) << rest.failure;
  EXPECT_EQ(rest.active, contact);
  EXPECT_LE((rest.lambda - lambda).cwiseAbs().maxCoeff(), 1e-13);
  EXPECT_EQ(first.iterations + rest.iterations, whole.iterations);
  // A start of another size is refused.
  fictus::NewtonResult wrong = first;
  wrong.lambda.resize(m - 1);
  options.start = &wrong;
  EXPECT_THROW(fictus::solve_semismooth_newton(schur, b0, c0, g, options), std::invalid_argument);
}

}  // namespace

namespace {

/// Blocks S_B, S_C (diagonally dominant, not symmetric) and a bordering for the NewtonFactorization tests.
struct NewtonBlocks {
  Eigen::MatrixXd S_B, S_C;
  fictus::ConstantMode mode;
};

NewtonBlocks newton_blocks(int m) {
  NewtonBlocks b{Eigen::MatrixXd(m, m), Eigen::MatrixXd(m, m), {}};
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) {
      b.S_B(i, j) = (i == j ? 4.0 : 0.0) + std::sin(0.37 * i + 1.3 * j) / (1.0 + std::abs(i - j));
      b.S_C(i, j) = (i == j ? 3.0 : 0.0) + std::cos(0.11 * i - 0.7 * j) / (1.0 + std::abs(i - j));
    }
  b.mode.trace_B = Eigen::VectorXd::LinSpaced(m, 1.0, 2.0);
  b.mode.trace_C = Eigen::VectorXd::LinSpaced(m, -0.5, 0.5);
  b.mode.arc_weights = Eigen::VectorXd::Constant(m, 1.0 / m);
  return b;
}

}  // namespace

// The kept LU with low-rank updates (NewtonFactorization) against a fresh LU of each S_𝒜: a sequence
// of active sets that changes a few rows of the factored one (solved through the update, which keeps
// the columns of rows changed before), more than update_fraction of them (factored anew), and back;
// with and without the bordering of c = 0. (The refinement would hide an update wrong by 1e-6, not
// a wrong column or sign.)
TEST(NewtonFactorization, UpdatesSolveAsAFreshLu) {
  const int m = 200;
  const auto [S_B, S_C, mode] = newton_blocks(m);
  const fictus::ExplicitSchur schur(S_B, S_C);
  const int cap = int(fictus::NewtonFactorization::update_fraction * m);  // 25 rows
  for (const fictus::ConstantMode* bordering : std::array<const fictus::ConstantMode*, 2>{nullptr, &mode}) {
    const int before = schur.factorizations();
    fictus::ActiveSet base(m, 1);
    for (int i = 0; i < m; i += 3) base[i] = 0;
    const auto flipped = [&](const std::vector<int>& rows) {
      fictus::ActiveSet active = base;
      for (const int i : rows) active[std::size_t(i)] ^= 1;
      return active;
    };
    const auto first_rows = [&](int count) {  // rows 3, 10, 17, …
      std::vector<int> rows;
      for (int k = 0; k < count; ++k) rows.push_back((7 * k + 3) % m);
      return rows;
    };
    std::vector<int> far = first_rows(cap + 5), far_and_more = far;
    far_and_more.insert(far_and_more.end(), {150, 151, 190});
    // The rows flipped against `base`, step by step: 1, 10, cap (updates, each keeping the earlier rows'
    // columns), a set whose kept columns move ({3, 10, 17} → {10, 17, 24} → {10}), back to the base,
    // the same set twice, cap + 1 and cap + 5 (factored anew), and updates from that new base.
    const std::vector<std::vector<int>> sequence = {
        {}, first_rows(1), first_rows(10), first_rows(cap),     {3, 10, 17}, {10, 17, 24}, {10},
        {}, {10},          {10},           first_rows(cap + 1), far,         far_and_more, first_rows(cap + 1),
        {}};
    int expected_factorizations = 0;
    bool was_updated = false;
    fictus::ActiveSet factored;
    for (std::size_t step = 0; step < sequence.size(); ++step) {
      const fictus::ActiveSet active = flipped(sequence[step]);
      const fictus::NewtonFactorization& f = schur.factorization(active, bordering);
      // An LU happens at the first call and whenever the set is too far from the factored one.
      int differ = 0;
      for (int i = 0; i < m && !factored.empty(); ++i) differ += active[std::size_t(i)] != factored[std::size_t(i)];
      if (factored.empty() || differ > cap) ++expected_factorizations, factored = active, differ = 0;
      EXPECT_EQ(schur.factorizations() - before, expected_factorizations) << "step " << step;
      EXPECT_EQ(f.updated(), differ > 0) << "step " << step;
      was_updated = was_updated || f.updated();
      const Eigen::MatrixXd S = schur.newton_matrix(active, bordering);
      const Eigen::VectorXd r = Eigen::VectorXd::LinSpaced(S.rows(), -1.0, 3.0);
      const Eigen::VectorXd x = f.solve(r), fresh = S.partialPivLu().solve(r);
      EXPECT_LE((x - fresh).norm(), 1e-12 * fresh.norm()) << "step " << step;
      Eigen::VectorXd y;
      schur.apply_newton(active, bordering, x, y);  // S_𝒜 x without forming S_𝒜
      EXPECT_LE((y - S * x).norm(), 1e-13 * (S * x).norm());
    }
    EXPECT_TRUE(was_updated);
    // Another bordering is another matrix: factored anew (all active: far from the next round's sets).
    const int now = schur.factorizations();
    schur.factorization(fictus::ActiveSet(m, 1), bordering ? nullptr : &mode);
    EXPECT_EQ(schur.factorizations(), now + 1);
  }
}

// Mixed conditions: on a small S (symmetric, diagonally dominant) Dirichlet rows hold b = g and Neumann
// rows c = q whatever the start; the Signorini rows satisfy their conditions; with only fixed rows one
// linear solve does it.
TEST(NewtonMixedConditions, FixedRowsHoldAndSignoriniRowsChoose) {
  const int m = 12;
  Eigen::MatrixXd S_B(m, m), S_C(m, m);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) {
      S_B(i, j) = (i == j ? 4.0 : 0.0) + 0.3 / (1 + std::abs(i - j));
      S_C(i, j) = (i == j ? 3.0 : 0.0) + 0.2 / (1 + std::abs(i - j)) + 0.05 * ((i + j) % 3);
    }
  const fictus::ExplicitSchur schur(S_B, S_C);
  Eigen::VectorXd b0(m), c0(m), g(m);
  for (int i = 0; i < m; ++i) b0(i) = 0.1 * i - 0.5, c0(i) = 0.2 * std::sin(double(i)), g(i) = 0.05 * (i % 4);
  fictus::PointConditions conditions;
  conditions.kind.assign(m, fictus::PointCondition::signorini);
  conditions.flux = Eigen::VectorXd::Zero(m);
  for (int i : {0, 1, 2}) conditions.kind[std::size_t(i)] = fictus::PointCondition::dirichlet;
  for (int i : {7, 8})
    conditions.kind[std::size_t(i)] = fictus::PointCondition::neumann, conditions.flux(i) = 0.3 - i * 0.1;
  for (const bool all : {true, false}) {
    fictus::NewtonOptions o;
    o.start_all_active = all;
    o.conditions = &conditions;
    const fictus::NewtonResult r = fictus::solve_semismooth_newton(schur, b0, c0, g, o);
    ASSERT_TRUE(r.converged) << r.failure;
    for (int i = 0; i < m; ++i) {
      if (conditions.kind[std::size_t(i)] == fictus::PointCondition::dirichlet) {
        EXPECT_EQ(r.active[std::size_t(i)], 1);
        EXPECT_NEAR(r.trace(i), g(i), 1e-12);
      } else if (conditions.kind[std::size_t(i)] == fictus::PointCondition::neumann) {
        EXPECT_EQ(r.active[std::size_t(i)], 0);
        EXPECT_NEAR(r.normal_derivative(i), conditions.flux(i), 1e-12);
      } else {  // Signorini: u ≥ g, ∂u/∂n ≥ 0, complementarity
        EXPECT_GE(r.trace(i) - g(i), -1e-12);
        EXPECT_GE(r.normal_derivative(i), -1e-12);
        EXPECT_LE(std::abs((r.trace(i) - g(i)) * r.normal_derivative(i)), 1e-12);
      }
    }
  }
  for (auto& kind : conditions.kind)  // no Signorini row left: linear, one step
    if (kind == fictus::PointCondition::signorini) kind = fictus::PointCondition::dirichlet;
  fictus::NewtonOptions o;
  o.conditions = &conditions;
  const fictus::NewtonResult r = fictus::solve_semismooth_newton(schur, b0, c0, g, o);
  ASSERT_TRUE(r.converged);
  EXPECT_EQ(r.iterations, 1);
  conditions.kind.pop_back();
  EXPECT_THROW(fictus::solve_semismooth_newton(schur, b0, c0, g, o), std::invalid_argument);
}

// cond₂(S_𝒜) by Lanczos from the kept LU against all singular values (Eigen's SVD): on the matrices above
// (bordered and not, prepared through an update, so factored anew for the transposed solves), and on a
// matrix of given singular values 1e-6 … 1 whose two largest and two smallest lie 0.1 % apart, where the
// Lanczos process needs the most steps to tell them apart. Each estimate is never above the truth.
TEST(NewtonFactorization, ConditionNumberIsThatOfTheSingularValues) {
  const auto exact = [](const Eigen::MatrixXd& S) {
    const Eigen::BDCSVD<Eigen::MatrixXd> svd(S);
    const Eigen::VectorXd& s = svd.singularValues();
    return s(0) / s(s.size() - 1);
  };
  const int m = 200;
  const auto [S_B, S_C, mode] = newton_blocks(m);
  const fictus::ExplicitSchur schur(S_B, S_C);
  for (const fictus::ConstantMode* bordering : std::array<const fictus::ConstantMode*, 2>{nullptr, &mode}) {
    fictus::ActiveSet active(m, 1);
    for (int i = 0; i < m; i += 3) active[std::size_t(i)] = 0;
    schur.factorization(active, bordering);
    active[5] ^= 1, active[40] ^= 1;
    EXPECT_TRUE(schur.factorization(active, bordering).updated());
    const double want = exact(schur.newton_matrix(active, bordering));
    const double got = *schur.condition_number(active, bordering);
    EXPECT_LE(got, want * (1 + 1e-12));
    EXPECT_NEAR(got, want, 1e-9 * want) << (bordering ? "bordered" : "not bordered");
  }
  // U Σ Vᵀ with orthogonal U, V from the QR of two fixed matrices.
  Eigen::MatrixXd P(m, m), R(m, m);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) P(i, j) = std::sin(1.7 * i * j + i), R(i, j) = std::cos(0.9 * i * j - j);
  const Eigen::MatrixXd U = Eigen::HouseholderQR<Eigen::MatrixXd>(P).householderQ(),
                        V = Eigen::HouseholderQR<Eigen::MatrixXd>(R).householderQ();
  Eigen::VectorXd sigma =
      Eigen::VectorXd::LinSpaced(m, 0.0, -6.0).unaryExpr([](double e) { return std::pow(10.0, e); });
  sigma(1) = 0.999 * sigma(0), sigma(m - 2) = 1.001 * sigma(m - 1);
  const Eigen::MatrixXd S = U * sigma.asDiagonal() * V.transpose();
  const fictus::ExplicitSchur spread(S, S_C);
  const double got = *spread.condition_number(fictus::ActiveSet(m, 1), nullptr);
  EXPECT_LE(got, 1e6 * (1 + 1e-9));
  EXPECT_NEAR(got, exact(S), 1e-8 * exact(S));
  // Singular (a zero row): the LU's solves are not finite, so there is no value.
  Eigen::MatrixXd Z = S;
  Z.row(7).setZero();
  EXPECT_FALSE(fictus::ExplicitSchur(Z, S_C).condition_number(fictus::ActiveSet(m, 1), nullptr).has_value());
  // Fewer than 3 unknowns (Spectra's least): the singular values in full.
  const Eigen::MatrixXd T{{2.0, 1.0}, {0.0, 0.5}};
  EXPECT_NEAR(*fictus::ExplicitSchur(T, T).condition_number(fictus::ActiveSet(2, 1), nullptr), exact(T),
              1e-12 * exact(T));
}
