// Convergence tables: the paper's rates beside ours follow the levels shown.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "fictus/solve/convergence_table.hpp"
#include "fictus/solve/paper_problem.hpp"

namespace {

std::vector<fictus::LevelResult> levels(int first, int last) {
  std::vector<fictus::LevelResult> rows;
  for (int level = first; level <= last; ++level)
    rows.push_back({.N = 1 << level, .l2_omega = 1, .h1_omega = 1, .l2_gamma = 1});
  return rows;
}

TEST(ConvergenceTable, PaperRatesFollowTheLevelsShown) {
  using fictus::Variant;
  // All six of the paper's levels: its printed rates.
  const auto all = fictus::paper_rates_over(Variant::smooth, levels(7, 12));
  ASSERT_TRUE(all);
  EXPECT_EQ(*all, fictus::paper_rates(Variant::smooth));
  // Two of them: the slope between its two rows, log2(e(1/128)/e(1/256)).
  const auto two = fictus::paper_rates_over(Variant::nonsmooth, levels(7, 8));
  ASSERT_TRUE(two);
  const auto a = *fictus::paper_row(Variant::nonsmooth, 128), b = *fictus::paper_row(Variant::nonsmooth, 256);
  EXPECT_NEAR((*two)[0], std::log2(a.l2_omega / b.l2_omega), 1e-12);
  EXPECT_NEAR((*two)[2], std::log2(a.l2_gamma / b.l2_gamma), 1e-12);
  // Levels the paper does not have (1/64, and beyond 1/4096): no rate of its own.
  EXPECT_FALSE(fictus::paper_rates_over(Variant::smooth, levels(5, 7)));
  EXPECT_FALSE(fictus::paper_rates_over(Variant::smooth, levels(12, 14)));
  // The printed table names the paper's fit over the same levels.
  const std::string table = fictus::format_convergence_table("t", levels(7, 8), Variant::nonsmooth);
  char expected[64];
  std::snprintf(expected, sizeof expected, "%9.2f", (*two)[0]);
  const std::string fit_line = table.substr(table.find("rates (least-squares fit)"));
  EXPECT_NE(fit_line.find("paper"), std::string::npos) << table;
  EXPECT_NE(fit_line.find(expected), std::string::npos) << table;
}

}  // namespace
