// The solver object: the singular periodic case, reuse across obstacles and curves.
#include <gtest/gtest.h>

#include <cmath>
#include <thread>

#include "fictus/solve/fictitious_domain_solver.hpp"
#include "fictus/solve/options.hpp"
#include "fictus/solve/paper_problem.hpp"

namespace {

fictus::SolverOptions options_for(fictus::Variant variant, fictus::InnerSolver inner, int N) {
  fictus::SolverOptions o = fictus::paper_options(N, variant);
  o.inner = inner;
  return o;
}

template <class Vector>
double max_abs_diff(const Vector& a, const Vector& b) {
  double d = 0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, std::abs(a[i] - b[i]));
  return d;
}

class SingularPeriodic : public ::testing::TestWithParam<fictus::Variant> {};

TEST_P(SingularPeriodic, SolvabilityHoldsAndTheExactSolutionIsFound) {
  // c = 0 on a periodic box: A is singular; u = u₀ + A⁺B_Γᵀλ + α with 1ᵀ(f + B_Γᵀλ) = 0.
  const fictus::Variant variant = GetParam();
  std::vector<double> errors;
  for (int N : {128, 256}) {
    const fictus::Problem problem = fictus::paper_problem(N, 0.0, fictus::Boundary::periodic);
    fictus::FictitiousDomainSolver solver(problem);
    const fictus::Solution s = solver.solve(problem, options_for(variant, fictus::InnerSolver::green, N));
    ASSERT_TRUE(s.newton.converged) << s.newton.failure;
    EXPECT_LE(s.signorini.max_complementarity, 1e-10);
    EXPECT_GE(s.signorini.min_gap, -1e-10);
    EXPECT_GE(s.signorini.min_normal_derivative, -1e-10);
    // Solvability: Σ(f + B_Γᵀλ) = 0, i.e. the field satisfies A û = f + B_Γᵀλ exactly, so its
    // mean-free load balances; check it on the assembled data through the arc lengths.
    double total_load = 0;
    {
      const fictus::Grid2& grid = solver.grid();
      fictus::GridVector load = fictus::assemble_load(grid, problem.f);
      for (double v : load) total_load += v;
    }
    double multiplier_load = 0;
    const double spacing_gamma = s.collocation.spacing;
    for (double l : s.lambda) multiplier_load += l;
    if (variant == fictus::Variant::nonsmooth) {  // arcs of γ all have length L/m
      EXPECT_NEAR(total_load + spacing_gamma * multiplier_load, 0.0, 1e-12 * (std::abs(total_load) + 1));
    }
    errors.push_back(s.errors->rel_l2_omega);
  }
  // The exact solution u_ex (f = −Δu_ex) is recovered at the rate of the Dirichlet case.
  if (variant == fictus::Variant::nonsmooth) {
    EXPECT_LT(errors[0], 8e-3);  // kink-corrected field; the Dirichlet c = 1 problem gives 2.9e-3
    EXPECT_GT(std::log2(errors[0] / errors[1]), 1.5);
  } else {
    EXPECT_LT(errors[0], 2e-3);
    EXPECT_GT(std::log2(errors[0] / errors[1]), 1.7);
  }
}

TEST_P(SingularPeriodic, GreenAndKrylovAgree) {
  const fictus::Problem problem = fictus::paper_problem(128, 0.0, fictus::Boundary::periodic);
  fictus::FictitiousDomainSolver solver(problem);
  const fictus::Solution green = solver.solve(problem, options_for(GetParam(), fictus::InnerSolver::green, 128));
  fictus::SolverOptions ko = options_for(GetParam(), fictus::InnerSolver::krylov, 128);
  ko.krylov_tolerance = 1e-12;
  const fictus::Solution krylov = solver.solve(problem, ko);
  ASSERT_TRUE(green.newton.converged && krylov.newton.converged);
  EXPECT_EQ(green.newton.active, krylov.newton.active);
  double scale = 0;
  for (double l : green.lambda) scale = std::max(scale, std::abs(l));
  EXPECT_LE(max_abs_diff(green.lambda, krylov.lambda) / scale, 1e-7);  // cond(S) ≤ 1e5, GMRES to 1e-12
  EXPECT_NEAR(green.alpha, krylov.alpha, 1e-7 * (1 + std::abs(green.alpha)));
}

INSTANTIATE_TEST_SUITE_P(Variants, SingularPeriodic,
                         ::testing::Values(fictus::Variant::nonsmooth, fictus::Variant::smooth),
                         [](const auto& info) { return std::string(fictus::to_string(info.param)); });

TEST(Reuse, NewObstacleReusesTheCurveAndMatchesAFreshSolve) {
  fictus::Problem problem = fictus::paper_problem(256);
  fictus::FictitiousDomainSolver solver(problem);
  const fictus::SolverOptions o = options_for(fictus::Variant::smooth, fictus::InnerSolver::green, 256);
  const fictus::Solution first = solver.solve(problem, o);
  EXPECT_FALSE(first.reused_curve);
  const fictus::ScalarField g = problem.g;
  problem.g = [g](double x, double y) { return 0.8 * g(x, y); };
  const fictus::Solution second = solver.solve(problem, o, false);
  EXPECT_TRUE(second.reused_curve);
  EXPECT_EQ(second.fast_solves, 0u);  // boundary values only: no transform at all
  const fictus::Solution fresh = fictus::solve(problem, o);
  EXPECT_EQ(second.newton.active, fresh.newton.active);
  EXPECT_LE(max_abs_diff(second.lambda, fresh.lambda), 1e-10);
  EXPECT_LE(max_abs_diff(second.trace, fresh.trace), 1e-12);  // from the Schur blocks vs from û
  EXPECT_LE(max_abs_diff(second.normal_derivative, fresh.normal_derivative), 1e-10);
}

TEST(Reuse, DefaultMultiplierRuleAlsoReuses) {
  fictus::Problem problem = fictus::paper_problem(256);
  fictus::FictitiousDomainSolver solver(problem);
  fictus::SolverOptions o;  // m = 0: the default rule
  const fictus::Solution first = solver.solve(problem, o, false);
  const fictus::Solution second = solver.solve(problem, o, false);
  EXPECT_TRUE(second.reused_curve);
  EXPECT_EQ(second.collocation.m, first.collocation.m);
  EXPECT_EQ(second.options.multipliers, first.collocation.m);
}

TEST(Reuse, NewCurveMatchesAFreshSolve) {
  fictus::Problem problem = fictus::paper_problem(256);
  fictus::FictitiousDomainSolver solver(problem);
  const fictus::SolverOptions o = options_for(fictus::Variant::nonsmooth, fictus::InnerSolver::green, 256);
  solver.solve(problem, o);
  problem.gamma = std::make_shared<fictus::Ellipse>(fictus::Point2{0.5, 0.5}, 0.4, 0.2, 0.3);
  const fictus::Solution moved = solver.solve(problem, o);
  EXPECT_FALSE(moved.reused_curve);
  const fictus::Solution fresh = fictus::solve(problem, o);
  EXPECT_EQ(moved.newton.active, fresh.newton.active);
  EXPECT_LE(max_abs_diff(moved.lambda, fresh.lambda), 1e-10);
}

TEST(Reuse, NewLoadKeepsTheCurveAndMatchesAFreshSolve) {
  // replace_load: u₀ again, the rows and Schur blocks kept (the sweep over a parameter of f). Also on
  // the singular periodic box, where the load's total enters the bordered Newton system.
  for (const auto& [c, boundary] : {std::pair{1.0, fictus::Boundary::dirichlet}, {0.0, fictus::Boundary::periodic}}) {
    fictus::Problem problem = fictus::paper_problem(128, c, boundary);
    fictus::FictitiousDomainSolver solver(problem);
    const fictus::SolverOptions o = options_for(fictus::Variant::smooth, fictus::InnerSolver::green, 128);
    solver.solve(problem, o);
    const fictus::ScalarField f = problem.f;
    problem.f = [f](double x, double y) { return 1.7 * f(x, y) - 0.3 * x; };
    solver.replace_load(problem);
    const fictus::Solution reloaded = solver.solve(problem, o);
    EXPECT_TRUE(reloaded.reused_curve);
    const fictus::Solution fresh = fictus::solve(problem, o);
    ASSERT_TRUE(fresh.newton.converged);
    EXPECT_EQ(reloaded.newton.active, fresh.newton.active);
    EXPECT_LE(max_abs_diff(reloaded.lambda, fresh.lambda), 1e-10);
    EXPECT_LE(max_abs_diff(reloaded.u, fresh.u), 1e-12);
    EXPECT_NEAR(reloaded.alpha, fresh.alpha, 1e-12);
  }
  fictus::Problem other = fictus::paper_problem(256);
  fictus::FictitiousDomainSolver solver(fictus::paper_problem(128));
  EXPECT_THROW(solver.replace_load(other), std::invalid_argument);  // another grid needs another solver
}

TEST(Options, ThoseOfTheOtherDimensionAreRefusedPerSolveToo) {
  // The constructor checks its options; each solve checks its own: a 3-D option set in a 2-D solve
  // (or the reverse) is an error naming the key, never ignored.
  const fictus::Problem problem = fictus::paper_problem(128);
  fictus::FictitiousDomainSolver solver(problem);
  fictus::SolverOptions o = options_for(fictus::Variant::smooth, fictus::InnerSolver::green, 128);
  o.flux_balance = !o.flux_balance;
  try {
    (void)solver.solve(problem, o);
    ADD_FAILURE() << "formulation.flux_balance accepted in a 2-D solve";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("formulation.flux_balance: applies to 3-D problems only"), std::string::npos)
        << e.what();
  }
  o = options_for(fictus::Variant::smooth, fictus::InnerSolver::green, 128);
  o.nested_start = 0;
  EXPECT_THROW((void)solver.solve(problem, o), std::invalid_argument);
  fictus::DomainSettings domain(2);
  EXPECT_THROW(fictus::set_option(*fictus::find_option("far_field"), domain, o, false), std::invalid_argument);
}

TEST(ContactSummary, MeasureForceAndGapsFromThePoints) {
  const fictus::Problem problem = fictus::paper_problem(256);
  const fictus::Solution s =
      fictus::solve(problem, options_for(fictus::Variant::smooth, fictus::InnerSolver::green, 256));
  const fictus::ContactSummary c = fictus::contact_summary(s);
  double force = 0, measure = 0, min_gap = 1e300, max_gap = -1e300, total = 0;
  long points = 0;
  for (int i = 0; i < s.collocation.m; ++i) {
    min_gap = std::min(min_gap, s.trace[i] - s.g[i]);
    max_gap = std::max(max_gap, s.trace[i] - s.g[i]);
    total += s.collocation.arc[i];
    if (s.newton.active[i] == 1) ++points, force += s.normal_derivative[i] * s.collocation.arc[i];
    if (s.newton.active[i] == 1) measure += s.collocation.arc[i];
  }
  EXPECT_NEAR(total, s.collocation.length, 1e-12);  // the arcs cover γ once
  EXPECT_GT(points, 0);
  EXPECT_EQ(c.points, points);
  EXPECT_NEAR(c.measure_points, measure, 1e-14);
  EXPECT_NEAR(c.measure, measure, 0.5 * s.collocation.spacing * double(s.contact_boundary.size()));
  EXPECT_NEAR(c.force_patches, force, 1e-14 * std::abs(force));
  ASSERT_TRUE(s.domain && c.force_from_domain);  // the force is the domain identity, the patch sum its check
  EXPECT_EQ(c.force, s.domain->flux);
  EXPECT_NEAR(c.force, force, 0.02 * std::abs(force));
  EXPECT_GT(c.force, 0);
  EXPECT_EQ(c.min_gap, min_gap);
  EXPECT_EQ(c.max_gap, max_gap);
}

// The error estimate says when the solve on the grid of N/2 could not follow this grid's rule: here an
// offset of 2 (δ = 0.061) fits the ellipse's margin of 0.1 at N = 256 but not at N = 128, where m/2 doubles
// s and δ; with an offset of 1 both grids keep δ/s and s/h.
TEST(ErrorEstimate, NamesACoarseSolveOffTheRule) {
  const fictus::Problem problem = fictus::paper_problem(256);
  const auto solve_with = [&problem](double offset) {
    fictus::SolverOptions o = options_for(fictus::Variant::smooth, fictus::InnerSolver::green, 256);
    o.multipliers = 64, o.offset = offset, o.error_estimate = true;
    return fictus::solve(problem, o);
  };
  const fictus::Solution off = solve_with(2.0), on = solve_with(1.0);
  for (const fictus::Solution* s : {&off, &on}) {
    ASSERT_TRUE(s->newton.converged && s->estimate);
    ASSERT_TRUE(s->estimate->skipped.empty()) << s->estimate->skipped;
    EXPECT_EQ(s->estimate->N, 128);
  }
  EXPECT_EQ(off.options.offset, 2.0);
  EXPECT_NE(off.estimate->caveat.find("against 2 s here"), std::string::npos) << off.estimate->caveat;
  EXPECT_EQ(off.estimate->caveat.find("spacing"), std::string::npos) << off.estimate->caveat;  // m/2: s/h kept
  EXPECT_TRUE(on.estimate->caveat.empty()) << on.estimate->caveat;
}

}  // namespace

// The estimates before a solve: memory and time grow like the grid (N² and N² log N) once the grid
// dominates; GMRES is estimated slower than the explicit Schur complement; more threads, less time.
TEST(Estimates, GrowWithTheGridAndFollowTheInnerSolverAndThreads) {
  auto estimate = [](int N, fictus::InnerSolver inner, int threads) {
    const fictus::Problem problem = fictus::paper_problem(N);
    fictus::SolverOptions options = fictus::paper_options(N, fictus::Variant::smooth);
    options.inner = inner;
    options.threads = threads;
    return std::pair{double(fictus::estimated_peak_bytes(problem, options)),
                     fictus::estimated_seconds(problem, options)};
  };
  const auto [bytes_4k, seconds_4k] = estimate(4096, fictus::InnerSolver::green, 1);
  const auto [bytes_8k, seconds_8k] = estimate(8192, fictus::InnerSolver::green, 1);
  EXPECT_GT(bytes_8k / bytes_4k, 3.5);  // 4 for the grid arrays; the m² blocks and the fixed part grow less
  EXPECT_LT(bytes_8k / bytes_4k, 4.0);
  EXPECT_GT(seconds_8k / seconds_4k, 4.0);
  EXPECT_LT(seconds_8k / seconds_4k, 5.0);
  EXPECT_GT(bytes_4k, 3 * 8.0 * 4097 * 4097);  // three grid arrays at least
  EXPECT_GT(estimate(1024, fictus::InnerSolver::krylov, 1).second,
            10 * estimate(1024, fictus::InnerSolver::green, 1).second);
  if (std::thread::hardware_concurrency() >= 2)
    EXPECT_LT(estimate(4096, fictus::InnerSolver::green, 2).second, seconds_4k);
}

namespace {

TEST(SchurStorage, HierarchicalGivesTheDenseAnswerIn2d) {
  // The same code as in 3-D (one pipeline): the compressed S̃, GMRES with block LUs, refined on the
  // exact S, against the dense LU path, both variants of the paper's problem.
  const fictus::Problem problem = fictus::paper_problem(512);
  for (const fictus::Variant v : {fictus::Variant::smooth, fictus::Variant::nonsmooth}) {
    fictus::SolverOptions o = options_for(v, fictus::InnerSolver::green, 512);
    o.error_estimate = false;
    o.schur_storage = fictus::SchurStorageKind::dense;
    const fictus::Solution dense = fictus::solve(problem, o);
    o.schur_storage = fictus::SchurStorageKind::hierarchical;
    const fictus::Solution h = fictus::solve(problem, o);
    ASSERT_TRUE(dense.newton.converged && h.newton.converged) << fictus::to_string(v);
    ASSERT_TRUE(h.schur_storage.has_value());
    EXPECT_EQ(h.schur_storage->kind, "hierarchical");
    EXPECT_EQ(dense.schur_storage->kind, "dense");
    EXPECT_EQ(h.newton.active, dense.newton.active) << fictus::to_string(v);
    double largest = 0;
    for (double l : dense.lambda) largest = std::max(largest, std::abs(l));
    EXPECT_LE(max_abs_diff(h.lambda, dense.lambda), 1e-9 * largest) << fictus::to_string(v);
  }
}

}  // namespace
