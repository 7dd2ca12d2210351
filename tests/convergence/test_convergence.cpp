// Observed convergence, printed in the paper's layout:
//   - the paper's problem with the paper's method (shifted C_γ): the paper's rates, in bands;
//   - the paper's problem with fictus's default (reconstructed traces): second order in L²(ω);
//   - manufactured solutions with ∂²u/∂n² ≠ 0 on the free part and free-boundary points in general
//     position (tests/convergence/manufactured.py): both variants, N = 256 … 2048.
#include <gtest/gtest.h>

#include <iostream>

#include "fictus/solve/convergence_table.hpp"
#include "fictus/solve/fictitious_domain_solver.hpp"
#include "fictus/solve/paper_problem.hpp"
#include "manufactured_solutions.hpp"

namespace {

fictus::LevelResult level_of(const fictus::Solution& s) {
  return {s.grid.nx(),     s.grid.n_nodes(),       s.collocation.m,        s.newton.iterations,   s.fast_solves,
          s.timings.total, s.errors->rel_l2_omega, s.errors->rel_h1_omega, s.errors->rel_l2_gamma};
}

std::vector<fictus::LevelResult> run_paper(fictus::Variant variant, fictus::NormalDerivative rule, int first,
                                           int last) {
  std::vector<fictus::LevelResult> rows;
  for (int level = first; level <= last; ++level) {
    const int N = 1 << level;
    fictus::SolverOptions o = fictus::paper_options(N, variant);
    o.normal_derivative = rule;
    o.condition_number = false;
    const fictus::Solution s = fictus::solve(fictus::paper_problem(N), o);
    EXPECT_TRUE(s.newton.converged) << "N = " << N << ": " << s.newton.failure;
    rows.push_back(level_of(s));
  }
  std::cout << fictus::format_convergence_table(
      std::string("variant ") + fictus::to_string(variant) + ", " + fictus::to_string(rule) + " traces", rows, variant);
  return rows;
}

TEST(PaperMethod, NonSmoothVariant) {
  const auto rows = run_paper(fictus::Variant::nonsmooth, fictus::NormalDerivative::shifted, 6, 10);
  const auto fit = fictus::fitted_rates(rows);
  // Paper: 1.03 / 0.51 / 0.93 (fit over 1/128 … 1/4096). Bands: ±0.25 around the theory (1, ½, 1);
  // single pairs of levels scatter by ±0.3 (the kink of û crosses cells differently per level).
  EXPECT_NEAR(fit[0], 1.0, 0.25);
  EXPECT_NEAR(fit[1], 0.5, 0.25);
  EXPECT_NEAR(fit[2], 1.0, 0.25);
  for (const auto& r : rows)  // relative L²(ω) error within 25 % of the paper's
    if (auto p = fictus::paper_row(fictus::Variant::nonsmooth, r.N))
      EXPECT_NEAR(r.l2_omega / p->l2_omega, 1.0, 0.25) << "N = " << r.N;
}

TEST(PaperMethod, SmoothVariant) {
  // Level 6 is left out: with the paper's m (19 points) Γ at δ = L/m ≈ 0.1 would leave the box.
  const auto rows = run_paper(fictus::Variant::smooth, fictus::NormalDerivative::shifted, 7, 10);
  const auto rates = fictus::observed_rates(rows);
  // On the two finest pairs: at least the paper's 1.76 / 0.88 / 1.5 and at most the Q1 optimum
  // (2 / 1 / 2) plus 0.3. The coarsest pair (1/128 → 1/256) is pre-asymptotic (Γ is 5 cells
  // from ∂Ω there) and is only printed.
  for (std::size_t k = rates.size() - 2; k < rates.size(); ++k) {
    EXPECT_GE(rates[k][0], 1.76);
    EXPECT_LE(rates[k][0], 2.3);
    EXPECT_GE(rates[k][1], 0.88);
    EXPECT_LE(rates[k][1], 1.3);
    EXPECT_GE(rates[k][2], 1.50);
    EXPECT_LE(rates[k][2], 2.3);
  }
}

TEST(PaperProblem, NonSmoothVariantReconstructedTraces) {
  const auto rows = run_paper(fictus::Variant::nonsmooth, fictus::NormalDerivative::reconstructed, 7, 10);
  const auto fit = fictus::fitted_rates(rows);
  // Kink-corrected traces and field: Q1's own orders (2 / 1 / 2) up to the resolution of the contact
  // ends; measured 2.25 / 1.26 / 1.82 over 1/128 … 1/1024.
  EXPECT_GE(fit[0], 1.8);
  EXPECT_GE(fit[1], 1.0);
  EXPECT_GE(fit[2], 1.5);
  for (const auto& r : rows)  // and far below the paper's errors (8–140× at these levels)
    if (auto p = fictus::paper_row(fictus::Variant::nonsmooth, r.N)) EXPECT_LT(r.l2_omega, 0.2 * p->l2_omega);
}

TEST(PaperProblem, SmoothVariantReconstructedTraces) {
  const auto rows = run_paper(fictus::Variant::smooth, fictus::NormalDerivative::reconstructed, 8, 10);
  const auto fit = fictus::fitted_rates(rows);
  EXPECT_GE(fit[0], 1.8);
  EXPECT_GE(fit[1], 0.9);
  EXPECT_GE(fit[2], 1.8);
}

/// The manufactured problems at N = 256 … 2048 with the default options of a variant.
struct ManufacturedCase {
  std::string name;
  fictus::Variant variant;
};

class Manufactured : public ::testing::TestWithParam<ManufacturedCase> {};

TEST_P(Manufactured, ConvergesAtTheVariantsOrder) {
  const ManufacturedCase c = GetParam();
  std::vector<fictus::LevelResult> rows;
  std::vector<double> dudn_errors;
  for (int N = 256; N <= 2048; N *= 2) {
    for (const auto& mp : manufactured::all(N)) {
      if (mp.name != c.name) continue;
      fictus::SolverOptions o;
      o.variant = c.variant;
      o.condition_number = false;
      o.threads = 2;
      const fictus::Solution s = fictus::solve(mp.problem, o);
      ASSERT_TRUE(s.newton.converged) << "N = " << N << ": " << s.newton.failure;
      rows.push_back(level_of(s));
      dudn_errors.push_back(s.point_errors->max_normal_derivative);
    }
  }
  std::cout << fictus::format_convergence_table(c.name + ", " + fictus::to_string(c.variant), rows, std::nullopt);
  const auto fit = fictus::fitted_rates(rows);
  if (c.variant == fictus::Variant::smooth) {
    // Measured: 2.00 / 1.00 / 1.8–2.4 on all three.
    EXPECT_GE(fit[0], 1.8);
    EXPECT_GE(fit[1], 0.9);
    EXPECT_GE(fit[2], 1.7);
  } else {
    // Measured 1.5–2.2 in L²(ω) (the contact ends are resolved to s = 12h); the floor asked for is 0.85.
    EXPECT_GE(fit[0], 1.0);
    EXPECT_GE(fit[1], 0.9);
    EXPECT_GE(fit[2], 1.0);
  }
  // ∂u/∂n at the collocation points converges too (it does not with the shifted rule).
  EXPECT_LT(dudn_errors.back(), 0.5 * dudn_errors.front());
}

INSTANTIATE_TEST_SUITE_P(Shapes, Manufactured,
                         ::testing::Values(ManufacturedCase{"circle", fictus::Variant::smooth},
                                           ManufacturedCase{"ellipse", fictus::Variant::smooth},
                                           ManufacturedCase{"star", fictus::Variant::smooth},
                                           ManufacturedCase{"circle", fictus::Variant::nonsmooth},
                                           ManufacturedCase{"ellipse", fictus::Variant::nonsmooth},
                                           ManufacturedCase{"star", fictus::Variant::nonsmooth}),
                         [](const auto& info) {
                           return info.param.name + "_" + fictus::to_string(info.param.variant);
                         });

}  // namespace
