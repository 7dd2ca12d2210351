// fictus against converged fitted-mesh references (tests/references/*.json: FreeFEM, P2 on meshes
// fitted to γ and graded at the contact ends, primal-dual active set, sampled values changing by
// < 1e-7 between the last two meshes) for three problems without a closed form: a rotated ellipse,
// a five-lobed star and a peanut (the last two non-convex), with free-boundary points in general
// position. Errors in ω come from the reference's polar Gauss rule, on γ from its trace samples.
#include <gtest/gtest.h>

#include <iostream>

#include "fictus/io/problem_file.hpp"
#include "reference_comparison.hpp"

namespace {

struct ReferenceCase {
  std::string name;
  fictus::Variant variant;
};

class References : public ::testing::TestWithParam<ReferenceCase> {};

TEST_P(References, ConvergeToTheFittedMeshSolution) {
  const ReferenceCase c = GetParam();
  const reference::Reference reference = reference::load(std::string(FICTUS_SOURCE_DIR) + "/tests/references", c.name);
  std::vector<fictus::LevelResult> rows;
  std::vector<double> end_errors;
  for (int N = 256; N <= 2048; N *= 2) {
    fictus::ProblemSpec spec =
        fictus::read_problem_file(std::string(FICTUS_SOURCE_DIR) + "/tests/references/" + c.name + ".toml");
    spec.problem.N = N;
    spec.options.variant = c.variant;
    spec.options.condition_number = false;
    spec.options.threads = 2;
    const fictus::Solution s = fictus::solve(spec.problem, spec.options);
    ASSERT_TRUE(s.newton.converged) << "N = " << N << ": " << s.newton.failure;
    const reference::Comparison cmp = reference::compare(reference, s);
    rows.push_back(cmp.level);
    end_errors.push_back(cmp.end_error_spacings);
  }
  std::cout << fictus::format_convergence_table(
      c.name + " against its fitted-mesh reference, " + fictus::to_string(c.variant), rows, std::nullopt);
  std::cout << "contact ends, largest distance to the reference's in spacings s = L/m:";
  for (double e : end_errors) std::cout << ' ' << e;
  std::cout << '\n';
  const auto fit = fictus::fitted_rates(rows);
  if (c.variant == fictus::Variant::smooth) {
    EXPECT_GE(fit[0], 1.8);
    EXPECT_GE(fit[2], 1.8);
  } else {
    EXPECT_GE(fit[0], 0.85);
    EXPECT_GE(fit[2], 0.85);
  }
  EXPECT_GE(fit[1], 0.85);
  for (double e : end_errors) EXPECT_LE(e, 1.0);  // every contact end within one spacing
}

INSTANTIATE_TEST_SUITE_P(Problems, References,
                         ::testing::Values(ReferenceCase{"ellipse", fictus::Variant::smooth},
                                           ReferenceCase{"star", fictus::Variant::smooth},
                                           ReferenceCase{"peanut", fictus::Variant::smooth},
                                           ReferenceCase{"ellipse", fictus::Variant::nonsmooth},
                                           ReferenceCase{"star", fictus::Variant::nonsmooth},
                                           ReferenceCase{"peanut", fictus::Variant::nonsmooth}),
                         [](const auto& info) {
                           return info.param.name + "_" + fictus::to_string(info.param.variant);
                         });

}  // namespace
