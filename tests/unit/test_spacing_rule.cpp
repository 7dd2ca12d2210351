// The rules for m and δ (spacing_rule.hpp): the default rule where it fits, the nearest fitting δ
// with a warning where it does not, and refusals that name what would fit.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <regex>
#include <stdexcept>
#include <string>
#include <utility>

#include "fictus/boundary/collocation.hpp"
#include "fictus/solve/spacing_rule.hpp"
#include "fictus/solve/surface_discretization.hpp"

namespace {

using fictus::SolverOptions;
using fictus::SpacingInput;
using fictus::SpacingPlan;

/// A circle of radius r in the unit box: Γ at δ keeps 2h from the box while r + δ <= 0.5 − 2h.
SpacingInput circle(double r, int N) {
  const double L = 2 * std::acos(-1.0) * r, h = 1.0 / N;
  return {2,
          L,
          h,
          1.0,
          [L](double k) { return fictus::default_multipliers(L, k, 8.0); },
          [r](double k) { return 0.5 - r - 2 * k; }};
}

/// A sphere of radius r in the unit box, as a surface.
SpacingInput sphere(double r, int N) {
  const double A = 4 * std::acos(-1.0) * r * r, h = 1.0 / N;
  return {3,
          A,
          h,
          1.0,
          [A](double k) { return fictus::default_patches(A, k, fictus::Variant::smooth); },
          [r](double k) { return 0.5 - r - 2 * k; }};
}

int number_after(const std::string& text, const std::string& words) {
  std::smatch match;
  if (!std::regex_search(text, match, std::regex(words + " (\\d+)"))) return -1;
  return std::stoi(match[1]);
}

TEST(SpacingRule, TheDefaultRuleWhereItFits) {
  const SpacingInput in = circle(0.3, 256);
  const SpacingPlan plan = fictus::plan_spacing(in, SolverOptions{});
  EXPECT_EQ(plan.m, in.default_m(in.h));
  EXPECT_DOUBLE_EQ(plan.offset, 2.0);  // on a curve
  EXPECT_DOUBLE_EQ(plan.delta, 2.0 * in.measure / plan.m);
  EXPECT_EQ(plan.warning, "");
  const SpacingInput surface = sphere(0.3, 256);
  const SpacingPlan on_surface = fictus::plan_spacing(surface, SolverOptions{});
  EXPECT_DOUBLE_EQ(on_surface.offset, 1.5);  // on a surface
  EXPECT_DOUBLE_EQ(on_surface.delta, 1.5 * on_surface.spacing);
  EXPECT_EQ(on_surface.warning, "");
}

// A circle of radius 0.3 at N = 64 (the default δ of 16h leaves the box's margin) and a sphere
// of radius 0.3 at N = 32 … 44 (δ = 1.5·5h fits from N = 48): the default rule shrinks to fit, with a warning naming
// the N from which it fits unchanged; at that N it does, one below it does not.
TEST(SpacingRule, CoarseGridsRunWithTheNearestFittingOffset) {
  for (const auto& [make, N] :
       {std::pair{&circle, 64}, std::pair{&sphere, 32}, std::pair{&sphere, 40}, std::pair{&sphere, 44}}) {
    const SpacingInput in = make(0.3, N);
    const SpacingPlan plan = fictus::plan_spacing(in, SolverOptions{});
    ASSERT_NE(plan.warning, "") << "N = " << N;
    EXPECT_NE(plan.warning.find(in.dim == 2 ? "formulation.offset: the default Γ (δ = 2 s = "
                                            : "formulation.offset: the default Γ (δ = 1.5 s = "),
              std::string::npos)
        << plan.warning;
    EXPECT_LE(plan.delta, in.room(in.h) * (1 + 1e-12));
    EXPECT_GE(plan.delta, 4 * in.h);
    EXPECT_GE(plan.spacing, 2 * in.h * (1 - 1e-12));
    EXPECT_GT(plan.m, in.default_m(in.h));                   // the points move closer
    const double standard = fictus::default_offset(in.dim);  // 2 on a curve, 1.5 on a surface
    EXPECT_NEAR(plan.offset, standard, standard * 0.1);      // δ/s stays near the default's
    EXPECT_DOUBLE_EQ(plan.offset * plan.spacing, plan.delta);
    const int keeps = number_after(plan.warning, "N >=");
    ASSERT_GT(keeps, N) << plan.warning;
    EXPECT_EQ(fictus::plan_spacing(make(0.3, keeps), SolverOptions{}).warning, "") << "N = " << keeps;
    EXPECT_NE(fictus::plan_spacing(make(0.3, keeps - 1), SolverOptions{}).warning, "") << "N = " << keeps - 1;
  }
}

/// The refusal of a given offset that does not fit, and the range of offsets it names ({-1, -1} if none).
std::pair<std::string, std::array<double, 2>> refused_offset(const SpacingInput& in, const SolverOptions& o) {
  std::string what;
  try {
    fictus::plan_spacing(in, o);
  } catch (const std::invalid_argument& e) {
    what = e.what();
  }
  std::smatch match;
  if (!std::regex_search(what, match, std::regex(R"(offsets in \[([0-9.e+-]+), ([0-9.e+-]+)\] fit)")))
    return {what, {-1, -1}};
  return {what, {std::stod(match[1]), std::stod(match[2])}};
}

TEST(SpacingRule, AGivenOffsetThatDoesNotFitNamesTheOffsetsThatDo) {
  const SpacingInput in = circle(0.3, 64);
  SolverOptions o;
  for (double offset : {0.3, 1.5, 3.0}) {  // too near (δ < 4h), too far (beyond the box margin)
    o.offset = offset;
    const auto [what, range] = refused_offset(in, o);
    const auto [low, high] = range;
    ASSERT_GT(low, 0) << offset << ": " << what;
    EXPECT_EQ(what.rfind("formulation.offset: ", 0), 0u) << what;
    EXPECT_TRUE(offset < low || offset > high) << what;
    for (double fits : {low, (low + high) / 2, high}) {  // the range it names fits, its printed ends too
      o.offset = fits;
      EXPECT_NO_THROW(fictus::plan_spacing(in, o)) << fits << ": " << what;
    }
  }
}

// The printed lower end fits where the stencil's bound lies a hair above a round offset: 3-D, m = 510
// at N = 96 on a surface of area 0.8849 puts 4h at 1.0003 s (a refusal once named [1, …] and refused 1).
TEST(SpacingRule, TheNamedOffsetsFitToTheLastPrintedDigit) {
  SpacingInput in = sphere(0.3, 96);
  in.measure = 0.884917604224;
  SolverOptions o;
  o.multipliers = 510;
  o.offset = 1.0;
  const auto [what, range] = refused_offset(in, o);
  ASSERT_GT(range[0], 1.0) << what;
  o.offset = range[0];
  EXPECT_NO_THROW(fictus::plan_spacing(in, o)) << what;
}

// Both printed ends fit, on either side, over many grids (their fourth digits run through 0 … 9).
TEST(SpacingRule, BothNamedEndsFitOnEveryGrid) {
  int named = 0;
  for (const auto& make : {&circle, &sphere})
    for (int N = 40; N <= 240; ++N)
      for (double offset : {0.05, 50.0}) {  // too near, too far
        const SpacingInput in = make(0.3, N);
        SolverOptions o;
        o.offset = offset;
        const auto [what, range] = refused_offset(in, o);
        if (range[0] < 0) continue;  // no range named (nothing fits at this N)
        ++named;
        ASSERT_LE(range[0], range[1]) << what;
        for (double end : range) {
          o.offset = end;
          EXPECT_NO_THROW(fictus::plan_spacing(in, o)) << "N = " << N << ", offset " << end << ": " << what;
        }
      }
  EXPECT_GT(named, 600);
}

// Nothing fits: the refusal names an N that runs, and N − 1 does not.
TEST(SpacingRule, NoRoomNamesTheNThatRuns) {
  for (const auto& make : {&circle, &sphere}) {
    const SpacingInput in = make(0.3, 16);
    std::string what;
    try {
      fictus::plan_spacing(in, SolverOptions{});
    } catch (const std::invalid_argument& e) {
      what = e.what();
    }
    EXPECT_EQ(what.rfind("formulation.offset: no room for Γ at N = 16", 0), 0u) << what;
    const int runs = number_after(what, "N >=");
    ASSERT_GT(runs, 16) << what;
    EXPECT_NO_THROW(fictus::plan_spacing(make(0.3, runs), SolverOptions{}));
    EXPECT_THROW(fictus::plan_spacing(make(0.3, runs - 1), SolverOptions{}), std::invalid_argument);
  }
}

TEST(SpacingRule, MultipliersOutsideTheirRangeAreRefused) {
  const SpacingInput in = circle(0.3, 64);
  SolverOptions o;
  o.multipliers = 5;
  EXPECT_THROW(fictus::plan_spacing(in, o), std::invalid_argument);
  o.multipliers = 400;
  try {
    fictus::plan_spacing(in, o);
    FAIL();
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("formulation.multipliers: m = 400 is too large", 0), 0u) << what;
    o.multipliers = number_after(what, "m <=");  // the largest it names fits
    o.variant = fictus::Variant::nonsmooth;
    EXPECT_NO_THROW(fictus::plan_spacing(in, o)) << what;
    ++o.multipliers;
    EXPECT_THROW(fictus::plan_spacing(in, o), std::invalid_argument) << what;
  }
}

}  // namespace
